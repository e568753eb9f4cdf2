// Hubble, procedurally. Body x towards the aperture, the soft-capture interface on the aft bulkhead facing -x
// (frames.h), origin at mid-length taken as the centre of mass. Tags as in iss.cpp.
#include "ardsim_description/models.h"
#include "model_builder.h"

namespace ardsim_description {

VehicleModel buildHubbleModel(const HubbleOptions& options) {
  ModelBuilder b;
  const auto skin = b.material("hubble_mli", 0.75f);        // aluminised MLI [estimate]
  const auto solar_cell = b.material("solar_cell", 0.15f);  // [estimate]
  constexpr int kSegments = 48;

  // 13.2 m long [src] from the soft-capture ring (x = -6.6) to the front of the light shield (+6.6); 4.2 m
  // maximum diameter [src] over the aft shroud and equipment section; forward shell and light shield 3.1 m
  // [estimate].
  constexpr double kAftBulkheadX = -6.3, kShroudEndX = 0.9, kFrontX = 6.6;
  b.frustum(Eigen::Isometry3d::Identity(), 2.1, 2.1, kAftBulkheadX, kShroudEndX, kSegments,
            {skin, b.part("aft_shroud", false)}, Collide::kYes);
  b.frustum(Eigen::Isometry3d::Identity(), 1.55, 1.55, kShroudEndX, kFrontX, kSegments,
            {skin, b.part("light_shield", false)}, Collide::kYes);
  // Aperture door, open: hinged on the -z rim of the light shield, standing forward [estimate: 3.2 m, 90
  // deg].
  b.box(at(kFrontX + 1.6, 0, -1.6), Eigen::Vector3d(3.2, 3.2, 0.08), {skin, b.part("aperture_door", false)},
        Collide::kYes);

  // Two solar arrays ~7.1 x 2.6 m [memory] on masts at the aft shroud / equipment section boundary, turning
  // about their mast (body y) by solar_array_deg; at 0 they face +-z. The masts are round booms [estimate:
  // 0.17 m across, 1 m long] that the arrays turn about: turning about its own axis, a cylinder keeps its
  // surface, so they are rigid structure, in a reference model whatever the arrays' angle (2-3 m off the
  // axis, they show the roll of Hubble seen end-on).
  for (double side : {-1.0, 1.0}) {
    b.frustum(at(-1.5, 0, 0) * alongY(), 0.085, 0.085, side > 0 ? 2.0 : -3.0, side > 0 ? 3.0 : -2.0, 16,
              {skin, b.part("solar_array_masts", false)}, Collide::kYes);
    const Eigen::Isometry3d T_mast = at(-1.5, 0, 0) * rotY(options.solar_array_deg);
    b.box(T_mast * at(0, side * (3.0 + 7.1 / 2), 0), Eigen::Vector3d(2.6, 7.1, 0.04),
          {solar_cell, b.part("solar_arrays", true)}, Collide::kYes);
  }
  // High-gain antennas on booms at the +-z sides [estimate: 1.3 m dishes on 2 m booms].
  for (double side : {-1.0, 1.0}) {
    b.box(at(0.0, 0, side * 3.1), Eigen::Vector3d(0.1, 0.1, 2.0),
          {skin, b.part("high_gain_antenna_booms", false)}, Collide::kYes);
    b.frustum(at(0.0, 0, side * 4.1) * alongZ(), 0.65, 0.2, -0.15, 0.15, 24,
              {skin, b.part("high_gain_antennas", true)}, Collide::kYes);
  }

  // Soft Capture Mechanism (SM4, 2009) on the aft bulkhead: an IDSS-compatible ring with reflector targets
  // [memory]; no hatch, the bulkhead closes the passage.
  IdssInterface scm;
  scm.tunnel_outer_radius_m = 0.8;  // [estimate]
  scm.hatch_depth_m = 0.0;
  addIdssInterface(b, T_target_port(TargetKind::kHubble), scm);

  return b.finish(targetMassProperties(TargetKind::kHubble));
}

TriangleMesh buildHubble(const HubbleOptions& options) {
  return buildHubbleModel(options).mesh;
}

}  // namespace ardsim_description
