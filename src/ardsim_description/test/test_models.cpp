#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "ardsim_description/mesh_tools.h"
#include "ardsim_description/models.h"

using namespace ardsim_description;

namespace {

const std::set<std::string> kDockingParts = {"soft_capture_ring",  "guide_petals",
                                             "docking_adapter",    "docking_hatch",
                                             "docking_reflectors", "centreline_docking_target"};

TriangleMesh part(const TriangleMesh& mesh, const std::string& name) {
  partIndex(mesh, name);  // throws when absent
  return selectParts(mesh, [&](const Part& p) { return p.name == name; });
}

// Vertices of a part in the port frame.
std::vector<Eigen::Vector3d> inPortFrame(const TriangleMesh& mesh, const std::string& name,
                                         const Eigen::Isometry3d& T_body_port) {
  std::vector<Eigen::Vector3d> points;
  for (const auto& v : part(mesh, name).vertices) points.push_back(T_body_port.inverse() * v.cast<double>());
  return points;
}

double degrees(double radians) {
  return radians * 180.0 / M_PI;
}

struct Vehicle {
  const char* name;
  TriangleMesh mesh;
  Eigen::Isometry3d T_body_port;
};

std::vector<Vehicle> vehicles() {
  return {{"iss", buildIss(), T_target_port(TargetKind::kIss)},
          {"hubble", buildHubble(), T_target_port(TargetKind::kHubble)},
          {"chaser", buildChaser(), T_chaser_port()}};
}

}  // namespace

TEST(Models, MeshesAreValidWithoutDegenerateTriangles) {
  for (const auto& vehicle : vehicles()) {
    SCOPED_TRACE(vehicle.name);
    const TriangleMesh& mesh = vehicle.mesh;
    EXPECT_NO_THROW(validate(mesh));
    ASSERT_GT(mesh.triangles.size(), 100u);
    for (const auto& t : mesh.triangles) {
      const Eigen::Vector3f a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
      ASSERT_GT(0.5 * (b - a).cross(c - a).norm(), 1e-6) << "degenerate triangle";
    }
  }
}

TEST(Models, EveryPartIsClosedAndWoundOutwards) {
  // Every primitive is a closed surface wound counter-clockwise from outside, so each part encloses a
  // positive volume; an inward-wound primitive would subtract its volume.
  for (const auto& vehicle : vehicles()) {
    for (const auto& p : vehicle.mesh.parts) {
      SCOPED_TRACE(std::string(vehicle.name) + " " + p.name);
      EXPECT_GT(signedVolume(part(vehicle.mesh, p.name)), 1e-5);
    }
  }
  // Destiny: a 32-sided prism of radius 2.15 m and length 8.5 m [src].
  const double n = 32, r = 2.15, length = 8.5;
  EXPECT_NEAR(signedVolume(part(buildIss(), "destiny")), n / 2 * r * r * std::sin(2 * M_PI / n) * length,
              1e-2);
}

TEST(Models, IssFitsTheTriangleBudgetWithDetailAtTheDockingAdapter) {
  const TriangleMesh iss = buildIss();
  EXPECT_LE(iss.triangles.size(), 50000u);
  const TriangleMesh docking =
      selectParts(iss, [](const Part& p) { return kDockingParts.count(p.name) > 0; });
  const TriangleMesh rest = selectParts(iss, [](const Part& p) { return kDockingParts.count(p.name) == 0; });
  const double docking_density = docking.triangles.size() / surfaceArea(docking);
  const double rest_density = rest.triangles.size() / surfaceArea(rest);
  EXPECT_GT(docking_density, 100.0 * rest_density) << docking_density << " vs " << rest_density << " per m^2";
}

TEST(Models, IssDimensionsFollowTheReference) {
  const TriangleMesh iss = buildIss();
  const TriangleMesh truss = selectParts(iss, [](const Part& p) { return p.name.rfind("truss_", 0) == 0; });
  EXPECT_NEAR(bounds(truss).sizes().y(), 109.0, 1e-3);  // [src] truss span
  // A wing pair tip to tip 73 m [src], along z at SARJ 0.
  const Eigen::AlignedBox3f pair = bounds(part(iss, "wing_1a")).extend(bounds(part(iss, "wing_3a")));
  EXPECT_NEAR(pair.sizes().z(), 73.0, 1e-3);
  // The pressurized stack from the IDA-2 docking plane to Zvezda's aft end: the sum of the module lengths in
  // the reference, 51.73 m [derived] (its 51.8 uses rounded lengths; NASA: 51 m [src]).
  EXPECT_NEAR(bounds(part(iss, "soft_capture_ring")).max().x() - bounds(part(iss, "zvezda")).min().x(), 51.73,
              1e-3);
  // IDA outer diameter 2.4 m including the reflector targets [src].
  const Eigen::AlignedBox3f reflectors = bounds(part(iss, "docking_reflectors"));
  EXPECT_NEAR(std::max(reflectors.max().y(), -reflectors.min().y()), 1.2, 0.01);
}

TEST(Models, HubbleDimensionsFollowTheReference) {
  const TriangleMesh hubble = buildHubble();
  EXPECT_NEAR(
      bounds(part(hubble, "light_shield")).max().x() - bounds(part(hubble, "soft_capture_ring")).min().x(),
      13.2, 1e-3);                                                         // [src] length
  EXPECT_NEAR(bounds(part(hubble, "aft_shroud")).sizes().y(), 4.2, 1e-3);  // [src] maximum diameter
}

TEST(Models, PortFramesSitOnTheSoftCaptureRing) {
  for (const auto& vehicle : vehicles()) {
    SCOPED_TRACE(vehicle.name);
    Eigen::AlignedBox3d ring;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const auto ring_points = inPortFrame(vehicle.mesh, "soft_capture_ring", vehicle.T_body_port);
    for (const auto& p : ring_points) {
      ring.extend(p);
      sum += p;
    }
    EXPECT_NEAR(ring.max().x(), 0.0, 1e-5);  // the front face is the docking plane
    EXPECT_NEAR(ring.min().x(), -0.12, 1e-5);
    EXPECT_NEAR(ring.max().y(), 0.6, 1e-5);  // outer diameter ~1.2 m [src]
    EXPECT_NEAR(sum.y() / ring_points.size(), 0.0, 1e-5);
    EXPECT_NEAR(sum.z() / ring_points.size(), 0.0, 1e-5);
    // The petals stand out of the port, along its +x, and nothing else of the vehicle does.
    double petal_top = -1.0;
    for (const auto& p : inPortFrame(vehicle.mesh, "guide_petals", vehicle.T_body_port))
      petal_top = std::max(petal_top, p.x());
    EXPECT_GT(petal_top, 0.2);
    for (const auto& v : vehicle.mesh.vertices) {
      const Eigen::Vector3d p = vehicle.T_body_port.inverse() * v.cast<double>();
      if (p.x() > 1e-5) {
        ASSERT_LT(std::hypot(p.y(), p.z()), 0.6) << "something besides the petals in front of the port";
      }
    }
  }
}

TEST(Models, GuidePetalsStandAt120Degrees) {
  for (const auto& vehicle : vehicles()) {
    SCOPED_TRACE(vehicle.name);
    // Each petal's tip vertices, grouped by angle about the port axis.
    std::vector<double> angles_deg;
    for (const auto& p : inPortFrame(vehicle.mesh, "guide_petals", vehicle.T_body_port)) {
      if (p.x() < 0.2) continue;
      const double angle = std::fmod(degrees(std::atan2(p.z(), p.y())) + 360.0, 360.0);
      angles_deg.push_back(angle);
    }
    for (double centre : {0.0, 120.0, 240.0}) {
      int near = 0;
      for (double a : angles_deg) {
        const double difference = std::fabs(std::remainder(a - centre, 360.0));
        if (difference < 20.0) ++near;
      }
      EXPECT_EQ(near, static_cast<int>(angles_deg.size() / 3)) << "petal at " << centre << " deg";
    }
  }
}

TEST(Models, IssHasThreeRetroReflectorsAroundTheDockingPort) {
  const TriangleMesh iss = buildIss();
  const std::uint16_t retro = materialIndex(iss, "retro_reflector");
  EXPECT_TRUE(iss.materials[retro].retro_reflector);
  const Eigen::Isometry3d T_port_body = T_target_port(TargetKind::kIss).inverse();
  std::set<int> sectors;
  for (std::size_t t = 0; t < iss.triangles.size(); ++t) {
    if (iss.triangle_material[t] != retro) continue;
    const Eigen::Vector3d p = T_port_body * iss.vertices[iss.triangles[t][0]].cast<double>();
    EXPECT_NEAR(std::hypot(p.y(), p.z()), 1.125, 0.08);
    sectors.insert(static_cast<int>(std::lround(
                       std::fmod(degrees(std::atan2(p.z(), p.y())) + 360.0, 360.0) / 120.0 - 0.5)) %
                   3);
  }
  EXPECT_EQ(sectors.size(), 3u);
}

TEST(Models, CentrelineDockingTargetIsASwitch) {
  IssOptions without;
  without.centreline_docking_target = false;
  const TriangleMesh with_target = buildIss(), without_target = buildIss(without);
  EXPECT_LT(without_target.triangles.size(), with_target.triangles.size());
  EXPECT_THROW(partIndex(without_target, "centreline_docking_target"), std::out_of_range);
  // The target stands on the hatch, on the port axis, inside the passage.
  for (const auto& p :
       inPortFrame(with_target, "centreline_docking_target", T_target_port(TargetKind::kIss))) {
    EXPECT_LT(std::hypot(p.y(), p.z()), 0.21);
    EXPECT_LT(p.x(), -0.5);
    EXPECT_GT(p.x(), -0.95);
  }
}

TEST(Models, ArticulationMovesOnlyArticulatedPartsAndKeepsTopology) {
  const TriangleMesh reference = buildIss();
  IssOptions turned;
  turned.sarj_starboard_deg = 90.0;
  turned.sarj_port_deg = -30.0;
  turned.beta_deg = {10, 20, 30, 40, 50, 60, 70, 80};
  const TriangleMesh moved = buildIss(turned);
  ASSERT_EQ(moved.vertices.size(), reference.vertices.size());
  ASSERT_EQ(moved.triangles, reference.triangles);
  ASSERT_EQ(moved.triangle_part, reference.triangle_part);
  std::vector<bool> articulated_vertex(reference.vertices.size(), false);
  for (std::size_t t = 0; t < reference.triangles.size(); ++t) {
    if (!reference.parts[reference.triangle_part[t]].articulated) continue;
    for (int k = 0; k < 3; ++k) articulated_vertex[reference.triangles[t][k]] = true;
  }
  std::size_t moved_count = 0;
  for (std::size_t i = 0; i < reference.vertices.size(); ++i) {
    const bool same = moved.vertices[i] == reference.vertices[i];
    if (!articulated_vertex[i]) {
      ASSERT_TRUE(same) << "rigid vertex " << i << " moved";
    }
    moved_count += same ? 0 : 1;
  }
  EXPECT_GT(moved_count, 100u);
  // SARJ 90 deg about +y turns the zenith (-z) wing 1A to -x.
  const Eigen::AlignedBox3f wing = bounds(part(moved, "wing_1a"));
  EXPECT_NEAR(wing.min().x(), -36.5, 1e-3);
  EXPECT_LT(wing.sizes().z(), 11.7);
}

TEST(Models, BetaTurnsAWingAboutItsMast) {
  IssOptions options;
  options.beta_deg[0] = 90.0;
  const Eigen::AlignedBox3f flat = bounds(part(buildIss(), "wing_1a"));
  const Eigen::AlignedBox3f turned = bounds(part(buildIss(options), "wing_1a"));
  EXPECT_NEAR(flat.sizes().y(), 11.6, 1e-3);  // blankets and gap [src] across the truss at beta 0
  EXPECT_NEAR(turned.sizes().x(), 11.6, 1e-3);
  EXPECT_NEAR(turned.sizes().z(), flat.sizes().z(), 1e-4);
}

TEST(Models, RigidStructureDropsEveryArticulatedPart) {
  const TriangleMesh rigid = rigidStructure(buildIss());
  EXPECT_NO_THROW(validate(rigid));
  EXPECT_GT(rigid.triangles.size(), 1000u);
  for (auto p : rigid.triangle_part) ASSERT_FALSE(rigid.parts[p].articulated);
  EXPECT_EQ(rigidStructure(buildIss(IssOptions{30.0, -30.0, {}, true})).vertices, rigid.vertices);
}

TEST(Models, BuildsAreDeterministic) {
  const TriangleMesh a = buildIss(), b = buildIss();
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(buildTarget(TargetKind::kHubble).vertices, buildHubble().vertices);
}

TEST(Models, MassPropertiesArePhysical) {
  for (const MassProperties& mass : {targetMassProperties(TargetKind::kIss),
                                     targetMassProperties(TargetKind::kHubble), chaserMassProperties()}) {
    EXPECT_GT(mass.mass_kg, 0.0);
    EXPECT_TRUE(mass.inertia_kgm2.isApprox(mass.inertia_kgm2.transpose()));
    const Eigen::Vector3d principal =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mass.inertia_kgm2).eigenvalues();
    EXPECT_GT(principal.minCoeff(), 0.0);
    EXPECT_LE(principal[2], principal[0] + principal[1]);  // triangle inequality of a real body
  }
  EXPECT_DOUBLE_EQ(buildIssModel().mass.inertia_kgm2(2, 2), 1.64e8);  // JEOD [src]
  EXPECT_DOUBLE_EQ(chaserMassProperties().mass_kg, 12519.0);          // Crew Dragon at undock [src]
}
