#include "ardsim_dynamics/simulation.h"

#include <cmath>
#include <stdexcept>

namespace ardsim_dynamics {
namespace {

Environment makeEnvironment(const Scenario& s) {
  GravityField field =
      s.gravity_model_file.empty() ? GravityField::egm96() : GravityField::fromFile(s.gravity_model_file);
  return Environment(std::move(field), s.environment);
}

}  // namespace

Eigen::Isometry3d poseOf(const VehicleState& state) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = state.attitude.toRotationMatrix();
  T.translation() = state.position_m;
  return T;
}

InitialStates initialStates(const Scenario& s) {
  using ardsim_description::T_chaser_port;
  using ardsim_description::T_target_port;
  InitialStates out;
  const CartesianState target_orbit = keplerianToCartesian(s.target_orbit);
  out.target.position_m = target_orbit.position_m;
  out.target.velocity_mps = target_orbit.velocity_mps;
  const Eigen::Matrix3d R_eci_lvlh = ardsim_dynamics::R_eci_lvlh(target_orbit);
  const Eigen::Matrix3d R_lvlh_target = rotationFromRollPitchYaw(s.target_attitude_offset_rad);
  out.target.attitude = Eigen::Quaterniond(R_eci_lvlh * R_lvlh_target);
  // Rotating with LVLH: the LVLH rate, in body axes.
  out.target.angular_velocity_radps = R_lvlh_target.transpose() * lvlhRate(target_orbit);

  const Eigen::Isometry3d T_eci_target = poseOf(out.target);
  const Eigen::Isometry3d T_target_port_ = T_target_port(s.target_kind);
  const Eigen::Matrix3d R_offset = rotationFromRollPitchYaw(s.chaser_initial.attitude_offset_rad);
  const Eigen::Vector3d omega_target_eci = out.target.attitude * out.target.angular_velocity_radps;

  Eigen::Isometry3d T_eci_chaser;
  Eigen::Vector3d v_chaser;
  if (s.chaser_initial.frame == RelativeFrame::kTargetPort) {
    Eigen::Isometry3d T_tp_cp = Eigen::Isometry3d::Identity();
    T_tp_cp.linear() = ardsim_description::T_port_port_docked().linear() * R_offset;
    T_tp_cp.translation() = s.chaser_initial.position_m;
    T_eci_chaser = T_eci_target * T_target_port_ * T_tp_cp * T_chaser_port().inverse();
    const Eigen::Matrix3d R_eci_tp = (T_eci_target * T_target_port_).linear();
    v_chaser = out.target.velocity_mps +
               omega_target_eci.cross(T_eci_chaser.translation() - out.target.position_m) +
               R_eci_tp * s.chaser_initial.velocity_mps;
  } else {
    const CartesianState chaser = inertialFromLvlh(
        target_orbit, CartesianState{s.chaser_initial.position_m, s.chaser_initial.velocity_mps});
    T_eci_chaser = Eigen::Isometry3d::Identity();
    // Docking attitude relative to the target's attitude, then the offset.
    const Eigen::Matrix3d R_target_chaser = T_target_port_.linear() *
                                            ardsim_description::T_port_port_docked().linear() * R_offset *
                                            T_chaser_port().linear().transpose();
    T_eci_chaser.linear() = T_eci_target.linear() * R_target_chaser;
    T_eci_chaser.translation() = chaser.position_m;
    v_chaser = chaser.velocity_mps;
  }
  out.chaser.position_m = T_eci_chaser.translation();
  out.chaser.velocity_mps = v_chaser;
  out.chaser.attitude = Eigen::Quaterniond(T_eci_chaser.linear());
  out.chaser.angular_velocity_radps =
      T_eci_chaser.linear().transpose() * omega_target_eci + s.chaser_initial.angular_rate_offset_radps;
  return out;
}

Simulation::Simulation(const Scenario& scenario)
    : scenario_(scenario),
      environment_(makeEnvironment(scenario)),
      actuator_(scenario.chaser_actuator, scenario.seed("actuator")) {
  const InitialStates initial = initialStates(scenario_);
  target_ = initial.target;
  chaser_ = initial.chaser;
  substeps_ = static_cast<int>(std::lround(scenario_.control_step_s / scenario_.integration_step_s));
  if (scenario_.contact.enabled) {
    contact_detector_ = std::make_unique<ContactDetector>(scenario_.target_kind);
    const Touch touch = touchAt(target_, chaser_);
    if (touch.touching)
      contact_ =
          judgeContact(0.0, touch, chaserPortInTargetPort(),
                       ardsim_description::T_target_port(scenario_.target_kind), scenario_.contact.envelope);
  }
}

Simulation::~Simulation() = default;

BodyWrench Simulation::step(const BodyWrench& chaser_commanded) {
  if (contact_) throw std::logic_error("Simulation::step: halted at the first contact");
  const BodyWrench applied = actuator_.apply(chaser_commanded, scenario_.control_step_s);
  const double h = scenario_.integration_step_s;
  const double t0 = time();
  for (int i = 0; i < substeps_; ++i) {
    const double t = t0 + i * h;
    const VehicleState target0 = target_, chaser0 = chaser_;
    target_ = rk4Step(environment_, scenario_.target, target0, BodyWrench{}, t, h);
    chaser_ = rk4Step(environment_, scenario_.chaser, chaser0, applied, t, h);
    if (!contact_detector_) continue;
    const Touch touch = touchAt(target_, chaser_);
    if (touch.touching) {
      haltAtFirstContact(target0, chaser0, applied, t, touch);
      return applied;
    }
  }
  ++step_index_;
  return applied;
}

Touch Simulation::touchAt(const VehicleState& target, const VehicleState& chaser) const {
  // From differences, so that the 7e6 m eci positions cancel before rounding matters.
  const Eigen::Matrix3d R_eci_target = target.attitude.toRotationMatrix();
  Eigen::Isometry3d T_target_chaser = Eigen::Isometry3d::Identity();
  T_target_chaser.linear() = R_eci_target.transpose() * chaser.attitude.toRotationMatrix();
  T_target_chaser.translation() = R_eci_target.transpose() * (chaser.position_m - target.position_m);
  return contact_detector_->test(T_target_chaser);
}

void Simulation::haltAtFirstContact(const VehicleState& target0, const VehicleState& chaser0,
                                    const BodyWrench& applied, double t_s, Touch touch) {
  // Not touching at the step's start, touching at its end: bisect on the integrated states (each trial
  // re-integrates the step from its start over the trial length, RK4 with the same wrench), assuming a single
  // crossing within one integration step.
  double lo_s = 0.0, hi_s = scenario_.integration_step_s;
  while (hi_s - lo_s > scenario_.contact.time_tolerance_s) {
    const double mid_s = 0.5 * (lo_s + hi_s);
    const VehicleState target = rk4Step(environment_, scenario_.target, target0, BodyWrench{}, t_s, mid_s);
    const VehicleState chaser = rk4Step(environment_, scenario_.chaser, chaser0, applied, t_s, mid_s);
    const Touch trial = touchAt(target, chaser);
    if (trial.touching) {
      hi_s = mid_s;
      target_ = target;
      chaser_ = chaser;
      touch = trial;
    } else {
      lo_s = mid_s;
    }
  }
  contact_ =
      judgeContact(t_s + hi_s, touch, chaserPortInTargetPort(),
                   ardsim_description::T_target_port(scenario_.target_kind), scenario_.contact.envelope);
}

CartesianState Simulation::chaserInTargetLvlh() const {
  return relativeStateInLvlh(CartesianState{target_.position_m, target_.velocity_mps},
                             CartesianState{chaser_.position_m, chaser_.velocity_mps});
}

RelativeState Simulation::chaserPortInTargetPort() const {
  const Eigen::Isometry3d T_eci_tp =
      poseOf(target_) * ardsim_description::T_target_port(scenario_.target_kind);
  const Eigen::Isometry3d T_chaser_cp = ardsim_description::T_chaser_port();
  const Eigen::Isometry3d T_eci_cp = poseOf(chaser_) * T_chaser_cp;
  RelativeState rel;
  // Compose from differences so that the 7e6 m eci positions cancel before rounding matters.
  rel.pose.linear() = T_eci_tp.linear().transpose() * T_eci_cp.linear();
  rel.pose.translation() = T_eci_tp.linear().transpose() * (T_eci_cp.translation() - T_eci_tp.translation());
  const Eigen::Vector3d omega_t = target_.attitude * target_.angular_velocity_radps;
  const Eigen::Vector3d omega_c = chaser_.attitude * chaser_.angular_velocity_radps;
  const Eigen::Vector3d v_cp =
      chaser_.velocity_mps + omega_c.cross(T_eci_cp.translation() - chaser_.position_m);
  // Velocity of the target-fixed point that coincides with the chaser port.
  const Eigen::Vector3d v_fixed =
      target_.velocity_mps + omega_t.cross(T_eci_cp.translation() - target_.position_m);
  rel.velocity_mps = T_eci_tp.linear().transpose() * (v_cp - v_fixed);
  rel.angular_velocity_radps = T_eci_tp.linear().transpose() * (omega_c - omega_t);
  return rel;
}

}  // namespace ardsim_dynamics
