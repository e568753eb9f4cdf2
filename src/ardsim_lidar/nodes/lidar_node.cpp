// The flash LIDAR as a plain node (same interface as the nodelet). A bad parameter stops it at start with one
// line naming the parameter, and exit status 2.
#include <ardsim_msgs/startup_error.h>
#include <ros/ros.h>

#include "lidar_driver.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "lidar");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  return ardsim_msgs::spinNode<ardsim_lidar::LidarDriver>("lidar", nh, private_nh);
}
