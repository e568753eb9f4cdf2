// Standard views of a target used by the benchmark and tests: the sensor on the docking axis, looking at the
// port. ROS-free.
#pragma once

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"

namespace ardsim_lidar {

// T_lidar_target with the sensor range_m out along the port's x axis, boresight into the port, image x along
// the port's y axis.
inline Eigen::Isometry3d lidarOnDockingAxis(ardsim_description::TargetKind kind, double range_m) {
  Eigen::Isometry3d T_port_lidar = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d::UnitY();   // image right
  R.col(1) = -Eigen::Vector3d::UnitZ();  // image down
  R.col(2) = -Eigen::Vector3d::UnitX();  // boresight, into the port
  T_port_lidar.linear() = R;
  T_port_lidar.translation() = Eigen::Vector3d(range_m, 0.0, 0.0);
  return (ardsim_description::T_target_port(kind) * T_port_lidar).inverse();
}

}  // namespace ardsim_lidar
