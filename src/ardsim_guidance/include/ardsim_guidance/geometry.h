// Frame algebra of guidance: the chaser port in the target port from a pose estimate, and the LVLH frame from
// the chaser's own inertial state. T_a_b maps coordinates in frame b to frame a.
#pragma once

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"

namespace ardsim_guidance {

// The fixed frames of ardsim_description that guidance needs.
struct VehicleFrames {
  Eigen::Isometry3d T_target_port;   // target_port in target
  Eigen::Isometry3d T_chaser_port;   // chaser_port in chaser
  Eigen::Isometry3d T_chaser_lidar;  // lidar_optical in chaser
  static VehicleFrames fromDescription(ardsim_description::TargetKind kind);
};

// T_targetport_chaserport from an estimate T_lidar_target (the target body in lidar_optical).
Eigen::Isometry3d chaserPortInTargetPort(const VehicleFrames& frames,
                                         const Eigen::Isometry3d& T_lidar_target);

// Inverse of chaserPortInTargetPort: the T_lidar_target that puts the chaser port at T_targetport_chaserport.
Eigen::Isometry3d lidarTargetFromPortPose(const VehicleFrames& frames,
                                          const Eigen::Isometry3d& T_targetport_chaserport);

// Direction and position of the approach: a point on the docking axis range_m out of the port, in
// target_port.
inline Eigen::Vector3d approachAxisPoint(double range_m) {
  return {range_m, 0.0, 0.0};
}

// Attitude error as a rotation vector (rad) of R_desired^T R_actual, in the actual body frame: the rotation
// that takes the desired attitude to the actual one. Shortest way round.
Eigen::Vector3d attitudeError(const Eigen::Quaterniond& q_ref_actual,
                              const Eigen::Quaterniond& q_ref_desired);

}  // namespace ardsim_guidance
