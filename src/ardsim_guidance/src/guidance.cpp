#include "ardsim_guidance/guidance.h"
#include "ardsim_dynamics/orbit.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ardsim_guidance {

AttitudeMode parseAttitudeMode(const std::string& name) {
  if (name == "lvlh") return AttitudeMode::kLvlhHold;
  if (name == "align_port") return AttitudeMode::kAlignPort;
  throw std::invalid_argument("attitude mode '" + name + "' is not one of: lvlh, align_port");
}

const char* phaseName(Phase phase) {
  switch (phase) {
    case Phase::kWait:
      return "WAIT";
    case Phase::kFarField:
      return "FAR_FIELD";
    case Phase::kApproach:
      return "APPROACH";
    case Phase::kHold:
      return "HOLD";
    case Phase::kRetreat:
      return "RETREAT";
    case Phase::kContact:
      return "CONTACT";
  }
  return "?";
}

namespace {

// Open (lo, hi) unless the flags say closed.
void require(const std::string& name, double value, double lo, double hi, bool lo_closed = false,
             bool hi_closed = false) {
  const bool ok = std::isfinite(value) && (lo_closed ? value >= lo : value > lo) &&
                  (hi_closed ? value <= hi : value < hi);
  if (ok) return;
  std::ostringstream s;
  s << "parameter '" << name << "' = " << value << " is outside the allowed range " << (lo_closed ? "[" : "(")
    << lo << ", " << hi << (hi_closed ? "]" : ")");
  throw std::invalid_argument(s.str());
}

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

void validate(const GuidanceOptions& o) {
  require("chaser_mass_kg", o.chaser_mass_kg, 0.0, kInf);
  require("control_period_s", o.control_period_s, 0.0, 10.0, false, true);
  require("near_field_range_m", o.near_field_range_m, 0.0, kInf);
  require("contact_range_m", o.contact_range_m, 0.0, o.near_field_range_m, true, false);
  require("retreat_speed_mps", o.retreat_speed_mps, 0.0, 1.0, false, true);
  require("retreat_range_m", o.retreat_range_m, 0.0, kInf);
  require("degraded_sigma_factor", o.degraded_sigma_factor, 1.0, kInf, true);
  require("target_attitude_time_constant_s", o.target_attitude_time_constant_s, 0.0, kInf, true);
  for (int i = 0; i < 3; ++i) {
    require("target_rpy_in_lvlh_deg[" + std::to_string(i) + "] (rad)", o.target_rpy_in_lvlh_rad[i], -M_PI,
            M_PI, true, true);
    require("max_force_n[" + std::to_string(i) + "]", o.max_force_n[i], 0.0, kInf);
    require("max_torque_nm[" + std::to_string(i) + "]", o.max_torque_nm[i], 0.0, kInf);
    require("attitude/inertia_kg_m2[" + std::to_string(i) + "]", o.attitude.inertia_kg_m2[i], 0.0, kInf);
  }
  const OwnStateNoiseOptions& sn = o.own_state_noise;
  require("own_state_noise/position_sigma_m", sn.position_sigma_m, 0.0, kInf, true);
  require("own_state_noise/velocity_sigma_mps", sn.velocity_sigma_mps, 0.0, kInf, true);
  require("own_state_noise/attitude_sigma_rad", sn.attitude_sigma_rad, 0.0, 0.1, true, true);
  require("own_state_noise/rate_sigma_rad_s", sn.rate_sigma_rad_s, 0.0, 0.1, true, true);
  const NavigatorOptions& n = o.navigator;
  require("navigator/median_window", n.median_window, 1, 101, true, true);
  require("navigator/difference_span", n.difference_span, 1, 1000, true, true);
  require("navigator/history_reset_gap_s", n.history_reset_gap_s, 0.0, kInf);
  require("navigator/measurement_sigma_m", n.measurement_sigma_m, 0.0, kInf);
  require("navigator/process_accel_sigma_mps2", n.process_accel_sigma_mps2, 0.0, kInf);
  require("navigator/initial_velocity_sigma_mps", n.initial_velocity_sigma_mps, 0.0, kInf);
  const ApproachOptions& a = o.approach;
  require("approach/contact_speed_mps", a.contact_speed_mps, 0.0, 1.0);
  require("approach/max_closing_speed_mps", a.max_closing_speed_mps, a.contact_speed_mps, 2.0, true, true);
  require("approach/closing_time_constant_s", a.closing_time_constant_s, 0.0, kInf);
  if (a.hold_ranges_m.size() != a.hold_durations_s.size()) {
    require("approach/hold_durations_s (count, must equal approach/hold_ranges_m count " +
                std::to_string(a.hold_ranges_m.size()) + ")",
            static_cast<double>(a.hold_durations_s.size()), a.hold_ranges_m.size(), a.hold_ranges_m.size(),
            true, true);
  }
  for (size_t i = 0; i < a.hold_ranges_m.size(); ++i) {
    require("approach/hold_ranges_m[" + std::to_string(i) + "]", a.hold_ranges_m[i], 0.0, kInf);
    require("approach/hold_durations_s[" + std::to_string(i) + "]", a.hold_durations_s[i], 0.0, kInf, true);
  }
  require("approach/hold_approach_time_constant_s", a.hold_approach_time_constant_s, 0.0, kInf);
  require("approach/bandwidth_rad_s", a.bandwidth_rad_s, 0.0, 0.5 * M_PI / o.control_period_s);
  require("approach/damping_ratio", a.damping_ratio, 0.0, 5.0, false, true);
  require("approach/integral_time_s", a.integral_time_s, 0.0, kInf);
  require("approach/integral_limit_mps2", a.integral_limit_mps2, 0.0, kInf, true);
  const FarFieldOptions& f = o.far_field;
  require("far_field/aim_range_m (must be inside near_field_range_m)", f.aim_range_m, o.contact_range_m,
          o.near_field_range_m);
  require("far_field/transfer_time_s", f.transfer_time_s, 0.0, 0.45 * 2.0 * M_PI / 1.2e-3);
  require("far_field/retarget_interval_s", f.retarget_interval_s, 0.0, kInf);
  require("far_field/min_retarget_time_s", f.min_retarget_time_s, 0.0, kInf, true);
  require("far_field/burn_accel_mps2", f.burn_accel_mps2, 0.0, kInf);
  const SafetyOptions& s = o.safety;
  require("safety/corridor_half_angle_deg (rad)", s.corridor_half_angle_rad, 0.0, 0.5 * M_PI);
  require("safety/corridor_min_radius_m", s.corridor_min_radius_m, 0.0, kInf, true);
  require("safety/keep_out_radius_m", s.keep_out_radius_m, 0.0, kInf, true);
  require("safety/lost_limit_s", s.lost_limit_s, 0.0, kInf, true);
  require("attitude/bandwidth_rad_s", o.attitude.bandwidth_rad_s, 0.0, 0.5 * M_PI / o.control_period_s);
  require("attitude/damping_ratio", o.attitude.damping_ratio, 0.0, 5.0, false, true);
}

Guidance::Guidance(const GuidanceOptions& options)
    : options_(options),
      frames_(VehicleFrames::fromDescription(options.target)),
      navigator_(options.navigator),
      approach_reference_(options.approach),
      tracker_(options.approach),
      far_field_(options.far_field),
      safety_(options.safety),
      rng_(static_cast<std::uint64_t>(options.own_state_noise.seed)) {
  validate(options_);
}

OwnState Guidance::addSensorNoise(const OwnState& truth) {
  const OwnStateNoiseOptions& o = options_.own_state_noise;
  std::normal_distribution<double> unit(0.0, 1.0);
  // One draw at a time: the order of draws inside one expression would be unspecified.
  auto draw = [&](double sigma) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = unit(rng_) * sigma;
    return v;
  };
  OwnState noisy = truth;
  noisy.position_eci_m += draw(o.position_sigma_m);
  noisy.velocity_eci_mps += draw(o.velocity_sigma_mps);
  const Eigen::Vector3d tilt = draw(o.attitude_sigma_rad);
  if (tilt.norm() > 0.0) {
    noisy.q_eci_chaser =
        truth.q_eci_chaser * Eigen::Quaterniond(Eigen::AngleAxisd(tilt.norm(), tilt.normalized()));
  }
  noisy.rate_body_rad_s += draw(o.rate_sigma_rad_s);
  return noisy;
}

Eigen::Quaterniond Guidance::desiredAttitudeInLvlh() const {
  const Eigen::Vector3d& rpy = options_.target_rpy_in_lvlh_rad;
  const Eigen::Quaterniond q_nominal = Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                       Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                       Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX());
  const Eigen::Quaterniond q_lvlh_target =
      options_.attitude_mode == AttitudeMode::kAlignPort && have_target_attitude_ ? q_lvlh_target_
                                                                                  : q_nominal;
  const Eigen::Matrix3d R_lvlh_chaser = q_lvlh_target.toRotationMatrix() * frames_.T_target_port.linear() *
                                        ardsim_description::T_port_port_docked().linear() *
                                        frames_.T_chaser_port.linear().transpose();
  return Eigen::Quaterniond(R_lvlh_chaser).normalized();
}

GuidanceOutput Guidance::step(const EstimateInput& estimate, const OwnState* own_truth) {
  GuidanceOutput out;
  out.estimate_status = estimate.status;
  const double dt = have_time_ ? std::max(0.0, estimate.time_s - last_time_s_) : 0.0;
  have_time_ = true;
  last_time_s_ = std::max(last_time_s_, estimate.time_s);

  if (own_truth == nullptr) {
    // Without the chaser's own inertial state there is no LVLH frame and no attitude: command nothing.
    last_accel_lvlh_mps2_.setZero();
    out.phase = phase_ == Phase::kRetreat ? Phase::kRetreat : Phase::kWait;
    out.reason = "no own inertial state (truth/chaser/odom) yet";
    out.delta_v_used_mps = delta_v_mps_;
    return out;
  }
  const OwnState own = addSensorNoise(*own_truth);
  const Eigen::Matrix3d R_eci_lvlh = ardsim_dynamics::R_eci_lvlh({own.position_eci_m, own.velocity_eci_mps});
  const Eigen::Vector3d omega_lvlh = ardsim_dynamics::lvlhRate({own.position_eci_m, own.velocity_eci_mps});
  // Mean motion of the target's orbit, from the chaser's own (nearby, near-circular) orbit.
  const double n = -omega_lvlh.y();
  const Eigen::Matrix3d R_lvlh_chaser =
      R_eci_lvlh.transpose() * own.q_eci_chaser.normalized().toRotationMatrix();

  // 1. Navigation: propagate over the step just flown with the acceleration commanded for it.
  delta_v_mps_ += last_accel_lvlh_mps2_.norm() * dt;
  auto com_to_port = [&]() {
    return Eigen::Vector3d(R_lvlh_chaser * frames_.T_chaser_port.translation() -
                           q_lvlh_target_.toRotationMatrix() * frames_.T_target_port.translation());
  };
  navigator_.predict(dt, n, com_to_port(), last_accel_lvlh_mps2_);

  const bool usable = estimate.well_formed && estimate.status != EstimateStatus::kLost;
  if (usable) {
    const Eigen::Matrix3d R_lvlh_lidar = R_lvlh_chaser * frames_.T_chaser_lidar.linear();
    const Eigen::Quaterniond q_meas(R_lvlh_lidar * estimate.T_lidar_target.linear());
    const double tau = options_.target_attitude_time_constant_s;
    q_lvlh_target_ =
        have_target_attitude_ ? q_lvlh_target_.slerp(dt / (tau + dt), q_meas).normalized() : q_meas;
    have_target_attitude_ = true;
    const Eigen::Vector3d chaser_port_in_lidar =
        frames_.T_chaser_lidar.inverse() * frames_.T_chaser_port.translation();
    const Eigen::Vector3d measured =
        R_lvlh_lidar * (chaser_port_in_lidar - estimate.T_lidar_target.translation()) -
        q_lvlh_target_.toRotationMatrix() * frames_.T_target_port.translation();
    navigator_.update(measured,
                      estimate.status == EstimateStatus::kDegraded ? options_.degraded_sigma_factor : 1.0);
  }

  // 2. The chaser port relative to the target port, in target_port.
  const bool have_nav = navigator_.initialized() && have_target_attitude_;
  const Eigen::Matrix3d R_lvlh_tp = q_lvlh_target_.toRotationMatrix() * frames_.T_target_port.linear();
  const Eigen::Vector3d p = R_lvlh_tp.transpose() * navigator_.position();
  const Eigen::Vector3d v = R_lvlh_tp.transpose() * navigator_.velocity();
  const Eigen::Vector3d offset = com_to_port();
  const Eigen::Vector3d r_com = navigator_.position() - offset;
  const Eigen::Vector3d free_accel_tp =
      R_lvlh_tp.transpose() * cwAcceleration(n, r_com, navigator_.velocity());

  // 3. Safety, then the phase and the translational command.
  const SafetyDecision decision =
      safety_.check(estimate.time_s, usable, estimate.status, estimate.reason, have_nav, p);
  Eigen::Vector3d accel_lvlh = Eigen::Vector3d::Zero();
  Eigen::Vector3d ref_p = p, ref_v = Eigen::Vector3d::Zero();
  const double period = options_.control_period_s;
  if (!have_nav) {
    out.phase = decision.action == SafetyAction::kRetreat ? Phase::kRetreat : Phase::kWait;
    out.reason = decision.reason.empty() ? "no usable estimate yet" : decision.reason;
  } else if (decision.action == SafetyAction::kRetreat) {
    if (phase_ != Phase::kRetreat) {
      retreat_reference_m_ = p;
      tracker_.reset();
      far_field_.stop();
    }
    const bool out_far_enough = retreat_reference_m_.x() >= options_.retreat_range_m;
    if (!out_far_enough) {
      retreat_reference_m_.x() =
          std::min(options_.retreat_range_m, retreat_reference_m_.x() + options_.retreat_speed_mps * dt);
    }
    ref_p = retreat_reference_m_;
    ref_v = Eigen::Vector3d(out_far_enough ? 0.0 : options_.retreat_speed_mps, 0.0, 0.0);
    accel_lvlh = R_lvlh_tp * tracker_.command(period, p, v, ref_p, ref_v, free_accel_tp, false);
    out.phase = Phase::kRetreat;
    out.reason = decision.reason;
  } else if (decision.action == SafetyAction::kHold) {
    if (near_field_) {
      // Station-keeping on the frozen approach reference.
      approach_reference_.advance(dt, true);
      ref_p = approach_reference_.position();
      accel_lvlh = R_lvlh_tp * tracker_.command(period, p, v, ref_p, ref_v, free_accel_tp, false);
    } else {
      // Far field: coast on the CW transfer (it is a free trajectory); burns wait, and the transfer is
      // re-targeted from the state at the next usable estimate.
      far_field_.requestRetarget();
      ref_p = approachAxisPoint(options_.far_field.aim_range_m);
    }
    out.phase = Phase::kHold;
    out.reason = decision.reason;
  } else if (!near_field_ && p.x() > options_.near_field_range_m) {
    const FarFieldOptions& f = options_.far_field;
    const Eigen::Vector3d aim_port = R_lvlh_tp * approachAxisPoint(f.aim_range_m);
    const Eigen::Vector3d aim_velocity =
        R_lvlh_tp * Eigen::Vector3d(-profileClosingSpeed(options_.approach, f.aim_range_m), 0.0, 0.0);
    accel_lvlh = far_field_.step(estimate.time_s, period, n, r_com, navigator_.velocity(), aim_port - offset,
                                 aim_velocity);
    ref_p = approachAxisPoint(f.aim_range_m);
    ref_v = R_lvlh_tp.transpose() * far_field_.plan().v_start_mps;
    out.phase = Phase::kFarField;
    std::ostringstream s;
    s << "CW transfer to the aim point at " << f.aim_range_m << " m, arrival in "
      << std::max(0.0, far_field_.arrivalTime_s() - estimate.time_s) << " s";
    out.reason = s.str();
  } else {
    if (!near_field_) {
      near_field_ = true;
      far_field_.stop();
      approach_reference_.start(p.x());
      tracker_.reset();
    } else {
      approach_reference_.advance(dt, false);
    }
    ref_p = approach_reference_.position();
    ref_v = approach_reference_.velocity(false);
    accel_lvlh = R_lvlh_tp * tracker_.command(period, p, v, ref_p, ref_v, free_accel_tp, true);
    if (approach_reference_.atHoldPoint()) {
      out.phase = Phase::kHold;
      std::ostringstream s;
      s << "hold point at " << approach_reference_.holdPointRange_m() << " m, "
        << approach_reference_.holdLeft_s() << " s left";
      out.reason = s.str();
    } else if (p.x() <= options_.contact_range_m) {
      out.phase = Phase::kContact;
      out.reason = "final approach to contact";
    } else {
      out.phase = Phase::kApproach;
      out.reason = "closing along the docking axis";
    }
  }
  phase_ = out.phase;

  // 4. Force in the body frame, saturated per axis; navigation propagates with what was actually commanded.
  const Eigen::Vector3d force_body = (options_.chaser_mass_kg * (R_lvlh_chaser.transpose() * accel_lvlh))
                                         .cwiseMax(-options_.max_force_n)
                                         .cwiseMin(options_.max_force_n);
  last_accel_lvlh_mps2_ = R_lvlh_chaser * force_body / options_.chaser_mass_kg;
  out.force_body_n = force_body;

  // 5. Attitude: hold the docking attitude in LVLH (or aligned with the estimated target port).
  const Eigen::Quaterniond q_eci_desired(R_eci_lvlh * desiredAttitudeInLvlh().toRotationMatrix());
  const Eigen::Vector3d desired_rate_body = R_lvlh_chaser.transpose() * omega_lvlh;
  out.torque_body_nm = attitudeTorque(options_.attitude, own.q_eci_chaser.normalized(), own.rate_body_rad_s,
                                      q_eci_desired, desired_rate_body)
                           .cwiseMax(-options_.max_torque_nm)
                           .cwiseMin(options_.max_torque_nm);

  if (have_nav) {
    out.port_position_m = p;
    out.port_velocity_mps = v;
    out.reference_position_m = ref_p;
    out.reference_velocity_mps = ref_v;
    out.range_m = p.x();
    out.closing_speed_mps = -v.x();
    out.lateral_error_m = p.tail<2>().norm();
    out.in_corridor = insideCorridor(options_.safety, p);
  }
  out.delta_v_used_mps = delta_v_mps_;
  return out;
}

}  // namespace ardsim_guidance
