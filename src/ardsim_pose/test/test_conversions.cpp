// Message <-> core conversions of ardsim_pose (nodes/conversions.cpp).
#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "../nodes/conversions.h"

namespace ardsim_pose {
namespace {

const char kSensorFrame[] = "lidar_optical";

sensor_msgs::PointCloud2 makeCloud(std::uint32_t width, std::uint32_t height, float value) {
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = kSensorFrame;
  msg.width = width;
  msg.height = height;
  const char* names[4] = {"x", "y", "z", "intensity"};
  for (int k = 0; k < 4; ++k) {
    sensor_msgs::PointField field;
    field.name = names[k];
    field.offset = 4 * k;
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    msg.fields.push_back(field);
  }
  msg.point_step = 16;
  msg.row_step = 16 * width;
  msg.data.resize(static_cast<std::size_t>(msg.row_step) * height);
  for (std::size_t i = 0; i < static_cast<std::size_t>(width) * height; ++i) {
    const float p[4] = {value + i, value, -value, 0.5f};
    std::memcpy(&msg.data[16 * i], p, sizeof(p));
  }
  return msg;
}

TEST(PoseConversions, OrganizedCloudRoundTrip) {
  OrganizedCloud cloud;
  std::string error;
  ASSERT_TRUE(fromPointCloud2(makeCloud(4, 3, 2.0f), kSensorFrame, &cloud, &error)) << error;
  EXPECT_EQ(cloud.width, 4);
  EXPECT_EQ(cloud.height, 3);
  ASSERT_EQ(cloud.points.size(), 12u);
  EXPECT_FLOAT_EQ(cloud.points[5].x(), 7.0f);
  EXPECT_FLOAT_EQ(cloud.points[5].z(), -2.0f);
  EXPECT_FLOAT_EQ(cloud.intensity[5], 0.5f);
}

TEST(PoseConversions, RejectsMalformedClouds) {
  OrganizedCloud cloud;
  std::string error;
  EXPECT_FALSE(fromPointCloud2(makeCloud(10, 1, 1.0f), kSensorFrame, &cloud, &error));
  EXPECT_NE(error.find("organized"), std::string::npos);
  sensor_msgs::PointCloud2 short_data = makeCloud(4, 3, 1.0f);
  short_data.data.resize(10);
  EXPECT_FALSE(fromPointCloud2(short_data, kSensorFrame, &cloud, &error));
  sensor_msgs::PointCloud2 no_z = makeCloud(4, 3, 1.0f);
  no_z.fields[2].name = "w";
  EXPECT_FALSE(fromPointCloud2(no_z, kSensorFrame, &cloud, &error));
  EXPECT_NE(error.find("z"), std::string::npos);
  // A cloud in another frame (here the chaser body's, as a cloud transformed for display would be): refused,
  // the estimator would read its points as the sensor's pixels.
  sensor_msgs::PointCloud2 other_frame = makeCloud(4, 3, 1.0f);
  other_frame.header.frame_id = "chaser";
  EXPECT_FALSE(fromPointCloud2(other_frame, kSensorFrame, &cloud, &error));
  EXPECT_NE(error.find("'chaser', not the sensor's 'lidar_optical'"), std::string::npos) << error;
  other_frame.header.frame_id.clear();
  EXPECT_FALSE(fromPointCloud2(other_frame, kSensorFrame, &cloud, &error));
  // An empty cloud converts to an empty frame (the estimator answers LOST).
  EXPECT_TRUE(fromPointCloud2(makeCloud(0, 0, 1.0f), kSensorFrame, &cloud, &error));
  EXPECT_TRUE(cloud.points.empty());
}

// A header whose width x point_step passes 2^32 (here exactly: 65536 x 65536) with no data: in 32-bit
// arithmetic that size wraps to 0, the checks against row_step and the data pass, and the conversion reads
// far beyond the message (a crash). Refused instead, and nothing read.
TEST(PoseConversions, RejectsACloudWhoseSizeOverflows32Bits) {
  sensor_msgs::PointCloud2 msg = makeCloud(0, 0, 1.0f);
  msg.width = 65536;
  msg.height = 2;
  msg.point_step = 65536;
  msg.row_step = 0;
  msg.data.clear();
  OrganizedCloud cloud;
  std::string error;
  EXPECT_FALSE(fromPointCloud2(msg, kSensorFrame, &cloud, &error));
  EXPECT_NE(error.find("row_step 0 is shorter than width x point_step (4294967296)"), std::string::npos)
      << error;
  EXPECT_TRUE(cloud.points.empty());
  // The same where the wrapped size is not 0 (65537 x 65536 = 2^32 + 65536) and the data hold that much.
  msg.width = 65537;
  msg.row_step = 65536;
  msg.data.assign(2 * 65536, 0);
  EXPECT_FALSE(fromPointCloud2(msg, kSensorFrame, &cloud, &error));
  EXPECT_TRUE(cloud.points.empty());
}

TEST(PoseConversions, EstimateCarriesPoseStatusAndCovariance) {
  EstimatorOutput out;
  out.result.status = EstimateStatus::kDegraded;
  out.result.method = EstimateMethod::kIcp;
  out.result.reason = "fit rms";
  out.result.T_lidar_target =
      Eigen::Translation3d(1, 2, 30) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY());
  out.result.covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  out.velocity_mps = Eigen::Vector3d(0, 0, -0.1);
  out.velocity_valid = true;
  std_msgs::Header header;
  header.stamp = ros::Time(12, 5);
  const ardsim_msgs::PoseEstimatePtr msg = toPoseEstimate(out, header);
  EXPECT_EQ(msg->header.stamp, header.stamp);
  EXPECT_EQ(msg->status, ardsim_msgs::PoseEstimate::STATUS_DEGRADED);
  EXPECT_EQ(msg->method, ardsim_msgs::PoseEstimate::METHOD_ICP);
  EXPECT_DOUBLE_EQ(msg->pose.covariance[7], 1e-4);
  EXPECT_DOUBLE_EQ(msg->velocity.linear.z, -0.1);
  Eigen::Isometry3d back;
  std::string error;
  ASSERT_TRUE(poseFromEstimate(*msg, &back, &error));
  EXPECT_TRUE(back.isApprox(out.result.T_lidar_target, 1e-12));
  out.result.status = EstimateStatus::kLost;
  EXPECT_DOUBLE_EQ(toPoseEstimate(out, header)->pose.covariance[7], 0.0);
}

// (T_lidar_target from the truth at orbital distances: ardsim_description::lidarFromTarget, tested in
// ardsim_lidar's test_conversions.)
TEST(PoseConversions, TruthWithANonUnitQuaternionIsRejected) {
  nav_msgs::Odometry odometry;
  odometry.pose.pose.orientation.w = 2.0;
  Eigen::Isometry3d pose;
  std::string error;
  EXPECT_FALSE(poseFromOdometry(odometry, &pose, &error));
}

}  // namespace
}  // namespace ardsim_pose
