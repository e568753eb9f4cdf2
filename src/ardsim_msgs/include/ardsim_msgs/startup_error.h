// A node that cannot start (a bad parameter, a model that does not load) says why to the run monitor too, not
// only in its log: roslaunch respawns the pose node, which then fails the same way in a loop, and the
// dynamics waits for all its subscribers before the first step, so without this a run with a bad parameter
// would wait forever instead of ending with the parameter named.
#pragma once

#include <exception>
#include <memory>
#include <string>

#include <ros/node_handle.h>
#include <ros/ros.h>

namespace ardsim_msgs {

// Relative to the node's namespace: run_monitor (node "run") reads it as ~startup_error; docking.launch sets
// it empty first, so that a value left by an earlier launch on the same master does not end this run.
constexpr const char* kStartupErrorParam = "run/startup_error";

// The first error reported in the run stays: later ones are usually its consequences.
inline void reportStartupError(const ros::NodeHandle& nh, const std::string& node, const std::string& what) {
  std::string earlier;
  if (nh.getParam(kStartupErrorParam, earlier) && !earlier.empty()) return;
  nh.setParam(kStartupErrorParam, node + ": " + what);
}

// A plain node's main: Driver(nh, private_nh) set up, then spun. A failure to start is logged, reported as
// above and answered with exit status 2; an exception out of the spin is logged, exit status 2 as well.
template <typename Driver>
int spinNode(const char* node, const ros::NodeHandle& nh, const ros::NodeHandle& private_nh) {
  std::unique_ptr<Driver> driver;
  try {
    driver = std::make_unique<Driver>(nh, private_nh);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", node, e.what());
    reportStartupError(nh, node, e.what());
    return 2;
  }
  try {
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", node, e.what());
    return 2;
  }
  return 0;
}

}  // namespace ardsim_msgs
