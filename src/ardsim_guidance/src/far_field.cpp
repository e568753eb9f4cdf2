#include "ardsim_guidance/far_field.h"
#include "ardsim_dynamics/orbit.h"

#include <algorithm>
#include <vector>

namespace ardsim_guidance {

void FarFieldTargeting::retarget(double time_s, double n, const Eigen::Vector3d& r, const Eigen::Vector3d& v,
                                 const Eigen::Vector3d& r_aim, const Eigen::Vector3d& v_aim,
                                 double transfer_time_s) {
  const TwoImpulseTransfer plan = cwTwoImpulse(n, r, v, r_aim, v_aim, transfer_time_s);
  last_target_time_s_ = time_s;
  if (!plan.valid) return;  // keep flying the previous plan
  plan_ = plan;
  arrival_time_s_ = time_s + transfer_time_s;
  // The whole correction replaces what was left of the previous first impulse: it is computed from the
  // velocity already reached.
  pending_dv_mps_ = plan.dv1_mps;
  arrived_ = false;
}

Eigen::Vector3d FarFieldTargeting::step(double time_s, double dt, double n, const Eigen::Vector3d& r,
                                        const Eigen::Vector3d& v, const Eigen::Vector3d& r_aim,
                                        const Eigen::Vector3d& v_aim) {
  if (!active_) {
    active_ = true;
    retarget(time_s, n, r, v, r_aim, v_aim, options_.transfer_time_s);
  } else if (time_s >= arrival_time_s_ && !arrived_) {
    // Second impulse: match the wanted arrival velocity, then (if the near field has not taken over) fly a
    // new transfer of one re-targeting period to the aim point.
    arrived_ = true;
    pending_dv_mps_ = v_aim - v;
  } else if (arrived_ && pending_dv_mps_.isZero()) {
    retarget(time_s, n, r, v, r_aim, v_aim,
             std::max(options_.retarget_interval_s, options_.min_retarget_time_s));
  } else if (!arrived_ &&
             (retarget_requested_ || time_s - last_target_time_s_ >= options_.retarget_interval_s) &&
             arrival_time_s_ - time_s >= options_.min_retarget_time_s) {
    retarget(time_s, n, r, v, r_aim, v_aim, arrival_time_s_ - time_s);
  }
  retarget_requested_ = false;
  if (!(dt > 0.0)) return Eigen::Vector3d::Zero();
  const double a_max = options_.burn_accel_mps2;
  const Eigen::Vector3d accel = (pending_dv_mps_ / dt).cwiseMax(-a_max).cwiseMin(a_max);
  pending_dv_mps_ -= accel * dt;
  // Residues below a micro-metre per second are rounding, not manoeuvres.
  if (pending_dv_mps_.norm() < 1e-6) pending_dv_mps_.setZero();
  return accel;
}

std::vector<Eigen::Vector3d> cwPath(double n, const Eigen::Vector3d& r0, const Eigen::Vector3d& v0,
                                    double duration, int samples) {
  std::vector<Eigen::Vector3d> path;
  Vector6d x0;
  x0 << r0, v0;
  for (int i = 0; i < samples; ++i) {
    const double t = duration * (samples > 1 ? static_cast<double>(i) / (samples - 1) : 1.0);
    path.push_back((ardsim_dynamics::cwTransition(n, t) * x0).head<3>());
  }
  return path;
}

}  // namespace ardsim_guidance
