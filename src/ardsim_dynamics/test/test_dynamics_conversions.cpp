#include <gtest/gtest.h>

#include <cmath>

#include "../nodes/conversions.h"

using namespace ardsim_dynamics;

TEST(Conversions, VehicleOdometryRoundTrip) {
  VehicleState s;
  s.position_m = Eigen::Vector3d(6.8e6, -12.5, 3.25);
  s.velocity_mps = Eigen::Vector3d(1.0, 7650.0, -2.0);
  s.attitude = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  s.angular_velocity_radps = Eigen::Vector3d(0.001, -0.0011, 0.02);
  nav_msgs::Odometry msg;
  toOdometry(s, ros::Time(12.3), "chaser", msg);
  EXPECT_EQ(msg.header.frame_id, "eci");
  EXPECT_EQ(msg.child_frame_id, "chaser");
  EXPECT_EQ(msg.header.stamp, ros::Time(12.3));
  const VehicleState back = fromOdometry(msg);
  EXPECT_EQ(back.position_m, s.position_m);
  EXPECT_EQ(back.velocity_mps, s.velocity_mps);
  EXPECT_EQ(back.angular_velocity_radps, s.angular_velocity_radps);
  EXPECT_NEAR(back.attitude.angularDistance(s.attitude), 0.0, 1e-15);
}

TEST(Conversions, TransformCarriesThePose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(1, 2, 3);
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const geometry_msgs::TransformStamped msg = toTransform(T, ros::Time(1.0), "target", "target_port");
  EXPECT_EQ(msg.header.frame_id, "target");
  EXPECT_EQ(msg.child_frame_id, "target_port");
  EXPECT_DOUBLE_EQ(msg.transform.translation.y, 2.0);
  EXPECT_NEAR(msg.transform.rotation.z, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(msg.transform.rotation.w, std::sqrt(0.5), 1e-15);
}

TEST(Conversions, NonFiniteWrenchIsRejected) {
  BodyWrench w;
  w.force_n = Eigen::Vector3d(1, 2, 3);
  geometry_msgs::Wrench msg = toWrench(w);
  BodyWrench back;
  ASSERT_TRUE(fromWrench(msg, back));
  EXPECT_EQ(back.force_n, w.force_n);
  msg.torque.y = std::nan("");
  BodyWrench untouched;
  EXPECT_FALSE(fromWrench(msg, untouched));
  EXPECT_EQ(untouched.torque_nm, Eigen::Vector3d::Zero());
}

TEST(Conversions, ContactEventCarriesConditionsAndVerdict) {
  ContactEvent event;
  event.time_s = 528.3125;
  event.verdict = ContactVerdict::kCollision;
  event.reason = "closing speed 0.300 m/s > 0.100 m/s";
  event.target_part = "soft_capture_ring";
  event.chaser_part = "guide_petals";
  event.contact_point_m = Eigen::Vector3d(0.01, -0.4, 0.2);
  event.conditions = {0.3, 0.02, 0.01, 0.003, 0.0004};
  event.within_envelope = false;
  ardsim_msgs::ContactEvent msg;
  toContactEvent(event, msg);
  EXPECT_DOUBLE_EQ(msg.header.stamp.toSec(), 528.3125);
  EXPECT_EQ(msg.header.frame_id, "target_port");
  EXPECT_EQ(msg.verdict, ardsim_msgs::ContactEvent::VERDICT_COLLISION);
  EXPECT_EQ(msg.reason, event.reason);
  EXPECT_EQ(msg.target_part, "soft_capture_ring");
  EXPECT_EQ(msg.chaser_part, "guide_petals");
  EXPECT_DOUBLE_EQ(msg.contact_point.y, -0.4);
  EXPECT_DOUBLE_EQ(msg.closing_speed_mps, 0.3);
  EXPECT_DOUBLE_EQ(msg.lateral_misalignment_m, 0.02);
  EXPECT_DOUBLE_EQ(msg.angular_misalignment_rad, 0.01);
  EXPECT_DOUBLE_EQ(msg.lateral_rate_mps, 0.003);
  EXPECT_DOUBLE_EQ(msg.angular_rate_rad_s, 0.0004);
  EXPECT_FALSE(msg.within_envelope);
  event.verdict = ContactVerdict::kCapture;
  toContactEvent(event, msg);
  EXPECT_EQ(msg.verdict, ardsim_msgs::ContactEvent::VERDICT_CAPTURE);
}
