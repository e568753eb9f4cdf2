// Mass properties. Tags as in iss.cpp.
#include "ardsim_description/mass_properties.h"

namespace ardsim_description {

namespace {

MassProperties issMassProperties() {
  // NASA JEOD's ISS verification set [src: iss_environment_and_mass.md], about its CoM in SSACS axes (JEOD
  // puts the CoM at (-3, -1.5, 4) m from the S0 centre; frames.h takes the S0 centre as the CoM, an
  // approximation of the model, not of the inertia).
  MassProperties mass;
  mass.mass_kg = 400000.0;
  mass.inertia_kgm2 << 1.02e8, -6.96e6, -5.48e6,  //
      -6.96e6, 0.91e8, 5.90e5,                    //
      -5.48e6, 5.90e5, 1.64e8;
  return mass;
}

MassProperties hubbleMassProperties() {
  // 12,247 kg after SM4 [src]; inertia of a uniform solid cylinder of 4.2 m x 13.2 m with that mass [derived
  // estimate]: axial m r^2 / 2, transverse m (3 r^2 + L^2) / 12.
  MassProperties mass;
  mass.mass_kg = 12247.0;
  const double r = 2.1, length = 13.2;
  const double axial = mass.mass_kg * r * r / 2,
               transverse = mass.mass_kg * (3 * r * r + length * length) / 12;
  mass.inertia_kgm2 = Eigen::Vector3d(axial, transverse, transverse).asDiagonal();
  return mass;
}

}  // namespace

MassProperties targetMassProperties(TargetKind kind) {
  return kind == TargetKind::kIss ? issMassProperties() : hubbleMassProperties();
}

MassProperties chaserMassProperties() {
  // In orbit at ISS undock 12,519 kg [src]; solid-cylinder inertia 2.5e4 axial, 8.1e4 transverse [derived
  // estimate].
  MassProperties mass;
  mass.mass_kg = 12519.0;
  mass.inertia_kgm2 = Eigen::Vector3d(2.5e4, 8.1e4, 8.1e4).asDiagonal();
  return mass;
}

}  // namespace ardsim_description
