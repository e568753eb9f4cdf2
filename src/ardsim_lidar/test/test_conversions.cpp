// nodes/conversions: truth odometry to T_lidar_target, and frames to PointCloud2 / Image / CameraInfo that
// agree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "../nodes/conversions.h"
#include "ardsim_description/frames.h"

namespace ardsim_lidar {
namespace {

nav_msgs::Odometry odometry(const Eigen::Vector3d& position, const Eigen::Quaterniond& q) {
  nav_msgs::Odometry msg;
  msg.child_frame_id = "body";
  msg.pose.pose.position.x = position.x();
  msg.pose.pose.position.y = position.y();
  msg.pose.pose.position.z = position.z();
  msg.pose.pose.orientation.x = q.x();
  msg.pose.pose.orientation.y = q.y();
  msg.pose.pose.orientation.z = q.z();
  msg.pose.pose.orientation.w = q.w();
  return msg;
}

TEST(Conversions, RelativePoseKeepsMillimetresAtOrbitalDistances) {
  const Eigen::Vector3d target_eci(6.778e6, 1.234567e5, -2.5e5);
  const Eigen::Quaterniond q_target(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Quaterniond q_chaser(Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0, 1, 1).normalized()));
  const Eigen::Vector3d offset_eci(12.3456789, -0.0012345, 3.000001);
  Eigen::Isometry3d T_eci_target;
  Eigen::Isometry3d T_eci_chaser;
  std::string error;
  ASSERT_TRUE(bodyPoseFromOdometry(odometry(target_eci, q_target), &T_eci_target, &error));
  ASSERT_TRUE(bodyPoseFromOdometry(odometry(target_eci + offset_eci, q_chaser), &T_eci_chaser, &error));
  Eigen::Isometry3d T_chaser_lidar = Eigen::Isometry3d::Identity();
  T_chaser_lidar.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  const Eigen::Isometry3d T_lidar_target =
      ardsim_description::lidarFromTarget(T_eci_target, T_eci_chaser, T_chaser_lidar);
  // Expected, built from the small relative quantities only.
  const Eigen::Vector3d expected_translation =
      q_chaser.conjugate() * (-offset_eci) - Eigen::Vector3d(2.0, 0.0, 0.0);
  EXPECT_LT((T_lidar_target.translation() - expected_translation).norm(), 1e-6);
  EXPECT_TRUE(T_lidar_target.linear().isApprox((q_chaser.conjugate() * q_target).toRotationMatrix(), 1e-12));
}

TEST(Conversions, BadQuaternionsAreRejectedWithAReason) {
  Eigen::Isometry3d T;
  std::string error;
  nav_msgs::Odometry msg = odometry(Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity());
  msg.pose.pose.orientation.w = 0.0;
  EXPECT_FALSE(bodyPoseFromOdometry(msg, &T, &error));
  EXPECT_NE(error.find("norm"), std::string::npos);
  msg.pose.pose.position.x = std::nan("");
  EXPECT_FALSE(bodyPoseFromOdometry(msg, &T, &error));
}

TEST(Conversions, PointsRangeImageAndCameraInfoAgree) {
  SensorOptions sensor;
  sensor.width = 64;
  sensor.height = 48;
  const Intrinsics k = intrinsicsFor(sensor);
  const PixelRays rays(k);
  LidarFrame frame;
  frame.width = sensor.width;
  frame.height = sensor.height;
  for (int i = 0; i < sensor.width * sensor.height; ++i) {
    const bool hit = i % 7 != 0;
    frame.range_m.push_back(hit ? 5.0f + 0.01f * i : std::nanf(""));
    frame.intensity.push_back(hit ? 0.5f : std::nanf(""));
  }
  std_msgs::Header header;
  header.stamp = ros::Time(12, 500);
  header.frame_id = "lidar_optical";
  const auto cloud = toPointCloud2(frame, rays, header);
  const auto image = toRangeImage(frame, header);
  const auto info = toCameraInfo(k, header);
  ASSERT_EQ(cloud->width, 64u);
  ASSERT_EQ(cloud->height, 48u);
  ASSERT_EQ(cloud->fields.size(), 4u);
  EXPECT_EQ(cloud->fields[3].name, "intensity");
  EXPECT_EQ(image->encoding, "32FC1");
  EXPECT_EQ(info->header.stamp, header.stamp);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      const int i = v * 64 + u;
      float point[4];
      float range = 0.0f;
      std::memcpy(point, &cloud->data[i * cloud->point_step], sizeof(point));
      std::memcpy(&range, &image->data[v * image->step + u * sizeof(float)], sizeof(range));
      if (std::isnan(frame.range_m[i])) {
        EXPECT_TRUE(std::isnan(point[0]) && std::isnan(range));
        continue;
      }
      const Eigen::Vector3d ray =
          Eigen::Vector3d((u - info->K[2]) / info->K[0], (v - info->K[5]) / info->K[4], 1.0).normalized();
      EXPECT_LT((Eigen::Vector3d(point[0], point[1], point[2]) - range * ray).norm(), 1e-5);
      EXPECT_EQ(point[3], 0.5f);
    }
  }
}

}  // namespace
}  // namespace ardsim_lidar
