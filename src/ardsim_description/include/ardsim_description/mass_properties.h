// Rigid-body mass properties of the vehicles, in their body frames (origin at the centre of mass, see
// frames.h).
#pragma once

#include <Eigen/Core>

#include "ardsim_description/frames.h"

namespace ardsim_description {

struct MassProperties {
  double mass_kg = 0.0;
  Eigen::Matrix3d inertia_kgm2 = Eigen::Matrix3d::Zero();  // about the centre of mass, body axes
};

MassProperties targetMassProperties(TargetKind kind);
MassProperties chaserMassProperties();

}  // namespace ardsim_description
