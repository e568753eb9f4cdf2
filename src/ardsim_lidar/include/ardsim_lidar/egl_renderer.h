// Off-screen OpenGL depth renderer of a triangle mesh seen by the flash LIDAR. EGL without any window system:
// the EGL device platform on a hardware GPU (NVIDIA's EGL, found with eglQueryDevicesEXT) where one exists,
// otherwise Mesa's surfaceless platform (llvmpipe on machines without a GPU). ROS-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"
#include "ardsim_lidar/rendered_frame.h"
#include "ardsim_lidar/sensor.h"

namespace ardsim_lidar {

enum class EglPlatform {
  kAuto,         // a hardware EGL device if there is one, else Mesa surfaceless
  kDevice,       // EGL_EXT_platform_device only (fails without a hardware device)
  kSurfaceless,  // EGL_MESA_platform_surfaceless only
};
// "auto", "device" or "surfaceless"; throws std::invalid_argument otherwise.
EglPlatform parseEglPlatform(const std::string& name);

// Where the calling thread's time went in the last renderSequence (milliseconds, summed over its frames).
// Reported by the benchmark; wall-clock, never decides anything.
struct SequenceTiming {
  std::size_t frames = 0;
  double submit_ms = 0.0;   // drawing and starting the asynchronous readback
  double wait_ms = 0.0;     // waiting for a frame's readback to finish
  double copy_ms = 0.0;     // mapping the pixel buffer and copying the frame out
  double consume_ms = 0.0;  // in consume
};

// What the renderer reads back: per pixel, the nearest triangle along the pixel's ray as its id (1 + its
// index in the renderer's drawing order; 0: no surface within the render volume). EglRenderer::resolve turns
// it into a RenderedFrame.
struct TriangleIdFrame {
  int width = 0;
  int height = 0;
  std::vector<std::uint32_t> triangle_id;  // row-major, row 0 at the top of the image (y down)
};

// Whether each frame's triangles are selected on the CPU before drawing: only those facing the sensor whose
// bounding sphere reaches into the frustum go to OpenGL, through a per-frame index buffer. llvmpipe shades,
// clips and bins every triangle it is given on one thread before rasterising; a GPU culls for nothing.
enum class CpuCulling {
  kAuto,  // on a software rasteriser (GL_RENDERER llvmpipe or softpipe), not on a GPU
  kOn,
  kOff,  // chunks wholly outside the frustum are still skipped
};

struct RendererOptions {
  EglPlatform platform = EglPlatform::kAuto;
  CpuCulling cpu_culling = CpuCulling::kAuto;
  // Triangles are grouped into spatially compact chunks; chunks whose bounding sphere lies outside the view
  // frustum are skipped whole; with CPU culling the triangles of the others are tested one by one (llvmpipe's
  // cost grows with the triangles it is given).
  int triangles_per_chunk = 1024;
};

// Renders into a framebuffer object: a GL_DEPTH_COMPONENT32F depth buffer with reversed Z (uniform relative
// depth precision from the near plane to 5 km) for visibility, and an R32UI colour target holding, per pixel,
// the id of the nearest triangle (a visibility buffer). resolve() then intersects each pixel's ray with its
// triangle's plane on the CPU: the range along the ray (exact at the pixel centre, no depth-buffer
// quantisation), the cosine of incidence and the material index (SurfaceSample).
//
// Thread-safe: each call makes the context current on the calling thread and releases it again, so a
// nodelet's callbacks may run on any thread.
class EglRenderer {
 public:
  // Throws std::runtime_error when no EGL display, OpenGL 3.3 core context or required extension is
  // available.
  EglRenderer(const SensorOptions& sensor, const RendererOptions& options = {});
  ~EglRenderer();
  EglRenderer(const EglRenderer&) = delete;
  EglRenderer& operator=(const EglRenderer&) = delete;

  // Uploads the mesh once (vertex and index buffers, per-triangle normal and material); replaces any earlier
  // mesh.
  void setMesh(const ardsim_description::TriangleMesh& mesh);

  // Renders the mesh with T_lidar_target (target coordinates -> lidar_optical coordinates), reads back the
  // frame and resolves it. Without a mesh every pixel has no surface.
  void render(const Eigen::Isometry3d& T_lidar_target, RenderedFrame* frame);

  // Renders a whole sequence of poses, pipelined: a few frames are queued on the GPU, each read back
  // asynchronously into a pixel buffer object, while consume(k, ids) handles frame k on the calling thread,
  // in order k = 0, 1, ... resolve(ids, T_lidar_target[k]) gives what render() gives for the same pose; it is
  // left to the caller so that it runs where the caller's other per-frame work runs (in parallel), not on the
  // rendering thread. consume may take the ids (swap them out); it must not call the renderer's other
  // members. For datasets and benchmarks, where the poses are known ahead: a closed loop's next pose depends
  // on this frame, so it renders one at a time.
  void renderSequence(const std::vector<Eigen::Isometry3d>& T_lidar_target,
                      const std::function<void(std::size_t, TriangleIdFrame&)>& consume);

  // The surface at each pixel of a frame rendered with T_lidar_target. No OpenGL: safe from any number of
  // threads at once, also during renderSequence (not during setMesh). Throws std::invalid_argument for a
  // frame of another size.
  void resolve(const TriangleIdFrame& ids, const Eigen::Isometry3d& T_lidar_target,
               RenderedFrame* frame) const;

  const SequenceTiming& lastSequenceTiming() const;
  const std::string& glRenderer() const;        // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  const std::string& eglPlatform() const;       // "device" or "surfaceless"
  std::size_t trianglesDrawnLastFrame() const;  // given to OpenGL (after the CPU's culling, if any)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ardsim_lidar
