// The truth simulation: target and chaser propagated in eci under the scenario's environment, advanced one
// control step at a time with the chaser's applied wrench held over the step. ROS-free and deterministic: the
// same scenario and the same commands give bit-identical states.
#pragma once

#include <cstdint>

#include <Eigen/Geometry>

#include "ardsim_dynamics/actuator.h"
#include "ardsim_dynamics/scenario.h"
#include "ardsim_dynamics/vehicle_dynamics.h"

namespace ardsim_dynamics {

// Pose and velocity of one frame relative to another, all in the second frame's coordinates.
struct RelativeState {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
};

struct InitialStates {
  VehicleState target;
  VehicleState chaser;
};

// Places both vehicles as the scenario describes them.
InitialStates initialStates(const Scenario& scenario);

Eigen::Isometry3d poseOf(const VehicleState& state);

class Simulation {
 public:
  explicit Simulation(const Scenario& scenario);

  // Advances by one control step; the commanded wrench goes through the actuator model first. Returns what
  // was applied.
  BodyWrench step(const BodyWrench& chaser_commanded);

  std::int64_t stepIndex() const { return step_index_; }
  // t_k = k * control step (no accumulated rounding).
  double time() const { return static_cast<double>(step_index_) * scenario_.control_step_s; }
  const VehicleState& target() const { return target_; }
  const VehicleState& chaser() const { return chaser_; }
  const Scenario& scenario() const { return scenario_; }
  const Environment& environment() const { return environment_; }

  // Chaser centre of mass in the target's LVLH.
  CartesianState chaserInTargetLvlh() const;
  // chaser_port relative to target_port (in target_port coordinates).
  RelativeState chaserPortInTargetPort() const;

 private:
  Scenario scenario_;
  Environment environment_;
  ActuatorModel actuator_;
  VehicleState target_;
  VehicleState chaser_;
  std::int64_t step_index_ = 0;
  int substeps_ = 1;
};

}  // namespace ardsim_dynamics
