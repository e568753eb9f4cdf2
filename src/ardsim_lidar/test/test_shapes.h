// Simple test geometry as TriangleMesh: a square plate and a box, triangles counter-clockwise seen from
// outside.
#pragma once

#include <cmath>

#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"

namespace ardsim_lidar::test {

inline ardsim_description::Material material(float reflectivity, bool retro = false) {
  ardsim_description::Material m;
  m.name = retro ? "retro" : "paint";
  m.reflectivity = reflectivity;
  m.retro_reflector = retro;
  return m;
}

// Appends a square of side size_m in the z = 0 plane of `pose`, facing +z of `pose`, with material index
// `material`.
inline void addPlate(ardsim_description::TriangleMesh* mesh, double size_m, const Eigen::Isometry3d& pose,
                     std::uint16_t material_index) {
  const int first = static_cast<int>(mesh->vertices.size());
  const double h = 0.5 * size_m;
  for (const auto& corner : {Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(h, h, 0),
                             Eigen::Vector3d(-h, h, 0)})
    mesh->vertices.push_back((pose * corner).cast<float>());
  mesh->triangles.emplace_back(first, first + 1, first + 2);
  mesh->triangles.emplace_back(first, first + 2, first + 3);
  for (int t = 0; t < 2; ++t) {
    mesh->triangle_material.push_back(material_index);
    mesh->triangle_part.push_back(0);
  }
}

// A single plate facing +z of the target frame.
inline ardsim_description::TriangleMesh makePlate(double size_m, float reflectivity = 0.5f) {
  ardsim_description::TriangleMesh mesh;
  mesh.materials = {material(reflectivity)};
  mesh.parts = {ardsim_description::Part{"plate", false}};
  addPlate(&mesh, size_m, Eigen::Isometry3d::Identity(), 0);
  return mesh;
}

// Axis-aligned box centred at the target origin with the given full sizes.
inline ardsim_description::TriangleMesh makeBox(const Eigen::Vector3d& size_m, float reflectivity = 0.5f) {
  ardsim_description::TriangleMesh mesh;
  mesh.materials = {material(reflectivity)};
  mesh.parts = {ardsim_description::Part{"box", false}};
  const Eigen::Vector3d h = 0.5 * size_m;
  for (int i = 0; i < 8; ++i)
    mesh.vertices.push_back(
        Eigen::Vector3d(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z())
            .cast<float>());
  // Faces as quads around their normal; each triangle is then turned to be counter-clockwise seen from
  // outside.
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& q : quads) {
    for (const Eigen::Vector3i& tri :
         {Eigen::Vector3i(q[0], q[1], q[2]), Eigen::Vector3i(q[0], q[2], q[3])}) {
      const Eigen::Vector3f a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
      const bool outward = (b - a).cross(c - a).dot(a + b + c) > 0.0f;
      mesh.triangles.push_back(outward ? tri : Eigen::Vector3i(tri[0], tri[2], tri[1]));
    }
  }
  mesh.triangle_material.assign(mesh.triangles.size(), 0);
  mesh.triangle_part.assign(mesh.triangles.size(), 0);
  return mesh;
}

// T_lidar_target placing the target's +z face towards the sensor at distance_m along the boresight.
inline Eigen::Isometry3d facingSensor(double distance_m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.0, 0.0, distance_m);
  return T;
}

}  // namespace ardsim_lidar::test
