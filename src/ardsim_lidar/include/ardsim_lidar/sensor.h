// The flash LIDAR's focal plane: image size, field of view, range window, and the unit ray of every pixel in
// `lidar_optical` (z boresight, x right, y down). ROS-free.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace ardsim_lidar {

// Defaults: the Ball Vision Navigation Sensor flown on STORRM (STS-134): 256 x 256 pixels, 20 x 20 deg.
struct SensorOptions {
  int width = 256;              // pixels
  int height = 256;             // pixels
  double fov_deg = 20.0;        // horizontal field of view; square pixels, so vertical = fov * height / width
  double min_range_m = 0.3;     // closer surfaces give no return (they still hide what is behind them)
  double max_range_m = 5000.0;  // farther surfaces give no return
  double near_plane_m = 0.01;   // renderer near clip plane, well below min_range_m so contact is still seen
};

// Throws std::invalid_argument naming the parameter, its value and the allowed range.
void validate(const SensorOptions& options);

// Pinhole intrinsics of the sensor (ROS CameraInfo convention: integer pixel coordinates are pixel centres).
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
};
Intrinsics intrinsicsFor(const SensorOptions& options);

// Unit ray of each pixel, row-major (index = v * width + u), in `lidar_optical`. A return at range r along
// pixel i is the point r * ray(i) (ortho-rectification through the pixel rays).
class PixelRays {
 public:
  explicit PixelRays(const Intrinsics& intrinsics);
  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Eigen::Vector3f& ray(int index) const { return rays_[index]; }
  const std::vector<Eigen::Vector3f>& rays() const { return rays_; }
  int size() const { return static_cast<int>(rays_.size()); }

 private:
  Intrinsics intrinsics_;
  std::vector<Eigen::Vector3f> rays_;
};

}  // namespace ardsim_lidar
