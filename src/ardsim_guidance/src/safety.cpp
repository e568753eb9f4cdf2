#include "ardsim_guidance/safety.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ardsim_guidance {

double corridorRadius(const SafetyOptions& o, const Eigen::Vector3d& p) {
  return std::max(o.corridor_min_radius_m, p.x() * std::tan(o.corridor_half_angle_rad));
}

bool insideCorridor(const SafetyOptions& o, const Eigen::Vector3d& p) {
  return p.tail<2>().norm() <= corridorRadius(o, p);
}

bool insideKeepOut(const SafetyOptions& o, const Eigen::Vector3d& p) {
  return p.norm() < o.keep_out_radius_m;
}

bool corridorViolated(const SafetyOptions& o, const Eigen::Vector3d& p) {
  return insideKeepOut(o, p) && !insideCorridor(o, p);
}

namespace {
std::string format(const char* fmt, double a, double b, double c = 0.0) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), fmt, a, b, c);
  return buffer;
}
}  // namespace

SafetyDecision SafetyMonitor::check(double time_s, bool usable, EstimateStatus status, const std::string& why,
                                    bool have_position, const Eigen::Vector3d& p) {
  if (usable) {
    seen_usable_ = true;
    last_usable_time_s_ = time_s;
  }
  if (!retreating_ && seen_usable_ && !usable && time_s - last_usable_time_s_ > options_.lost_limit_s) {
    retreating_ = true;
    retreat_reason_ = format("estimate LOST for %.1f s > limit %.1f s", time_s - last_usable_time_s_,
                             options_.lost_limit_s);
  }
  // The corridor is judged only at steps with a usable estimate, never on a position propagated without one.
  if (!retreating_ && usable && have_position && corridorViolated(options_, p)) {
    retreating_ = true;
    retreat_reason_ = format("corridor left: %.2f m off the axis > %.2f m allowed at range %.2f m",
                             p.tail<2>().norm(), corridorRadius(options_, p), p.x());
  }
  if (retreating_) return {SafetyAction::kRetreat, retreat_reason_};
  if (!usable) {
    if (!seen_usable_) return {SafetyAction::kHold, "no usable estimate yet"};
    return {SafetyAction::kHold, format("estimate unusable for %.1f s (limit %.1f s)",
                                        time_s - last_usable_time_s_, options_.lost_limit_s) +
                                     (why.empty() ? std::string() : ": " + why)};
  }
  if (status == EstimateStatus::kDegraded)
    return {SafetyAction::kHold, "estimate DEGRADED" + (why.empty() ? std::string() : ": " + why)};
  return {};
}

}  // namespace ardsim_guidance
