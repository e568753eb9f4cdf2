// Guidance of the chaser, one command per pose estimate: far-field CW targeting, near-field PID down the
// approach corridor, HOLD and RETREAT on estimate loss or corridor violation, and chaser attitude control.
// ROS-free.
//
// Inputs per step: the pose estimate T_lidar_target (relative navigation: the only relative information) and
// the chaser's OWN inertial state (its GPS, star tracker and gyros; optionally with seeded noise). Relative
// truth is never an input. Output: force (N) and torque (N m) in the chaser body frame, and the guidance
// state.
#pragma once

#include <random>
#include <string>

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"
#include "ardsim_guidance/approach.h"
#include "ardsim_guidance/attitude_controller.h"
#include "ardsim_guidance/far_field.h"
#include "ardsim_guidance/geometry.h"
#include "ardsim_guidance/relative_navigator.h"
#include "ardsim_guidance/safety.h"

namespace ardsim_guidance {

enum class AttitudeMode { kLvlhHold, kAlignPort };
AttitudeMode parseAttitudeMode(const std::string& name);  // "lvlh" or "align_port"; throws otherwise

// Noise added to the chaser's own inertial state (standing in for its own sensors), seeded.
struct OwnStateNoiseOptions {
  double position_sigma_m = 0.0;
  double velocity_sigma_mps = 0.0;
  double attitude_sigma_rad = 0.0;
  double rate_sigma_rad_s = 0.0;
  int seed = 1;
};

struct GuidanceOptions {
  ardsim_description::TargetKind target = ardsim_description::TargetKind::kIss;
  double chaser_mass_kg = 12500.0;   // Dragon-class chaser (reference iss_environment_and_mass.md; estimate)
  double control_period_s = 0.1;     // the dynamics' control step: a command is applied over this long
  double near_field_range_m = 30.0;  // range along the docking axis below which the near-field PID takes over
  double contact_range_m = 2.0;      // below this range the phase is CONTACT (same control law)
  double retreat_speed_mps = 0.10;   // RETREAT: speed out along the docking axis...
  double retreat_range_m = 50.0;     // ... up to this range, then hold there
  double degraded_sigma_factor = 3.0;  // DEGRADED estimates enter navigation with this much larger noise
  double target_attitude_time_constant_s = 10.0;  // low-pass of the estimated target attitude in LVLH
  // Attitude the target holds in LVLH (ISS: +XVV torque equilibrium, ~identity), roll-pitch-yaw (rad): used
  // by attitude mode kLvlhHold to point the chaser port at the target port without relying on the estimate.
  Eigen::Vector3d target_rpy_in_lvlh_rad{0.0, 0.0, 0.0};
  AttitudeMode attitude_mode = AttitudeMode::kLvlhHold;
  // Per-axis actuator limits in the chaser body frame. Estimates sized for a ~12.5 t chaser (Dragon-class
  // thrusters give a few hundred newtons per axis), not sourced.
  Eigen::Vector3d max_force_n{400.0, 400.0, 400.0};
  Eigen::Vector3d max_torque_nm{200.0, 200.0, 200.0};
  OwnStateNoiseOptions own_state_noise;
  NavigatorOptions navigator;
  ApproachOptions approach;
  FarFieldOptions far_field;
  SafetyOptions safety;
  AttitudeOptions attitude;
};

// Throws std::invalid_argument "parameter '<name>' = <value> is outside the allowed range <range>" for the
// first bad value. Parameter names are those of the node (config/guidance.yaml).
void validate(const GuidanceOptions& options);

enum class Phase { kWait = 0, kFarField = 1, kApproach = 2, kHold = 3, kRetreat = 4, kContact = 5 };  // = msg
const char* phaseName(Phase phase);

struct OwnState {
  Eigen::Vector3d position_eci_m{0, 0, 0};
  Eigen::Vector3d velocity_eci_mps{0, 0, 0};
  Eigen::Quaterniond q_eci_chaser = Eigen::Quaterniond::Identity();
  Eigen::Vector3d rate_body_rad_s{0, 0, 0};
};

struct EstimateInput {
  double time_s = 0.0;
  EstimateStatus status = EstimateStatus::kLost;
  std::string reason;        // the estimate's own reason, or why it is malformed
  bool well_formed = false;  // finite pose, unit quaternion
  Eigen::Isometry3d T_lidar_target = Eigen::Isometry3d::Identity();
};

struct GuidanceOutput {
  Eigen::Vector3d force_body_n{0, 0, 0};
  Eigen::Vector3d torque_body_nm{0, 0, 0};
  Phase phase = Phase::kWait;
  std::string reason;
  // Chaser port relative to the target port, in target_port.
  Eigen::Vector3d port_position_m{0, 0, 0}, port_velocity_mps{0, 0, 0};
  Eigen::Vector3d reference_position_m{0, 0, 0}, reference_velocity_mps{0, 0, 0};
  double range_m = 0.0;            // along the docking axis
  double closing_speed_mps = 0.0;  // rate of decrease of range_m
  double lateral_error_m = 0.0;
  bool in_corridor = false;
  EstimateStatus estimate_status = EstimateStatus::kLost;
  double delta_v_used_mps = 0.0;  // cumulative commanded delta-v
};

class Guidance {
 public:
  explicit Guidance(const GuidanceOptions& options);
  // One command per estimate. own_state: the chaser's inertial state at the estimate's time, or nullptr if
  // none yet.
  GuidanceOutput step(const EstimateInput& estimate, const OwnState* own_state);

  const GuidanceOptions& options() const { return options_; }

 private:
  OwnState addSensorNoise(const OwnState& truth);
  Eigen::Quaterniond desiredAttitudeInLvlh() const;

  GuidanceOptions options_;
  VehicleFrames frames_;
  RelativeNavigator navigator_;
  ApproachReference approach_reference_;
  PortTracker tracker_;
  FarFieldTargeting far_field_;
  SafetyMonitor safety_;
  std::mt19937_64 rng_;

  bool have_time_ = false;
  double last_time_s_ = 0.0;
  bool have_target_attitude_ = false;
  Eigen::Quaterniond q_lvlh_target_ = Eigen::Quaterniond::Identity();  // filtered estimate
  Eigen::Vector3d last_accel_lvlh_mps2_{0, 0, 0};  // acceleration commanded over the step that just ended
  double delta_v_mps_ = 0.0;
  Phase phase_ = Phase::kWait;
  bool near_field_ = false;
  Eigen::Vector3d retreat_reference_m_{0, 0, 0};  // retreat reference point (target_port)
};

}  // namespace ardsim_guidance
