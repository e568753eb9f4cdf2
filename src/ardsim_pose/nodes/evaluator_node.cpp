// pose_evaluator: publishes pose/error (estimate minus truth at the same stamp) for every pose/estimate.
// Truth T_lidar_target comes from truth/target/odom and truth/chaser/odom (paired by exact stamp) with
// T_chaser_lidar. Either side may arrive first: both wait in bounded buffers keyed by stamp (StampMatcher,
// which also keeps time lines apart when time goes back). Evaluation only.
#include <cmath>
#include <cstdint>
#include <string>

#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/param_read.h>
#include <ardsim_msgs/startup_error.h>
#include <ros/ros.h>

#include "ardsim_description/frames.h"
#include "ardsim_pose/require_option.h"
#include "ardsim_pose/stamp_matcher.h"
#include "conversions.h"

namespace ardsim_pose {

class PoseEvaluator {
  using Matcher =
      StampMatcher<ardsim_msgs::PoseEstimateConstPtr, nav_msgs::OdometryConstPtr, nav_msgs::OdometryConstPtr>;

 public:
  PoseEvaluator(ros::NodeHandle nh, const ros::NodeHandle& private_nh) : matcher_(makeMatcher(private_nh)) {
    std::string target = "iss";
    private_nh.param("target", target, target);
    ardsim_msgs::validateParameters(
        [&] {
          T_target_port_ = ardsim_description::T_target_port(ardsim_description::parseTargetKind(target));
        },
        "target: ");
    T_chaser_lidar_ = ardsim_description::T_chaser_lidar();
    error_publisher_ = nh.advertise<ardsim_msgs::PoseError>("pose/error", 1000, true);  // see pose/estimate
    // The evaluator is outside the lockstep loop: at 10x real time and more, a queue of 10 (1 s of sim time)
    // overflowed when it was held up by ~0.1 s of other load, and frames went without an error (4 of 5291 in
    // one default run). 1000 messages: 100 s of sim time.
    constexpr std::uint32_t kQueue = 1000;
    estimate_subscriber_ = nh.subscribe("pose/estimate", kQueue, &PoseEvaluator::onEstimate, this);
    target_subscriber_ = nh.subscribe("truth/target/odom", kQueue, &PoseEvaluator::onTarget, this);
    // truth/chaser/odom only once connected to the other two's publishers: the dynamics starts once this node
    // too listens to it (docking.launch's wait_for_subscribers), and connected later, under load, this node
    // missed the first 275 frames' estimates or truth (a CI run of the default scenario: its first
    // /pose/error at 27.5 s). Polled in wall time: the clock stands still until the dynamics starts.
    connect_timer_ =
        nh.createWallTimer(ros::WallDuration(0.01), [this, nh](const ros::WallTimerEvent&) mutable {
          if (estimate_subscriber_.getNumPublishers() == 0 || target_subscriber_.getNumPublishers() == 0)
            return;
          chaser_subscriber_ = nh.subscribe("truth/chaser/odom", kQueue, &PoseEvaluator::onChaser, this);
          connect_timer_.stop();
        });
  }

 private:
  static Matcher makeMatcher(const ros::NodeHandle& private_nh) {
    int buffer_size = 100;
    private_nh.param("buffer_size", buffer_size, buffer_size);
    requireParameter(buffer_size >= 1 && buffer_size <= 10000, "buffer_size", buffer_size, "1 .. 10000");
    double restart_time_jump_s = 1.0;
    private_nh.param("restart_time_jump_s", restart_time_jump_s, restart_time_jump_s);
    requireParameter(
        std::isfinite(restart_time_jump_s) && restart_time_jump_s >= 0.0 && restart_time_jump_s <= 1e6,
        "restart_time_jump_s", restart_time_jump_s, "0 .. 1e6");
    return Matcher(buffer_size, static_cast<Matcher::Stamp>(std::llround(restart_time_jump_s * 1e9)));
  }

  // A new time line (time went back) is logged; a completed stamp is evaluated.
  void handle(const Matcher::Added& added, const ros::Time& stamp) {
    if (added.went_back_from)
      ARDSIM_WARN_THROTTLE(
          5.0,
          "pose_evaluator: t = %.6f is %.3f s before the last stamp evaluated: time went back, "
          "matching starts again (the earlier time line's late messages are matched among "
          "themselves)",
          stamp.toSec(), (*added.went_back_from - static_cast<std::int64_t>(stamp.toNSec())) * 1e-9);
    if (added.match) evaluate(stamp, *added.match);
  }

  void onEstimate(const ardsim_msgs::PoseEstimateConstPtr& msg) {
    handle(matcher_.add<0>(msg->header.stamp.toNSec(), msg), msg->header.stamp);
  }
  void onTarget(const nav_msgs::OdometryConstPtr& msg) {
    handle(matcher_.add<1>(msg->header.stamp.toNSec(), msg), msg->header.stamp);
  }
  void onChaser(const nav_msgs::OdometryConstPtr& msg) {
    handle(matcher_.add<2>(msg->header.stamp.toNSec(), msg), msg->header.stamp);
  }

  void evaluate(const ros::Time& stamp, const Matcher::Match& match) {
    const auto& [estimate, target, chaser] = match;
    Eigen::Isometry3d T_eci_target, T_eci_chaser, T_estimate;
    std::string error;
    if (!poseFromOdometry(*target, &T_eci_target, &error) ||
        !poseFromOdometry(*chaser, &T_eci_chaser, &error) ||
        !poseFromEstimate(*estimate, &T_estimate, &error)) {
      ARDSIM_WARN_THROTTLE(5.0, "pose_evaluator: cannot evaluate t = %.6f: %s", stamp.toSec(), error.c_str());
    } else {
      const Eigen::Isometry3d truth =
          ardsim_description::lidarFromTarget(T_eci_target, T_eci_chaser, T_chaser_lidar_);
      error_publisher_.publish(toPoseError(poseError(T_estimate, truth, T_target_port_), *estimate));
    }
  }

  Eigen::Isometry3d T_target_port_;
  Eigen::Isometry3d T_chaser_lidar_;
  Matcher matcher_;
  ros::Publisher error_publisher_;
  ros::Subscriber estimate_subscriber_, target_subscriber_, chaser_subscriber_;
  ros::WallTimer connect_timer_;
};

}  // namespace ardsim_pose

int main(int argc, char** argv) {
  ros::init(argc, argv, "pose_evaluator");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  return ardsim_msgs::spinNode<ardsim_pose::PoseEvaluator>("pose_evaluator", nh, private_nh);
}
