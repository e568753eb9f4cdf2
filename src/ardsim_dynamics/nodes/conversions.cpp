#include "conversions.h"

#include <cmath>

#include <tf2_eigen/tf2_eigen.h>

namespace ardsim_dynamics {
namespace {

void setPose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q, geometry_msgs::Pose& pose) {
  pose.position.x = p.x();
  pose.position.y = p.y();
  pose.position.z = p.z();
  pose.orientation.w = q.w();
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
}

void setVector(const Eigen::Vector3d& v, geometry_msgs::Vector3& out) {
  out.x = v.x();
  out.y = v.y();
  out.z = v.z();
}

Eigen::Vector3d vec(const geometry_msgs::Vector3& v) {
  return Eigen::Vector3d(v.x, v.y, v.z);
}

}  // namespace

void toOdometry(const VehicleState& s, const ros::Time& stamp, const std::string& child_frame,
                nav_msgs::Odometry& msg) {
  msg.header.stamp = stamp;
  msg.header.frame_id = "eci";
  msg.child_frame_id = child_frame;
  setPose(s.position_m, s.attitude, msg.pose.pose);
  setVector(s.velocity_mps, msg.twist.twist.linear);
  setVector(s.angular_velocity_radps, msg.twist.twist.angular);
}

void toOdometry(const RelativeState& s, const ros::Time& stamp, const std::string& frame,
                const std::string& child_frame, nav_msgs::Odometry& msg) {
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.child_frame_id = child_frame;
  setPose(s.pose.translation(), Eigen::Quaterniond(s.pose.linear()), msg.pose.pose);
  setVector(s.velocity_mps, msg.twist.twist.linear);
  setVector(s.angular_velocity_radps, msg.twist.twist.angular);
}

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& T, const ros::Time& stamp,
                                            const std::string& parent, const std::string& child) {
  geometry_msgs::TransformStamped msg = tf2::eigenToTransform(Eigen::Affine3d(T.matrix()));
  msg.header.stamp = stamp;
  msg.header.frame_id = parent;
  msg.child_frame_id = child;
  return msg;
}

geometry_msgs::Wrench toWrench(const BodyWrench& w) {
  geometry_msgs::Wrench msg;
  setVector(w.force_n, msg.force);
  setVector(w.torque_nm, msg.torque);
  return msg;
}

bool fromWrench(const geometry_msgs::Wrench& msg, BodyWrench& w) {
  const Eigen::Vector3d force = vec(msg.force), torque = vec(msg.torque);
  if (!force.allFinite() || !torque.allFinite()) return false;
  w.force_n = force;
  w.torque_nm = torque;
  return true;
}

void toContactEvent(const ContactEvent& event, ardsim_msgs::ContactEvent& msg) {
  msg.header.stamp = ros::Time(event.time_s);
  msg.header.frame_id = "target_port";
  msg.verdict = event.verdict == ContactVerdict::kCapture ? ardsim_msgs::ContactEvent::VERDICT_CAPTURE
                                                          : ardsim_msgs::ContactEvent::VERDICT_COLLISION;
  msg.reason = event.reason;
  msg.target_part = event.target_part;
  msg.chaser_part = event.chaser_part;
  msg.contact_point.x = event.contact_point_m.x();
  msg.contact_point.y = event.contact_point_m.y();
  msg.contact_point.z = event.contact_point_m.z();
  const ContactConditions& c = event.conditions;
  msg.closing_speed_mps = c.closing_speed_mps;
  msg.lateral_misalignment_m = c.lateral_misalignment_m;
  msg.angular_misalignment_rad = c.angular_misalignment_rad;
  msg.lateral_rate_mps = c.lateral_rate_mps;
  msg.angular_rate_rad_s = c.angular_rate_radps;
  msg.within_envelope = event.within_envelope;
}

VehicleState fromOdometry(const nav_msgs::Odometry& msg) {
  VehicleState s;
  const auto& p = msg.pose.pose.position;
  const auto& q = msg.pose.pose.orientation;
  s.position_m = Eigen::Vector3d(p.x, p.y, p.z);
  s.attitude = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
  s.velocity_mps = vec(msg.twist.twist.linear);
  s.angular_velocity_radps = vec(msg.twist.twist.angular);
  return s;
}

}  // namespace ardsim_dynamics
