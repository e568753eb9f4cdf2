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
