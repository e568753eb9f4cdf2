#include "ardsim_dynamics/actuator.h"

#include <algorithm>
#include <cmath>

namespace ardsim_dynamics {

ActuatorModel::ActuatorModel(const ActuatorOptions& options, std::uint64_t seed)
    : options_(options), rng_(seed) {}

Eigen::Vector3d ActuatorModel::applyAxes(const Eigen::Vector3d& commanded, const Eigen::Vector3d& limit,
                                         double min_impulse, double noise_fraction, double duration_s) {
  Eigen::Vector3d applied;
  for (int i = 0; i < 3; ++i) {
    // Draw for every axis every step so the random sequence does not depend on which axes fired.
    const double noise = normal_(rng_);
    double value = std::isfinite(commanded[i]) ? std::clamp(commanded[i], -limit[i], limit[i]) : 0.0;
    if (std::abs(value) * duration_s < min_impulse) value = 0.0;
    applied[i] = value * (1.0 + noise_fraction * noise);
  }
  return applied;
}

BodyWrench ActuatorModel::apply(const BodyWrench& commanded, double duration_s) {
  BodyWrench applied;
  applied.force_n = applyAxes(commanded.force_n, options_.max_force_n, options_.min_impulse_bit_ns,
                              options_.force_noise_fraction, duration_s);
  applied.torque_nm =
      applyAxes(commanded.torque_nm, options_.max_torque_nm, options_.min_angular_impulse_bit_nms,
                options_.torque_noise_fraction, duration_s);
  return applied;
}

}  // namespace ardsim_dynamics
