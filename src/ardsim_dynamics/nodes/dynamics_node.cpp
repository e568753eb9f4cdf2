// dynamics_node: the truth of the simulation and its only clock, run in lockstep (see README.md).
//
// Publishes, at each control step t_k: /clock, truth/target/odom, truth/chaser/odom (eci), truth/relative
// (chaser_port in target_port), tf eci->{ecef, target_lvlh, target, chaser}; then waits for guidance/command
// stamped t_k, applies it through the actuator model over [t_k, t_k + dt] (published on
// dynamics/applied_wrench, stamped t_k) and advances.
//
// When the vehicles first touch inside a step (README.md "Contact"), the run ends there: the state at the
// contact time is published like a step, then dynamics/contact (latched) with the conditions and the verdict,
// and the node stops advancing.
#include <ardsim_msgs/ContactEvent.h>
#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/startup_error.h>
#include <ardsim_msgs/subscriber_wait.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include <geometry_msgs/WrenchStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>

#include "ardsim_dynamics/simulation.h"
#include "conversions.h"

namespace ardsim_dynamics {
namespace {

struct DynamicsNodeOptions {
  std::string scenario_path;        // required
  double real_time_factor = 0.0;    // sim seconds per wall second; 0 = as fast as possible
  double command_timeout_s = 2.0;   // wall time to wait for guidance/command before applying zero wrench
  double startup_timeout_s = 60.0;  // the same for the first step, while the other nodes start
  bool free_run = false;            // no command expected (drift scenarios)
  int wait_for_subscribers = 0;     // before the first step, wait (up to startup_timeout_s) for this many
                                    // subscribers of truth/chaser/odom
  double duration_s = 0.0;          // run length; 0 = the scenario's simulation.duration_s
  // > 0: publish step k only once the recorder's record/progress has reached step k - recorder_lag_steps
  // (the publishers' queues to it then never overflow); one that has not caught up within recorder_timeout_s
  // is no longer waited for.
  int recorder_lag_steps = 0;
  double recorder_timeout_s = 10.0;
  // false: after the last step keep the final state latched until shut down, so that slower subscribers drain
  // their queues (a free run outpaces them).
  bool exit_at_end = true;
};

void requireRange(const std::string& name, double value, double min, double max) {
  if (!(value >= min && value <= max))
    throw std::invalid_argument("parameter ~" + name + " = " + std::to_string(value) +
                                " is outside the allowed range [" + std::to_string(min) + ", " +
                                std::to_string(max) + "]");
}

// Fills and validates the options from the private namespace; a bad value throws naming parameter, value and
// range.
DynamicsNodeOptions loadOptions(const ros::NodeHandle& pnh) {
  DynamicsNodeOptions o;
  if (!pnh.getParam("scenario", o.scenario_path) || o.scenario_path.empty())
    throw std::invalid_argument("parameter ~scenario (path of a scenario YAML file) is required");
  pnh.param("real_time_factor", o.real_time_factor, o.real_time_factor);
  pnh.param("command_timeout_s", o.command_timeout_s, o.command_timeout_s);
  pnh.param("startup_timeout_s", o.startup_timeout_s, o.startup_timeout_s);
  pnh.param("free_run", o.free_run, o.free_run);
  pnh.param("wait_for_subscribers", o.wait_for_subscribers, o.wait_for_subscribers);
  pnh.param("duration_s", o.duration_s, o.duration_s);
  pnh.param("recorder_lag_steps", o.recorder_lag_steps, o.recorder_lag_steps);
  pnh.param("recorder_timeout_s", o.recorder_timeout_s, o.recorder_timeout_s);
  pnh.param("exit_at_end", o.exit_at_end, o.exit_at_end);
  requireRange("real_time_factor", o.real_time_factor, 0.0, 1e6);
  requireRange("command_timeout_s", o.command_timeout_s, 1e-3, 3600.0);
  requireRange("startup_timeout_s", o.startup_timeout_s, 1e-3, 3600.0);
  requireRange("wait_for_subscribers", o.wait_for_subscribers, 0, 100);
  requireRange("duration_s", o.duration_s, 0.0, 1e7);
  requireRange("recorder_lag_steps", o.recorder_lag_steps, 0, 100000);
  requireRange("recorder_timeout_s", o.recorder_timeout_s, 1e-3, 3600.0);
  return o;
}

class DynamicsNode {
 public:
  DynamicsNode(ros::NodeHandle& nh, const DynamicsNodeOptions& options, Simulation& sim)
      : options_(options), sim_(sim) {
    // Latched: a node that connects late (at start-up, or respawned) still gets the current step. In lockstep
    // at most one step is in flight to the nodes in it, but the recorder is outside it and falls behind by
    // hundreds of steps while it writes clouds; a free run publishes as fast as it integrates, so its queues
    // must hold a whole burst.
    const std::uint32_t queue = options_.free_run ? 100000 : 1000;
    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", queue, true);
    target_pub_ = nh.advertise<nav_msgs::Odometry>("truth/target/odom", queue, true);
    chaser_pub_ = nh.advertise<nav_msgs::Odometry>("truth/chaser/odom", queue, true);
    relative_pub_ = nh.advertise<nav_msgs::Odometry>("truth/relative", queue, true);
    applied_pub_ = nh.advertise<geometry_msgs::WrenchStamped>("dynamics/applied_wrench", queue);
    tf_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf", queue);
    contact_pub_ = nh.advertise<ardsim_msgs::ContactEvent>("dynamics/contact", 1, true);
    if (!options_.free_run) {
      ros::SubscribeOptions so = ros::SubscribeOptions::create<geometry_msgs::WrenchStamped>(
          "guidance/command", 10,
          [this](const geometry_msgs::WrenchStamped::ConstPtr& msg) { onCommand(msg); }, ros::VoidPtr(),
          &command_queue_);
      command_sub_ = nh.subscribe(so);
    }
    if (options_.recorder_lag_steps > 0) {
      ros::SubscribeOptions so = ros::SubscribeOptions::create<rosgraph_msgs::Clock>(
          "record/progress", 10,
          [this](const rosgraph_msgs::Clock::ConstPtr& msg) {
            recorded_until_ = std::max(recorded_until_, msg->clock);
          },
          ros::VoidPtr(), &command_queue_);
      progress_sub_ = nh.subscribe(so);
    }
  }

  int run() {
    const double dt = sim_.scenario().control_step_s;
    const double duration = options_.duration_s > 0.0 ? options_.duration_s : sim_.scenario().duration_s;
    const std::int64_t last_step = std::llround(duration / dt);
    waitForSubscribers();
    ROS_INFO("dynamics: scenario '%s', %s, %lld steps of %.3f s%s", sim_.scenario().name.c_str(),
             options_.free_run ? "free run" : "lockstep", static_cast<long long>(last_step), dt,
             options_.real_time_factor > 0.0 ? "" : ", as fast as possible");
    const ros::WallTime wall_start = ros::WallTime::now();
    while (ros::ok()) {
      const ros::Time stamp(sim_.time());
      pace(wall_start);
      waitForRecorder(dt);
      publishStep(stamp);
      ros::getGlobalCallbackQueue()->callAvailable();
      if (sim_.contact()) {
        publishContact(*sim_.contact());
        break;
      }
      if (sim_.stepIndex() >= last_step) break;
      BodyWrench command;
      if (!options_.free_run)
        command = waitForCommand(
            stamp, sim_.stepIndex() == 0 ? options_.startup_timeout_s : options_.command_timeout_s);
      const BodyWrench applied = sim_.step(command);
      auto applied_msg = boost::make_shared<geometry_msgs::WrenchStamped>();
      applied_msg->header.stamp = stamp;
      applied_msg->header.frame_id = "chaser";
      applied_msg->wrench = toWrench(applied);
      applied_pub_.publish(applied_msg);
    }
    const double wall_s = (ros::WallTime::now() - wall_start).toSec();
    ROS_INFO("dynamics: reached t = %.1f s in %.1f s wall (real-time factor %.1f), %d command timeouts",
             sim_.time(), wall_s, wall_s > 0.0 ? sim_.time() / wall_s : 0.0, timeouts_);
    if (!options_.exit_at_end) ros::waitForShutdown();
    return 0;
  }

 private:
  void waitForSubscribers() {
    if (options_.wait_for_subscribers <= 0) return;
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(options_.startup_timeout_s);
    while (ros::ok() &&
           chaser_pub_.getNumSubscribers() < static_cast<std::uint32_t>(options_.wait_for_subscribers) &&
           ros::WallTime::now() < deadline)
      ros::WallDuration(0.01).sleep();
    // Then until every node the master lists as a subscriber of a topic of ours is connected to it (the
    // recorder, connected to truth/chaser/odom, lacked the first 30 truth/target/odom of a short run).
    for (const ros::Publisher* publisher :
         {&clock_pub_, &target_pub_, &chaser_pub_, &relative_pub_, &applied_pub_, &tf_pub_, &contact_pub_})
      ardsim_msgs::waitForRegisteredSubscribers(*publisher, deadline, "dynamics");
  }

  void publishContact(const ContactEvent& event) {
    auto msg = boost::make_shared<ardsim_msgs::ContactEvent>();
    toContactEvent(event, *msg);
    contact_pub_.publish(msg);
    const ContactConditions& c = event.conditions;
    char conditions[256];
    std::snprintf(
        conditions, sizeof(conditions),
        "closing %.4f m/s, lateral %.4f m, angular %.2f deg, lateral rate %.4f m/s, angular rate %.4f deg/s",
        c.closing_speed_mps, c.lateral_misalignment_m, c.angular_misalignment_rad * 180.0 / M_PI,
        c.lateral_rate_mps, c.angular_rate_radps * 180.0 / M_PI);
    char time[32];
    std::snprintf(time, sizeof(time), "%.3f", event.time_s);
    const std::string text = std::string("dynamics: ") + verdictName(event.verdict) + " at t = " + time +
                             " s (chaser '" + event.chaser_part + "' on target '" + event.target_part +
                             "'): " + event.reason + "; " + conditions + ". The run ends here.";
    if (event.verdict == ContactVerdict::kCapture)
      ROS_INFO("%s", text.c_str());
    else
      ROS_WARN("%s", text.c_str());
  }

  void pace(const ros::WallTime& wall_start) {
    if (options_.real_time_factor <= 0.0) return;
    const ros::WallTime due = wall_start + ros::WallDuration(sim_.time() / options_.real_time_factor);
    const ros::WallTime now = ros::WallTime::now();
    if (due > now) (due - now).sleep();
  }

  void publishStep(const ros::Time& stamp) {
    auto clock = boost::make_shared<rosgraph_msgs::Clock>();
    clock->clock = stamp;
    clock_pub_.publish(clock);

    auto target = boost::make_shared<nav_msgs::Odometry>();
    toOdometry(sim_.target(), stamp, "target", *target);
    target_pub_.publish(target);
    auto chaser = boost::make_shared<nav_msgs::Odometry>();
    toOdometry(sim_.chaser(), stamp, "chaser", *chaser);
    chaser_pub_.publish(chaser);
    auto relative = boost::make_shared<nav_msgs::Odometry>();
    toOdometry(sim_.chaserPortInTargetPort(), stamp, "target_port", "chaser_port", *relative);
    relative_pub_.publish(relative);

    auto tf = boost::make_shared<tf2_msgs::TFMessage>();
    Eigen::Isometry3d T_eci_ecef = Eigen::Isometry3d::Identity();
    T_eci_ecef.linear() = R_ecef_eci(sim_.environment().greenwichAngle(sim_.time())).transpose();
    tf->transforms.push_back(toTransform(T_eci_ecef, stamp, "eci", "ecef"));
    Eigen::Isometry3d T_eci_lvlh = Eigen::Isometry3d::Identity();
    T_eci_lvlh.linear() = R_eci_lvlh(CartesianState{sim_.target().position_m, sim_.target().velocity_mps});
    T_eci_lvlh.translation() = sim_.target().position_m;
    tf->transforms.push_back(toTransform(T_eci_lvlh, stamp, "eci", "target_lvlh"));
    tf->transforms.push_back(toTransform(poseOf(sim_.target()), stamp, "eci", "target"));
    tf->transforms.push_back(toTransform(poseOf(sim_.chaser()), stamp, "eci", "chaser"));
    tf_pub_.publish(tf);
  }

  void waitForRecorder(double dt) {
    if (options_.recorder_lag_steps <= 0 || recorder_gone_) return;
    const double due_s = sim_.time() - (options_.recorder_lag_steps + 0.5) * dt;
    if (due_s < 0.0) return;
    const ros::Time due(due_s);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(options_.recorder_timeout_s);
    while (ros::ok() && recorded_until_ < due) {
      command_queue_.callAvailable(ros::WallDuration(0.002));
      if (ros::WallTime::now() > deadline) {
        recorder_gone_ = true;
        ROS_ERROR(
            "dynamics: the recorder's record/progress is at t = %.3f s, more than %d steps behind "
            "t = %.3f s, after %.1f s wall: no longer waiting for it (the bag may lack messages from here "
            "on)",
            recorded_until_.toSec(), options_.recorder_lag_steps, sim_.time(), options_.recorder_timeout_s);
        return;
      }
    }
  }

  BodyWrench waitForCommand(const ros::Time& stamp, double timeout_s) {
    expected_stamp_ = stamp;
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::ok()) {
      command_queue_.callAvailable(ros::WallDuration(0.002));
      if (have_command_) {
        have_command_ = false;
        return command_;
      }
      if (ros::WallTime::now() > deadline) {
        ++timeouts_;
        ARDSIM_WARN_THROTTLE(
            5.0,
            "dynamics: no guidance/command for t = %.3f s within %.2f s wall: applying zero wrench "
            "(%d timeouts so far)",
            stamp.toSec(), timeout_s, timeouts_);
        return BodyWrench{};
      }
    }
    return BodyWrench{};
  }

  void onCommand(const geometry_msgs::WrenchStamped::ConstPtr& msg) {
    if (msg->header.stamp != expected_stamp_) {
      ARDSIM_WARN_THROTTLE(5.0, "dynamics: ignoring guidance/command stamped %.3f s while waiting for %.3f s",
                           msg->header.stamp.toSec(), expected_stamp_.toSec());
      return;
    }
    BodyWrench command;
    if (!msg->header.frame_id.empty() && msg->header.frame_id != "chaser") {
      ARDSIM_WARN_THROTTLE(
          5.0, "dynamics: guidance/command in frame '%s', expected 'chaser': applying zero wrench",
          msg->header.frame_id.c_str());
    } else if (!fromWrench(msg->wrench, command)) {
      ARDSIM_WARN_THROTTLE(5.0, "dynamics: non-finite guidance/command at t = %.3f s: applying zero wrench",
                           msg->header.stamp.toSec());
    }
    command_ = command;
    have_command_ = true;
  }

  DynamicsNodeOptions options_;
  Simulation& sim_;
  ros::Publisher clock_pub_, target_pub_, chaser_pub_, relative_pub_, applied_pub_, tf_pub_, contact_pub_;
  ros::CallbackQueue command_queue_;
  ros::Subscriber command_sub_, progress_sub_;
  ros::Time recorded_until_;
  bool recorder_gone_ = false;
  ros::Time expected_stamp_;
  BodyWrench command_;
  bool have_command_ = false;
  int timeouts_ = 0;
};

}  // namespace
}  // namespace ardsim_dynamics

int main(int argc, char** argv) {
  ros::init(argc, argv, "dynamics");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<ardsim_dynamics::Simulation> sim;
  std::unique_ptr<ardsim_dynamics::DynamicsNode> node;
  try {
    const ardsim_dynamics::DynamicsNodeOptions options = ardsim_dynamics::loadOptions(pnh);
    sim = std::make_unique<ardsim_dynamics::Simulation>(ardsim_dynamics::loadScenario(options.scenario_path));
    node = std::make_unique<ardsim_dynamics::DynamicsNode>(nh, options, *sim);
  } catch (const std::exception& e) {
    ROS_FATAL("dynamics: %s", e.what());
    ardsim_msgs::reportStartupError(nh, "dynamics", e.what());
    return 1;
  }
  try {
    return node->run();
  } catch (const std::exception& e) {
    ROS_FATAL("dynamics: %s", e.what());
    return 1;
  }
}
