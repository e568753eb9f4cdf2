// The whole sensor: renders the target at a pose, applies the noise model, and ortho-rectifies returns into
// points through the pixel rays. What the node, the render_dataset tool and the benchmark share. ROS-free.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"
#include "ardsim_lidar/egl_renderer.h"
#include "ardsim_lidar/noise_model.h"
#include "ardsim_lidar/sensor.h"

namespace ardsim_lidar {

struct FrameTiming {
  double render_ms = 0.0;  // draw, readback and resolving the triangle ids
  double noise_ms = 0.0;   // noise model
};

class LidarSimulator {
 public:
  // Throws std::invalid_argument for bad options, std::runtime_error when EGL/OpenGL cannot be set up.
  LidarSimulator(const SensorOptions& sensor, const NoiseOptions& noise, std::uint64_t seed,
                 const RendererOptions& renderer_options = {});

  // Uploads the target mesh (once; again only if the model changes).
  void setTarget(const ardsim_description::TriangleMesh& mesh);

  // One frame with T_lidar_target (target coordinates -> lidar_optical). frame_index seeds the frame's noise.
  void simulate(const Eigen::Isometry3d& T_lidar_target, std::uint64_t frame_index, LidarFrame* frame);

  // Frames for a sequence of poses known ahead (datasets, benchmarks), pipelined: the renderer keeps frames
  // queued on the GPU (EglRenderer::renderSequence) while the noise of earlier frames is applied in parallel
  // tasks. Frame k is seeded with first_frame_index + k and equals simulate()'s. consume(k, frame) is called
  // once per frame, from several threads at once and in no particular order. lastTiming() is not updated.
  void simulateSequence(const std::vector<Eigen::Isometry3d>& T_lidar_target, std::uint64_t first_frame_index,
                        const std::function<void(std::size_t, const LidarFrame&)>& consume);

  const SensorOptions& sensor() const { return sensor_; }
  const PixelRays& rays() const { return rays_; }
  const EglRenderer& renderer() const { return renderer_; }
  const NoiseModel& noiseModel() const { return noise_model_; }
  const RenderedFrame& lastRendered() const { return rendered_; }
  const FrameTiming& lastTiming() const { return timing_; }

 private:
  SensorOptions sensor_;
  PixelRays rays_;
  EglRenderer renderer_;
  NoiseModel noise_model_;
  std::vector<ardsim_description::Material> materials_;
  RenderedFrame rendered_;
  FrameTiming timing_;
  struct SequenceSlot {  // a frame in simulateSequence's noise stage
    TriangleIdFrame ids;
    RenderedFrame rendered;
    LidarFrame frame;
  };
  std::vector<SequenceSlot> sequence_slots_;
};

// Organized W x H cloud in lidar_optical: point = range * unit ray of its pixel; NaN x, y, z, intensity = no
// return.
void toPointCloud(const LidarFrame& frame, const PixelRays& rays, pcl::PointCloud<pcl::PointXYZI>* cloud);

}  // namespace ardsim_lidar
