// relative_motion_monitor: prints the chaser's motion in the target's LVLH from the truth topics, next to the
// Clohessy-Wiltshire prediction from the first state received (the free-drift demo's table).
// Parameter ~print_every_s (default 300): simulation time between rows.
#include <cmath>
#include <cstdio>
#include <optional>

#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "ardsim_dynamics/orbit.h"
#include "conversions.h"

namespace {

using ardsim_dynamics::CartesianState;

struct Monitor {
  double print_every_s = 300.0;
  std::optional<CartesianState> initial_relative;
  double t0 = 0.0, mean_motion = 0.0, next_print = 0.0, worst_difference = 0.0;

  void onTruth(const nav_msgs::Odometry::ConstPtr& target_msg,
               const nav_msgs::Odometry::ConstPtr& chaser_msg) {
    const auto target = ardsim_dynamics::fromOdometry(*target_msg);
    const auto chaser = ardsim_dynamics::fromOdometry(*chaser_msg);
    const CartesianState ref{target.position_m, target.velocity_mps};
    const CartesianState rel =
        ardsim_dynamics::relativeStateInLvlh(ref, {chaser.position_m, chaser.velocity_mps});
    const double t = target_msg->header.stamp.toSec();
    if (!initial_relative) {
      initial_relative = rel;
      t0 = next_print = t;
      // Mean motion of the target's osculating orbit (vis-viva semi-major axis).
      const double a =
          1.0 / (2.0 / ref.position_m.norm() - ref.velocity_mps.squaredNorm() / ardsim_dynamics::kEarthGm);
      mean_motion = std::sqrt(ardsim_dynamics::kEarthGm / (a * a * a));
      std::printf("chaser relative to the target in its LVLH (x V-bar, y H-bar, z R-bar), metres\n");
      std::printf("%8s | %9s %9s %9s | %9s %9s %9s | %9s\n", "t [s]", "truth x", "truth y", "truth z", "CW x",
                  "CW y", "CW z", "|diff|");
    }
    const CartesianState cw = ardsim_dynamics::cwPropagate(*initial_relative, mean_motion, t - t0);
    const double difference = (rel.position_m - cw.position_m).norm();
    worst_difference = std::max(worst_difference, difference);
    if (t + 1e-9 >= next_print) {
      std::printf("%8.0f | %9.2f %9.2f %9.2f | %9.2f %9.2f %9.2f | %9.3f\n", t, rel.position_m.x(),
                  rel.position_m.y(), rel.position_m.z(), cw.position_m.x(), cw.position_m.y(),
                  cw.position_m.z(), difference);
      std::fflush(stdout);
      next_print += print_every_s;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "relative_motion_monitor");
  ros::NodeHandle nh, pnh("~");
  Monitor monitor;
  pnh.param("print_every_s", monitor.print_every_s, monitor.print_every_s);
  if (!(monitor.print_every_s > 0.0)) {
    ROS_FATAL("parameter ~print_every_s = %g is outside the allowed range (0, inf)", monitor.print_every_s);
    return 1;
  }
  // Deep queues: in a free run the dynamics publishes faster than this prints.
  message_filters::Subscriber<nav_msgs::Odometry> target_sub(nh, "truth/target/odom", 100000);
  message_filters::Subscriber<nav_msgs::Odometry> chaser_sub(nh, "truth/chaser/odom", 100000);
  message_filters::TimeSynchronizer<nav_msgs::Odometry, nav_msgs::Odometry> sync(target_sub, chaser_sub,
                                                                                 1000);
  sync.registerCallback(&Monitor::onTruth, &monitor);
  ros::spin();
  if (monitor.initial_relative)
    std::printf("largest truth - CW difference over the run: %.3f m\n", monitor.worst_difference);
  return 0;
}
