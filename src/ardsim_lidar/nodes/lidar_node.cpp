// The flash LIDAR as a plain node (same interface as the nodelet). A bad parameter stops it at start with one
// line naming the parameter, and exit status 2.
#include <ros/ros.h>

#include "lidar_driver.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "lidar");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    ardsim_lidar::LidarDriver driver(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("lidar: %s", e.what());
    return 2;
  }
  return 0;
}
