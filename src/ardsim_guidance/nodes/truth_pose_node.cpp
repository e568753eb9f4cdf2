// truth_pose — TEST TOOL, never used in a real run. Publishes pose/estimate (METHOD_TRUTH) = T_lidar_target
// from truth/target/odom and truth/chaser/odom of the same stamp, with optional seeded noise, random dropouts
// and scripted LOST intervals, so guidance can be tested without the LIDAR and pose chain. One estimate per
// stamp for which both odometries arrived.
#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/startup_error.h>
#include <map>
#include <vector>

#include <ros/ros.h>

#include "conversions.h"

using namespace ardsim_guidance;

namespace {

// Reads and validates every parameter; throws std::invalid_argument.
TruthPoseOptions loadOptions(const ros::NodeHandle& pnh, ardsim_description::TargetKind* target) {
  TruthPoseOptions o;
  std::string target_name = "iss";
  pnh.param("target", target_name, target_name);
  *target = ardsim_description::parseTargetKind(target_name);
  pnh.param("position_sigma_m", o.position_sigma_m, o.position_sigma_m);
  std::vector<double> bias{0.0, 0.0, 0.0};
  pnh.param("position_bias_m", bias, bias);
  if (bias.size() != 3) {
    throw std::invalid_argument("parameter 'position_bias_m' has " + std::to_string(bias.size()) +
                                " elements; allowed: exactly 3");
  }
  o.position_bias_m = Eigen::Vector3d(bias[0], bias[1], bias[2]);
  double attitude_sigma_deg = 0.0;
  pnh.param("attitude_sigma_deg", attitude_sigma_deg, attitude_sigma_deg);
  o.attitude_sigma_rad = attitude_sigma_deg * M_PI / 180.0;
  pnh.param("dropout_probability", o.dropout_probability, o.dropout_probability);
  pnh.param("seed", o.seed, o.seed);
  std::vector<double> lost;
  pnh.param("lost_intervals_s", lost, lost);
  if (lost.size() % 2 != 0) {
    throw std::invalid_argument("parameter 'lost_intervals_s' has " + std::to_string(lost.size()) +
                                " elements; allowed: pairs [t0, t1, t0, t1, ...]");
  }
  for (size_t i = 0; i + 1 < lost.size(); i += 2) o.lost_intervals_s.push_back({lost[i], lost[i + 1]});
  validate(o);
  return o;
}

class TruthPoseNode {
 public:
  TruthPoseNode(ros::NodeHandle& nh, const TruthPoseOptions& options, ardsim_description::TargetKind target)
      : options_(options), generator_(options, VehicleFrames::fromDescription(target)) {
    // Latched: a subscriber that connects late still gets the estimate of the current lockstep step. A deep
    // queue per subscriber, as the pose node's: with 100 (1 s of wall at 10x real time) run_monitor, a Python
    // subscriber that a loaded machine stalls, lost 13-14 of 1694 (dock_short: bag_frames > frames).
    pub_ = nh.advertise<ardsim_msgs::PoseEstimate>("pose/estimate", 1000, true);
    target_sub_ = nh.subscribe<nav_msgs::Odometry>(
        "truth/target/odom", 100, [this](const nav_msgs::Odometry::ConstPtr& m) { on(m, 0); });
    chaser_sub_ = nh.subscribe<nav_msgs::Odometry>(
        "truth/chaser/odom", 100, [this](const nav_msgs::Odometry::ConstPtr& m) { on(m, 1); });
  }

 private:
  struct Pair {
    nav_msgs::Odometry::ConstPtr odom[2];
  };

  // Exact-time synchronization of the two odometries.
  void on(const nav_msgs::Odometry::ConstPtr& msg, int which) {
    const ros::Time stamp = msg->header.stamp;
    Pair& pair = pairs_[stamp];
    pair.odom[which] = msg;
    if (!pair.odom[0] || !pair.odom[1]) {
      while (pairs_.size() > 100) pairs_.erase(pairs_.begin());
      return;
    }
    OwnState target, chaser;
    std::string why;
    const bool ok = fromOdometry(*pair.odom[0], &target, &why) && fromOdometry(*pair.odom[1], &chaser, &why);
    // Stamps older than a matched pair will never match.
    pairs_.erase(pairs_.begin(), std::next(pairs_.find(stamp)));
    if (!ok) {
      ARDSIM_WARN_THROTTLE(5.0, "truth_pose: malformed odometry at %.3f s: %s; publishing LOST",
                           stamp.toSec(), why.c_str());
      TruthPoseSample lost;
      lost.status = EstimateStatus::kLost;
      lost.reason = "truth_pose: malformed odometry";
      pub_.publish(toPoseEstimate(lost, options_, stamp));
      return;
    }
    auto pose = [](const OwnState& s) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = s.q_eci_chaser.toRotationMatrix();
      T.translation() = s.position_eci_m;
      return T;
    };
    const TruthPoseSample sample = generator_.generate(stamp.toSec(), pose(target), pose(chaser));
    pub_.publish(toPoseEstimate(sample, options_, stamp));
  }

  TruthPoseOptions options_;
  TruthPoseGenerator generator_;
  ros::Publisher pub_;
  ros::Subscriber target_sub_, chaser_sub_;
  std::map<ros::Time, Pair> pairs_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "truth_pose");
  ros::NodeHandle nh, pnh("~");
  TruthPoseOptions options;
  ardsim_description::TargetKind target;
  try {
    options = loadOptions(pnh, &target);
  } catch (const std::exception& e) {
    ROS_FATAL("truth_pose: %s", e.what());
    ardsim_msgs::reportStartupError(nh, "truth_pose", e.what());
    return 1;
  }
  ROS_INFO("truth_pose: TEST TOOL publishing pose/estimate from truth (never use in a real run)");
  TruthPoseNode node(nh, options, target);
  ros::spin();
  return 0;
}
