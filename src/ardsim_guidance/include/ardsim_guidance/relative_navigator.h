// Relative navigation of the chaser port with respect to the target port, in LVLH axes, from the position
// part of the pose estimates. Two ways to get the relative velocity, selectable:
//  - kDifferencing: a component-wise median filter over the last positions, then the difference of two
//  medians
//    difference_span samples apart divided by their time difference (what the source study did);
//  - kKalman: a Kalman filter whose process model is the Clohessy-Wiltshire state transition (closed form)
//  plus the
//    commanded acceleration, with white-noise acceleration as process noise.
// Between measurements both propagate the last state with the same CW model, so a short dropout is bridged.
#pragma once

#include <deque>
#include <string>

#include <Eigen/Core>

#include "ardsim_guidance/cw.h"

namespace ardsim_guidance {

enum class VelocitySource { kDifferencing, kKalman };
VelocitySource parseVelocitySource(const std::string& name);  // "differencing" or "kalman"; throws otherwise

struct NavigatorOptions {
  VelocitySource velocity_source = VelocitySource::kKalman;
  int median_window = 5;              // samples in the median filter (differencing)
  int difference_span = 10;           // samples between the two differenced medians (differencing)
  double history_reset_gap_s = 1.0;   // a gap between measurements longer than this restarts the differencing
  double measurement_sigma_m = 0.05;  // 1-sigma noise of a TRACKING position measurement per axis (Kalman)
  double process_accel_sigma_mps2 =
      2e-4;  // unmodelled acceleration: actuator errors, J2, drag, port offsets (Kalman)
  double initial_velocity_sigma_mps = 0.5;  // velocity uncertainty at the first measurement (Kalman)
};

class RelativeNavigator {
 public:
  explicit RelativeNavigator(const NavigatorOptions& options = {});

  // Advances the state by dt_s under CW dynamics of mean motion n_rad_s. The CW model applies to the centres
  // of mass: com_to_port_offset_m = r_port - r_com (held constant over the step). accel_mps2: commanded
  // acceleration applied over the step, LVLH.
  void predict(double dt_s, double n_rad_s, const Eigen::Vector3d& com_to_port_offset_m,
               const Eigen::Vector3d& accel_mps2);

  // A port-relative position measurement (LVLH) at the current time; sigma_scale inflates its noise
  // (DEGRADED).
  void update(const Eigen::Vector3d& position_m, double sigma_scale = 1.0);

  bool initialized() const { return initialized_; }
  const Eigen::Vector3d& position() const { return position_; }
  const Eigen::Vector3d& velocity() const { return velocity_; }
  // Kalman covariance of [position, velocity]; zero in differencing mode.
  const Matrix6d& covariance() const { return covariance_; }

 private:
  void updateDifferencing(const Eigen::Vector3d& position_m);
  void updateKalman(const Eigen::Vector3d& position_m, double sigma_scale);

  NavigatorOptions options_;
  bool initialized_ = false;
  double time_s_ = 0.0;  // time since the first measurement
  Eigen::Vector3d position_{0, 0, 0}, velocity_{0, 0, 0};
  Matrix6d covariance_ = Matrix6d::Zero();
  struct Sample {
    double time_s;
    Eigen::Vector3d position_m;
  };
  std::deque<Sample> raw_;      // last median_window measurements
  std::deque<Sample> medians_;  // last difference_span + 1 median outputs
};

}  // namespace ardsim_guidance
