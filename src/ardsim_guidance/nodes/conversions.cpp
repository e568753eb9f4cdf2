#include "conversions.h"

#include <cmath>

namespace ardsim_guidance {

namespace {
geometry_msgs::Vector3 toVector3(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}
Eigen::Vector3d fromVector3(const geometry_msgs::Vector3& m) {
  return {m.x, m.y, m.z};
}
}  // namespace

bool toIsometry(const geometry_msgs::Pose& pose, Eigen::Isometry3d* T, std::string* why) {
  const Eigen::Vector3d t(pose.position.x, pose.position.y, pose.position.z);
  const Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
  if (!t.allFinite()) {
    *why = "non-finite position";
    return false;
  }
  if (!q.coeffs().allFinite()) {
    *why = "non-finite quaternion";
    return false;
  }
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    *why = "quaternion norm " + std::to_string(q.norm()) + " is not 1";
    return false;
  }
  *T = Eigen::Isometry3d::Identity();
  T->linear() = q.normalized().toRotationMatrix();
  T->translation() = t;
  return true;
}

geometry_msgs::Pose toPose(const Eigen::Isometry3d& T) {
  geometry_msgs::Pose pose;
  pose.position.x = T.translation().x();
  pose.position.y = T.translation().y();
  pose.position.z = T.translation().z();
  const Eigen::Quaterniond q(T.linear());
  pose.orientation.w = q.w();
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
  return pose;
}

EstimateInput fromPoseEstimate(const ardsim_msgs::PoseEstimate& msg) {
  EstimateInput in;
  in.time_s = msg.header.stamp.toSec();
  in.reason = msg.reason;
  switch (msg.status) {
    case ardsim_msgs::PoseEstimate::STATUS_TRACKING:
      in.status = EstimateStatus::kTracking;
      break;
    case ardsim_msgs::PoseEstimate::STATUS_DEGRADED:
      in.status = EstimateStatus::kDegraded;
      break;
    case ardsim_msgs::PoseEstimate::STATUS_LOST:
      in.status = EstimateStatus::kLost;
      break;
    default:
      in.status = EstimateStatus::kLost;
      in.reason = "unknown status " + std::to_string(msg.status);
      return in;
  }
  // A LOST estimate carries a display-only pose; it is not steered on, so it need not be checked.
  if (in.status == EstimateStatus::kLost) return in;
  std::string why;
  in.well_formed = toIsometry(msg.pose.pose, &in.T_lidar_target, &why);
  if (!in.well_formed) in.reason = "malformed estimate: " + why;
  return in;
}

bool fromOdometry(const nav_msgs::Odometry& msg, OwnState* state, std::string* why) {
  Eigen::Isometry3d T;
  if (!toIsometry(msg.pose.pose, &T, why)) return false;
  const Eigen::Vector3d v = fromVector3(msg.twist.twist.linear), w = fromVector3(msg.twist.twist.angular);
  if (!v.allFinite() || !w.allFinite()) {
    *why = "non-finite twist";
    return false;
  }
  if (T.translation().norm() < 1.0) {
    *why = "position at the Earth's centre";
    return false;
  }
  state->position_eci_m = T.translation();
  state->q_eci_chaser = Eigen::Quaterniond(T.linear());
  state->velocity_eci_mps = v;
  state->rate_body_rad_s = w;
  return true;
}

geometry_msgs::WrenchStamped toWrench(const GuidanceOutput& out, const ros::Time& stamp) {
  geometry_msgs::WrenchStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "chaser";
  msg.wrench.force = toVector3(out.force_body_n);
  msg.wrench.torque = toVector3(out.torque_body_nm);
  return msg;
}

ardsim_msgs::GuidanceState toGuidanceState(const GuidanceOutput& out, const ros::Time& stamp) {
  ardsim_msgs::GuidanceState msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "target_port";
  msg.phase = static_cast<uint8_t>(out.phase);
  msg.reason = out.reason;
  msg.port_position = toVector3(out.port_position_m);
  msg.port_velocity = toVector3(out.port_velocity_mps);
  msg.reference_position = toVector3(out.reference_position_m);
  msg.reference_velocity = toVector3(out.reference_velocity_mps);
  msg.range_m = out.range_m;
  msg.closing_speed_mps = out.closing_speed_mps;
  msg.lateral_error_m = out.lateral_error_m;
  msg.in_corridor = out.in_corridor;
  msg.estimate_status = static_cast<uint8_t>(out.estimate_status);
  msg.delta_v_used_mps = out.delta_v_used_mps;
  return msg;
}

ardsim_msgs::PoseEstimate toPoseEstimate(const TruthPoseSample& sample, const TruthPoseOptions& options,
                                         const ros::Time& stamp) {
  ardsim_msgs::PoseEstimate msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "lidar_optical";
  msg.pose.pose = toPose(sample.T_lidar_target);
  msg.method = ardsim_msgs::PoseEstimate::METHOD_TRUTH;
  msg.status = static_cast<uint8_t>(sample.status);
  msg.reason = sample.reason;
  if (sample.status != EstimateStatus::kLost) {
    const double p = options.position_sigma_m * options.position_sigma_m;
    const double a = options.attitude_sigma_rad * options.attitude_sigma_rad;
    for (int i = 0; i < 3; ++i) {
      msg.pose.covariance[i * 6 + i] = p;
      msg.pose.covariance[(i + 3) * 6 + i + 3] = a;
    }
  }
  msg.velocity_valid = false;
  msg.boresight_rotation_observed = true;
  return msg;
}

}  // namespace ardsim_guidance
