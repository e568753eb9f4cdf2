// lockstep_responder: a trivial stand-in for guidance (tests, benchmarks, drift demos). Answers every
// truth/chaser/odom with one zero guidance/command carrying the same stamp, so the lockstep clock runs.
#include <geometry_msgs/WrenchStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "lockstep_responder");
  ros::NodeHandle nh;
  // Latched like the truth topics, so an answer published before the dynamics node connects is not lost.
  ros::Publisher command_pub = nh.advertise<geometry_msgs::WrenchStamped>("guidance/command", 10, true);
  ros::Subscriber truth_sub = nh.subscribe<nav_msgs::Odometry>(
      "truth/chaser/odom", 10, [&command_pub](const nav_msgs::Odometry::ConstPtr& truth) {
        auto command = boost::make_shared<geometry_msgs::WrenchStamped>();
        command->header.stamp = truth->header.stamp;
        command->header.frame_id = "chaser";
        command_pub.publish(command);
      });
  ros::spin();
  return 0;
}
