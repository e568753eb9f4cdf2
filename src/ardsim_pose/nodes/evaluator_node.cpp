// pose_evaluator: publishes pose/error (estimate minus truth at the same stamp) for every pose/estimate.
// Truth T_lidar_target comes from truth/target/odom and truth/chaser/odom (paired by exact stamp) with
// T_chaser_lidar. Either side may arrive first: both wait in bounded buffers keyed by stamp. Evaluation only.
// Time going back (a bag played again, a simulation restarted) empties the buffers: what waits there is of
// the old time line, and being newer it would outlive the new messages when a buffer is bounded (the oldest
// go first).
#include <cmath>
#include <map>
#include <string>

#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/startup_error.h>
#include <ros/ros.h>

#include "ardsim_description/frames.h"
#include "conversions.h"

namespace ardsim_pose {

class PoseEvaluator {
 public:
  PoseEvaluator(ros::NodeHandle nh, const ros::NodeHandle& private_nh) {
    std::string target = "iss";
    private_nh.param("target", target, target);
    try {
      T_target_port_ = ardsim_description::T_target_port(ardsim_description::parseTargetKind(target));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("parameter target: ") + e.what());
    }
    private_nh.param("buffer_size", buffer_size_, buffer_size_);
    if (buffer_size_ < 1 || buffer_size_ > 10000)
      throw std::invalid_argument("parameter buffer_size = " + std::to_string(buffer_size_) +
                                  " is out of range: 1 .. 10000");
    private_nh.param("restart_time_jump_s", restart_time_jump_s_, restart_time_jump_s_);
    if (!(std::isfinite(restart_time_jump_s_) && restart_time_jump_s_ >= 0.0))
      throw std::invalid_argument("parameter restart_time_jump_s = " + std::to_string(restart_time_jump_s_) +
                                  " is out of range: >= 0");
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
  template <typename Map>
  void bound(Map* map) {
    while (static_cast<int>(map->size()) > buffer_size_) map->erase(map->begin());
  }

  // A message stamped more than restart_time_jump_s before the last stamp evaluated: time went back.
  void startAgainIfTimeWentBack(const ros::Time& stamp) {
    if (!have_evaluated_ || stamp.toSec() >= last_evaluated_.toSec() - restart_time_jump_s_) return;
    ROS_WARN(
        "pose_evaluator: t = %.6f is %.3f s before the last stamp evaluated: time went back, buffers emptied "
        "(%zu estimates, %zu target and %zu chaser states waiting)",
        stamp.toSec(), (last_evaluated_ - stamp).toSec(), estimates_.size(), target_.size(), chaser_.size());
    estimates_.clear();
    target_.clear();
    chaser_.clear();
    have_evaluated_ = false;
  }

  void onTarget(const nav_msgs::OdometryConstPtr& msg) {
    startAgainIfTimeWentBack(msg->header.stamp);
    target_[msg->header.stamp] = msg;
    bound(&target_);
    evaluate(msg->header.stamp);
  }
  void onChaser(const nav_msgs::OdometryConstPtr& msg) {
    startAgainIfTimeWentBack(msg->header.stamp);
    chaser_[msg->header.stamp] = msg;
    bound(&chaser_);
    evaluate(msg->header.stamp);
  }
  void onEstimate(const ardsim_msgs::PoseEstimateConstPtr& msg) {
    startAgainIfTimeWentBack(msg->header.stamp);
    estimates_[msg->header.stamp] = msg;
    bound(&estimates_);
    evaluate(msg->header.stamp);
  }

  void evaluate(const ros::Time& stamp) {
    const auto estimate = estimates_.find(stamp);
    const auto target = target_.find(stamp);
    const auto chaser = chaser_.find(stamp);
    if (estimate == estimates_.end() || target == target_.end() || chaser == chaser_.end()) return;
    Eigen::Isometry3d T_eci_target, T_eci_chaser, T_estimate;
    std::string error;
    if (!poseFromOdometry(*target->second, &T_eci_target, &error) ||
        !poseFromOdometry(*chaser->second, &T_eci_chaser, &error) ||
        !poseFromEstimate(*estimate->second, &T_estimate, &error)) {
      ARDSIM_WARN_THROTTLE(5.0, "pose_evaluator: cannot evaluate t = %.6f: %s", stamp.toSec(), error.c_str());
    } else {
      const Eigen::Isometry3d truth =
          ardsim_description::lidarFromTarget(T_eci_target, T_eci_chaser, T_chaser_lidar_);
      error_publisher_.publish(toPoseError(poseError(T_estimate, truth, T_target_port_), *estimate->second));
    }
    last_evaluated_ = stamp;
    have_evaluated_ = true;
    // This stamp is done; older ones will not be completed either.
    estimates_.erase(estimates_.begin(), std::next(estimate));
    target_.erase(target_.begin(), std::next(target));
    chaser_.erase(chaser_.begin(), std::next(chaser));
  }

  int buffer_size_ = 100;
  double restart_time_jump_s_ = 1.0;
  bool have_evaluated_ = false;
  ros::Time last_evaluated_;
  Eigen::Isometry3d T_target_port_;
  Eigen::Isometry3d T_chaser_lidar_;
  std::map<ros::Time, nav_msgs::OdometryConstPtr> target_;
  std::map<ros::Time, nav_msgs::OdometryConstPtr> chaser_;
  std::map<ros::Time, ardsim_msgs::PoseEstimateConstPtr> estimates_;
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
