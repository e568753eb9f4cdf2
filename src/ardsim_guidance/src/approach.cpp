#include "ardsim_guidance/approach.h"

#include <algorithm>
#include <cmath>

namespace ardsim_guidance {

double profileClosingSpeed(const ApproachOptions& o, double range_m) {
  return std::clamp(range_m / o.closing_time_constant_s, o.contact_speed_mps, o.max_closing_speed_mps);
}

void ApproachReference::start(double range_m) {
  started_ = true;
  range_m_ = range_m;
  speed_mps_ = profileClosingSpeed(options_, range_m);
  hold_left_s_ = 0.0;
  // Hold points already behind the start are skipped.
  hold_done_.assign(options_.hold_ranges_m.size(), false);
  for (size_t i = 0; i < hold_done_.size(); ++i) hold_done_[i] = options_.hold_ranges_m[i] >= range_m;
}

void ApproachReference::advance(double dt, bool frozen) {
  if (!started_ || frozen || !(dt > 0.0)) return;
  if (hold_left_s_ > 0.0) {
    hold_left_s_ = std::max(0.0, hold_left_s_ - dt);
    return;
  }
  // Slow down into the next hold point so that stopping there does not overshoot.
  double speed = profileClosingSpeed(options_, range_m_);
  for (size_t i = 0; i < hold_done_.size(); ++i) {
    if (hold_done_[i]) continue;
    speed = std::min(speed, (range_m_ - options_.hold_ranges_m[i]) / options_.hold_approach_time_constant_s +
                                kHoldArrivalSpeed_mps);
  }
  speed_mps_ = speed;
  const double next = range_m_ - speed * dt;
  for (size_t i = 0; i < hold_done_.size(); ++i) {
    if (!hold_done_[i] && next <= options_.hold_ranges_m[i]) {
      hold_done_[i] = true;
      hold_range_m_ = options_.hold_ranges_m[i];
      hold_left_s_ = options_.hold_durations_s[i];
      range_m_ = hold_range_m_;
      return;
    }
  }
  range_m_ = next;
}

Eigen::Vector3d ApproachReference::velocity(bool frozen) const {
  if (!started_ || frozen || hold_left_s_ > 0.0) return Eigen::Vector3d::Zero();
  return {-speed_mps_, 0.0, 0.0};
}

Eigen::Vector3d PortTracker::command(double dt, const Eigen::Vector3d& position,
                                     const Eigen::Vector3d& velocity,
                                     const Eigen::Vector3d& reference_position,
                                     const Eigen::Vector3d& reference_velocity,
                                     const Eigen::Vector3d& disturbance_accel, bool integrate) {
  const double w = options_.bandwidth_rad_s;
  const double kp = w * w, kd = 2.0 * options_.damping_ratio * w, ki = kp / options_.integral_time_s;
  const Eigen::Vector3d error = reference_position - position;
  if (integrate && dt > 0.0) {
    integral_ += error * dt;
    // Anti-windup: the integral term alone never asks for more than integral_limit.
    const double limit = options_.integral_limit_mps2 / ki;
    integral_ = integral_.cwiseMax(-limit).cwiseMin(limit);
  }
  return kp * error + kd * (reference_velocity - velocity) + ki * integral_ - disturbance_accel;
}

}  // namespace ardsim_guidance
