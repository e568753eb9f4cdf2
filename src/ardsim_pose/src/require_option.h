// The option checks' one error format, "name = value is out of range: allowed" (the node prefixes
// "parameter "). Private to the core's sources.
#pragma once

#include <stdexcept>
#include <string>

namespace ardsim_pose {

inline void requireOption(bool ok, const std::string& name, double value, const std::string& allowed) {
  if (!ok) throw std::invalid_argument(name + " = " + std::to_string(value) + " is out of range: " + allowed);
}

}  // namespace ardsim_pose
