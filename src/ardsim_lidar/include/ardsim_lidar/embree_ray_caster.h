// The same pixel rays cast with Embree 3 (CPU ray tracing): the peer the EGL renderer is benchmarked against
// and a second, independent geometry path to check it with. Produces the same RenderedFrame. ROS-free.
#pragma once

#include <memory>

#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"
#include "ardsim_lidar/rendered_frame.h"
#include "ardsim_lidar/sensor.h"

namespace ardsim_lidar {

class EmbreeRayCaster {
 public:
  // Builds the scene (BVH) once. Throws std::runtime_error when Embree fails.
  EmbreeRayCaster(const SensorOptions& sensor, const ardsim_description::TriangleMesh& mesh);
  ~EmbreeRayCaster();
  EmbreeRayCaster(const EmbreeRayCaster&) = delete;
  EmbreeRayCaster& operator=(const EmbreeRayCaster&) = delete;

  // Casts every pixel ray (packets of 4 x 4 pixels, rtcIntersect16, rows of packets in parallel with TBB)
  // between the renderer's near and far planes. Unlike the renderer it does not cull back faces.
  void cast(const Eigen::Isometry3d& T_lidar_target, RenderedFrame* frame) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ardsim_lidar
