// Queries on a TriangleMesh that the renderer, the pose estimator and the tests share.
#pragma once

#include <functional>
#include <string>

#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"

namespace ardsim_description {

// Index of the part or material with this name; throws std::out_of_range naming it when absent.
std::uint16_t partIndex(const TriangleMesh& mesh, const std::string& name);
std::uint16_t materialIndex(const TriangleMesh& mesh, const std::string& name);

// The triangles whose part satisfies `keep`, with only the vertices they use; materials and parts are kept
// whole so that indices stay valid.
TriangleMesh selectParts(const TriangleMesh& mesh, const std::function<bool(const Part&)>& keep);

// The rigid structure only (parts not flagged articulated): a reference model that does not depend on array
// angles.
TriangleMesh rigidStructure(const TriangleMesh& mesh);

// Axis-aligned bounds of the vertices (an empty box for an empty mesh).
Eigen::AlignedBox3f bounds(const TriangleMesh& mesh);

double surfaceArea(const TriangleMesh& mesh);

// Volume enclosed by the triangles (divergence theorem): positive when every closed surface winds
// counter-clockwise seen from outside.
double signedVolume(const TriangleMesh& mesh);

// Throws std::invalid_argument saying what is wrong: sizes of the per-triangle arrays, indices out of range,
// non-finite vertices.
void validate(const TriangleMesh& mesh);

}  // namespace ardsim_description
