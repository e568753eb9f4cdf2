// The flash LIDAR as a plain node (same interface as the nodelet). A bad parameter stops it at start with one
// line naming the parameter, and exit status 2.
#include <memory>

#include <ardsim_msgs/startup_error.h>
#include <ros/ros.h>

#include "lidar_driver.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "lidar");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  std::unique_ptr<ardsim_lidar::LidarDriver> driver;
  try {
    driver = std::make_unique<ardsim_lidar::LidarDriver>(nh, private_nh);
  } catch (const std::exception& e) {
    ROS_FATAL("lidar: %s", e.what());
    ardsim_msgs::reportStartupError(nh, "lidar", e.what());
    return 2;
  }
  try {
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("lidar: %s", e.what());
    return 2;
  }
  return 0;
}
