#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "../nodes/conversions.h"

using namespace ardsim_guidance;

namespace {
ardsim_msgs::PoseEstimate estimate(double qw, double qx, double qy, double qz) {
  ardsim_msgs::PoseEstimate m;
  m.header.stamp = ros::Time(12.3);
  m.status = ardsim_msgs::PoseEstimate::STATUS_TRACKING;
  m.pose.pose.position.x = 1.0;
  m.pose.pose.position.y = -2.0;
  m.pose.pose.position.z = 30.0;
  m.pose.pose.orientation.w = qw;
  m.pose.pose.orientation.x = qx;
  m.pose.pose.orientation.y = qy;
  m.pose.pose.orientation.z = qz;
  return m;
}
}  // namespace

TEST(Conversions, PoseRoundTrip) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1, -2, 3);
  Eigen::Isometry3d back;
  std::string why;
  ASSERT_TRUE(toIsometry(toPose(T), &back, &why));
  EXPECT_LT((back.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Conversions, WellFormedEstimate) {
  const EstimateInput in = fromPoseEstimate(estimate(1, 0, 0, 0));
  EXPECT_TRUE(in.well_formed);
  EXPECT_EQ(in.status, EstimateStatus::kTracking);
  EXPECT_DOUBLE_EQ(in.time_s, 12.3);
  EXPECT_DOUBLE_EQ(in.T_lidar_target.translation().z(), 30.0);
}

TEST(Conversions, NanAndZeroQuaternionsAreMalformed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const EstimateInput nan_q = fromPoseEstimate(estimate(nan, 0, 0, 0));
  EXPECT_FALSE(nan_q.well_formed);
  EXPECT_NE(nan_q.reason.find("malformed"), std::string::npos);
  EXPECT_FALSE(fromPoseEstimate(estimate(0, 0, 0, 0)).well_formed);
  ardsim_msgs::PoseEstimate nan_p = estimate(1, 0, 0, 0);
  nan_p.pose.pose.position.y = nan;
  EXPECT_FALSE(fromPoseEstimate(nan_p).well_formed);
  ardsim_msgs::PoseEstimate bad_status = estimate(1, 0, 0, 0);
  bad_status.status = 17;
  EXPECT_EQ(fromPoseEstimate(bad_status).status, EstimateStatus::kLost);
}

TEST(Conversions, OdometryToOwnState) {
  nav_msgs::Odometry odom;
  odom.pose.pose.position.x = 6.8e6;
  odom.pose.pose.orientation.w = 1.0;
  odom.twist.twist.linear.y = 7660.0;
  odom.twist.twist.angular.z = 1e-3;
  OwnState s;
  std::string why;
  ASSERT_TRUE(fromOdometry(odom, &s, &why));
  EXPECT_DOUBLE_EQ(s.velocity_eci_mps.y(), 7660.0);
  EXPECT_DOUBLE_EQ(s.rate_body_rad_s.z(), 1e-3);
  odom.pose.pose.orientation.w = 0.0;
  EXPECT_FALSE(fromOdometry(odom, &s, &why));
}

TEST(Conversions, CommandStateAndTruthEstimate) {
  GuidanceOutput out;
  out.force_body_n = {1, 2, 3};
  out.torque_body_nm = {4, 5, 6};
  out.phase = Phase::kRetreat;
  out.reason = "corridor left";
  out.estimate_status = EstimateStatus::kDegraded;
  const geometry_msgs::WrenchStamped w = toWrench(out, ros::Time(5.0));
  EXPECT_EQ(w.header.frame_id, "chaser");
  EXPECT_EQ(w.header.stamp, ros::Time(5.0));
  EXPECT_DOUBLE_EQ(w.wrench.force.z, 3.0);
  EXPECT_DOUBLE_EQ(w.wrench.torque.x, 4.0);
  const ardsim_msgs::GuidanceState s = toGuidanceState(out, ros::Time(5.0));
  EXPECT_EQ(s.phase, ardsim_msgs::GuidanceState::PHASE_RETREAT);
  EXPECT_EQ(s.estimate_status, ardsim_msgs::PoseEstimate::STATUS_DEGRADED);
  EXPECT_EQ(s.header.frame_id, "target_port");

  TruthPoseSample sample;
  sample.T_lidar_target.translation() = Eigen::Vector3d(0, 0, 50);
  TruthPoseOptions options;
  options.position_sigma_m = 0.1;
  const ardsim_msgs::PoseEstimate e = toPoseEstimate(sample, options, ros::Time(5.0));
  EXPECT_EQ(e.method, ardsim_msgs::PoseEstimate::METHOD_TRUTH);
  EXPECT_EQ(e.header.frame_id, "lidar_optical");
  EXPECT_NEAR(e.pose.covariance[0], 0.01, 1e-15);
  EXPECT_DOUBLE_EQ(e.pose.pose.position.z, 50.0);
}
