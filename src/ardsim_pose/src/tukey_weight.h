// Tukey's biweight, shared by ICP's plane residuals and the occluding contours. Private to the core's
// sources.
#pragma once

#include <cmath>

namespace ardsim_pose {

// Tukey's biweight of a residual against its limit (0 beyond it).
inline double tukeyWeight(double residual, double limit) {
  const double u = residual / limit;
  return std::abs(u) < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
}

}  // namespace ardsim_pose
