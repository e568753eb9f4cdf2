// Export of meshes for rviz and other tools.
#pragma once

#include <string>

#include "ardsim_description/mesh.h"

namespace ardsim_description {

// Binary STL (geometry only, facet normals from the winding).
void writeStl(const TriangleMesh& mesh, const std::string& path);

// Binary little-endian PLY: vertices, and per face its vertex indices, an RGB colour (grey = reflectivity,
// red = retro-reflector), and the material and part indices; the material and part names are in comment
// lines.
void writePly(const TriangleMesh& mesh, const std::string& path);

// By the file's extension (.stl or .ply, any case). Throws std::invalid_argument for another extension and
// std::runtime_error when the file cannot be written.
void writeMesh(const TriangleMesh& mesh, const std::string& path);

}  // namespace ardsim_description
