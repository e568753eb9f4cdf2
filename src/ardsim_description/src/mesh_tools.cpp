#include "ardsim_description/mesh_tools.h"

#include <cmath>
#include <stdexcept>

namespace ardsim_description {

std::uint16_t partIndex(const TriangleMesh& mesh, const std::string& name) {
  for (std::size_t i = 0; i < mesh.parts.size(); ++i) {
    if (mesh.parts[i].name == name) return static_cast<std::uint16_t>(i);
  }
  throw std::out_of_range("no part named '" + name + "' in the mesh");
}

std::uint16_t materialIndex(const TriangleMesh& mesh, const std::string& name) {
  for (std::size_t i = 0; i < mesh.materials.size(); ++i) {
    if (mesh.materials[i].name == name) return static_cast<std::uint16_t>(i);
  }
  throw std::out_of_range("no material named '" + name + "' in the mesh");
}

TriangleMesh selectParts(const TriangleMesh& mesh, const std::function<bool(const Part&)>& keep) {
  TriangleMesh out;
  out.materials = mesh.materials;
  out.parts = mesh.parts;
  std::vector<int> new_index(mesh.vertices.size(), -1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!keep(mesh.parts[mesh.triangle_part[t]])) continue;
    Eigen::Vector3i triangle;
    for (int k = 0; k < 3; ++k) {
      int& index = new_index[mesh.triangles[t][k]];
      if (index < 0) {
        index = static_cast<int>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[mesh.triangles[t][k]]);
      }
      triangle[k] = index;
    }
    out.triangles.push_back(triangle);
    out.triangle_material.push_back(mesh.triangle_material[t]);
    out.triangle_part.push_back(mesh.triangle_part[t]);
  }
  return out;
}

TriangleMesh rigidStructure(const TriangleMesh& mesh) {
  return selectParts(mesh, [](const Part& part) { return !part.articulated; });
}

Eigen::AlignedBox3f bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3f box;
  for (const auto& v : mesh.vertices) box.extend(v);
  return box;
}

double surfaceArea(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

double signedVolume(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

void validate(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangles.size();
  if (mesh.triangle_material.size() != n || mesh.triangle_part.size() != n) {
    throw std::invalid_argument("mesh has " + std::to_string(n) + " triangles but " +
                                std::to_string(mesh.triangle_material.size()) + " materials and " +
                                std::to_string(mesh.triangle_part.size()) + " parts per triangle");
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!mesh.vertices[i].allFinite())
      throw std::invalid_argument("vertex " + std::to_string(i) + " is not finite");
  }
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  for (std::size_t t = 0; t < n; ++t) {
    if ((mesh.triangles[t].array() < 0).any() || (mesh.triangles[t].array() >= vertex_count).any()) {
      throw std::invalid_argument("triangle " + std::to_string(t) + " indexes a vertex outside 0.." +
                                  std::to_string(vertex_count - 1));
    }
    if (mesh.triangle_material[t] >= mesh.materials.size() || mesh.triangle_part[t] >= mesh.parts.size()) {
      throw std::invalid_argument("triangle " + std::to_string(t) +
                                  " names a material or part that does not exist");
    }
  }
}

}  // namespace ardsim_description
