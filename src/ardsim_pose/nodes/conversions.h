// All conversions between ROS messages and the ardsim_pose core, in one place (unit-tested in
// test/test_conversions.cpp).
#pragma once

#include <string>

#include <ardsim_msgs/PoseError.h>
#include <ardsim_msgs/PoseEstimate.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/PointCloud2.h>
#include <Eigen/Geometry>

#include "ardsim_pose/evaluation.h"
#include "ardsim_pose/pose_estimator.h"

namespace ardsim_pose {

// Organized cloud from lidar/points (float32 x, y, z; intensity optional). Returns false and says why in
// *error for a cloud in a frame other than sensor_frame_id (its pixels would be read as the sensor's: a wrong
// pose, not an error), one that is not organized, lacks a field, has another type or too little data. An
// empty cloud (0 points) in the sensor's frame converts (to an empty frame).
bool fromPointCloud2(const sensor_msgs::PointCloud2& msg, const std::string& sensor_frame_id,
                     OrganizedCloud* cloud, std::string* error);

ardsim_msgs::PoseEstimatePtr toPoseEstimate(const EstimatorOutput& output, const std_msgs::Header& header);

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& T_parent_child,
                                            const std_msgs::Header& header,
                                            const std::string& child_frame_id);

// Pose from an estimate. Returns false (and says why) for a non-finite value or a non-unit quaternion.
bool poseFromEstimate(const ardsim_msgs::PoseEstimate& msg, Eigen::Isometry3d* T_lidar_target,
                      std::string* error);

// Body pose in eci from truth odometry. Returns false (and says why) for a non-finite value or a non-unit
// quaternion.
bool poseFromOdometry(const nav_msgs::Odometry& msg, Eigen::Isometry3d* T_eci_body, std::string* error);

ardsim_msgs::PoseErrorPtr toPoseError(const PoseErrorValue& error, const ardsim_msgs::PoseEstimate& estimate);

}  // namespace ardsim_pose
