#include "ardsim_description/frames.h"

#include <stdexcept>

namespace ardsim_description {

TargetKind parseTargetKind(const std::string& name) {
  if (name == "iss") return TargetKind::kIss;
  if (name == "hubble") return TargetKind::kHubble;
  throw std::invalid_argument("target '" + name + "' is not one of: iss, hubble");
}

std::string targetKindName(TargetKind kind) {
  return kind == TargetKind::kIss ? "iss" : "hubble";
}

Eigen::Isometry3d T_target_port(TargetKind kind) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (kind == TargetKind::kIss) {
    // IDA-2 on PMA-2 on Harmony: docking plane at X ~ +14.5 m, Z ~ +4..+5 m below the truss, facing +X
    // (+V-bar) [iss_geometry.md: derived from module lengths; the Z offset is an estimate]. Body origin taken
    // at the CoM, assumed at the S0 centre (estimate).
    T.translation() = Eigen::Vector3d(14.5, 0.0, 4.5);
  } else {
    // Hubble soft-capture mechanism on the aft bulkhead, 13.2 m long telescope with its CoM near mid-length
    // [src: length; CoM position estimate]; body x points to the aperture, so the port faces -x.
    T.translation() = Eigen::Vector3d(-6.6, 0.0, 0.0);
    T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
  return T;
}

Eigen::Isometry3d T_chaser_port() {
  // Crew-Dragon-sized chaser (8.1 m with trunk): nose docking port 3.0 m ahead of the CoM (estimate).
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(3.0, 0.0, 0.0);
  return T;
}

Eigen::Isometry3d T_port_port_docked() {
  return Eigen::Isometry3d(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
}

Eigen::Isometry3d T_chaser_lidar() {
  // On the port axis, 1.0 m behind the port plane, looking out of the port (estimate): centred so that the
  // target port stays in the 20 deg field of view down to contact.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  // Columns: lidar x (image right) = chaser +y (starboard), lidar y (image down) = chaser +z (nadir side),
  // lidar z (boresight) = chaser +x.
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d::UnitY();
  R.col(1) = Eigen::Vector3d::UnitZ();
  R.col(2) = Eigen::Vector3d::UnitX();
  T.linear() = R;
  return T;
}

Eigen::Isometry3d lidarFromTarget(const Eigen::Isometry3d& T_eci_target,
                                  const Eigen::Isometry3d& T_eci_chaser,
                                  const Eigen::Isometry3d& T_chaser_lidar) {
  const Eigen::Matrix3d R_chaser_eci = T_eci_chaser.linear().transpose();
  Eigen::Isometry3d T_chaser_target = Eigen::Isometry3d::Identity();
  T_chaser_target.linear() = R_chaser_eci * T_eci_target.linear();
  T_chaser_target.translation() = R_chaser_eci * (T_eci_target.translation() - T_eci_chaser.translation());
  return T_chaser_lidar.inverse() * T_chaser_target;
}

}  // namespace ardsim_description
