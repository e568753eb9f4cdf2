// Clohessy-Wiltshire relative motion in the NASA LVLH frame of a circular target orbit: x V-bar (along the
// target's velocity), z R-bar (towards Earth), y = z x x (H-bar). State [x y z vx vy vz] of the chaser
// relative to the target. Equations: x'' = 2 n z',  y'' = -n^2 y,  z'' = 3 n^2 z - 2 n x'  (shared reference
// cw_and_approach.md).
#pragma once

#include <Eigen/Core>

namespace ardsim_guidance {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Relative acceleration of free (unforced) CW motion at state (r, v).
Eigen::Vector3d cwAcceleration(double mean_motion_rad_s, const Eigen::Vector3d& r, const Eigen::Vector3d& v);

struct TwoImpulseTransfer {
  bool valid = false;                     // false when the in-plane Phi_rv is (near) singular (nT = 2 pi k)
  Eigen::Vector3d dv1_mps{0, 0, 0};       // first impulse, at the start
  Eigen::Vector3d dv2_mps{0, 0, 0};       // second impulse, at arrival, to reach the desired arrival velocity
  Eigen::Vector3d v_start_mps{0, 0, 0};   // velocity just after the first impulse
  Eigen::Vector3d v_arrive_mps{0, 0, 0};  // velocity just before the second impulse
};

// Two-impulse targeting from (r0, v0) to position rf reached after transfer_time_s, arriving with velocity
// vf: v0+ = Phi_rv^-1 (rf - Phi_rr r0), vf- = Phi_vr r0 + Phi_vv v0+, in-plane and out-of-plane separately.
// At an out-of-plane singularity (nT = pi k) the y velocity is nulled instead of targeted.
TwoImpulseTransfer cwTwoImpulse(double mean_motion_rad_s, const Eigen::Vector3d& r0,
                                const Eigen::Vector3d& v0, const Eigen::Vector3d& rf,
                                const Eigen::Vector3d& vf, double transfer_time_s);

}  // namespace ardsim_guidance
