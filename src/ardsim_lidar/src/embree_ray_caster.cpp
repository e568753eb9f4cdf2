#include "ardsim_lidar/embree_ray_caster.h"

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace ardsim_lidar {

struct EmbreeRayCaster::Impl {
  SensorOptions sensor;
  PixelRays rays;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<Eigen::Vector3f> triangle_normals;  // target frame
  std::vector<float> triangle_materials;
  double far_plane_m = 0.0;

  explicit Impl(const SensorOptions& options) : sensor(options), rays(intrinsicsFor(options)) {}
};

EmbreeRayCaster::EmbreeRayCaster(const SensorOptions& sensor, const ardsim_description::TriangleMesh& mesh)
    : impl_(new Impl((validate(sensor), sensor))) {
  Impl& impl = *impl_;
  impl.far_plane_m = sensor.max_range_m * 1.001;
  impl.device = rtcNewDevice(nullptr);
  if (impl.device == nullptr) throw std::runtime_error("Embree: rtcNewDevice failed");
  impl.scene = rtcNewScene(impl.device);
  rtcSetSceneBuildQuality(impl.scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int axis = 0; axis < 3; ++axis) vertices[3 * i + axis] = mesh.vertices[i][axis];
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangles.size()));
  impl.triangle_normals.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    for (int corner = 0; corner < 3; ++corner) indices[3 * t + corner] = static_cast<unsigned>(tri[corner]);
    impl.triangle_normals.push_back((mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                                        .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]])
                                        .normalized());
    impl.triangle_materials.push_back(t < mesh.triangle_material.size() ? mesh.triangle_material[t] : -1.0f);
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl.scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl.scene);
  if (rtcGetDeviceError(impl.device) != RTC_ERROR_NONE)
    throw std::runtime_error("Embree: building the scene failed");
}

EmbreeRayCaster::~EmbreeRayCaster() {
  if (impl_->scene != nullptr) rtcReleaseScene(impl_->scene);
  if (impl_->device != nullptr) rtcReleaseDevice(impl_->device);
}

void EmbreeRayCaster::cast(const Eigen::Isometry3d& T_lidar_target, RenderedFrame* frame) const {
  const Impl& impl = *impl_;
  const int width = impl.sensor.width;
  const int height = impl.sensor.height;
  frame->width = width;
  frame->height = height;
  frame->pixels.assign(static_cast<std::size_t>(width) * height, SurfaceSample{});
  const Eigen::Isometry3d T_target_lidar = T_lidar_target.inverse();
  const Eigen::Vector3f origin = T_target_lidar.translation().cast<float>();
  const Eigen::Matrix3f R_target_lidar = T_target_lidar.linear().cast<float>();
  const int tiles_x = (width + 3) / 4;
  const int tiles_y = (height + 3) / 4;

  tbb::parallel_for(0, tiles_y, [&](int tile_y) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (int tile_x = 0; tile_x < tiles_x; ++tile_x) {
      alignas(64) RTCRayHit16 packet;
      alignas(64) int valid[16];
      for (int k = 0; k < 16; ++k) {
        const int u = 4 * tile_x + k % 4;
        const int v = 4 * tile_y + k / 4;
        valid[k] = u < width && v < height ? -1 : 0;
        const Eigen::Vector3f ray = valid[k] ? impl.rays.ray(v * width + u) : Eigen::Vector3f::UnitZ();
        const Eigen::Vector3f direction = R_target_lidar * ray;
        packet.ray.org_x[k] = origin.x();
        packet.ray.org_y[k] = origin.y();
        packet.ray.org_z[k] = origin.z();
        packet.ray.dir_x[k] = direction.x();
        packet.ray.dir_y[k] = direction.y();
        packet.ray.dir_z[k] = direction.z();
        // The renderer clips at the planes z = near and z = far of the lidar frame.
        packet.ray.tnear[k] = static_cast<float>(impl.sensor.near_plane_m / ray.z());
        packet.ray.tfar[k] = static_cast<float>(impl.far_plane_m / ray.z());
        packet.ray.time[k] = 0.0f;
        packet.ray.mask[k] = 0xffffffffu;
        packet.ray.id[k] = static_cast<unsigned>(k);
        packet.ray.flags[k] = 0;
        packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, impl.scene, &context, &packet);
      for (int k = 0; k < 16; ++k) {
        if (!valid[k] || packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
        const int u = 4 * tile_x + k % 4;
        const int v = 4 * tile_y + k / 4;
        const unsigned triangle = packet.hit.primID[k];
        const Eigen::Vector3f direction(packet.ray.dir_x[k], packet.ray.dir_y[k], packet.ray.dir_z[k]);
        SurfaceSample& sample = frame->pixels[static_cast<std::size_t>(v) * width + u];
        sample.range_m = packet.ray.tfar[k];
        sample.cos_incidence = std::abs(impl.triangle_normals[triangle].dot(direction));
        sample.material = impl.triangle_materials[triangle];
      }
    }
  });
}

}  // namespace ardsim_lidar
