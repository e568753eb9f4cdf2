// The estimator facade (PoseEstimator) with scripted methods: the median filter on a steady approach, and
// what the motion prediction learns from TRACKING, DEGRADED and acquisition estimates; the per-target config.
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/estimator_factory.h"
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

// The truth of a target closing at 5 m/s and turning at a constant rate, 1 deg a frame about the boresight
// and 0.5 deg about lidar x; per frame a scripted status. Records the prediction each frame was given.
class MotionScript : public PoseMethod {
 public:
  struct Step {
    EstimateStatus status = EstimateStatus::kTracking;
    bool acquiring = false;
    bool boresight_observed = true;
  };
  explicit MotionScript(std::map<int, Step> steps) : steps_(std::move(steps)) {}
  static Eigen::Isometry3d truth(int frame) {
    Eigen::Isometry3d T = truthAt(0.1 * frame);
    const Eigen::Vector3d turn_per_frame_rad = Eigen::Vector3d(0.5, 0.0, 1.0) * M_PI / 180.0;
    T.linear() = Eigen::AngleAxisd(frame * turn_per_frame_rad.norm(), turn_per_frame_rad.normalized())
                     .toRotationMatrix();
    return T;
  }
  PoseResult estimate(const OrganizedCloud& cloud, const Eigen::Isometry3d& predicted) override {
    const int frame = static_cast<int>(std::lround(cloud.stamp_s * 10.0));
    predictions[frame] = predicted;
    const Step step = steps_.count(frame) ? steps_.at(frame) : Step{};
    PoseResult result;
    result.status = step.status;
    result.acquiring = step.acquiring;
    result.boresight_rotation_observed = step.boresight_observed;
    result.T_lidar_target = truth(frame);
    return result;
  }
  void reset() override {}
  std::map<int, Eigen::Isometry3d> predictions;

 private:
  std::map<int, Step> steps_;
};

// The prediction each of frames 0 .. frames-1 was given by an estimator over MotionScript(steps).
std::map<int, Eigen::Isometry3d> predictionsOver(std::map<int, MotionScript::Step> steps, int frames) {
  auto script = std::make_unique<MotionScript>(std::move(steps));
  MotionScript* probe = script.get();
  PoseEstimator::Methods methods;
  methods[EstimateMethod::kIcp] = std::move(script);
  PoseEstimator estimator(EstimatorOptions{}, std::move(methods),
                          std::make_unique<FixedMethodSelector>(EstimateMethod::kIcp));
  estimator.setPrior(MotionScript::truth(0));
  OrganizedCloud cloud;
  for (int frame = 0; frame < frames; ++frame) {
    cloud.stamp_s = 0.1 * frame;
    estimator.process(cloud);
  }
  return probe->predictions;
}

double angleDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

TEST(PoseEstimatorPrediction, DegradedKeepsTheLinearVelocityAcquisitionResetsIt) {
  using Step = MotionScript::Step;
  std::map<int, Step> steps;
  steps[5] = Step{EstimateStatus::kDegraded, false, true};  // tracking, but degraded
  steps[9] = Step{EstimateStatus::kDegraded, true, true};   // an acquisition estimate
  const std::map<int, Eigen::Isometry3d> predictions = predictionsOver(steps, 13);
  auto position_error = [&](int frame) {
    return (predictions.at(frame).translation() - MotionScript::truth(frame).translation()).norm();
  };
  // Learnt from TRACKING pairs: the next frame predicted exactly.
  EXPECT_LT(position_error(5), 1e-9);
  EXPECT_LT(angleDeg(predictions.at(5), MotionScript::truth(5)), 1e-6);
  // After the DEGRADED frame: the linear velocity kept (it was reset before: 0.5 m off), the angular one
  // dropped (the prediction keeps frame 5's attitude).
  EXPECT_LT(position_error(6), 1e-9);
  EXPECT_NEAR(angleDeg(predictions.at(6), MotionScript::truth(5)), 0.0, 1e-6);
  // After the acquisition estimate: no velocity at all, the prediction is that estimate; so after the next
  // (TRACKING, but paired with the acquisition's).
  EXPECT_NEAR(position_error(10), 0.5, 1e-9);
  EXPECT_NEAR(position_error(11), 0.5, 1e-9);
  // After a TRACKING pair it is learnt again.
  EXPECT_LT(position_error(12), 1e-9);
}

TEST(PoseEstimatorPrediction, AnUnobservedBoresightRotationIsNoMotion) {
  using Step = MotionScript::Step;
  std::map<int, Step> steps;
  for (int frame = 0; frame < 6; ++frame) steps[frame] = Step{EstimateStatus::kTracking, false, false};
  const std::map<int, Eigen::Isometry3d> predictions = predictionsOver(steps, 6);
  // The turn about lidar x is extrapolated, the one about the boresight (held by the method) is not. (The
  // prediction's turn from frame 4 is the rotation vector's x part of one frame's turn.)
  const Eigen::Matrix3d R = predictions.at(5).linear() * MotionScript::truth(4).linear().transpose();
  const Eigen::AngleAxisd turn(R);
  const Eigen::Vector3d turn_deg = turn.angle() * turn.axis() * 180.0 / M_PI;
  EXPECT_NEAR(turn_deg.z(), 0.0, 1e-3);
  EXPECT_NEAR(std::abs(turn_deg.x()), 0.5, 0.02);
}

// Hubble hands over to the close-range method at 20 m; the pyramid method gave poses 7 cm off beyond 12 m, so
// choosing it there is an error at start that names the parameter.
TEST(PoseConfigTargets, PyramidBeyondTwelveMetresIsRefused) {
  PoseConfig hubble;
  hubble.target = ardsim_description::TargetKind::kHubble;
  applyTargetDefaults(&hubble);
  EXPECT_DOUBLE_EQ(hubble.mode.close_enter_range_m, 20.0);
  EXPECT_NO_THROW(validate(hubble));
  hubble.mode.close_method = EstimateMethod::kPyramid;
  try {
    validate(hubble);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mode/close_enter_range_m = 20"), std::string::npos) << e.what();
  }
  hubble.mode.close_enter_range_m = 12.0;
  EXPECT_NO_THROW(validate(hubble));
  PoseConfig iss;
  applyTargetDefaults(&iss);
  iss.mode.close_method = EstimateMethod::kPyramid;
  EXPECT_NO_THROW(validate(iss));
}

}  // namespace
}  // namespace ardsim_pose
