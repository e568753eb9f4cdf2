// Procedural, parametric meshes of the targets and the chaser, in their body frames (origin at the centre of
// mass, see frames.h). Dimensions: shared reference iss_geometry.md; the sources say which values are sourced
// or estimated.
#pragma once

#include <array>
#include <vector>

#include "ardsim_description/collision.h"
#include "ardsim_description/frames.h"
#include "ardsim_description/mass_properties.h"
#include "ardsim_description/mesh.h"

namespace ardsim_description {

struct IssOptions {
  double sarj_port_deg = 0.0;             // port solar alpha rotary joint: outboard truss about body y
  double sarj_starboard_deg = 0.0;        // starboard solar alpha rotary joint
  std::array<double, 8> beta_deg{};       // beta gimbals of the eight wings (about each wing's mast)
  bool centreline_docking_target = true;  // the standoff cross behind the IDA-2 hatch
};
TriangleMesh buildIss(const IssOptions& options = {});

struct HubbleOptions {
  double solar_array_deg = 0.0;  // rotation of both arrays about their masts
};
TriangleMesh buildHubble(const HubbleOptions& options = {});

TriangleMesh buildChaser();

// The target of that kind, with its articulation options (those of the other kind are not used).
TriangleMesh buildTarget(TargetKind kind, const IssOptions& iss = {}, const HubbleOptions& hubble = {});

// Everything the simulation knows about a vehicle's shape and mass, built from one set of primitives so that
// the rendered mesh and the collision shapes cannot disagree. The mesh's topology (vertex and triangle counts
// and order) does not depend on the articulation angles, so a renderer can update vertex buffers in place.
struct VehicleModel {
  TriangleMesh mesh;
  std::vector<CollisionShape> collision;  // part indices refer to mesh.parts
  MassProperties mass;
};
VehicleModel buildIssModel(const IssOptions& options = {});
VehicleModel buildHubbleModel(const HubbleOptions& options = {});
VehicleModel buildChaserModel();
VehicleModel buildTargetModel(TargetKind kind);

}  // namespace ardsim_description
