#include "ardsim_lidar/fault_schedule.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ardsim_lidar {

namespace {

void validateIntervals(const std::vector<double>& times_s, const std::string& name) {
  std::ostringstream text;
  for (double t : times_s) text << (text.tellp() > 0 ? " " : "") << t;
  const std::string value = "[" + text.str() + "]";
  if (times_s.size() % 2 != 0)
    throw std::invalid_argument(name + " = " + value +
                                " is out of range: allowed a flat list of pairs [t0, t1, ...] (s)");
  for (std::size_t i = 0; i < times_s.size(); i += 2)
    if (!std::isfinite(times_s[i]) || !std::isfinite(times_s[i + 1]) || times_s[i + 1] < times_s[i])
      throw std::invalid_argument(name + " = " + value +
                                  " is out of range: each pair needs finite times with t0 <= t1 (s)");
}

bool inside(const std::vector<double>& times_s, double t_s) {
  for (std::size_t i = 0; i + 1 < times_s.size(); i += 2)
    if (t_s >= times_s[i] && t_s <= times_s[i + 1]) return true;
  return false;
}

}  // namespace

void validate(const FaultOptions& options) {
  validateIntervals(options.drop_intervals_s, "faults/drop_intervals_s");
  validateIntervals(options.blind_intervals_s, "faults/blind_intervals_s");
}

SensorFault faultAt(const FaultOptions& options, double t_s) {
  if (inside(options.drop_intervals_s, t_s)) return SensorFault::kDropped;
  if (inside(options.blind_intervals_s, t_s)) return SensorFault::kBlinded;
  return SensorFault::kNone;
}

void applyFault(SensorFault fault, LidarFrame* frame) {
  if (fault == SensorFault::kNone) return;
  const std::size_t pixels = static_cast<std::size_t>(frame->width) * static_cast<std::size_t>(frame->height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  frame->range_m.assign(pixels, nan);
  frame->intensity.assign(pixels, fault == SensorFault::kBlinded ? 1.0f : nan);
}

const char* faultName(SensorFault fault) {
  switch (fault) {
    case SensorFault::kDropped:
      return "dropped";
    case SensorFault::kBlinded:
      return "blinded";
    case SensorFault::kNone:
      break;
  }
  return "none";
}

}  // namespace ardsim_lidar
