// Flash-LIDAR measurement model: turns the rendered nearest surfaces into returns (range, intensity) with the
// effects seen in the STORRM flight data. Every effect can be switched off; all randomness is seeded.
// ROS-free.
#pragma once

#include <cstdint>
#include <vector>

#include "ardsim_description/mesh.h"
#include "ardsim_lidar/rendered_frame.h"
#include "ardsim_lidar/sensor.h"

namespace ardsim_lidar {

// Return strength s of a surface (dimensionless): s = reflectivity * cos(incidence) * (detection_range_m /
// range)^2, 1 for a white Lambertian surface facing the sensor at detection_range_m. A retro-reflector within
// its acceptance cone returns retro_gain * reflectivity * (detection_range_m / range)^2 whatever the
// incidence. Intensity = min(1, s / s_saturation) with s_saturation = (detection_range_m /
// saturation_range_m)^2.
struct NoiseOptions {
  bool enabled =
      true;  // master switch: false gives the ideal sensor (rendered surfaces inside the range window)

  double detection_range_m = 6000.0;  // range at which s = 1 for a white surface at normal incidence
  double saturation_range_m = 3.0;    // a white surface at normal incidence saturates closer than this

  bool range_noise = true;            // Gaussian range error, sigma = floor + weak / sqrt(s)
  double range_sigma_floor_m = 0.01;  // sigma for strong returns
  double range_sigma_weak_m = 0.05;   // extra sigma at s = 1; grows as 1/sqrt(s), so with range and darkness

  bool incidence_cutoff = true;  // no return where the ray grazes the surface
  double max_incidence_deg = 80.0;

  bool return_probability = true;  // a return is detected with probability 1 - exp(-s)

  bool dead_pixels = true;  // never return; fixed per sensor (from the seed)
  double dead_pixel_fraction = 0.002;
  bool hot_pixels = true;  // return every frame at a random range; fixed per sensor (from the seed)
  double hot_pixel_fraction = 0.0005;

  bool background_returns = true;  // spurious returns (solar background, stray light), per pixel and frame
  double background_probability = 2e-4;
  double background_intensity = 0.001;  // upper bound of their (uniform) intensity

  bool mixed_pixels = true;  // flying pixels: a pixel straddling a depth edge reports a range in between
  double mixed_pixel_min_jump_m = 0.3;
  double mixed_pixel_probability = 0.5;

  bool retro_reflectors = true;  // strong returns from retro-reflector materials
  double retro_gain = 1.0e4;
  double retro_acceptance_deg = 45.0;

  bool blooming = true;  // saturated retro-reflector returns spill into neighbouring pixels
  int bloom_radius_px = 2;
  double bloom_probability = 0.8;  // at 1 px; falls linearly to 0 beyond bloom_radius_px

  bool saturation = true;  // saturated returns read short (leading-edge walk of the detector)
  double saturation_range_bias_m = -0.02;
};

// Throws std::invalid_argument naming the parameter (prefixed "noise/"), its value and the allowed range.
void validate(const NoiseOptions& options);

// The measured frame: NaN range and intensity where there is no return.
struct LidarFrame {
  int width = 0;
  int height = 0;
  std::vector<float> range_m;    // along each pixel's unit ray; NaN = no return
  std::vector<float> intensity;  // 0..1 (1 = saturated); NaN = no return
  std::size_t returnCount() const;
};

class NoiseModel {
 public:
  // Dead and hot pixels are drawn here from the seed: they belong to the sensor, not to a frame.
  NoiseModel(const SensorOptions& sensor, const NoiseOptions& options, std::uint64_t seed);

  // frame_index selects the frame's random stream (seed and frame_index together), so a frame is the same
  // whatever order frames are produced in. materials: the mesh's material table (indexed by
  // SurfaceSample::material).
  void apply(const RenderedFrame& rendered, const std::vector<ardsim_description::Material>& materials,
             std::uint64_t frame_index, LidarFrame* frame) const;

  // The model's terms, exposed for tests and documentation.
  double strength(double reflectivity, double cos_incidence, bool retro_reflector, double range_m) const;
  double rangeSigma(double strength) const;
  double returnProbability(double strength) const;
  double intensity(double strength) const;

  const std::vector<std::uint8_t>& deadPixels() const { return dead_; }
  const std::vector<std::uint8_t>& hotPixels() const { return hot_; }

 private:
  SensorOptions sensor_;
  NoiseOptions options_;
  std::uint64_t seed_;
  double cos_max_incidence_;
  double cos_retro_acceptance_;
  double saturation_strength_;
  std::vector<std::uint8_t> dead_;
  std::vector<std::uint8_t> hot_;
};

}  // namespace ardsim_lidar
