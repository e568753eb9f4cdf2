#include "ardsim_guidance/approach_sim.h"

#include <cmath>

namespace ardsim_guidance {

namespace {

constexpr double kMu = 3.986004415e14;  // Earth GM, m^3/s^2

Eigen::Vector3d gravity(const Eigen::Vector3d& r) {
  return -kMu * r / std::pow(r.norm(), 3);
}

struct Body {
  Eigen::Vector3d r, v;
};

// One RK4 step of point-mass gravity plus a constant inertial acceleration.
void rk4(Body& b, const Eigen::Vector3d& accel, double h) {
  auto f = [&](const Eigen::Vector3d& r) { return Eigen::Vector3d(gravity(r) + accel); };
  const Eigen::Vector3d k1r = b.v, k1v = f(b.r);
  const Eigen::Vector3d k2r = b.v + 0.5 * h * k1v, k2v = f(b.r + 0.5 * h * k1r);
  const Eigen::Vector3d k3r = b.v + 0.5 * h * k2v, k3v = f(b.r + 0.5 * h * k2r);
  const Eigen::Vector3d k4r = b.v + h * k3v, k4v = f(b.r + h * k3r);
  b.r += h / 6.0 * (k1r + 2 * k2r + 2 * k3r + k4r);
  b.v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
}

}  // namespace

ApproachSimResult runApproachSim(const ApproachSimOptions& o) {
  const GuidanceOptions& g = o.guidance;
  const VehicleFrames frames = VehicleFrames::fromDescription(g.target);
  Guidance guidance(g);
  TruthPoseGenerator truth_pose(o.truth_pose, frames);

  // Target: circular orbit in the x-y plane of eci, attitude = LVLH (rotated by the nominal target attitude).
  const double n = std::sqrt(kMu / std::pow(o.orbit_radius_m, 3));
  Body target{{o.orbit_radius_m, 0.0, 0.0}, {0.0, n * o.orbit_radius_m, 0.0}};
  const Eigen::Vector3d& rpy = g.target_rpy_in_lvlh_rad;
  const Eigen::Matrix3d R_lvlh_target = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                         Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                            .toRotationMatrix();
  auto targetPose = [&]() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = inertialFromLvlh(target.r, target.v) * R_lvlh_target;
    T.translation() = target.r;
    return T;
  };
  const Eigen::Vector3d omega_target_eci = Eigen::Vector3d(0, 0, n);  // LVLH-holding target

  // Chaser: port at the start point in target_port, docking attitude with an offset, at rest in the LVLH
  // frame.
  const Eigen::Isometry3d T_eci_target0 = targetPose();
  const Eigen::Isometry3d T_eci_tp0 = T_eci_target0 * frames.T_target_port;
  Eigen::Matrix3d R_eci_chaser =
      T_eci_tp0.linear() * dockedChaserPortInTargetPort() * frames.T_chaser_port.linear().transpose();
  const Eigen::Vector3d& e = o.start_attitude_error_rad;
  if (e.norm() > 0.0)
    R_eci_chaser = R_eci_chaser * Eigen::AngleAxisd(e.norm(), e.normalized()).toRotationMatrix();
  const Eigen::Vector3d port_eci = T_eci_tp0 * o.start_port_position_m;
  Body chaser{port_eci - R_eci_chaser * frames.T_chaser_port.translation(), Eigen::Vector3d::Zero()};
  chaser.v = target.v + omega_target_eci.cross(chaser.r - target.r);
  Eigen::Quaterniond q_eci_chaser(R_eci_chaser);
  Eigen::Vector3d omega_body = q_eci_chaser.conjugate() * omega_target_eci;
  const Eigen::Vector3d inertia = g.attitude.inertia_kg_m2;

  ApproachSimResult result;
  double sum_force_sq = 0.0;
  int force_samples = 0;
  const double dt = g.control_period_s, h = dt / o.substeps;
  double prev_range = o.start_port_position_m.x();
  for (double t = 0.0; t <= o.max_time_s; t += dt) {
    const Eigen::Isometry3d T_eci_target = targetPose();
    Eigen::Isometry3d T_eci_chaser = Eigen::Isometry3d::Identity();
    T_eci_chaser.linear() = q_eci_chaser.toRotationMatrix();
    T_eci_chaser.translation() = chaser.r;
    // Truth port state in target_port (derivative in the rotating target frame).
    const Eigen::Isometry3d T_eci_tp = T_eci_target * frames.T_target_port;
    const Eigen::Isometry3d T_eci_cp = T_eci_chaser * frames.T_chaser_port;
    const Eigen::Vector3d omega_chaser_eci = q_eci_chaser * omega_body;
    const Eigen::Vector3d v_cp = chaser.v + omega_chaser_eci.cross(T_eci_cp.translation() - chaser.r);
    const Eigen::Vector3d v_tp = target.v + omega_target_eci.cross(T_eci_tp.translation() - target.r);
    const Eigen::Vector3d d_eci = T_eci_cp.translation() - T_eci_tp.translation();
    const Eigen::Vector3d p_tp = T_eci_tp.linear().transpose() * d_eci;
    const Eigen::Vector3d v_rel_tp =
        T_eci_tp.linear().transpose() * (v_cp - v_tp - omega_target_eci.cross(d_eci));
    if (p_tp.x() <= 0.0 && prev_range > 0.0) {
      result.contact = true;
      result.time_s = t;
      result.closing_speed_mps = -v_rel_tp.x();
      result.lateral_misalignment_m = p_tp.tail<2>().norm();
      result.lateral_rate_mps = v_rel_tp.tail<2>().norm();
      const Eigen::Matrix3d R_tp_cp = T_eci_tp.linear().transpose() * T_eci_cp.linear();
      result.angular_misalignment_rad =
          Eigen::AngleAxisd(dockedChaserPortInTargetPort().transpose() * R_tp_cp).angle();
      result.angular_rate_rad_s = (omega_chaser_eci - omega_target_eci).norm();
      break;
    }
    prev_range = p_tp.x();
    if (p_tp.x() <= g.near_field_range_m) {
      SafetyOptions s = g.safety;
      result.max_corridor_ratio =
          std::max(result.max_corridor_ratio, p_tp.tail<2>().norm() / corridorRadius(s, p_tp));
    }

    const TruthPoseSample sample = truth_pose.generate(t, T_eci_target, T_eci_chaser);
    EstimateInput estimate;
    estimate.time_s = t;
    estimate.status = sample.status;
    estimate.reason = sample.reason;
    estimate.well_formed = true;
    estimate.T_lidar_target = sample.T_lidar_target;
    OwnState own;
    own.position_eci_m = chaser.r;
    own.velocity_eci_mps = chaser.v;
    own.q_eci_chaser = q_eci_chaser;
    own.rate_body_rad_s = omega_body;
    const GuidanceOutput command = guidance.step(estimate, &own);
    result.delta_v_mps = command.delta_v_used_mps;
    result.final_phase = command.phase;
    result.final_reason = command.reason;
    result.time_s = t;
    if (p_tp.x() <= 10.0) {
      sum_force_sq += command.force_body_n.squaredNorm();
      ++force_samples;
    }

    // Apply the command over [t, t + dt].
    const Eigen::Vector3d accel_eci = q_eci_chaser * command.force_body_n / g.chaser_mass_kg;
    for (int i = 0; i < o.substeps; ++i) {
      rk4(target, Eigen::Vector3d::Zero(), h);
      rk4(chaser, accel_eci, h);
      const Eigen::Vector3d domega =
          (command.torque_body_nm - omega_body.cross(inertia.cwiseProduct(omega_body)))
              .cwiseQuotient(inertia);
      omega_body += domega * h;
      const Eigen::Vector3d rotation = omega_body * h;
      if (rotation.norm() > 0.0) {
        q_eci_chaser =
            (q_eci_chaser * Eigen::Quaterniond(Eigen::AngleAxisd(rotation.norm(), rotation.normalized())))
                .normalized();
      }
    }
  }
  result.rms_force_last_10m_n = force_samples > 0 ? std::sqrt(sum_force_sq / force_samples) : 0.0;
  return result;
}

}  // namespace ardsim_guidance
