#include "ardsim_pose/evaluation.h"

#include <cmath>
#include <random>

#include "ardsim_dynamics/simulation.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {

PoseErrorValue poseError(const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_truth,
                         const Eigen::Isometry3d& T_target_port) {
  PoseErrorValue e;
  const Eigen::Vector3d port_truth = (T_truth * T_target_port).translation();
  e.range_m = port_truth.norm();
  e.port_position_error_m = (T_est * T_target_port).translation() - port_truth;
  const Eigen::AngleAxisd error(T_est.linear() * T_truth.linear().transpose());
  e.attitude_error_angle_rad = error.angle();
  e.attitude_error_rad = error.angle() * error.axis();
  return e;
}

NormalizedError normalizedError(const PoseErrorValue& error, const Eigen::Matrix<double, 6, 6>& covariance,
                                const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_target_port) {
  const Eigen::Vector3d lever = T_est.linear() * T_target_port.translation();
  NormalizedError n;
  n.port_sigma_m = covarianceAt(covariance, lever).diagonal().head<3>().cwiseMax(0.0).cwiseSqrt();
  n.attitude_sigma_rad = covariance.bottomRightCorner<3, 3>().diagonal().cwiseMax(0.0).cwiseSqrt();
  for (int i = 0; i < 3; ++i) {
    if (n.port_sigma_m(i) > 0.0) n.port_position(i) = error.port_position_error_m(i) / n.port_sigma_m(i);
    if (n.attitude_sigma_rad(i) > 0.0) n.attitude(i) = error.attitude_error_rad(i) / n.attitude_sigma_rad(i);
  }
  return n;
}

Eigen::Isometry3d dockingAxisPose(ardsim_description::TargetKind kind, double port_distance_m) {
  using namespace ardsim_description;
  Eigen::Isometry3d T_port_chaser_port = T_port_port_docked();
  T_port_chaser_port.translation() = Eigen::Vector3d(port_distance_m, 0.0, 0.0);
  const Eigen::Isometry3d T_target_lidar =
      T_target_port(kind) * T_port_chaser_port * T_chaser_port().inverse() * T_chaser_lidar();
  return T_target_lidar.inverse();
}

Eigen::Isometry3d initialFromScenario(const ardsim_dynamics::Scenario& scenario) {
  const ardsim_dynamics::InitialStates states = ardsim_dynamics::initialStates(scenario);
  const Eigen::Isometry3d T_eci_target = ardsim_dynamics::poseOf(states.target);
  Eigen::Isometry3d T_eci_chaser = ardsim_dynamics::poseOf(states.chaser);
  // Subtract the eci positions (7e6 m) first so that no precision is lost.
  Eigen::Isometry3d T_target_chaser = Eigen::Isometry3d::Identity();
  T_target_chaser.linear() = T_eci_target.linear().transpose() * T_eci_chaser.linear();
  T_target_chaser.translation() =
      T_eci_target.linear().transpose() * (states.chaser.position_m - states.target.position_m);
  return (T_target_chaser * ardsim_description::T_chaser_lidar()).inverse();
}

Eigen::Isometry3d perturbPrior(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_target_port,
                               const PriorPerturbation& p, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  auto randomUnit = [&]() {
    Eigen::Vector3d v;
    do v = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    while (v.norm() < 1e-6);
    return v.normalized();
  };
  const Eigen::Vector3d port = (T * T_target_port).translation();
  // Attitude about the port: the port stays where it was.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(p.attitude_deg * M_PI / 180.0, randomUnit()).toRotationMatrix();
  Eigen::Isometry3d out = T;
  out.linear() = R * T.linear();
  out.translation() = port + R * (T.translation() - port);
  // Range and lateral offset of the port.
  const double sign = std::uniform_int_distribution<int>(0, 1)(rng) ? 1.0 : -1.0;
  const Eigen::Vector3d line_of_sight = port.normalized();
  Eigen::Vector3d lateral = randomUnit();
  lateral = (lateral - lateral.dot(line_of_sight) * line_of_sight).normalized();
  const Eigen::Vector3d port_moved = port * (1.0 + sign * p.range_fraction) + p.lateral_m * lateral;
  out.translation() += port_moved - port;
  return out;
}

}  // namespace ardsim_pose
