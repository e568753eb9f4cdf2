// Golden regression of the close-range methods on a committed noisy approach (golden/, made by
// pose_close_range_make_golden, see make_golden.cpp): the estimates must match the recorded ones.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/close_range/pyramid.h"
#include "ardsim_pose/close_range/ring_detector.h"
#include "golden_io.h"
#include "rendering.h"

namespace ardsim_pose {
namespace close_range {
namespace {

const std::string kDir = CLOSE_RANGE_GOLDEN_DIR;

void checkAgainstGolden(PoseMethod& method, const std::string& name) {
  const std::vector<golden::Row> truth = golden::readRows(kDir + "/truth.csv", false);
  const std::vector<golden::Row> expected = golden::readRows(kDir + "/expected_" + name + ".csv", true);
  ASSERT_EQ(truth.size(), golden::goldenRanges().size());
  ASSERT_EQ(expected.size(), truth.size());
  std::vector<OrganizedCloud> frames(truth.size());
  for (std::size_t k = 0; k < frames.size(); ++k)
    ASSERT_TRUE(golden::readFrame(kDir, static_cast<int>(k), &frames[k]));
  std::vector<Eigen::Isometry3d> truths;
  for (const golden::Row& row : truth) truths.push_back(row.T);
  const std::vector<golden::Row> rows = golden::estimateAll(method, frames, truths);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    SCOPED_TRACE(name + " frame " + std::to_string(k));
    EXPECT_EQ(rows[k].status, expected[k].status);
    EXPECT_EQ(rows[k].observed, expected[k].observed);
    EXPECT_LT((rows[k].T.translation() - expected[k].T.translation()).norm(), 1e-3);
    EXPECT_LT(Eigen::AngleAxisd(rows[k].T.linear().transpose() * expected[k].T.linear()).angle(),
              0.01 * testing::kDegToRad);
    // And still within the goals against the truth.
    const testing::PortError e = testing::portError(rows[k].T, truth[k].T);
    EXPECT_NE(rows[k].status, static_cast<int>(EstimateStatus::kLost));
    EXPECT_LT(e.lateral(), 0.02);
    EXPECT_LT(std::abs(e.range_m), 0.01);
  }
}

TEST(CloseRangeGolden, Ring) {
  RingMethod ring;
  checkAgainstGolden(ring, "ring");
}

TEST(CloseRangeGolden, Pyramid) {
  PyramidMethod pyramid;
  checkAgainstGolden(pyramid, "pyramid");
}

}  // namespace
}  // namespace close_range
}  // namespace ardsim_pose
