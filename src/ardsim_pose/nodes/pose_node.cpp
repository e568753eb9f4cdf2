// The pose estimator as a plain node (same interface as the nodelet). A bad parameter stops it at start with
// one line naming the parameter, and exit status 2.
#include <ros/ros.h>

#include "pose_driver.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "pose");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    ardsim_pose::PoseDriver driver(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("pose: %s", e.what());
    return 2;
  }
  return 0;
}
