// Near field: the reference trajectory down the docking axis (a closing-speed profile that slows with range
// to the contact speed, with optional hold points) and a PID that makes the chaser port track a reference,
// all in target_port coordinates (x out of the port; the chaser closes along +x towards the origin).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace ardsim_guidance {

struct ApproachOptions {
  double max_closing_speed_mps = 0.20;     // cap of the profile far out
  double closing_time_constant_s = 100.0;  // profile: closing speed = range / time constant, ...
  double contact_speed_mps = 0.075;        // ... but never below this (inside the 0.05-0.10 m/s envelope)
  std::vector<double> hold_ranges_m;       // hold points on the axis, m (any order)
  std::vector<double> hold_durations_s;    // how long to hold at each, s
  double hold_approach_time_constant_s =
      20.0;  // closing speed towards a hold point <= distance / this + 1 cm/s
  // PID on the port position error; gains from a second-order closed loop: kp = w^2, kd = 2 zeta w, ki = kp /
  // Ti.
  double bandwidth_rad_s = 0.15;
  double damping_ratio = 0.9;
  double integral_time_s = 100.0;
  double integral_limit_mps2 = 0.002;  // anti-windup: bound on the integral term's acceleration
};

// Closing speed of the profile at range_m (metres along the docking axis).
double profileClosingSpeed(const ApproachOptions& options, double range_m);

// The reference point of the approach: starts at the current range and moves in along the axis at the
// profile's closing speed, stopping at hold points for their duration. Lateral reference: the axis.
class ApproachReference {
 public:
  explicit ApproachReference(const ApproachOptions& options = {}) : options_(options) {}
  void start(double range_m);
  // Advances by dt_s; frozen (no motion) when `frozen` (a HOLD for a degraded or lost estimate).
  void advance(double dt_s, bool frozen);
  bool started() const { return started_; }
  double range_m() const { return range_m_; }
  bool atHoldPoint() const { return hold_left_s_ > 0.0; }
  double holdPointRange_m() const { return hold_range_m_; }
  double holdLeft_s() const { return hold_left_s_; }
  Eigen::Vector3d position() const { return {range_m_, 0.0, 0.0}; }
  Eigen::Vector3d velocity(bool frozen) const;

 private:
  ApproachOptions options_;
  bool started_ = false;
  static constexpr double kHoldArrivalSpeed_mps = 0.01;
  double range_m_ = 0.0;
  double speed_mps_ = 0.0;  // closing speed of the reference over the last step
  double hold_left_s_ = 0.0;
  double hold_range_m_ = 0.0;
  std::vector<bool> hold_done_;
};

// PID with feedforward of the known acceleration (gravity gradient / CW terms) on the port position.
class PortTracker {
 public:
  explicit PortTracker(const ApproachOptions& options = {}) : options_(options) {}
  void reset() { integral_.setZero(); }
  // Commanded acceleration (same frame as the inputs) that drives (position, velocity) to the reference.
  // disturbance_accel_mps2: the free-motion acceleration to cancel. `integrate` false freezes the integral.
  Eigen::Vector3d command(double dt_s, const Eigen::Vector3d& position_m, const Eigen::Vector3d& velocity_mps,
                          const Eigen::Vector3d& reference_position_m,
                          const Eigen::Vector3d& reference_velocity_mps,
                          const Eigen::Vector3d& disturbance_accel_mps2, bool integrate);

 private:
  ApproachOptions options_;
  Eigen::Vector3d integral_{0, 0, 0};  // integral of the position error, m s
};

}  // namespace ardsim_guidance
