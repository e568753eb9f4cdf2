#include "ardsim_dynamics/orbit.h"

#include <cmath>

namespace ardsim_dynamics {

Eigen::Matrix3d R_ecef_eci(double greenwich_angle_rad) {
  return Eigen::AngleAxisd(-greenwich_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

CartesianState keplerianToCartesian(const KeplerianElements& e, double gm) {
  const double p = e.semi_major_axis_m * (1.0 - e.eccentricity * e.eccentricity);
  const double nu = e.true_anomaly_rad;
  const double r = p / (1.0 + e.eccentricity * std::cos(nu));
  const Eigen::Vector3d r_pqw(r * std::cos(nu), r * std::sin(nu), 0.0);
  const Eigen::Vector3d v_pqw(-std::sqrt(gm / p) * std::sin(nu),
                              std::sqrt(gm / p) * (e.eccentricity + std::cos(nu)), 0.0);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(e.raan_rad, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(e.inclination_rad, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(e.arg_perigee_rad, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  return {R * r_pqw, R * v_pqw};
}

Eigen::Matrix3d R_eci_lvlh(const CartesianState& ref) {
  const Eigen::Vector3d z = -ref.position_m.normalized();
  const Eigen::Vector3d y = -ref.position_m.cross(ref.velocity_mps).normalized();
  Eigen::Matrix3d R;
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  return R;
}

Eigen::Vector3d lvlhRate(const CartesianState& ref) {
  const double r2 = ref.position_m.squaredNorm();
  return Eigen::Vector3d(0.0, -ref.position_m.cross(ref.velocity_mps).norm() / r2, 0.0);
}

CartesianState relativeStateInLvlh(const CartesianState& ref, const CartesianState& other) {
  const Eigen::Matrix3d R = R_eci_lvlh(ref);
  const Eigen::Vector3d rho = R.transpose() * (other.position_m - ref.position_m);
  const Eigen::Vector3d rho_dot =
      R.transpose() * (other.velocity_mps - ref.velocity_mps) - lvlhRate(ref).cross(rho);
  return {rho, rho_dot};
}

CartesianState inertialFromLvlh(const CartesianState& ref, const CartesianState& rel) {
  const Eigen::Matrix3d R = R_eci_lvlh(ref);
  return {ref.position_m + R * rel.position_m,
          ref.velocity_mps + R * (rel.velocity_mps + lvlhRate(ref).cross(rel.position_m))};
}

Eigen::Matrix<double, 6, 6> cwTransition(double n, double t) {
  const double s = std::sin(n * t), c = std::cos(n * t);
  Eigen::Matrix<double, 6, 6> P;
  // Rows: x y z vx vy vz (shared reference cw_and_approach.md, checked there against RK4 of the linear ODE).
  P << 1, 0, 6 * (n * t - s), (4 * s - 3 * n * t) / n, 0, 2 * (1 - c) / n,  //
      0, c, 0, 0, s / n, 0,                                                 //
      0, 0, 4 - 3 * c, -2 * (1 - c) / n, 0, s / n,                          //
      0, 0, 6 * n * (1 - c), 4 * c - 3, 0, 2 * s,                           //
      0, -n * s, 0, 0, c, 0,                                                //
      0, 0, 3 * n * s, -2 * s, 0, c;
  return P;
}

CartesianState cwPropagate(const CartesianState& rel, double n, double t) {
  Eigen::Matrix<double, 6, 1> x0;
  x0 << rel.position_m, rel.velocity_mps;
  const Eigen::Matrix<double, 6, 1> x = cwTransition(n, t) * x0;
  return {x.head<3>(), x.tail<3>()};
}

}  // namespace ardsim_dynamics
