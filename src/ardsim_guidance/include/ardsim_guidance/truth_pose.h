// TEST TOOL, never part of a real run: a pose "estimate" made from the truth (the target and chaser body
// poses in eci), with optional seeded noise and dropouts, so guidance can be exercised without the LIDAR and
// pose chain.
#pragma once

#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_guidance/geometry.h"
#include "ardsim_guidance/safety.h"

namespace ardsim_guidance {

struct TruthPoseOptions {
  double position_sigma_m = 0.0;  // 1-sigma noise per axis on T_lidar_target's translation (lidar_optical)
  // Constant error added to T_lidar_target's translation (lidar_optical): a biased estimator. Guidance trusts
  // it, so a sideways bias aims the chaser beside the port (the collision test).
  Eigen::Vector3d position_bias_m = Eigen::Vector3d::Zero();
  double attitude_sigma_rad = 0.0;   // 1-sigma noise per axis of a small rotation applied to T_lidar_target
  double dropout_probability = 0.0;  // chance that a frame is LOST at random
  std::vector<std::pair<double, double>>
      lost_intervals_s;  // scripted LOST intervals [t0, t1] (simulation time)
  int seed = 1;
};

// Throws std::invalid_argument naming the parameter, value and allowed range.
void validate(const TruthPoseOptions& options);

struct TruthPoseSample {
  Eigen::Isometry3d T_lidar_target = Eigen::Isometry3d::Identity();
  EstimateStatus status = EstimateStatus::kTracking;
  std::string reason;
};

class TruthPoseGenerator {
 public:
  TruthPoseGenerator(const TruthPoseOptions& options, const VehicleFrames& frames);
  // T_eci_target, T_eci_chaser: the body frames in eci at time_s. LOST samples carry the last good pose.
  TruthPoseSample generate(double time_s, const Eigen::Isometry3d& T_eci_target,
                           const Eigen::Isometry3d& T_eci_chaser);

 private:
  TruthPoseOptions options_;
  VehicleFrames frames_;
  std::mt19937_64 rng_;
  Eigen::Isometry3d last_good_ = Eigen::Isometry3d::Identity();
};

}  // namespace ardsim_guidance
