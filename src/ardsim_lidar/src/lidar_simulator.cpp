#include "ardsim_lidar/lidar_simulator.h"

#include <chrono>
#include <cmath>
#include <limits>

namespace ardsim_lidar {

namespace {

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

LidarSimulator::LidarSimulator(const SensorOptions& sensor, const NoiseOptions& noise, std::uint64_t seed,
                               const RendererOptions& renderer_options)
    : sensor_(sensor),
      rays_((validate(sensor), intrinsicsFor(sensor))),
      renderer_(sensor, renderer_options),
      noise_model_(sensor, noise, seed) {}

void LidarSimulator::setTarget(const ardsim_description::TriangleMesh& mesh) {
  renderer_.setMesh(mesh);
  materials_ = mesh.materials;
}

void LidarSimulator::simulate(const Eigen::Isometry3d& T_lidar_target, std::uint64_t frame_index,
                              LidarFrame* frame) {
  // Wall-clock timing is reported (diagnostics, benchmarks) and never decides anything.
  const auto render_start = std::chrono::steady_clock::now();
  renderer_.render(T_lidar_target, &rendered_);
  timing_.render_ms = millisecondsSince(render_start);
  const auto noise_start = std::chrono::steady_clock::now();
  noise_model_.apply(rendered_, materials_, frame_index, frame);
  timing_.noise_ms = millisecondsSince(noise_start);
}

void toPointCloud(const LidarFrame& frame, const PixelRays& rays, pcl::PointCloud<pcl::PointXYZI>* cloud) {
  cloud->width = static_cast<std::uint32_t>(frame.width);
  cloud->height = static_cast<std::uint32_t>(frame.height);
  cloud->is_dense = false;
  cloud->points.resize(static_cast<std::size_t>(frame.width) * frame.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < cloud->points.size(); ++i) {
    pcl::PointXYZI& point = cloud->points[i];
    const float range = frame.range_m[i];
    if (std::isnan(range)) {
      point.x = point.y = point.z = point.intensity = nan;
      continue;
    }
    const Eigen::Vector3f& ray = rays.ray(static_cast<int>(i));
    point.x = range * ray.x();
    point.y = range * ray.y();
    point.z = range * ray.z();
    point.intensity = frame.intensity[i];
  }
}

}  // namespace ardsim_lidar
