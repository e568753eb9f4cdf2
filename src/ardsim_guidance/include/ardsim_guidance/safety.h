// Safety checks of the approach: the corridor (a cone about the docking axis) and the keep-out sphere around
// the target port, inside which the chaser port must stay in the corridor; and the estimate-status rules
// (DEGRADED -> HOLD, LOST longer than a limit -> RETREAT, corridor left -> RETREAT).
#pragma once

#include <string>

#include <Eigen/Core>

namespace ardsim_guidance {

enum class EstimateStatus { kTracking = 0, kDegraded = 1, kLost = 2 };  // = PoseEstimate.STATUS_*

struct SafetyOptions {
  double corridor_half_angle_rad = 10.0 * M_PI / 180.0;  // approach cone about the docking axis
  double corridor_min_radius_m = 0.5;  // radius of the corridor at the port (the cone's apex is blunted)
  double keep_out_radius_m = 30.0;     // sphere about the target port: inside it, only in the corridor
  double lost_limit_s = 3.0;           // estimate LOST (or unusable) longer than this: RETREAT
};

// Allowed distance from the docking axis at a point of target_port coordinates.
double corridorRadius(const SafetyOptions& options, const Eigen::Vector3d& port_position_m);
bool insideCorridor(const SafetyOptions& options, const Eigen::Vector3d& port_position_m);
bool insideKeepOut(const SafetyOptions& options, const Eigen::Vector3d& port_position_m);
// Inside the keep-out sphere and outside the corridor.
bool corridorViolated(const SafetyOptions& options, const Eigen::Vector3d& port_position_m);

enum class SafetyAction { kProceed, kHold, kRetreat };

struct SafetyDecision {
  SafetyAction action = SafetyAction::kProceed;
  std::string reason;
};

// The estimate-status rules, with the corridor check on the current port position (target_port).
class SafetyMonitor {
 public:
  explicit SafetyMonitor(const SafetyOptions& options = {}) : options_(options) {}
  // usable: the estimate at time_s can be steered on (not LOST, well-formed). status: its status.
  SafetyDecision check(double time_s, bool usable, EstimateStatus status, const std::string& status_reason,
                       bool have_position, const Eigen::Vector3d& port_position_m);
  bool retreating() const { return retreating_; }
  const std::string& retreatReason() const { return retreat_reason_; }

 private:
  SafetyOptions options_;
  bool seen_usable_ = false;
  double last_usable_time_s_ = 0.0;
  bool retreating_ = false;
  std::string retreat_reason_;
};

}  // namespace ardsim_guidance
