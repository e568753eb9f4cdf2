// Golden regression: the estimator over the committed frames of test/golden (ISS, noise on, 128 x 128, two
// frames at 100, 30 and 10 m, initial estimate = truth) must reproduce the stored estimates
// (expected_estimates.csv, written by evaluate_dataset) within 1 mm and 0.01 deg with the same status, and
// meet the accuracy goals against the truth. Regenerate with test/golden/regenerate.sh (see README).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/dataset.h"
#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"

namespace ardsim_pose {
namespace {

struct ExpectedRow {
  std::string status;
  Eigen::Isometry3d T_lidar_target = Eigen::Isometry3d::Identity();
};

std::vector<ExpectedRow> readExpected(const std::string& path) {
  std::ifstream input(path);
  EXPECT_TRUE(input.good()) << path;
  std::vector<ExpectedRow> rows;
  std::string line;
  std::getline(input, line);  // header
  while (std::getline(input, line)) {
    std::vector<std::string> fields;
    std::stringstream stream(line);
    for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
    if (fields.size() < 10) {
      ADD_FAILURE() << path << ": malformed row " << line;
      continue;
    }
    ExpectedRow row;
    row.status = fields[2];
    row.T_lidar_target.translation() =
        Eigen::Vector3d(std::stod(fields[3]), std::stod(fields[4]), std::stod(fields[5]));
    row.T_lidar_target.linear() = Eigen::Quaterniond(std::stod(fields[9]), std::stod(fields[6]),
                                                     std::stod(fields[7]), std::stod(fields[8]))
                                      .normalized()
                                      .toRotationMatrix();
    rows.push_back(row);
  }
  return rows;
}

const char* statusName(EstimateStatus status) {
  return status == EstimateStatus::kTracking ? "TRACKING"
                                             : (status == EstimateStatus::kDegraded ? "DEGRADED" : "LOST");
}

class Golden : public ::testing::TestWithParam<int> {};

TEST_P(Golden, ReproducesTheStoredEstimatesAndMeetsTheGoals) {
  const int range_m = GetParam();
  const std::string directory = std::string(ARDSIM_POSE_GOLDEN_DIR) + "/iss_" + std::to_string(range_m);
  const std::vector<TruthRow> truth = readTruth(directory + "/truth.csv");
  const std::vector<ExpectedRow> expected = readExpected(directory + "/expected_estimates.csv");
  ASSERT_EQ(truth.size(), expected.size());
  ASSERT_FALSE(truth.empty());

  // As evaluate_dataset --init truth: the sensor size from the frames, frames 0.1 s apart.
  std::vector<OrganizedCloud> clouds;
  for (std::size_t k = 0; k < truth.size(); ++k)
    clouds.push_back(loadFrame(framePath(directory, truth[k].frame), 0.1 * static_cast<double>(k)));
  PoseConfig config;
  config.sensor.width = clouds[0].width;
  config.sensor.height = clouds[0].height;
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(config);
  estimator->setPrior(truth.front().T_lidar_target);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(config.target);
  const double position_goal_m = range_m > 50 ? 0.05 : 0.02;
  const double attitude_goal_deg = range_m > 50 ? 0.1 : 0.05;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const EstimatorOutput out = estimator->process(clouds[k]);
    EXPECT_EQ(statusName(out.result.status), expected[k].status) << out.result.reason;
    // Against the stored estimate: a regression of the estimator's output.
    const PoseErrorValue drift =
        poseError(out.result.T_lidar_target, expected[k].T_lidar_target, T_target_port);
    EXPECT_LT(drift.port_position_error_m.norm(), 0.001);
    EXPECT_LT(drift.attitude_error_angle_rad * 180.0 / M_PI, 0.01);
    // Against the truth: the goals.
    const PoseErrorValue error = poseError(out.result.T_lidar_target, truth[k].T_lidar_target, T_target_port);
    EXPECT_LT(error.port_position_error_m.norm(), position_goal_m);
    EXPECT_LT(error.attitude_error_angle_rad * 180.0 / M_PI, attitude_goal_deg);
  }
}

INSTANTIATE_TEST_SUITE_P(Ranges, Golden, ::testing::Values(100, 30, 10));

// The tool itself, with --out: its estimates go there (the same as the stored ones), none into the dataset.
TEST(EvaluateDataset, WritesItsEstimatesWhereAsked) {
  const std::string directory = std::string(ARDSIM_POSE_GOLDEN_DIR) + "/iss_30";
  const std::string out = ::testing::TempDir() + "/evaluate_dataset_out.csv";
  std::remove(out.c_str());
  const std::string command = std::string(ARDSIM_POSE_EVALUATE_DATASET) + " --dataset " + directory +
                              " --init truth --out " + out + " > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const std::vector<ExpectedRow> written = readExpected(out);
  const std::vector<ExpectedRow> expected = readExpected(directory + "/expected_estimates.csv");
  ASSERT_EQ(written.size(), expected.size());
  const Eigen::Isometry3d T_target_port =
      ardsim_description::T_target_port(ardsim_description::TargetKind::kIss);
  for (std::size_t k = 0; k < written.size(); ++k) {
    EXPECT_EQ(written[k].status, expected[k].status);
    const PoseErrorValue drift =
        poseError(written[k].T_lidar_target, expected[k].T_lidar_target, T_target_port);
    EXPECT_LT(drift.port_position_error_m.norm(), 0.001);
  }
  EXPECT_FALSE(std::ifstream(directory + "/estimates.csv").good());
}

}  // namespace
}  // namespace ardsim_pose
