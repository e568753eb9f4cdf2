// The truth simulation: target and chaser propagated in eci under the scenario's environment, advanced one
// control step at a time with the chaser's applied wrench held over the step, until the vehicles first touch
// (contact.h). ROS-free and deterministic: the same scenario and the same commands give bit-identical states.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <Eigen/Geometry>

#include "ardsim_dynamics/actuator.h"
#include "ardsim_dynamics/contact.h"
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
  ~Simulation();

  // Advances by one control step; the commanded wrench goes through the actuator model first. Returns what
  // was applied. When the vehicles touch inside the step (tested after every integration step, the first
  // contact located by bisection; scenario contact options), it stops there and the simulation is halted:
  // contact() holds the event, time() is the contact time and the states are those at contact. Stepping a
  // halted simulation throws std::logic_error.
  BodyWrench step(const BodyWrench& chaser_commanded);

  // The first contact (also at t = 0 when the initial states already touch); empty while none happened or
  // with contact detection off.
  const std::optional<ContactEvent>& contact() const { return contact_; }

  // Control steps completed (a step cut short by contact does not count).
  std::int64_t stepIndex() const { return step_index_; }
  // t_k = k * control step (no accumulated rounding); after contact, the contact time.
  double time() const {
    return contact_ ? contact_->time_s : static_cast<double>(step_index_) * scenario_.control_step_s;
  }
  const VehicleState& target() const { return target_; }
  const VehicleState& chaser() const { return chaser_; }
  const Scenario& scenario() const { return scenario_; }
  const Environment& environment() const { return environment_; }

  // Chaser centre of mass in the target's LVLH.
  CartesianState chaserInTargetLvlh() const;
  // chaser_port relative to target_port (in target_port coordinates).
  RelativeState chaserPortInTargetPort() const;

 private:
  Touch touchAt(const VehicleState& target, const VehicleState& chaser) const;
  // After a touch found at the end of the integration step that began at t_s from target0 / chaser0: bisects
  // the step for the first touching time and halts there.
  void haltAtFirstContact(const VehicleState& target0, const VehicleState& chaser0, const BodyWrench& applied,
                          double t_s, Touch touch);

  Scenario scenario_;
  Environment environment_;
  ActuatorModel actuator_;
  VehicleState target_;
  VehicleState chaser_;
  std::int64_t step_index_ = 0;
  int substeps_ = 1;
  std::unique_ptr<ContactDetector> contact_detector_;  // null with contact detection off
  std::optional<ContactEvent> contact_;
};

}  // namespace ardsim_dynamics
