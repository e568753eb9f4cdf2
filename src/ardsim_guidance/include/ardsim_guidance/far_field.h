// Far field: Clohessy-Wiltshire two-impulse targeting of an aim point on the approach axis, re-targeted at
// set intervals from the current relative state. The impulses are flown as short burns at a bounded
// acceleration over as many control steps as they need. All vectors in LVLH, centre-of-mass relative state.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "ardsim_guidance/cw.h"

namespace ardsim_guidance {

struct FarFieldOptions {
  double aim_range_m = 25.0;          // aim point on the docking axis, range from the target port (m)
  double transfer_time_s = 300.0;     // time of flight of the first transfer
  double retarget_interval_s = 30.0;  // re-targeting period
  double min_retarget_time_s =
      20.0;                        // no re-targeting when less time than this is left: fly out the transfer
  double burn_accel_mps2 = 0.015;  // acceleration per LVLH axis at which the impulses are flown
};

class FarFieldTargeting {
 public:
  explicit FarFieldTargeting(const FarFieldOptions& options = {}) : options_(options) {}
  bool active() const { return active_; }
  void stop() { active_ = false; }
  // Re-target at the next step (after a HOLD), if enough transfer time is left.
  void requestRetarget() { retarget_requested_ = true; }

  // Commanded acceleration for the step starting at time_s: plans a transfer on the first call, re-targets at
  // intervals, and flies the pending impulse. r_com/v: current relative state; r_aim/v_aim: aim point and the
  // velocity wanted there. dt_s: the control period the burn is applied over. A singular targeting problem
  // keeps the previous plan.
  Eigen::Vector3d step(double time_s, double dt_s, double n_rad_s, const Eigen::Vector3d& r_com_m,
                       const Eigen::Vector3d& v_mps, const Eigen::Vector3d& r_aim_m,
                       const Eigen::Vector3d& v_aim_mps);

  const TwoImpulseTransfer& plan() const { return plan_; }
  double arrivalTime_s() const { return arrival_time_s_; }
  const Eigen::Vector3d& pendingDeltaV_mps() const { return pending_dv_mps_; }

 private:
  void retarget(double time_s, double n, const Eigen::Vector3d& r, const Eigen::Vector3d& v,
                const Eigen::Vector3d& r_aim, const Eigen::Vector3d& v_aim, double transfer_time_s);

  FarFieldOptions options_;
  bool active_ = false;
  bool arrived_ = false;
  bool retarget_requested_ = false;
  double arrival_time_s_ = 0.0;
  double last_target_time_s_ = 0.0;
  TwoImpulseTransfer plan_;
  Eigen::Vector3d pending_dv_mps_{0, 0, 0};
};

// Points of the coasting CW trajectory from (r0, v0) over duration_s, `samples` evenly spaced, end included.
std::vector<Eigen::Vector3d> cwPath(double n_rad_s, const Eigen::Vector3d& r0, const Eigen::Vector3d& v0,
                                    double duration_s, int samples);

}  // namespace ardsim_guidance
