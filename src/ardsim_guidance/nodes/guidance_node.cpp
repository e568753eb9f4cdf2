// guidance_node: one guidance/command (and one guidance/state) per pose/estimate, stamped with the estimate's
// stamp. Reads the chaser's own inertial state from truth/chaser/odom (standing in for its GPS, star tracker
// and gyros); never any relative truth. Parameters: config/guidance.yaml.
#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/startup_error.h>
#include <deque>
#include <map>
#include <vector>

#include <ros/ros.h>

#include "conversions.h"

using namespace ardsim_guidance;

namespace {

// Reads every parameter (defaults = the core's in-class defaults) and validates; throws
// std::invalid_argument.
GuidanceOptions loadOptions(const ros::NodeHandle& pnh, double* own_state_timeout_s) {
  GuidanceOptions o;
  auto get = [&](const std::string& name, double& value) { pnh.param(name, value, value); };
  auto get_int = [&](const std::string& name, int& value) { pnh.param(name, value, value); };
  auto get_vec3 = [&](const std::string& name, Eigen::Vector3d& value, double scale) {
    std::vector<double> v{value.x() / scale, value.y() / scale, value.z() / scale};
    pnh.param(name, v, v);
    if (v.size() != 3) {
      throw std::invalid_argument("parameter '" + name + "' has " + std::to_string(v.size()) +
                                  " elements; allowed: exactly 3");
    }
    value = Eigen::Vector3d(v[0], v[1], v[2]) * scale;
  };
  const double deg = M_PI / 180.0;
  std::string target = ardsim_description::targetKindName(o.target), velocity = "kalman",
              attitude_mode = "lvlh";
  pnh.param("target", target, target);
  o.target = ardsim_description::parseTargetKind(target);
  get("chaser_mass_kg", o.chaser_mass_kg);
  get("control_period_s", o.control_period_s);
  get("near_field_range_m", o.near_field_range_m);
  get("contact_range_m", o.contact_range_m);
  get("retreat_speed_mps", o.retreat_speed_mps);
  get("retreat_range_m", o.retreat_range_m);
  get("degraded_sigma_factor", o.degraded_sigma_factor);
  get("target_attitude_time_constant_s", o.target_attitude_time_constant_s);
  get_vec3("target_rpy_in_lvlh_deg", o.target_rpy_in_lvlh_rad, deg);
  pnh.param("attitude_mode", attitude_mode, attitude_mode);
  o.attitude_mode = parseAttitudeMode(attitude_mode);
  get_vec3("max_force_n", o.max_force_n, 1.0);
  get_vec3("max_torque_nm", o.max_torque_nm, 1.0);
  OwnStateNoiseOptions& sn = o.own_state_noise;
  get("own_state_noise/position_sigma_m", sn.position_sigma_m);
  get("own_state_noise/velocity_sigma_mps", sn.velocity_sigma_mps);
  double attitude_sigma_deg = sn.attitude_sigma_rad / deg, rate_sigma_deg_s = sn.rate_sigma_rad_s / deg;
  get("own_state_noise/attitude_sigma_deg", attitude_sigma_deg);
  get("own_state_noise/rate_sigma_deg_s", rate_sigma_deg_s);
  sn.attitude_sigma_rad = attitude_sigma_deg * deg;
  sn.rate_sigma_rad_s = rate_sigma_deg_s * deg;
  get_int("own_state_noise/seed", sn.seed);
  NavigatorOptions& n = o.navigator;
  pnh.param("navigator/velocity_source", velocity, velocity);
  n.velocity_source = parseVelocitySource(velocity);
  get_int("navigator/median_window", n.median_window);
  get_int("navigator/difference_span", n.difference_span);
  get("navigator/history_reset_gap_s", n.history_reset_gap_s);
  get("navigator/measurement_sigma_m", n.measurement_sigma_m);
  get("navigator/process_accel_sigma_mps2", n.process_accel_sigma_mps2);
  get("navigator/initial_velocity_sigma_mps", n.initial_velocity_sigma_mps);
  ApproachOptions& a = o.approach;
  get("approach/max_closing_speed_mps", a.max_closing_speed_mps);
  get("approach/closing_time_constant_s", a.closing_time_constant_s);
  get("approach/contact_speed_mps", a.contact_speed_mps);
  pnh.param("approach/hold_ranges_m", a.hold_ranges_m, a.hold_ranges_m);
  pnh.param("approach/hold_durations_s", a.hold_durations_s, a.hold_durations_s);
  get("approach/hold_approach_time_constant_s", a.hold_approach_time_constant_s);
  get("approach/bandwidth_rad_s", a.bandwidth_rad_s);
  get("approach/damping_ratio", a.damping_ratio);
  get("approach/integral_time_s", a.integral_time_s);
  get("approach/integral_limit_mps2", a.integral_limit_mps2);
  FarFieldOptions& f = o.far_field;
  get("far_field/aim_range_m", f.aim_range_m);
  get("far_field/transfer_time_s", f.transfer_time_s);
  get("far_field/retarget_interval_s", f.retarget_interval_s);
  get("far_field/min_retarget_time_s", f.min_retarget_time_s);
  get("far_field/burn_accel_mps2", f.burn_accel_mps2);
  SafetyOptions& s = o.safety;
  double half_angle_deg = s.corridor_half_angle_rad / deg;
  get("safety/corridor_half_angle_deg", half_angle_deg);
  s.corridor_half_angle_rad = half_angle_deg * deg;
  get("safety/corridor_min_radius_m", s.corridor_min_radius_m);
  get("safety/keep_out_radius_m", s.keep_out_radius_m);
  get("safety/lost_limit_s", s.lost_limit_s);
  get("attitude/bandwidth_rad_s", o.attitude.bandwidth_rad_s);
  get("attitude/damping_ratio", o.attitude.damping_ratio);
  get_vec3("attitude/inertia_kg_m2", o.attitude.inertia_kg_m2, 1.0);
  get("own_state_timeout_s", *own_state_timeout_s);
  if (!(*own_state_timeout_s > 0.0 && *own_state_timeout_s <= 60.0)) {
    throw std::invalid_argument("parameter 'own_state_timeout_s' = " + std::to_string(*own_state_timeout_s) +
                                " is outside the allowed range (0, 60]");
  }
  validate(o);
  return o;
}

class GuidanceNode {
 public:
  GuidanceNode(ros::NodeHandle& nh, const GuidanceOptions& options, double own_state_timeout_s)
      : guidance_(options), own_state_timeout_s_(own_state_timeout_s) {
    // Latched: the dynamics gets the command of the current step even if it connects after it was sent. 1000
    // queued per subscriber: the recorder, outside the lockstep, falls behind by hundreds of steps.
    command_pub_ = nh.advertise<geometry_msgs::WrenchStamped>("guidance/command", 1000, true);
    state_pub_ = nh.advertise<ardsim_msgs::GuidanceState>("guidance/state", 1000, true);
    odom_sub_ = nh.subscribe("truth/chaser/odom", 100, &GuidanceNode::onOdometry, this);
    estimate_sub_ = nh.subscribe("pose/estimate", 100, &GuidanceNode::onEstimate, this);
    // Deadlock breaker only: an estimate whose own-state message never comes is answered after a wall
    // timeout.
    timer_ = nh.createWallTimer(ros::WallDuration(0.1), [this](const ros::WallTimerEvent&) { flush(true); });
  }

 private:
  struct Pending {
    ardsim_msgs::PoseEstimate::ConstPtr msg;
    ros::WallTime received;
  };

  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    OwnState state;
    std::string why;
    if (!fromOdometry(*msg, &state, &why)) {
      ARDSIM_WARN_THROTTLE(5.0, "guidance: ignoring malformed truth/chaser/odom at %.3f s: %s",
                           msg->header.stamp.toSec(), why.c_str());
      return;
    }
    own_states_[msg->header.stamp] = state;
    latest_odom_stamp_ = std::max(latest_odom_stamp_, msg->header.stamp);
    while (own_states_.size() > 200) own_states_.erase(own_states_.begin());
    flush(false);
  }

  void onEstimate(const ardsim_msgs::PoseEstimate::ConstPtr& msg) {
    // One answer per step. A repeat of a step already taken (a latched message delivered again as a
    // connection is made, which the pose node answers by publishing its estimate again) would advance the
    // guidance twice and change the command: the run would then depend on connection timing.
    if (have_estimate_ && msg->header.stamp <= last_estimate_stamp_) {
      ARDSIM_WARN_THROTTLE(5.0, "guidance: pose/estimate for t = %.3f s again (latest %.3f s): ignored",
                           msg->header.stamp.toSec(), last_estimate_stamp_.toSec());
      return;
    }
    have_estimate_ = true;
    last_estimate_stamp_ = msg->header.stamp;
    pending_.push_back({msg, ros::WallTime::now()});
    flush(false);
  }

  // Answers the pending estimates in order, each with the own state of its stamp, as soon as that is known
  // (or a later own state shows it never will be, or the wall timeout passed).
  void flush(bool on_timer) {
    while (!pending_.empty()) {
      const Pending& p = pending_.front();
      const ros::Time stamp = p.msg->header.stamp;
      const auto exact = own_states_.find(stamp);
      const bool timed_out = on_timer && (ros::WallTime::now() - p.received).toSec() > own_state_timeout_s_;
      if (exact == own_states_.end() && !(latest_odom_stamp_ > stamp) && !timed_out) return;
      const OwnState* own = nullptr;
      if (exact != own_states_.end()) {
        own = &exact->second;
      } else {
        // The latest own state not after the estimate, if any.
        auto it = own_states_.upper_bound(stamp);
        if (it != own_states_.begin()) own = &std::prev(it)->second;
        ARDSIM_WARN_THROTTLE(5.0, "guidance: no truth/chaser/odom at the estimate's stamp %.3f s; using %s",
                             stamp.toSec(), own ? "an earlier one" : "none (hold)");
      }
      answer(*p.msg, own);
      pending_.pop_front();
    }
  }

  void answer(const ardsim_msgs::PoseEstimate& msg, const OwnState* own) {
    const EstimateInput input = fromPoseEstimate(msg);
    if (!input.well_formed && input.status != EstimateStatus::kLost) {
      ARDSIM_WARN_THROTTLE(5.0, "guidance: %s at %.3f s; answering with a hold command", input.reason.c_str(),
                           msg.header.stamp.toSec());
    }
    const GuidanceOutput out = guidance_.step(input, own);
    if (out.phase != last_phase_ || (out.phase == Phase::kRetreat && out.reason != last_reason_)) {
      ROS_INFO("guidance: %s at %.1f s: %s", phaseName(out.phase), msg.header.stamp.toSec(),
               out.reason.c_str());
      last_phase_ = out.phase;
      last_reason_ = out.reason;
    }
    command_pub_.publish(toWrench(out, msg.header.stamp));
    state_pub_.publish(toGuidanceState(out, msg.header.stamp));
  }

  Guidance guidance_;
  double own_state_timeout_s_;
  ros::Publisher command_pub_, state_pub_;
  ros::Subscriber odom_sub_, estimate_sub_;
  ros::WallTimer timer_;
  std::map<ros::Time, OwnState> own_states_;
  ros::Time latest_odom_stamp_;
  bool have_estimate_ = false;
  ros::Time last_estimate_stamp_;
  std::deque<Pending> pending_;
  Phase last_phase_ = Phase::kWait;
  std::string last_reason_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "guidance");
  ros::NodeHandle nh, pnh("~");
  double own_state_timeout_s = 2.0;
  GuidanceOptions options;
  try {
    options = loadOptions(pnh, &own_state_timeout_s);
  } catch (const std::exception& e) {
    ROS_FATAL("guidance: %s", e.what());
    ardsim_msgs::reportStartupError(nh, "guidance", e.what());
    return 1;
  }
  GuidanceNode node(nh, options, own_state_timeout_s);
  ros::spin();
  return 0;
}
