#include "ardsim_guidance/approach_sim.h"

#include <algorithm>
#include <cmath>

#include "ardsim_dynamics/simulation.h"

namespace ardsim_guidance {

namespace {

ardsim_dynamics::Scenario plantScenario(const ApproachSimOptions& o) {
  const GuidanceOptions& g = o.guidance;
  ardsim_dynamics::Scenario s;
  s.target_kind = g.target;
  s.target_orbit = {o.orbit_radius_m, 0.0, s.target_orbit.inclination_rad, 0.0, 0.0, 0.0};
  s.target_attitude_offset_rad = g.target_rpy_in_lvlh_rad;
  s.environment.gravity_degree = 0;
  s.environment.atmosphere_density_kgm3 = 0.0;
  s.environment.gravity_gradient_torque = false;
  s.chaser.mass_kg = g.chaser_mass_kg;
  s.chaser.inertia_kgm2 = g.attitude.inertia_kg_m2.asDiagonal();
  s.chaser_initial.frame = ardsim_dynamics::RelativeFrame::kTargetPort;
  s.chaser_initial.position_m = o.start_port_position_m;
  s.chaser_initial.velocity_mps = Eigen::Vector3d::Zero();
  s.chaser_initial.attitude_offset_rad = o.start_attitude_error_rad;
  // Guidance saturates its own commands; the plant applies them exactly.
  s.chaser_actuator.max_force_n = Eigen::Vector3d::Constant(1e5);
  s.chaser_actuator.max_torque_nm = Eigen::Vector3d::Constant(1e5);
  s.control_step_s = g.control_period_s;
  s.integration_step_s = g.control_period_s / o.substeps;
  s.duration_s = o.max_time_s;
  return s;
}

}  // namespace

ApproachSimResult runApproachSim(const ApproachSimOptions& o) {
  const GuidanceOptions& g = o.guidance;
  const VehicleFrames frames = VehicleFrames::fromDescription(g.target);
  Guidance guidance(g);
  TruthPoseGenerator truth_pose(o.truth_pose, frames);
  ardsim_dynamics::Simulation plant(plantScenario(o));

  ApproachSimResult result;
  double sum_force_sq = 0.0;
  int force_samples = 0;
  while (plant.time() <= o.max_time_s && !plant.contact()) {
    const double t = plant.time();
    const ardsim_dynamics::RelativeState port = plant.chaserPortInTargetPort();
    const Eigen::Vector3d& p_tp = port.pose.translation();
    if (p_tp.x() <= g.near_field_range_m)
      result.max_corridor_ratio =
          std::max(result.max_corridor_ratio, p_tp.tail<2>().norm() / corridorRadius(g.safety, p_tp));

    const ardsim_dynamics::VehicleState& chaser = plant.chaser();
    const TruthPoseSample sample =
        truth_pose.generate(t, ardsim_dynamics::poseOf(plant.target()), ardsim_dynamics::poseOf(chaser));
    EstimateInput estimate;
    estimate.time_s = t;
    estimate.status = sample.status;
    estimate.reason = sample.reason;
    estimate.well_formed = true;
    estimate.T_lidar_target = sample.T_lidar_target;
    OwnState own;
    own.position_eci_m = chaser.position_m;
    own.velocity_eci_mps = chaser.velocity_mps;
    own.q_eci_chaser = chaser.attitude;
    own.rate_body_rad_s = chaser.angular_velocity_radps;
    const GuidanceOutput command = guidance.step(estimate, &own);
    result.delta_v_mps = command.delta_v_used_mps;
    result.final_phase = command.phase;
    result.final_reason = command.reason;
    result.time_s = t;
    if (p_tp.x() <= 10.0) {
      sum_force_sq += command.force_body_n.squaredNorm();
      ++force_samples;
    }
    plant.step(ardsim_dynamics::BodyWrench{command.force_body_n, command.torque_body_nm});
  }
  if (const auto& contact = plant.contact()) {
    result.contact = true;
    result.captured = contact->verdict == ardsim_dynamics::ContactVerdict::kCapture;
    result.contact_reason = contact->reason;
    result.time_s = contact->time_s;
    result.closing_speed_mps = contact->conditions.closing_speed_mps;
    result.lateral_misalignment_m = contact->conditions.lateral_misalignment_m;
    result.lateral_rate_mps = contact->conditions.lateral_rate_mps;
    result.angular_misalignment_rad = contact->conditions.angular_misalignment_rad;
    result.angular_rate_rad_s = contact->conditions.angular_rate_radps;
  }
  result.rms_force_last_10m_n = force_samples > 0 ? std::sqrt(sum_force_sq / force_samples) : 0.0;
  return result;
}

}  // namespace ardsim_guidance
