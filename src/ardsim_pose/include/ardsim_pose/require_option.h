// The option checks' one error format, "name = value is out of range: allowed", for the core (whose callers
// prefix the parameter namespace) and the nodes' own parameters ("parameter name = ...").
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace ardsim_pose {

// The value as a user writes it: "3", "-0.001", "0.1" (std::to_string gives "3.000000").
inline std::string optionValueText(double value) {
  std::ostringstream text;
  text.precision(10);
  text << value;
  return text.str();
}

inline void requireOption(bool ok, const std::string& name, double value, const std::string& allowed) {
  if (!ok)
    throw std::invalid_argument(name + " = " + optionValueText(value) + " is out of range: " + allowed);
}

inline void requireParameter(bool ok, const std::string& name, double value, const std::string& allowed) {
  requireOption(ok, "parameter " + name, value, allowed);
}

}  // namespace ardsim_pose
