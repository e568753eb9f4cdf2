// Orbits, the Earth's rotation, LVLH frames and Clohessy-Wiltshire relative motion. ROS-free.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ardsim_dynamics {

// EGM96 GM and the IERS nominal mean Earth rotation rate.
constexpr double kEarthGm = 3.986004415e14;                  // m^3/s^2
constexpr double kEarthRotationRate = 7.292115146706979e-5;  // rad/s

// Earth-fixed frame as a rotation about the inertial z axis by the Greenwich angle gmst0 + w t (precession,
// nutation and polar motion are left out: eci is "J2000-like", enough for relative motion over hours).
Eigen::Matrix3d R_ecef_eci(double greenwich_angle_rad);

struct CartesianState {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
};

struct KeplerianElements {
  double semi_major_axis_m = 0.0;
  double eccentricity = 0.0;
  double inclination_rad = 0.0;
  double raan_rad = 0.0;
  double arg_perigee_rad = 0.0;
  double true_anomaly_rad = 0.0;
};

CartesianState keplerianToCartesian(const KeplerianElements& elements, double gm = kEarthGm);

// LVLH of a vehicle at the given inertial state (NASA convention): x along-track (V-bar), z to the Earth's
// centre (R-bar), y = z x x (H-bar, minus the orbit normal). Columns are the LVLH axes in eci: maps LVLH
// coords to eci.
Eigen::Matrix3d R_eci_lvlh(const CartesianState& reference);
// Angular velocity of that LVLH frame relative to eci, in LVLH coordinates: (0, -|r x v| / |r|^2, 0).
Eigen::Vector3d lvlhRate(const CartesianState& reference);

// Relative state of `other` in the LVLH of `reference` (position and velocity as seen in the rotating frame),
// and back.
CartesianState relativeStateInLvlh(const CartesianState& reference, const CartesianState& other);
CartesianState inertialFromLvlh(const CartesianState& reference, const CartesianState& relative_lvlh);

// Clohessy-Wiltshire closed-form transition over t seconds for mean motion n, in the LVLH axes above.
Eigen::Matrix<double, 6, 6> cwTransition(double mean_motion_rad_s, double t_s);
CartesianState cwPropagate(const CartesianState& relative_lvlh, double mean_motion_rad_s, double t_s);

}  // namespace ardsim_dynamics
