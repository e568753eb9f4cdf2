#include "ardsim_lidar/sensor.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ardsim_lidar {

namespace {

void require(bool ok, const std::string& name, double value, const std::string& allowed) {
  if (ok) return;
  std::ostringstream message;
  message << name << " = " << value << " is out of range: allowed " << allowed;
  throw std::invalid_argument(message.str());
}

}  // namespace

void validate(const SensorOptions& options) {
  require(options.width >= 1 && options.width <= 4096, "width", options.width, "1..4096");
  require(options.height >= 1 && options.height <= 4096, "height", options.height, "1..4096");
  require(std::isfinite(options.fov_deg) && options.fov_deg > 0.0 && options.fov_deg < 170.0, "fov_deg",
          options.fov_deg, "(0, 170)");
  const double vertical_fov_deg = options.fov_deg * options.height / options.width;
  require(vertical_fov_deg < 170.0, "fov_deg", options.fov_deg, "such that fov_deg * height / width < 170");
  require(std::isfinite(options.near_plane_m) && options.near_plane_m > 0.0, "near_plane_m",
          options.near_plane_m, "> 0");
  require(std::isfinite(options.min_range_m) && options.min_range_m >= options.near_plane_m, "min_range_m",
          options.min_range_m, ">= near_plane_m (" + std::to_string(options.near_plane_m) + ")");
  require(std::isfinite(options.max_range_m) && options.max_range_m > options.min_range_m, "max_range_m",
          options.max_range_m, "> min_range_m (" + std::to_string(options.min_range_m) + ")");
}

Intrinsics intrinsicsFor(const SensorOptions& options) {
  Intrinsics k;
  k.width = options.width;
  k.height = options.height;
  const double half_fov_rad = 0.5 * options.fov_deg * M_PI / 180.0;
  k.fx = 0.5 * options.width / std::tan(half_fov_rad);
  k.fy = k.fx;
  k.cx = 0.5 * options.width - 0.5;
  k.cy = 0.5 * options.height - 0.5;
  return k;
}

PixelRays::PixelRays(const Intrinsics& intrinsics) : intrinsics_(intrinsics) {
  rays_.resize(static_cast<size_t>(intrinsics.width) * intrinsics.height);
  for (int v = 0; v < intrinsics.height; ++v) {
    for (int u = 0; u < intrinsics.width; ++u) {
      const Eigen::Vector3d direction((u - intrinsics.cx) / intrinsics.fx,
                                      (v - intrinsics.cy) / intrinsics.fy, 1.0);
      rays_[static_cast<size_t>(v) * intrinsics.width + u] = direction.normalized().cast<float>();
    }
  }
}

}  // namespace ardsim_lidar
