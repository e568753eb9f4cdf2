#include "ardsim_guidance/geometry.h"

namespace ardsim_guidance {

VehicleFrames VehicleFrames::fromDescription(ardsim_description::TargetKind kind) {
  return {ardsim_description::T_target_port(kind), ardsim_description::T_chaser_port(),
          ardsim_description::T_chaser_lidar()};
}

Eigen::Isometry3d chaserPortInTargetPort(const VehicleFrames& f, const Eigen::Isometry3d& T_lidar_target) {
  return f.T_target_port.inverse() * T_lidar_target.inverse() * f.T_chaser_lidar.inverse() * f.T_chaser_port;
}

Eigen::Isometry3d lidarTargetFromPortPose(const VehicleFrames& f, const Eigen::Isometry3d& T_tp_cp) {
  // T_tp_cp = T_tp_target T_target_lidar T_lidar_chaser T_chaser_cp, solved for T_lidar_target.
  return f.T_chaser_lidar.inverse() * f.T_chaser_port * T_tp_cp.inverse() * f.T_target_port.inverse();
}

Eigen::Vector3d attitudeError(const Eigen::Quaterniond& q_ref_actual,
                              const Eigen::Quaterniond& q_ref_desired) {
  Eigen::Quaterniond q_err = q_ref_desired.conjugate() * q_ref_actual;
  if (q_err.w() < 0.0) q_err.coeffs() = -q_err.coeffs();
  const Eigen::AngleAxisd aa(q_err.normalized());
  return aa.angle() * aa.axis();
}

}  // namespace ardsim_guidance
