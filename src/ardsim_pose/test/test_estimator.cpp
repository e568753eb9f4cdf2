// The estimator facade (PoseEstimator) with a scripted method: the median filter on a steady approach.
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/pose_estimator.h"

namespace ardsim_pose {
namespace {

// The target closing along the boresight at 5 m/s (0.5 m a 0.1 s frame, as the approach datasets), with
// scripted lateral noise and, at one frame, a 0.5 m outlier across the boresight.
Eigen::Isometry3d truthAt(double stamp_s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.0, 0.0, 60.0 - 5.0 * stamp_s);
  return T;
}

class ScriptedMethod : public PoseMethod {
 public:
  PoseResult estimate(const OrganizedCloud& cloud, const Eigen::Isometry3d&) override {
    PoseResult result;
    result.status = EstimateStatus::kTracking;
    result.T_lidar_target = truthAt(cloud.stamp_s);
    const int frame = static_cast<int>(std::lround(cloud.stamp_s * 10.0));
    result.T_lidar_target.translation().x() += frame == 12 ? 0.5 : 0.02 * std::sin(2.3 * frame);
    return result;
  }
  void reset() override {}
};

TEST(PoseEstimatorMedianFilter, NeitherLagsASteadyApproachNorPassesAnOutlier) {
  EstimatorOptions options;
  options.median_filter = true;
  PoseEstimator::Methods methods;
  methods[EstimateMethod::kIcp] = std::make_unique<ScriptedMethod>();
  PoseEstimator estimator(options, std::move(methods),
                          std::make_unique<FixedMethodSelector>(EstimateMethod::kIcp));
  estimator.setPrior(truthAt(0.0));
  OrganizedCloud cloud;
  for (int frame = 0; frame < 30; ++frame) {
    cloud.stamp_s = 0.1 * frame;
    const EstimatorOutput out = estimator.process(cloud);
    const Eigen::Vector3d error =
        out.result.T_lidar_target.translation() - truthAt(cloud.stamp_s).translation();
    SCOPED_TRACE("frame " + std::to_string(frame));
    // Along the motion: a plain median of the last five lagged 1 m (two frames).
    EXPECT_LT(std::abs(error.z()), 1e-9);
    // Across: within the scripted noise, the outlier rejected once the window holds three estimates.
    EXPECT_LT(std::abs(error.x()), frame == 12 ? 0.05 : 0.021);
  }
}

}  // namespace
}  // namespace ardsim_pose
