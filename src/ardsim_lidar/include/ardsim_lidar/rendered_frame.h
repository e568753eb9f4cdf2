// What the geometry stage (EGL renderer or Embree ray caster) hands to the noise model: per pixel, the
// nearest surface along the pixel's ray. ROS-free.
#pragma once

#include <vector>

namespace ardsim_lidar {

// The surface seen by one pixel.
struct SurfaceSample {
  float range_m = 0.0f;        // along the pixel's unit ray; 0 = no surface within the render volume
  float cos_incidence = 0.0f;  // |cos| of the angle between the ray and the triangle's normal
  float material = -1.0f;      // index into TriangleMesh::materials; < 0 where there is no surface
};

struct RenderedFrame {
  int width = 0;
  int height = 0;
  std::vector<SurfaceSample> pixels;  // row-major, row 0 at the top of the image (y down)

  bool hasSurface(int index) const { return pixels[index].range_m > 0.0f; }
};

}  // namespace ardsim_lidar
