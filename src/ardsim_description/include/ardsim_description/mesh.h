// A triangle mesh with per-triangle material and part, the geometry exchanged between the description (which
// builds it), the LIDAR renderer, the pose estimator's reference model, the contact shapes and rviz.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace ardsim_description {

struct Material {
  std::string name;
  float reflectivity = 0.5f;     // Lambertian reflectance at the LIDAR wavelength, 0..1
  bool retro_reflector = false;  // returns strongly towards the source whatever the incidence
};

struct Part {
  std::string name;
  bool articulated = false;  // moves relative to the body (solar arrays, radiators): not rigid structure
};

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;         // m, in the vehicle's body frame
  std::vector<Eigen::Vector3i> triangles;        // vertex indices, counter-clockwise seen from outside
  std::vector<std::uint16_t> triangle_material;  // index into materials, one per triangle
  std::vector<std::uint16_t> triangle_part;      // index into parts, one per triangle
  std::vector<Material> materials;
  std::vector<Part> parts;
};

}  // namespace ardsim_description
