#include "ardsim_lidar/lidar_simulator.h"

#include <tbb/concurrent_queue.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>
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

void LidarSimulator::simulateSequence(const std::vector<Eigen::Isometry3d>& T_lidar_target,
                                      std::uint64_t first_frame_index,
                                      const std::function<void(std::size_t, const LidarFrame&)>& consume) {
  // Frames in the noise stage at once: enough to keep every core busy while the GPU renders ahead. A frame
  // takes a free slot (waiting for one if need be) and gives it back when its consumer returns.
  const int threads = tbb::this_task_arena::max_concurrency();
  // The slots are kept from call to call: a fresh 1 MB frame costs its page faults (0.3 ms on the GPU
  // machine).
  const std::size_t slot_count = 2 * static_cast<std::size_t>(threads);
  std::vector<SequenceSlot>& slots = sequence_slots_;
  if (slots.size() < slot_count) slots.resize(slot_count);
  tbb::concurrent_bounded_queue<std::size_t> free_slots;
  for (std::size_t s = 0; s < slot_count; ++s) free_slots.push(s);
  tbb::task_group tasks;
  try {
    renderer_.renderSequence(T_lidar_target, [&](std::size_t k, TriangleIdFrame& ids) {
      std::size_t s = 0;
      // Without worker threads the tasks run only inside wait(): never block on the queue then.
      while (!free_slots.try_pop(s)) {
        if (threads > 1) {
          free_slots.pop(s);
          break;
        }
        tasks.wait();
      }
      std::swap(slots[s].ids, ids);
      tasks.run([this, &slots, &free_slots, &consume, &T_lidar_target, s, k, first_frame_index] {
        struct Release {
          tbb::concurrent_bounded_queue<std::size_t>& queue;
          std::size_t slot;
          ~Release() { queue.push(slot); }
        } release{free_slots, s};
        renderer_.resolve(slots[s].ids, T_lidar_target[k], &slots[s].rendered);
        noise_model_.apply(slots[s].rendered, materials_, first_frame_index + k, &slots[s].frame);
        consume(k, slots[s].frame);
      });
    });
  } catch (...) {
    tasks.wait();
    throw;
  }
  tasks.wait();
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
