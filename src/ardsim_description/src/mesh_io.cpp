#include "ardsim_description/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "ardsim_description/mesh_tools.h"

namespace ardsim_description {

namespace {

// Both formats are little-endian; so is every machine this runs on (checked at compile time).
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "mesh export writes host byte order as little-endian");

template <typename T>
void put(std::ofstream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

std::ofstream openForWriting(const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
  return out;
}

void finishWriting(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw std::runtime_error("writing '" + path + "' failed: " + std::strerror(errno));
}

}  // namespace

void writeStl(const TriangleMesh& mesh, const std::string& path) {
  validate(mesh);
  std::ofstream out = openForWriting(path);
  char header[80] = {};
  std::strncpy(header, "ardsim_description procedural mesh, metres, body frame", sizeof(header) - 1);
  out.write(header, sizeof(header));
  put<std::uint32_t>(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const Eigen::Vector3f normal = (b - a).cross(c - a).normalized();
    for (const Eigen::Vector3f& v : {normal, a, b, c}) {
      for (int k = 0; k < 3; ++k) put<float>(out, v[k]);
    }
    put<std::uint16_t>(out, 0);
  }
  finishWriting(out, path);
}

void writePly(const TriangleMesh& mesh, const std::string& path) {
  validate(mesh);
  std::ofstream out = openForWriting(path);
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment ardsim_description procedural mesh, metres, body frame\n";
  for (std::size_t i = 0; i < mesh.materials.size(); ++i) {
    out << "comment material " << i << ' ' << mesh.materials[i].name << " reflectivity "
        << mesh.materials[i].reflectivity << (mesh.materials[i].retro_reflector ? " retro_reflector" : "")
        << '\n';
  }
  for (std::size_t i = 0; i < mesh.parts.size(); ++i) {
    out << "comment part " << i << ' ' << mesh.parts[i].name
        << (mesh.parts[i].articulated ? " articulated" : "") << '\n';
  }
  out << "element vertex " << mesh.vertices.size() << '\n'
      << "property float x\nproperty float y\nproperty float z\n"
      << "element face " << mesh.triangles.size() << '\n'
      << "property list uchar int vertex_indices\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "property ushort material\nproperty ushort part\n"
      << "end_header\n";
  for (const auto& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) put<float>(out, v[k]);
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    put<std::uint8_t>(out, 3);
    for (int k = 0; k < 3; ++k) put<std::int32_t>(out, mesh.triangles[t][k]);
    const Material& material = mesh.materials[mesh.triangle_material[t]];
    const auto grey = static_cast<std::uint8_t>(std::clamp(material.reflectivity, 0.0f, 1.0f) * 255.0f);
    put<std::uint8_t>(out, material.retro_reflector ? 255 : grey);
    put<std::uint8_t>(out, material.retro_reflector ? 0 : grey);
    put<std::uint8_t>(out, material.retro_reflector ? 0 : grey);
    put<std::uint16_t>(out, mesh.triangle_material[t]);
    put<std::uint16_t>(out, mesh.triangle_part[t]);
  }
  finishWriting(out, path);
}

void writeMesh(const TriangleMesh& mesh, const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string extension = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == "stl") return writeStl(mesh, path);
  if (extension == "ply") return writePly(mesh, path);
  throw std::invalid_argument("'" + path + "' does not end in .ply or .stl");
}

}  // namespace ardsim_description
