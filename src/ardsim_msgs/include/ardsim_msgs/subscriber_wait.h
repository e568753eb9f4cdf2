// Start-up for lockstep publishers: a message goes only to the subscribers connected when it is published,
// and each node connects to each topic on its own, so a node that steps as soon as one topic is listened to
// loses the first messages of its other topics to a subscriber still connecting (the recorder missed a run's
// first 25 lidar frames, and a short run's first 30 truth/target/odom).
#pragma once

#include <ros/master.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <string>

namespace ardsim_msgs {

// How many nodes the master lists as subscribers of topic (0 if it cannot be asked).
inline int registeredSubscribers(const std::string& topic) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", args, result, payload, true) || payload.size() < 2) return 0;
  XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i)
    if (static_cast<std::string>(subscribers[i][0]) == topic) return subscribers[i][1].size();
  return 0;
}

// Waits until the wall-clock deadline for every node registered as a subscriber of the publisher's topic to
// be connected to it; false (logged, as `node`) if some are not.
inline bool waitForRegisteredSubscribers(const ros::Publisher& publisher, const ros::WallTime& deadline,
                                         const char* node) {
  int registered = 0;
  while (ros::ok() && ros::WallTime::now() < deadline) {
    registered = registeredSubscribers(publisher.getTopic());
    if (static_cast<int>(publisher.getNumSubscribers()) >= registered) return true;
    ros::WallDuration(0.01).sleep();
  }
  ROS_WARN("%s: %d of %d registered subscribers of %s connected at the start-up deadline; starting anyway",
           node, static_cast<int>(publisher.getNumSubscribers()), registered, publisher.getTopic().c_str());
  return false;
}

}  // namespace ardsim_msgs
