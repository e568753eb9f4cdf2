#include "ardsim_guidance/cw.h"

#include <cmath>

#include <Eigen/LU>

#include "ardsim_dynamics/orbit.h"

namespace ardsim_guidance {

Eigen::Vector3d cwAcceleration(double n, const Eigen::Vector3d& r, const Eigen::Vector3d& v) {
  return {2.0 * n * v.z(), -n * n * r.y(), 3.0 * n * n * r.z() - 2.0 * n * v.x()};
}

TwoImpulseTransfer cwTwoImpulse(double n, const Eigen::Vector3d& r0, const Eigen::Vector3d& v0,
                                const Eigen::Vector3d& rf, const Eigen::Vector3d& vf,
                                double transfer_time_s) {
  TwoImpulseTransfer out;
  if (!(transfer_time_s > 0.0)) return out;
  const Matrix6d phi = ardsim_dynamics::cwTransition(n, transfer_time_s);
  // In-plane (x, z) and out-of-plane (y) decouple; solved separately so that an out-of-plane singularity
  // (nT = pi k: y(T) = -/+ y0 whatever vy) does not prevent the in-plane transfer.
  Eigen::Matrix2d rr, rv, vr, vv;
  const int ip[2] = {0, 2};
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      rr(i, j) = phi(ip[i], ip[j]);
      rv(i, j) = phi(ip[i], 3 + ip[j]);
      vr(i, j) = phi(3 + ip[i], ip[j]);
      vv(i, j) = phi(3 + ip[i], 3 + ip[j]);
    }
  }
  // The in-plane Phi_rv scales like T; compare its determinant with T^2 so the test is dimensionless.
  // Singular at nT = 2 pi k.
  if (std::abs(rv.determinant()) < 1e-6 * transfer_time_s * transfer_time_s) return out;
  const Eigen::Vector2d r0_ip(r0.x(), r0.z()), rf_ip(rf.x(), rf.z());
  const Eigen::Vector2d v_start_ip = rv.partialPivLu().solve(rf_ip - rr * r0_ip);
  const Eigen::Vector2d v_arrive_ip = vr * r0_ip + vv * v_start_ip;
  // Out of plane: y(T) = c y0 + s/n vy0. Where s ~ 0 the y target cannot be met: null the y velocity instead.
  const double s = std::sin(n * transfer_time_s), c = std::cos(n * transfer_time_s);
  const double vy_start = std::abs(s) > 1e-6 ? n * (rf.y() - c * r0.y()) / s : 0.0;
  const double vy_arrive = -n * s * r0.y() + c * vy_start;
  out.v_start_mps = Eigen::Vector3d(v_start_ip.x(), vy_start, v_start_ip.y());
  out.v_arrive_mps = Eigen::Vector3d(v_arrive_ip.x(), vy_arrive, v_arrive_ip.y());
  out.dv1_mps = out.v_start_mps - v0;
  out.dv2_mps = vf - out.v_arrive_mps;
  out.valid = out.v_start_mps.allFinite();
  return out;
}

}  // namespace ardsim_guidance
