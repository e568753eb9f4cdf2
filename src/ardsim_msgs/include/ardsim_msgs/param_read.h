// Reading a node's private parameters the same way in every ardsim node: an absent parameter keeps its
// default, and one that is set but has the wrong type is an error naming it, not a silent default.
#pragma once

#include <stdexcept>
#include <string>

#include <ros/node_handle.h>

namespace ardsim_msgs {

// defaults_file: where the parameter is documented (e.g. "config/pose.yaml"), for the error message.
template <typename T>
void readParam(const ros::NodeHandle& nh, const std::string& name, T* value,
               const std::string& defaults_file) {
  if (!nh.hasParam(name)) return;
  if (!nh.getParam(name, *value))
    throw std::invalid_argument("parameter " + name + " has the wrong type (see " + defaults_file + ")");
}

// Runs a core's option check and names what it refuses as a node parameter: a core says "name = value is out
// of range: ...", the node "parameter <prefix>name = value ...".
template <typename Check>
void validateParameters(Check check, const std::string& prefix = "") {
  try {
    check();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("parameter " + prefix + e.what());
  }
}

}  // namespace ardsim_msgs
