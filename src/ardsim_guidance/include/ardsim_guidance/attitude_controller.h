// Chaser attitude: a PD controller producing body torque, with gyroscopic feedforward.
#pragma once

#include <Eigen/Geometry>

namespace ardsim_guidance {

struct AttitudeOptions {
  double bandwidth_rad_s = 0.3;  // closed-loop natural frequency per axis
  double damping_ratio = 0.9;
  // Chaser inertia about its CoM, body axes (kg m^2): solid-cylinder estimate for a 12.5 t Dragon-class
  // chaser (shared reference iss_environment_and_mass.md: I_axial 2.5e4, I_transverse 8.1e4) — an estimate.
  Eigen::Vector3d inertia_kg_m2{2.5e4, 8.1e4, 8.1e4};
};

// Torque (N m, body axes) that drives q_inertial_body to q_inertial_desired and the body rate to the desired
// rate (both rad/s in body axes): tau = J (-kp e - kd (w - w_d)) + w x J w, with kp = w_n^2, kd = 2 zeta w_n.
Eigen::Vector3d attitudeTorque(const AttitudeOptions& options, const Eigen::Quaterniond& q_inertial_body,
                               const Eigen::Vector3d& rate_body_rad_s,
                               const Eigen::Quaterniond& q_inertial_desired,
                               const Eigen::Vector3d& desired_rate_body_rad_s);

}  // namespace ardsim_guidance
