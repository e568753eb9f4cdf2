#include "ardsim_lidar/egl_renderer.h"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace ardsim_lidar {

namespace {

// renderSequence keeps this many frames queued on the GPU (drawn, their readback under way) while the
// caller handles the oldest: enough to hide the GPU's latency behind the CPU's work per frame.
constexpr std::size_t kFramesInFlight = 8;

using Clock = std::chrono::steady_clock;
// Milliseconds since *start, which moves to now.
double millisecondsSince(Clock::time_point* start) {
  const Clock::time_point now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - *start).count();
  *start = now;
  return ms;
}

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position_target;
layout(location = 1) in uint triangle_id_in;
uniform mat4 T_lidar_target;
uniform mat4 projection;
flat out uint triangle_id_vertex;
void main() {
  triangle_id_vertex = triangle_id_in;
  gl_Position = projection * (T_lidar_target * vec4(position_target, 1.0));
}
)";

// A visibility buffer: each pixel keeps the id of the nearest triangle (the range and the incidence follow
// exactly on the CPU from its plane and the pixel's ray). Cheaper than shading on llvmpipe (render 1.5-3.3 ->
// 1.0-2.0 ms a frame) and a quarter of the readback. The id comes flat from each triangle's provoking (last)
// vertex, which setMesh makes its own: gl_PrimitiveID cost llvmpipe another 0.2-0.3 ms a frame.
constexpr const char* kFragmentShader = R"(#version 330 core
flat in uint triangle_id_vertex;
layout(location = 0) out uint triangle_id;
void main() {
  triangle_id = triangle_id_vertex;
}
)";

bool hasExtension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const size_t length = std::strlen(name);
  for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + 1, name)) {
    const bool starts = p == list || p[-1] == ' ';
    const bool ends = p[length] == '\0' || p[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

template <typename F>
F eglProc(const char* name) {
  return reinterpret_cast<F>(eglGetProcAddress(name));
}

std::string eglErrorText(const std::string& what) {
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04x", eglGetError());
  return "EGL: " + what + " failed (error " + code + ")";
}

GLuint compileShader(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::array<char, 4096> log{};
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error(std::string("OpenGL shader compilation failed: ") + log.data());
  }
  return shader;
}

// A triangle whose plane passes within this of the sensor is drawn and left to the rasteriser to cull.
constexpr double kEdgeOnToleranceM = 1e-3;

struct Chunk {
  std::size_t first_triangle = 0;
  std::size_t triangle_count = 0;
  Eigen::Vector4f sphere_target = Eigen::Vector4f::Zero();  // bounding sphere: centre (xyz), radius (w)
};

enum class SphereView { kOutside, kCrossing, kInside };  // a bounding sphere against the view frustum

// Recursive median split on triangle centroids along the longest axis of their bounding box, so each chunk is
// spatially compact and can be culled as a whole.
void splitIntoChunks(const std::vector<Eigen::Vector3f>& centroids, std::vector<std::size_t>::iterator begin,
                     std::vector<std::size_t>::iterator end, std::size_t max_triangles,
                     std::vector<std::pair<std::size_t, std::size_t>>* ranges, std::size_t offset) {
  const std::size_t count = static_cast<std::size_t>(end - begin);
  if (count <= max_triangles) {
    ranges->emplace_back(offset, count);
    return;
  }
  Eigen::AlignedBox3f box;
  for (auto it = begin; it != end; ++it) box.extend(centroids[*it]);
  int axis = 0;
  box.sizes().maxCoeff(&axis);
  const auto middle = begin + static_cast<std::ptrdiff_t>(count / 2);
  std::nth_element(begin, middle, end,
                   [&](std::size_t a, std::size_t b) { return centroids[a][axis] < centroids[b][axis]; });
  splitIntoChunks(centroids, begin, middle, max_triangles, ranges, offset);
  splitIntoChunks(centroids, middle, end, max_triangles, ranges, offset + count / 2);
}

}  // namespace

EglPlatform parseEglPlatform(const std::string& name) {
  if (name == "auto") return EglPlatform::kAuto;
  if (name == "device") return EglPlatform::kDevice;
  if (name == "surfaceless") return EglPlatform::kSurfaceless;
  throw std::invalid_argument("egl_platform '" + name + "' is not one of: auto, device, surfaceless");
}

struct EglRenderer::Impl {
  explicit Impl(const SensorOptions& options) : sensor(options), rays(intrinsicsFor(options)) {}

  SensorOptions sensor;
  RendererOptions options;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::string gl_renderer;
  std::string egl_platform;
  bool cpu_culling = false;  // RendererOptions::cpu_culling resolved for this GL_RENDERER
  std::mutex mutex;

  GLuint program = 0;
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;
  GLuint index_buffer = 0;
  GLuint framebuffer = 0;
  GLuint colour_renderbuffer = 0;
  GLuint depth_renderbuffer = 0;
  // Pixel buffer objects of renderSequence: frames in flight, read back asynchronously.
  std::array<GLuint, kFramesInFlight> pixel_buffers{};
  std::array<const void*, kFramesInFlight> pixel_buffer_maps{};  // persistent mappings, or null
  GLint uniform_T_lidar_target = -1;
  GLint uniform_projection = -1;

  PixelRays rays;
  std::vector<Chunk> chunks;
  // Per triangle in drawing order (id - 1): the plane n . x = d in the target frame (unit n in xyz, d in w)
  // and the material index.
  std::vector<Eigen::Vector4f> triangle_planes;
  std::vector<float> triangle_materials;
  std::vector<GLuint> triangle_indices;           // 3 per triangle in drawing order, as in the index buffer
  std::vector<Eigen::Vector4f> triangle_spheres;  // bounding sphere per triangle: centre (xyz), radius (w)
  std::vector<std::uint32_t> draw_triangles;      // this frame's selection (draw), drawing order
  std::vector<Eigen::Vector4f> planes_lidar;      // render()'s, of the selected triangles
  std::vector<GLuint> draw_indices;               // this frame's selection (draw)
  TriangleIdFrame read_back;                      // render()'s
  std::size_t triangles_drawn = 0;
  SequenceTiming sequence_timing;
  std::array<float, 16> projection{};  // column-major
  std::array<Eigen::Vector3d, 4>
      side_plane_normals;  // inward normals of the frustum's side planes, lidar frame
  double far_plane_m = 0.0;

  // Makes the context current for the lifetime of the object and releases it after (any thread may call
  // next).
  class Current {
   public:
    explicit Current(Impl& impl) : impl_(impl), lock_(impl.mutex) {
      if (!eglMakeCurrent(impl_.display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_.context))
        throw std::runtime_error(eglErrorText("eglMakeCurrent"));
    }
    ~Current() { eglMakeCurrent(impl_.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

   private:
    Impl& impl_;
    std::lock_guard<std::mutex> lock_;
  };

  void openDisplay() {
    const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto getPlatformDisplay = eglProc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
    if (getPlatformDisplay == nullptr)
      throw std::runtime_error("EGL: eglGetPlatformDisplayEXT is not available");

    if (options.platform != EglPlatform::kSurfaceless &&
        hasExtension(client_extensions, "EGL_EXT_platform_device")) {
      auto queryDevices = eglProc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
      auto queryDeviceString = eglProc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
      std::array<EGLDeviceEXT, 16> devices{};
      EGLint device_count = 0;
      if (queryDevices != nullptr && queryDeviceString != nullptr &&
          queryDevices(static_cast<EGLint>(devices.size()), devices.data(), &device_count)) {
        for (EGLint i = 0; i < device_count && display == EGL_NO_DISPLAY; ++i) {
          // Mesa lists its software rasteriser as a device too; only a hardware device is worth this path.
          if (hasExtension(queryDeviceString(devices[i], EGL_EXTENSIONS), "EGL_MESA_device_software"))
            continue;
          EGLDisplay candidate = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
          if (candidate != EGL_NO_DISPLAY && eglInitialize(candidate, nullptr, nullptr)) {
            display = candidate;
            egl_platform = "device";
          }
        }
      }
    }
    if (display == EGL_NO_DISPLAY && options.platform != EglPlatform::kDevice &&
        hasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
      EGLDisplay candidate = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (candidate != EGL_NO_DISPLAY && eglInitialize(candidate, nullptr, nullptr)) {
        display = candidate;
        egl_platform = "surfaceless";
      }
    }
    if (display == EGL_NO_DISPLAY) {
      throw std::runtime_error(
          "EGL: no usable display (wanted a hardware EGL device or Mesa's surfaceless platform; client "
          "extensions: " +
          std::string(client_extensions ? client_extensions : "none") + ")");
    }
  }

  void createContext() {
    if (!hasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
      throw std::runtime_error("EGL: the display lacks EGL_KHR_surfaceless_context");
    if (!eglBindAPI(EGL_OPENGL_API)) throw std::runtime_error(eglErrorText("eglBindAPI(EGL_OPENGL_API)"));
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                        EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint config_count = 0;
    if (!eglChooseConfig(display, config_attributes, &config, 1, &config_count) || config_count < 1)
      throw std::runtime_error(eglErrorText("eglChooseConfig (desktop OpenGL)"));
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         3,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
    context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT)
      throw std::runtime_error(eglErrorText("eglCreateContext (OpenGL 3.3 core)"));
  }

  void createPipeline() {
    gl_renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const bool software_rasteriser = gl_renderer.find("llvmpipe") != std::string::npos ||
                                     gl_renderer.find("softpipe") != std::string::npos;
    cpu_culling = options.cpu_culling == CpuCulling::kOn ||
                  (options.cpu_culling == CpuCulling::kAuto && software_rasteriser);
    GLint major = 0;
    GLint minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    GLint extension_count = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &extension_count);
    // In core OpenGL from version.minor on, or as the extension.
    auto supports = [&](GLint need_major, GLint need_minor, const char* extension) {
      if (major > need_major || (major == need_major && minor >= need_minor)) return true;
      for (GLint i = 0; i < extension_count; ++i)
        if (std::strcmp(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, i)), extension) == 0)
          return true;
      return false;
    };
    if (!supports(4, 5, "GL_ARB_clip_control"))
      throw std::runtime_error("OpenGL: " + gl_renderer +
                               " lacks glClipControl (GL 4.5 or GL_ARB_clip_control)");

    const GLuint vertex_shader = compileShader(GL_VERTEX_SHADER, kVertexShader);
    const GLuint fragment_shader = compileShader(GL_FRAGMENT_SHADER, kFragmentShader);
    program = glCreateProgram();
    glAttachShader(program, vertex_shader);
    glAttachShader(program, fragment_shader);
    glLinkProgram(program);
    glDeleteShader(vertex_shader);
    glDeleteShader(fragment_shader);
    GLint linked = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &linked);
    if (linked != GL_TRUE) throw std::runtime_error("OpenGL: shader program failed to link");
    uniform_T_lidar_target = glGetUniformLocation(program, "T_lidar_target");
    uniform_projection = glGetUniformLocation(program, "projection");

    glGenVertexArrays(1, &vertex_array);
    glGenBuffers(1, &vertex_buffer);
    glGenBuffers(1, &index_buffer);

    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glGenRenderbuffers(1, &colour_renderbuffer);
    glBindRenderbuffer(GL_RENDERBUFFER, colour_renderbuffer);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_R32UI, sensor.width, sensor.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_renderbuffer);
    glGenRenderbuffers(1, &depth_renderbuffer);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_renderbuffer);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, sensor.width, sensor.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_renderbuffer);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("OpenGL: R32UI + DEPTH_COMPONENT32F framebuffer is incomplete on " +
                               gl_renderer);

    // Reversed Z: depth = near / z (1 at the near plane, near / far at the far plane) with a float depth
    // buffer.
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glClearDepth(0.0);
    // The image's y axis points down and row 0 is read back first, so the window is the image flipped
    // vertically and a triangle that is counter-clockwise seen from outside arrives clockwise.
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CW);
    glProvokingVertex(GL_LAST_VERTEX_CONVENTION);  // the flat triangle id (setMesh)
    glViewport(0, 0, sensor.width, sensor.height);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);

    // Pixel buffers for renderSequence. With buffer storage (OpenGL 4.4) they are mapped once, persistently,
    // in client memory: mapping a buffer per frame cost NVIDIA's driver ~0.3 ms per 1 MB frame (page faults).
    const bool buffer_storage = supports(4, 4, "GL_ARB_buffer_storage");
    glGenBuffers(static_cast<GLsizei>(pixel_buffers.size()), pixel_buffers.data());
    for (std::size_t slot = 0; slot < pixel_buffers.size(); ++slot) {
      const GLsizeiptr bytes = static_cast<GLsizeiptr>(frameBytes());
      glBindBuffer(GL_PIXEL_PACK_BUFFER, pixel_buffers[slot]);
      if (buffer_storage) {
        const GLbitfield access = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
        glBufferStorage(GL_PIXEL_PACK_BUFFER, bytes, nullptr, access | GL_CLIENT_STORAGE_BIT);
        pixel_buffer_maps[slot] = glMapBufferRange(GL_PIXEL_PACK_BUFFER, 0, bytes, access);
      } else {
        glBufferData(GL_PIXEL_PACK_BUFFER, bytes, nullptr, GL_STREAM_READ);
      }
    }
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    checkErrors("creating the pixel buffers");
  }

  std::size_t pixelCount() const { return static_cast<std::size_t>(sensor.width) * sensor.height; }
  std::size_t frameBytes() const { return pixelCount() * sizeof(std::uint32_t); }

  // Clears the framebuffer and draws the triangles that can be seen (context current). llvmpipe shades,
  // clips and bins every triangle it is given on the calling thread alone before its rasteriser threads
  // start, so on a software rasteriser the triangles facing away from the sensor (half of a closed surface)
  // and those outside the frustum are left out here, on the CPU, into a per-frame index list: drawing only
  // those (ISS: 1742-2305 of 5772 triangles at 3-100 m) cut the draw from 0.37-0.50 to 0.34-0.44 ms. A GPU
  // culls them for nothing, and the CPU's selection (~0.05 ms) would bound a pipelined sequence there: it
  // draws the chunks in the frustum from the mesh's own index buffer.
  void draw(const Eigen::Isometry3d& T_lidar_target) {
    // Double precision up to here; the float matrix only carries target-frame vertices of a few tens of
    // metres.
    const Eigen::Matrix4f T = T_lidar_target.matrix().cast<float>();

    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    const GLuint no_surface[] = {0, 0, 0, 0};
    glClearBufferuiv(GL_COLOR, 0, no_surface);
    glClear(GL_DEPTH_BUFFER_BIT);
    triangles_drawn = 0;
    if (chunks.empty()) return;
    glUseProgram(program);
    glUniformMatrix4fv(uniform_T_lidar_target, 1, GL_FALSE, T.data());
    glUniformMatrix4fv(uniform_projection, 1, GL_FALSE, projection.data());
    glBindVertexArray(vertex_array);
    if (!cpu_culling) {
      drawChunks(T_lidar_target);
      return;
    }
    selectTriangles(T_lidar_target);
    triangles_drawn = draw_triangles.size();
    if (draw_indices.empty()) return;
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(draw_indices.size() * sizeof(GLuint)),
                 draw_indices.data(), GL_STREAM_DRAW);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(draw_indices.size()), GL_UNSIGNED_INT, nullptr);
  }

  // The chunks in the frustum, merged into contiguous runs, one draw call per run.
  void drawChunks(const Eigen::Isometry3d& T_lidar_target) {
    const FrustumPlanes planes = frustumInTarget(T_lidar_target);
    std::size_t run_first = 0;
    std::size_t run_count = 0;
    auto flush = [&]() {
      if (run_count == 0) return;
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * run_count), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(3 * run_first * sizeof(GLuint)));
      triangles_drawn += run_count;
      run_count = 0;
    };
    for (const Chunk& chunk : chunks) {
      if (sphereView(planes, chunk.sphere_target) == SphereView::kOutside) {
        flush();
        continue;
      }
      if (run_count == 0) run_first = chunk.first_triangle;
      run_count += chunk.triangle_count;
    }
    flush();
  }

  // The frustum's planes in target coordinates (inward unit normal in xyz, offset in w: a point p is inside
  // where n . p + w >= 0). Float: target coordinates span tens of metres.
  using FrustumPlanes = std::array<Eigen::Vector4f, 6>;
  FrustumPlanes frustumInTarget(const Eigen::Isometry3d& T_lidar_target) const {
    const Eigen::Matrix3d R_target_lidar = T_lidar_target.linear().transpose();
    const Eigen::Vector3d t = T_lidar_target.translation();
    FrustumPlanes planes;
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d& normal = side_plane_normals[k];
      planes[k] << (R_target_lidar * normal).cast<float>(), static_cast<float>(normal.dot(t));
    }
    const Eigen::Vector3d boresight_target = R_target_lidar.col(2);
    planes[4] << boresight_target.cast<float>(), static_cast<float>(t.z() - sensor.near_plane_m);
    planes[5] << -boresight_target.cast<float>(), static_cast<float>(far_plane_m - t.z());
    return planes;
  }

  static SphereView sphereView(const FrustumPlanes& planes, const Eigen::Vector4f& sphere) {
    bool inside = true;
    for (const Eigen::Vector4f& plane : planes) {
      const float distance = plane.head<3>().dot(sphere.head<3>()) + plane.w();
      if (distance < -sphere.w()) return SphereView::kOutside;
      inside = inside && distance >= sphere.w();
    }
    return inside ? SphereView::kInside : SphereView::kCrossing;
  }

  // draw_indices = the front-facing triangles of the chunks in the frustum; in a chunk that crosses the
  // frustum's border, only the triangles whose bounding sphere reaches inside.
  void selectTriangles(const Eigen::Isometry3d& T_lidar_target) {
    draw_indices.clear();
    draw_triangles.clear();
    const FrustumPlanes planes = frustumInTarget(T_lidar_target);
    // The sensor in target coordinates: a triangle faces it where it lies on the outer side of the
    // triangle's plane.
    const Eigen::Vector3d eye_target = T_lidar_target.inverse().translation();
    for (const Chunk& chunk : chunks) {
      const SphereView chunk_view = sphereView(planes, chunk.sphere_target);
      if (chunk_view == SphereView::kOutside) continue;
      for (std::size_t k = chunk.first_triangle; k < chunk.first_triangle + chunk.triangle_count; ++k) {
        const Eigen::Vector4f& plane = triangle_planes[k];
        // A tolerance towards drawing: a triangle seen edge-on is left to the rasteriser's own culling.
        if (plane.head<3>().cast<double>().dot(eye_target) - plane.w() < -kEdgeOnToleranceM) continue;
        if (chunk_view == SphereView::kCrossing &&
            sphereView(planes, triangle_spheres[k]) == SphereView::kOutside)
          continue;
        draw_indices.insert(draw_indices.end(), &triangle_indices[3 * k], &triangle_indices[3 * k] + 3);
        draw_triangles.push_back(static_cast<std::uint32_t>(k));
      }
    }
  }

  void checkErrors(const char* what) const {
    const GLenum error = glGetError();
    if (error != GL_NO_ERROR)
      throw std::runtime_error(std::string("OpenGL: ") + what + " failed with error " +
                               std::to_string(error));
  }

  void setUpProjection() {
    const Intrinsics k = intrinsicsFor(sensor);
    const double near_m = sensor.near_plane_m;
    // A point beyond max_range has z > max_range only if it is on the boresight; any z > max_range is out of
    // range.
    far_plane_m = sensor.max_range_m * 1.001;
    const double b = near_m * far_plane_m / (far_plane_m - near_m);
    const double a = -near_m / (far_plane_m - near_m);
    projection.fill(0.0f);
    projection[0] = static_cast<float>(2.0 * k.fx / k.width);
    projection[5] = static_cast<float>(2.0 * k.fy / k.height);
    projection[10] = static_cast<float>(a);
    projection[11] = 1.0f;  // w = z (the sensor looks along +z)
    projection[14] = static_cast<float>(b);
    // Inward normals of the side planes through the pixel-edge rays at the image border.
    const double tan_x = 0.5 * k.width / k.fx;
    const double tan_y = 0.5 * k.height / k.fy;
    side_plane_normals = {
        Eigen::Vector3d(1.0, 0.0, tan_x).normalized(), Eigen::Vector3d(-1.0, 0.0, tan_x).normalized(),
        Eigen::Vector3d(0.0, 1.0, tan_y).normalized(), Eigen::Vector3d(0.0, -1.0, tan_y).normalized()};
  }

  // The planes of the given triangles (all where triangles is null) in the lidar frame (n . x = d there too),
  // so that each pixel needs only its dot product with the ray: (n, d) -> (R n, d + (R n) . t) as one 4 x 4
  // product.
  void planesInLidar(const Eigen::Isometry3d& T_lidar_target, const std::vector<std::uint32_t>* triangles,
                     std::vector<Eigen::Vector4f>* planes_lidar) const {
    Eigen::Matrix4d plane_map = Eigen::Matrix4d::Zero();
    plane_map.topLeftCorner<3, 3>() = T_lidar_target.linear();
    plane_map.bottomLeftCorner<1, 3>() = T_lidar_target.translation().transpose() * T_lidar_target.linear();
    plane_map(3, 3) = 1.0;
    const Eigen::Matrix4f plane_map_f = plane_map.cast<float>();
    planes_lidar->resize(triangle_planes.size());
    if (triangles == nullptr) {
      for (std::size_t k = 0; k < triangle_planes.size(); ++k)
        (*planes_lidar)[k] = plane_map_f * triangle_planes[k];
      return;
    }
    for (const std::uint32_t k : *triangles) (*planes_lidar)[k] = plane_map_f * triangle_planes[k];
  }

  // The surface at each pixel from its triangle id and the triangles' planes in the lidar frame.
  void resolvePixels(const TriangleIdFrame& ids, const std::vector<Eigen::Vector4f>& planes_lidar,
                     RenderedFrame* frame) const {
    frame->width = ids.width;
    frame->height = ids.height;
    frame->pixels.resize(pixelCount());
    const std::size_t triangle_count = planes_lidar.size();
    const float near_m = static_cast<float>(sensor.near_plane_m);
    const float far_m = static_cast<float>(far_plane_m);
    const int width = ids.width;
    tbb::parallel_for(tbb::blocked_range<int>(0, ids.height, 16), [&](const tbb::blocked_range<int>& rows) {
      for (int i = rows.begin() * width; i < rows.end() * width; ++i) {
        SurfaceSample& sample = frame->pixels[i];
        const std::uint32_t id = ids.triangle_id[i];
        if (id == 0 || id > triangle_count) {
          sample = SurfaceSample{};
          continue;
        }
        const Eigen::Vector4f& plane = planes_lidar[id - 1];
        const Eigen::Vector3f& ray = rays.ray(i);
        const float along = plane.head<3>().dot(ray);
        float range = plane.w() / along;
        // The rasteriser drew only front faces whose plane the pixel's centre ray crosses, between the near
        // and the far plane; this only guards the rounding of a plane seen nearly edge-on.
        const float z = range * ray.z();
        if (!(z >= near_m)) range = near_m / ray.z();
        if (!(z <= far_m)) range = far_m / ray.z();
        sample.range_m = range;
        sample.cos_incidence = std::abs(along);
        sample.material = triangle_materials[id - 1];
      }
    });
  }
};

EglRenderer::EglRenderer(const SensorOptions& sensor, const RendererOptions& options)
    : impl_(new Impl((validate(sensor), sensor))) {
  if (options.triangles_per_chunk < 1)
    throw std::invalid_argument("triangles_per_chunk = " + std::to_string(options.triangles_per_chunk) +
                                " is out of range: allowed >= 1");
  impl_->options = options;
  impl_->openDisplay();
  impl_->createContext();
  Impl::Current current(*impl_);
  impl_->createPipeline();
  impl_->setUpProjection();
}

EglRenderer::~EglRenderer() {
  if (impl_->display == EGL_NO_DISPLAY) return;
  if (impl_->context != EGL_NO_CONTEXT) {
    if (eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context)) {
      glDeleteProgram(impl_->program);
      glDeleteVertexArrays(1, &impl_->vertex_array);
      const GLuint buffers[] = {impl_->vertex_buffer, impl_->index_buffer};
      glDeleteBuffers(2, buffers);
      const GLuint renderbuffers[] = {impl_->colour_renderbuffer, impl_->depth_renderbuffer};
      glDeleteRenderbuffers(2, renderbuffers);
      glDeleteFramebuffers(1, &impl_->framebuffer);
      glDeleteBuffers(static_cast<GLsizei>(impl_->pixel_buffers.size()), impl_->pixel_buffers.data());
      eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(impl_->display, impl_->context);
  }
  eglTerminate(impl_->display);
}

void EglRenderer::setMesh(const ardsim_description::TriangleMesh& mesh) {
  const std::size_t triangle_count = mesh.triangles.size();
  if (mesh.triangle_material.size() != triangle_count)
    throw std::invalid_argument("mesh: triangle_material has " +
                                std::to_string(mesh.triangle_material.size()) + " entries for " +
                                std::to_string(triangle_count) + " triangles");
  for (const Eigen::Vector3i& triangle : mesh.triangles)
    for (int corner = 0; corner < 3; ++corner)
      if (triangle[corner] < 0 || static_cast<std::size_t>(triangle[corner]) >= mesh.vertices.size())
        throw std::invalid_argument("mesh: triangle vertex index " + std::to_string(triangle[corner]) +
                                    " is outside the " + std::to_string(mesh.vertices.size()) + " vertices");

  std::vector<Eigen::Vector3f> centroids(triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    centroids[t] = (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0f;
  }
  std::vector<std::size_t> order(triangle_count);
  std::iota(order.begin(), order.end(), 0);
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  if (triangle_count > 0)
    splitIntoChunks(centroids, order.begin(), order.end(),
                    static_cast<std::size_t>(impl_->options.triangles_per_chunk), &ranges, 0);

  std::vector<GLuint> indices;
  indices.reserve(3 * triangle_count);
  std::vector<Eigen::Vector4f> planes;
  planes.reserve(triangle_count);
  std::vector<float> materials;
  materials.reserve(triangle_count);
  std::vector<Eigen::Vector4f> spheres;  // bounding sphere about the centroid
  spheres.reserve(triangle_count);
  for (std::size_t t : order) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    for (int corner = 0; corner < 3; ++corner) indices.push_back(static_cast<GLuint>(tri[corner]));
    const Eigen::Vector3f normal = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                                       .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]])
                                       .normalized();
    planes.emplace_back(normal.x(), normal.y(), normal.z(), normal.dot(mesh.vertices[tri[0]]));
    materials.push_back(static_cast<float>(mesh.triangle_material[t]));
    const Eigen::Vector3f& centre = centroids[t];
    float radius = 0.0f;
    for (int corner = 0; corner < 3; ++corner)
      radius = std::max(radius, (mesh.vertices[tri[corner]] - centre).norm());
    spheres.emplace_back(centre.x(), centre.y(), centre.z(), radius);
  }
  std::vector<Chunk> chunks;
  for (const auto& [first, count] : ranges) {
    Eigen::AlignedBox3d box;
    for (std::size_t i = first; i < first + count; ++i)
      for (int corner = 0; corner < 3; ++corner)
        box.extend(mesh.vertices[indices[3 * i + corner]].cast<double>());
    const Eigen::Vector3d centre = box.center();
    chunks.push_back(
        {first, count,
         Eigen::Vector4f(static_cast<float>(centre.x()), static_cast<float>(centre.y()),
                         static_cast<float>(centre.z()), static_cast<float>(0.5 * box.diagonal().norm()))});
  }

  Impl::Current current(*impl_);
  glBindVertexArray(impl_->vertex_array);
  glBindBuffer(GL_ARRAY_BUFFER, impl_->vertex_buffer);
  // Vertices with the id of the triangle they provoke (0 if none). Each triangle gets a provoking vertex of
  // its own: one of its corners not yet taken, rotated last (the winding kept), or a copy of its last corner.
  // The ISS's 5772 triangles need 5772 vertices (3040 shared ones).
  struct Vertex {
    float x, y, z;
    std::uint32_t triangle_id;
  };
  std::vector<Vertex> corners;
  corners.reserve(2 * mesh.vertices.size());
  for (const Eigen::Vector3f& p : mesh.vertices) corners.push_back({p.x(), p.y(), p.z(), 0});
  std::vector<bool> provoking(mesh.vertices.size(), false);
  for (std::size_t t = 0; 3 * t < indices.size(); ++t) {
    GLuint* tri = &indices[3 * t];
    int corner = 2;
    while (corner >= 0 && provoking[tri[corner]]) --corner;
    if (corner < 0) {
      corners.push_back(corners[tri[2]]);
      provoking.push_back(false);
      tri[2] = static_cast<GLuint>(corners.size() - 1);
      corner = 2;
    }
    if (corner == 0) std::rotate(tri, tri + 1, tri + 3);
    if (corner == 1) std::rotate(tri, tri + 2, tri + 3);
    provoking[tri[2]] = true;
    corners[tri[2]].triangle_id = static_cast<std::uint32_t>(t + 1);
  }

  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(corners.size() * sizeof(Vertex)), corners.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribIPointer(1, 1, GL_UNSIGNED_INT, sizeof(Vertex),
                         reinterpret_cast<const void*>(3 * sizeof(float)));
  // A GPU draws from these; a software rasteriser's draw refills the buffer with its selection each frame.
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl_->index_buffer);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)),
               indices.data(), GL_STATIC_DRAW);
  impl_->chunks = std::move(chunks);
  impl_->triangle_indices = std::move(indices);
  impl_->triangle_spheres = std::move(spheres);
  impl_->triangle_planes = std::move(planes);
  impl_->triangle_materials = std::move(materials);
  impl_->checkErrors("uploading the mesh");
}

void EglRenderer::render(const Eigen::Isometry3d& T_lidar_target, RenderedFrame* frame) {
  Impl& impl = *impl_;
  Impl::Current current(impl);
  impl.draw(T_lidar_target);
  // The rasteriser threads start on the flush; the planes of the drawn triangles are moved meanwhile (only
  // those can be in the frame).
  glFlush();
  impl.planesInLidar(T_lidar_target, impl.cpu_culling ? &impl.draw_triangles : nullptr, &impl.planes_lidar);
  TriangleIdFrame& ids = impl.read_back;
  ids.width = impl.sensor.width;
  ids.height = impl.sensor.height;
  ids.triangle_id.resize(impl.pixelCount());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, impl.sensor.width, impl.sensor.height, GL_RED_INTEGER, GL_UNSIGNED_INT,
               ids.triangle_id.data());
  impl.checkErrors("rendering");
  impl.resolvePixels(ids, impl.planes_lidar, frame);
}

void EglRenderer::resolve(const TriangleIdFrame& ids, const Eigen::Isometry3d& T_lidar_target,
                          RenderedFrame* frame) const {
  const Impl& impl = *impl_;
  if (ids.width != impl.sensor.width || ids.height != impl.sensor.height ||
      ids.triangle_id.size() != impl.pixelCount())
    throw std::invalid_argument("resolve: the id frame is not " + std::to_string(impl.sensor.width) + " x " +
                                std::to_string(impl.sensor.height));
  std::vector<Eigen::Vector4f> planes_lidar;
  impl.planesInLidar(T_lidar_target, nullptr, &planes_lidar);
  impl.resolvePixels(ids, planes_lidar, frame);
}

void EglRenderer::renderSequence(const std::vector<Eigen::Isometry3d>& T_lidar_target,
                                 const std::function<void(std::size_t, TriangleIdFrame&)>& consume) {
  Impl& impl = *impl_;
  Impl::Current current(impl);
  std::array<GLsync, kFramesInFlight> fences{};
  auto deleteFences = [&fences]() {
    for (GLsync& fence : fences) {
      if (fence != nullptr) glDeleteSync(fence);
      fence = nullptr;
    }
  };
  TriangleIdFrame frame;
  SequenceTiming& timing = impl.sequence_timing;
  timing = SequenceTiming{};
  timing.frames = T_lidar_target.size();
  // Waits for frame k's readback, copies it out of its pixel buffer and hands it over.
  auto retrieve = [&](std::size_t k) {
    const std::size_t slot = k % kFramesInFlight;
    auto start = Clock::now();
    while (glClientWaitSync(fences[slot], GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000) == GL_TIMEOUT_EXPIRED) {
    }
    timing.wait_ms += millisecondsSince(&start);
    glDeleteSync(fences[slot]);
    fences[slot] = nullptr;
    const void* persistent = impl.pixel_buffer_maps[slot];
    const void* pixels = persistent;
    if (persistent == nullptr) {
      glBindBuffer(GL_PIXEL_PACK_BUFFER, impl.pixel_buffers[slot]);
      pixels = glMapBufferRange(GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(impl.frameBytes()),
                                GL_MAP_READ_BIT);
      if (pixels == nullptr) {
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        throw std::runtime_error("OpenGL: mapping the pixel buffer failed with error " +
                                 std::to_string(glGetError()));
      }
    }
    frame.width = impl.sensor.width;  // again: consume may have swapped the frame out
    frame.height = impl.sensor.height;
    frame.triangle_id.resize(impl.pixelCount());
    std::memcpy(frame.triangle_id.data(), pixels, impl.frameBytes());
    if (persistent == nullptr) {
      glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
      glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    }
    timing.copy_ms += millisecondsSince(&start);
    consume(k, frame);
    timing.consume_ms += millisecondsSince(&start);
  };
  try {
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    for (std::size_t k = 0; k < T_lidar_target.size(); ++k) {
      if (k >= kFramesInFlight) retrieve(k - kFramesInFlight);
      auto start = Clock::now();
      impl.draw(T_lidar_target[k]);
      const std::size_t slot = k % kFramesInFlight;
      glBindBuffer(GL_PIXEL_PACK_BUFFER, impl.pixel_buffers[slot]);
      glReadPixels(0, 0, impl.sensor.width, impl.sensor.height, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
      glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
      fences[slot] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
      impl.checkErrors("rendering");
      glFlush();  // start the GPU on it now, not when the queue fills
      timing.submit_ms += millisecondsSince(&start);
    }
    const std::size_t count = T_lidar_target.size();
    for (std::size_t k = count > kFramesInFlight ? count - kFramesInFlight : 0; k < count; ++k) retrieve(k);
  } catch (...) {
    deleteFences();
    throw;
  }
}

const SequenceTiming& EglRenderer::lastSequenceTiming() const {
  return impl_->sequence_timing;
}

const std::string& EglRenderer::glRenderer() const {
  return impl_->gl_renderer;
}
const std::string& EglRenderer::eglPlatform() const {
  return impl_->egl_platform;
}
std::size_t EglRenderer::trianglesDrawnLastFrame() const {
  return impl_->triangles_drawn;
}

}  // namespace ardsim_lidar
