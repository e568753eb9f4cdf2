// Estimate-minus-truth errors (the evaluator node and evaluate_dataset), the docking-axis approach poses used
// to render test datasets, and the initial estimate: from a scenario, and the coarse prior's seeded
// perturbation. ROS-free.
#pragma once

#include <cstdint>

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"

namespace ardsim_dynamics {
struct Scenario;
}

namespace ardsim_pose {

struct PoseErrorValue {
  double range_m = 0.0;  // truth distance from the lidar to the target_port origin
  Eigen::Vector3d port_position_error_m =
      Eigen::Vector3d::Zero();  // estimated - true target_port, lidar_optical
  // Rotation vector of R_est * R_truth^T in lidar_optical (x, y: tilts across the boresight; z: about it),
  // rad.
  Eigen::Vector3d attitude_error_rad = Eigen::Vector3d::Zero();
  double attitude_error_angle_rad = 0.0;
};

PoseErrorValue poseError(const Eigen::Isometry3d& T_lidar_target_estimated,
                         const Eigen::Isometry3d& T_lidar_target_truth,
                         const Eigen::Isometry3d& T_target_port);

// The error in the units of the estimate's own covariance (PoseResult::covariance: the target origin's
// position and rotation in lidar_optical): each component of the port position error and of the attitude
// error (both in lidar_optical) over its sigma, the port's propagated through the lever from the origin. A
// covariance that says what the errors are gives an RMS of 1 on every axis; below 1 it is pessimistic.
struct NormalizedError {
  Eigen::Vector3d port_sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d attitude_sigma_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d port_position = Eigen::Vector3d::Zero();  // error / sigma (0 where a sigma is 0)
  Eigen::Vector3d attitude = Eigen::Vector3d::Zero();
};
NormalizedError normalizedError(const PoseErrorValue& error, const Eigen::Matrix<double, 6, 6>& covariance,
                                const Eigen::Isometry3d& T_lidar_target_estimated,
                                const Eigen::Isometry3d& T_target_port);

// T_lidar_target with the chaser in docking attitude on the docking axis, its port port_distance_m out along
// target_port x; the lidar sits on the chaser port axis (T_chaser_lidar), so the target port is on the
// boresight.
Eigen::Isometry3d dockingAxisPose(ardsim_description::TargetKind kind, double port_distance_m);

// T_lidar_target at the scenario's initial state (the chaser's initial state relative to the target).
Eigen::Isometry3d initialFromScenario(const ardsim_dynamics::Scenario& scenario);

// A coarse prior: the truth (or initial estimate) turned by attitude_deg about a random axis through the
// target_port, its port range scaled by 1 +- range_fraction and moved lateral_m across the line of sight in a
// random direction. Seeded; the magnitudes are exact (the worst case of the +- bounds), the directions
// random.
struct PriorPerturbation {
  double attitude_deg = 10.0;
  double range_fraction = 0.1;
  double lateral_m = 2.0;
};
Eigen::Isometry3d perturbPrior(const Eigen::Isometry3d& T_lidar_target,
                               const Eigen::Isometry3d& T_target_port, const PriorPerturbation& perturbation,
                               std::uint64_t seed);

}  // namespace ardsim_pose
