#include "ardsim_guidance/truth_pose.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ardsim_guidance {

void validate(const TruthPoseOptions& o) {
  auto fail = [](const std::string& name, double value, const std::string& range) {
    std::ostringstream s;
    s << "parameter '" << name << "' = " << value << " is outside the allowed range " << range;
    throw std::invalid_argument(s.str());
  };
  if (!(o.position_sigma_m >= 0.0 && std::isfinite(o.position_sigma_m)))
    fail("position_sigma_m", o.position_sigma_m, "[0, inf)");
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(o.position_bias_m[i]) <= 100.0))
      fail("position_bias_m[" + std::to_string(i) + "]", o.position_bias_m[i], "[-100, 100]");
  }
  if (!(o.attitude_sigma_rad >= 0.0 && o.attitude_sigma_rad <= 0.5))
    fail("attitude_sigma_deg (rad)", o.attitude_sigma_rad, "[0, 0.5]");
  if (!(o.dropout_probability >= 0.0 && o.dropout_probability <= 1.0))
    fail("dropout_probability", o.dropout_probability, "[0, 1]");
  for (size_t i = 0; i < o.lost_intervals_s.size(); ++i) {
    const auto& [t0, t1] = o.lost_intervals_s[i];
    if (!(std::isfinite(t0) && std::isfinite(t1) && t1 >= t0)) {
      fail("lost_intervals_s[" + std::to_string(i) + "] end", t1, "[start " + std::to_string(t0) + ", inf)");
    }
  }
}

TruthPoseGenerator::TruthPoseGenerator(const TruthPoseOptions& options, const VehicleFrames& frames)
    : options_(options), frames_(frames), rng_(static_cast<std::uint64_t>(options.seed)) {
  validate(options_);
}

TruthPoseSample TruthPoseGenerator::generate(double t, const Eigen::Isometry3d& T_eci_target,
                                             const Eigen::Isometry3d& T_eci_chaser) {
  // Every frame draws the same numbers whatever its status, so a seed gives one noise sequence.
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Eigen::Vector3d dp, dtheta;
  for (int i = 0; i < 3; ++i) dp[i] = unit(rng_);
  for (int i = 0; i < 3; ++i) dtheta[i] = unit(rng_);
  const bool dropped = uniform(rng_) < options_.dropout_probability;

  TruthPoseSample sample;
  for (const auto& [t0, t1] : options_.lost_intervals_s) {
    if (t >= t0 && t <= t1) {
      sample.status = EstimateStatus::kLost;
      sample.reason = "scripted LOST interval";
    }
  }
  if (sample.status != EstimateStatus::kLost && dropped) {
    sample.status = EstimateStatus::kLost;
    sample.reason = "random dropout";
  }
  if (sample.status == EstimateStatus::kLost) {
    sample.T_lidar_target = last_good_;
    return sample;
  }
  Eigen::Isometry3d T = frames_.T_chaser_lidar.inverse() * T_eci_chaser.inverse() * T_eci_target;
  const Eigen::Vector3d rotation = dtheta * options_.attitude_sigma_rad;
  if (rotation.norm() > 0.0) {
    T.linear() = Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix() * T.linear();
  }
  T.translation() += dp * options_.position_sigma_m + options_.position_bias_m;
  sample.T_lidar_target = T;
  last_good_ = T;
  return sample;
}

}  // namespace ardsim_guidance
