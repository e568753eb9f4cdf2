// The flash LIDAR's ROS interface, shared by the nodelet (lidar_nodelet.cpp) and the node (lidar_node.cpp):
// answers every truth step (truth/target/odom and truth/chaser/odom with the same stamp) with exactly one
// frame stamped with that step's time.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "ardsim_description/models.h"
#include "ardsim_lidar/fault_schedule.h"
#include "ardsim_lidar/lidar_simulator.h"

namespace ardsim_lidar {

struct LidarNodeOptions {
  ardsim_description::TargetKind target = ardsim_description::TargetKind::kIss;
  SensorOptions sensor;
  NoiseOptions noise;
  std::uint64_t seed = 1;
  ardsim_description::IssOptions iss;
  ardsim_description::HubbleOptions hubble;
  RendererOptions renderer;
  std::string frame_id = "lidar_optical";
  // 0: a new frame at every truth step (the lockstep's step sets the rate). > 0: the sensor's own rate; a
  // step that comes sooner than 1 / frame_rate_hz after the last new frame is answered with that frame,
  // re-stamped.
  double frame_rate_hz = 0.0;
  FaultOptions faults;  // scripted sensor faults (scenario section `faults`)
};

// Reads every parameter from the private namespace, with the struct defaults as defaults, and validates them.
// Throws std::invalid_argument naming the parameter, its value and the allowed range.
LidarNodeOptions loadOptions(const ros::NodeHandle& private_nh);

class LidarDriver {
 public:
  // Throws std::invalid_argument for a bad parameter, std::runtime_error when EGL/OpenGL cannot be set up.
  LidarDriver(ros::NodeHandle nh, const ros::NodeHandle& private_nh);

 private:
  void onTruth(const nav_msgs::OdometryConstPtr& target, const nav_msgs::OdometryConstPtr& chaser);
  void publish(const LidarFrame& frame, const ros::Time& stamp, const std::string& status, bool ok);

  LidarNodeOptions options_;
  LidarSimulator simulator_;
  Eigen::Isometry3d T_chaser_lidar_;
  LidarFrame frame_;
  LidarFrame empty_frame_;
  LidarFrame fault_frame_;
  ros::Time last_frame_time_;
  bool have_frame_ = false;
  message_filters::Subscriber<nav_msgs::Odometry> target_subscriber_;
  message_filters::Subscriber<nav_msgs::Odometry> chaser_subscriber_;
  message_filters::TimeSynchronizer<nav_msgs::Odometry, nav_msgs::Odometry> synchronizer_;
  ros::Publisher points_publisher_;
  ros::Publisher range_publisher_;
  ros::Publisher camera_info_publisher_;
  ros::Publisher diagnostics_publisher_;
};

}  // namespace ardsim_lidar
