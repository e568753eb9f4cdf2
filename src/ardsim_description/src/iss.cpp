// The ISS, procedurally. Body frame = SSACS axes (x forward along the velocity in +XVV, y starboard along the
// truss, z nadir) with the origin at the S0 centre, taken as the centre of mass (frames.h). Tags: [src] a
// value from a cited public source in shared/reference/iss_geometry.md, [derived] computed from those,
// [memory] given there unverified, [estimate] chosen here.
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "ardsim_description/models.h"
#include "model_builder.h"

namespace ardsim_description {

namespace {

// Flat-sided polygons per round module: a module is seen from tens of metres, where 32 sides are within a
// centimetre of the cylinder; the docking adapter (model_builder.h) uses 128.
constexpr int kModuleSegments = 32;
constexpr double kModuleAxisZ = 4.5;  // pressurized stack below the truss, as T_target_port [estimate]

struct Module {
  const char* name;
  double length_m;
  double radius_m;
};

// The stack along x, forward to aft [src: adjacency and lengths, iss_geometry.md]; positions [derived] by
// stacking aft from the IDA-2 docking plane.
constexpr Module kStackAftOfIda[] = {
    {"pma2", 1.9, 0.0},  // conical, see below [memory: ~1.9 m long, 1.9-2.4 m diameter]
    {"harmony", 7.2, 2.2}, {"destiny", 8.5, 2.15}, {"unity", 5.47, 2.285},
    {"pma1", 1.9, 0.0},    {"zarya", 12.56, 2.05}, {"zvezda", 13.1, 2.055},
};
constexpr double kIdaHeight = 1.1;  // [src]

// Truss: y extents of each starboard segment (port mirrors), from the [memory] segment lengths S0 13.4,
// S1 13.7, S3/S4 13.7 with the SARJ between, S5 3.4, S6 13.9, scaled by 1.042 to the 109 m span [src].
constexpr double kTrussHalfSpan = 54.5;  // [src] 109 m
constexpr double kTrussSection = 4.5;    // box cross-section [memory]
constexpr double kS0End = 6.98, kS1End = 21.26, kS3End = 28.34, kSarjEnd = 29.38, kS4End = 36.47,
                 kS5End = 40.01;
constexpr double kSarjRadius = 2.6;  // [estimate]

// Solar array wings [src: 8 wings, two blankets each, ~34-35 m x 11.6 m, pair tip-to-tip 73 m]; the beta
// gimbal at |y| 33 (P4/S4) and 50 (P6/S6) [memory].
constexpr double kInboardWingY = 33.0, kOutboardWingY = 50.0;
constexpr double kWingTipZ = 36.5;     // pair tip-to-tip 73 m [src]
constexpr double kBlanketRootZ = 4.0;  // beyond the truss, gimbal and blanket box [estimate]
constexpr double kBlanketWidth = 5.0;  // two blankets and the mast between make 11.6 m [src total]
constexpr double kBlanketGap = 1.6;    // [estimate]

Eigen::Vector3d sizeXyz(double x, double y, double z) {
  return Eigen::Vector3d(x, y, z);
}

}  // namespace

VehicleModel buildIssModel(const IssOptions& options) {
  ModelBuilder b;
  const auto module_mli = b.material("module_mli", 0.7f);   // white beta cloth over MLI [estimate]
  const auto truss_metal = b.material("truss", 0.45f);      // [estimate]
  const auto solar_cell = b.material("solar_cell", 0.15f);  // [estimate]
  const auto radiator = b.material("radiator", 0.8f);       // white radiator panels [estimate]

  // --- The pressurized stack along x, and the forward docking adapter.
  const Eigen::Isometry3d T_target_ida = T_target_port(TargetKind::kIss);
  std::map<std::string, double> module_centre_x;
  double x_front = T_target_ida.translation().x() - kIdaHeight;
  for (const Module& m : kStackAftOfIda) {
    const Surface surface{module_mli, b.part(m.name, false)};
    const double x_back = x_front - m.length_m;
    module_centre_x[m.name] = (x_front + x_back) / 2;
    if (m.radius_m == 0.0) {
      // PMAs: cones narrowing towards the hatch they carry (pma2 forward to IDA-2, pma1 aft to Zarya)
      // [memory].
      const bool narrows_forward = std::string(m.name) == "pma2";
      b.frustum(at(0, 0, kModuleAxisZ), narrows_forward ? 1.2 : 0.95, narrows_forward ? 0.95 : 1.2, x_back,
                x_front, kModuleSegments * 2, surface, Collide::kYes);
    } else {
      b.frustum(at(0, 0, kModuleAxisZ), m.radius_m, m.radius_m, x_back, x_front, kModuleSegments, surface,
                Collide::kYes);
    }
    x_front = x_back;
  }
  const double harmony_centre = module_centre_x.at("harmony");
  const double unity_centre = module_centre_x.at("unity");
  const double zvezda_front = module_centre_x.at("zvezda") + 13.1 / 2;

  IdssInterface ida2;
  ida2.tunnel_outer_radius_m = 0.8;  // IDA width 1.6 m [src]
  ida2.hatch_depth_m = 0.9;          // [estimate]
  ida2.centreline_docking_target = options.centreline_docking_target;
  addIdssInterface(b, T_target_ida, ida2);

  // Modules on Harmony's sides [src: Columbus starboard, Kibo port], at Harmony's middle.
  b.frustum(at(harmony_centre, 0, kModuleAxisZ) * alongY(), 2.235, 2.235, 2.2, 9.1, kModuleSegments,
            {module_mli, b.part("columbus", false)}, Collide::kYes);  // [src] 6.9 x 4.47
  b.frustum(at(harmony_centre, 0, kModuleAxisZ) * alongY(), 2.2, 2.2, -13.4, -2.2, kModuleSegments,
            {module_mli, b.part("kibo_pm", false)}, Collide::kYes);  // [src] 11.2 x 4.4
  b.frustum(at(harmony_centre, -8.0, kModuleAxisZ) * alongZ(), 2.2, 2.2, -2.2 - 3.9, -2.0, kModuleSegments,
            {module_mli, b.part("kibo_elm", false)},
            Collide::kYes);  // ELM-PS on the PM's zenith [src] 3.9 x 4.4
  // PMA-3 and IDA-3 on Harmony's zenith, facing -z [memory]; a plain ring: the sensor does not look here
  // closely.
  b.frustum(at(harmony_centre, 0, kModuleAxisZ) * alongZ(), 0.95, 1.2, -2.2 - 1.9, -2.15, kModuleSegments,
            {module_mli, b.part("pma3", false)}, Collide::kYes);
  b.tube(at(harmony_centre, 0, kModuleAxisZ) * alongZ(), idss::kRingInnerRadius, 0.8, -2.2 - 1.9 - kIdaHeight,
         -2.2 - 1.85, kModuleSegments, {truss_metal, b.part("ida3", false)}, Collide::kYes);
  // Tranquility on Unity's port side [src] 6.706 x 4.48, the Cupola on its nadir [memory: ~3 m, 1.5 m tall].
  b.frustum(at(unity_centre, 0, kModuleAxisZ) * alongY(), 2.24, 2.24, -2.28 - 6.706, -2.28, kModuleSegments,
            {module_mli, b.part("tranquility", false)}, Collide::kYes);
  b.frustum(at(unity_centre, -5.5, kModuleAxisZ) * alongZ(), 1.5, 1.0, 2.2, 3.7, 16,
            {module_mli, b.part("cupola", false)}, Collide::kYes);
  // Nauka on the nadir port of Zvezda's forward node [src] 13.0 x 4.1.
  b.frustum(at(zvezda_front - 1.5, 0, kModuleAxisZ) * alongZ(), 2.05, 2.05, 2.0, 2.0 + 13.0, kModuleSegments,
            {module_mli, b.part("nauka", false)}, Collide::kYes);
  // Zvezda's two arrays near its aft end, 29.7 m tip to tip [src], 3.35 m wide [estimate from Zarya's, src].
  for (double side : {-1.0, 1.0}) {
    b.box(at(zvezda_front - 11.0, side * (2.2 + 12.65 / 2 + 0.3), kModuleAxisZ), sizeXyz(0.05, 12.65, 3.35),
          {solar_cell, b.part("zvezda_arrays", true)}, Collide::kYes);
  }

  // --- Integrated truss: inboard segments fixed; S4..S6 / P4..P6 turn with their SARJ about y.
  const auto truss_box = [&](const Eigen::Isometry3d& T, double y_start, double y_end,
                             const std::string& name, bool articulated) {
    b.box(T * at(0, (y_start + y_end) / 2, 0), sizeXyz(kTrussSection, y_end - y_start, kTrussSection),
          {truss_metal, b.part(name, articulated)}, Collide::kYes);
  };
  truss_box(Eigen::Isometry3d::Identity(), -kS0End, kS0End, "truss_s0", false);
  for (double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "s" : "p";
    const auto y = [side](double magnitude) { return side * magnitude; };
    const auto span = [&](double a, double c, const std::string& name, bool articulated,
                          const Eigen::Isometry3d& T = Eigen::Isometry3d::Identity()) {
      truss_box(T, std::min(y(a), y(c)), std::max(y(a), y(c)), name, articulated);
    };
    span(kS0End, kS1End, "truss_" + s + "1", false);
    span(kS1End, kS3End, "truss_" + s + "3", false);
    const double sarj_deg = side > 0 ? options.sarj_starboard_deg : options.sarj_port_deg;
    // The SARJ turns the outboard truss about the truss (y) axis [src]; the joint ring turns with it.
    const Eigen::Isometry3d T_sarj = rotY(sarj_deg);
    b.frustum(T_sarj * alongY(), kSarjRadius, kSarjRadius, std::min(y(kS3End), y(kSarjEnd)),
              std::max(y(kS3End), y(kSarjEnd)), kModuleSegments, {truss_metal, b.part("sarj_" + s, true)},
              Collide::kYes);
    span(kSarjEnd, kS4End, "truss_" + s + "4", true, T_sarj);
    span(kS4End, kS5End, "truss_" + s + "5", true, T_sarj);
    span(kS5End, kTrussHalfSpan, "truss_" + s + "6", true, T_sarj);

    // Main radiators on S1/P1: three wings of ~23 x 3.4 m [memory] side by side, deployed towards nadir.
    for (int k = 0; k < 3; ++k) {
      const double y_centre = y(9.9 + 4.2 * k);
      b.box(at(-1.0, y_centre, kTrussSection / 2 + 0.5 + 11.5), sizeXyz(0.1, 3.4, 23.0),
            {radiator, b.part("radiator_" + s + "1", true)}, Collide::kYes);
    }
    // Photovoltaic radiators on the P4/S4 and P6/S6 modules, ~13.6 x 3.4 m [memory], extending aft.
    for (double y_pvr : {31.5, 45.0}) {
      const std::string name = "pvr_" + s + (y_pvr < 40 ? "4" : "6");
      b.box(T_sarj * at(-kTrussSection / 2 - 6.8, y(y_pvr), 0), sizeXyz(13.6, 3.4, 0.1),
            {radiator, b.part(name, true)}, Collide::kYes);
    }
    // Wings: index order in IssOptions::beta_deg is 1A 3A (S4), 2A 4A (P4), 1B 3B (S6), 2B 4B (P6); the first
    // of each pair extends to zenith (-z) at SARJ 0, the second to nadir. Beta turns a wing about its mast;
    // at beta 0 the blankets face +-x (our convention).
    const int module_base = side > 0 ? 0 : 2;
    for (int outboard = 0; outboard < 2; ++outboard) {
      const double wing_y = y(outboard ? kOutboardWingY : kInboardWingY);
      for (int pair = 0; pair < 2; ++pair) {
        const int index = module_base + 4 * outboard + pair;
        const char* names[] = {"wing_1a", "wing_3a", "wing_2a", "wing_4a",
                               "wing_1b", "wing_3b", "wing_2b", "wing_4b"};
        const Surface wing{solar_cell, b.part(names[index], true)};
        const double direction = pair == 0 ? -1.0 : 1.0;  // -z zenith, +z nadir
        // Wing frame: origin on the truss axis under the mast, z along the mast outwards.
        const Eigen::Isometry3d T_wing = T_sarj * at(0, wing_y, 0) * rotX(pair == 0 ? 180.0 : 0.0) *
                                         rotZ(direction * options.beta_deg[index]);
        const double blanket_length = kWingTipZ - kBlanketRootZ;
        b.box(T_wing * at(0, 0, (kTrussSection / 2 + kWingTipZ) / 2),
              sizeXyz(0.3, 0.3, kWingTipZ - kTrussSection / 2), {truss_metal, wing.part},
              Collide::kYes);  // mast
        for (double blanket_side : {-1.0, 1.0}) {
          b.box(T_wing * at(0, blanket_side * (kBlanketGap + kBlanketWidth) / 2,
                            kBlanketRootZ + blanket_length / 2),
                sizeXyz(0.05, kBlanketWidth, blanket_length), wing, Collide::kYes);
        }
      }
    }
  }

  return b.finish(targetMassProperties(TargetKind::kIss));
}

TriangleMesh buildIss(const IssOptions& options) {
  return buildIssModel(options).mesh;
}

}  // namespace ardsim_description
