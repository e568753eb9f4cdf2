// Named frames of the vehicles: the one source of the port and sensor-mount geometry that the dynamics, the
// LIDAR, the pose estimator, guidance and rviz all use. ROS-free.
#pragma once

#include <string>

#include <Eigen/Geometry>

namespace ardsim_description {

enum class TargetKind { kIss, kHubble };

// "iss" or "hubble"; throws std::invalid_argument naming the allowed values otherwise.
TargetKind parseTargetKind(const std::string& name);
std::string targetKindName(TargetKind kind);

// Pose of `target_port` in `target`: origin at the docking plane centre, x out of the port. The `target`
// origin is the vehicle's centre of mass.
Eigen::Isometry3d T_target_port(TargetKind kind);

// Pose of `chaser_port` in `chaser` (x out of the port); `chaser` origin at its centre of mass, x towards the
// port.
Eigen::Isometry3d T_chaser_port();

// Pose of `chaser_port` in `target_port` when docked: the port axes opposed (x against x) and z shared, i.e.
// a half turn about z. The guide petals of the two IDSS interfaces (models.h) interleave in this attitude.
Eigen::Isometry3d T_port_port_docked();

// Pose of `lidar_optical` in `chaser`: z along the boresight (parallel to the chaser port axis), x right, y
// down.
Eigen::Isometry3d T_chaser_lidar();

// T_lidar_target = T_chaser_lidar^-1 * T_eci_chaser^-1 * T_eci_target from the vehicles' eci poses, with the
// eci positions (about 7e6 m) subtracted before anything else so that no precision is lost.
Eigen::Isometry3d lidarFromTarget(const Eigen::Isometry3d& T_eci_target,
                                  const Eigen::Isometry3d& T_eci_chaser,
                                  const Eigen::Isometry3d& T_chaser_lidar);

}  // namespace ardsim_description
