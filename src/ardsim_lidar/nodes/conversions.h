// All conversions between ROS messages and the ardsim_lidar core, in one place (unit-tested in
// test/test_conversions.cpp).
#pragma once

#include <string>

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <Eigen/Geometry>

#include "ardsim_lidar/noise_model.h"
#include "ardsim_lidar/sensor.h"

namespace ardsim_lidar {

// Body pose in eci from a truth odometry message. Returns false (and says why in *error) when a value is not
// finite or the quaternion is not of unit norm within 1e-3.
bool bodyPoseFromOdometry(const nav_msgs::Odometry& odometry, Eigen::Isometry3d* T_eci_body,
                          std::string* error);

// Organized width x height cloud, fields x y z intensity (float32), NaN where there is no return.
sensor_msgs::PointCloud2Ptr toPointCloud2(const LidarFrame& frame, const PixelRays& rays,
                                          const std_msgs::Header& header);

// 32FC1 range image in metres, NaN where there is no return.
sensor_msgs::ImagePtr toRangeImage(const LidarFrame& frame, const std_msgs::Header& header);

// Pinhole camera info of the focal plane (no distortion).
sensor_msgs::CameraInfoPtr toCameraInfo(const Intrinsics& intrinsics, const std_msgs::Header& header);

}  // namespace ardsim_lidar
