#include <gtest/gtest.h>

#include <sstream>

#include "ardsim_lidar/pose_file.h"

namespace ardsim_lidar {
namespace {

TEST(PoseFile, ParsesRowsSkipsHeaderAndCommentsAndReportsBadRowsByLine) {
  std::istringstream input(
      "x y z qx qy qz qw\n"              // 1: header
      "# a comment\n"                    // 2
      "1 2 3 0 0 0 1\n"                  // 3
      "\n"                               // 4
      "1,2,3,0,0,0.7071068,0.7071068\n"  // 5: commas
      "1 2 3 0 0 0\n"                    // 6: six fields
      "1 2 oops 0 0 0 1\n"               // 7: not a number
      "1 2 3 0 0 0 2\n"                  // 8: not a unit quaternion
      "4 5 6 0 0 0 1 \r\n");             // 9: CRLF and trailing space
  std::vector<PoseRow> poses;
  std::vector<PoseRowError> errors;
  parsePoses(input, &poses, &errors);
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[0].line_number, 3);
  EXPECT_TRUE(poses[0].T_lidar_target.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(poses[1].line_number, 5);
  EXPECT_TRUE(
      (poses[1].T_lidar_target.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-6));
  EXPECT_EQ(poses[2].line_number, 9);
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0].line_number, 6);
  EXPECT_EQ(errors[1].line_number, 7);
  EXPECT_NE(errors[1].message.find("oops"), std::string::npos);
  EXPECT_EQ(errors[2].line_number, 8);
}

TEST(PoseFile, ANonNumericLineAfterTheFirstIsAnError) {
  std::istringstream input("0 0 5 0 0 0 1\nx y z qx qy qz qw\n");
  std::vector<PoseRow> poses;
  std::vector<PoseRowError> errors;
  parsePoses(input, &poses, &errors);
  EXPECT_EQ(poses.size(), 1u);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].line_number, 2);
}

}  // namespace
}  // namespace ardsim_lidar
