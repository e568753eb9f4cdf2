// The pose estimator as a plain node (same interface as the nodelet). A bad parameter stops it at start with
// one line naming the parameter, and exit status 2.
#include <ardsim_msgs/startup_error.h>
#include <ros/ros.h>

#include "pose_driver.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "pose");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  return ardsim_msgs::spinNode<ardsim_pose::PoseDriver>("pose", nh, private_nh);
}
