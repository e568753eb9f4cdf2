// Actuator model between the commanded and the applied wrench: per-axis saturation, minimum impulse bit and
// seeded noise. ROS-free.
#pragma once

#include <cstdint>
#include <random>

#include "ardsim_dynamics/vehicle_dynamics.h"

namespace ardsim_dynamics {

struct ActuatorOptions {
  // Estimates for a ~12.5 t capsule with 16 Draco-class (~400 N) thrusters, paired per axis.
  Eigen::Vector3d max_force_n = Eigen::Vector3d::Constant(400.0);
  Eigen::Vector3d max_torque_nm = Eigen::Vector3d::Constant(400.0);
  // A thruster cannot deliver less than its minimum impulse bit: an axis whose commanded impulse over the
  // control step is below it fires nothing (N s, N m s).
  double min_impulse_bit_ns = 0.0;
  double min_angular_impulse_bit_nms = 0.0;
  // 1-sigma relative error of each fired axis (0 = exact).
  double force_noise_fraction = 0.0;
  double torque_noise_fraction = 0.0;
};

class ActuatorModel {
 public:
  ActuatorModel(const ActuatorOptions& options, std::uint64_t seed);
  // The wrench actually applied over a control step of the given duration. Non-finite commands apply nothing.
  BodyWrench apply(const BodyWrench& commanded, double duration_s);

 private:
  Eigen::Vector3d applyAxes(const Eigen::Vector3d& commanded, const Eigen::Vector3d& limit,
                            double min_impulse, double noise_fraction, double duration_s);
  ActuatorOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace ardsim_dynamics
