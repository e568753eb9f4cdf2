// The estimator facade that the node and evaluate_dataset drive, one frame at a time: it predicts the pose
// from the previous estimates, asks a MethodSelector which PoseMethod runs this frame (ICP only for now; the
// close-range mode manager is another selector over more methods), and follows the method with an optional
// median filter and the relative velocity. ROS-free.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {

// What a selector may look at to choose the method for a frame.
struct SelectionInput {
  const OrganizedCloud* cloud = nullptr;
  Eigen::Isometry3d T_lidar_target_predicted = Eigen::Isometry3d::Identity();
  const PoseResult* previous = nullptr;  // the last frame's result; nullptr on the first frame
};

class MethodSelector {
 public:
  virtual ~MethodSelector() = default;
  // One of the estimator's methods (a key of its method map).
  virtual EstimateMethod select(const SelectionInput& input) = 0;
  // After select: whether the estimate is to be blended from another method's (run on the same frame and
  // prediction) into the selected one's, and the selected one's weight (0..1); the output then does not jump
  // at a hand-over.
  virtual bool blending(EstimateMethod* /*from*/, double* /*weight*/) const { return false; }
  virtual void reset() {}
};

// Always the same method (ICP while it is the only one).
class FixedMethodSelector : public MethodSelector {
 public:
  explicit FixedMethodSelector(EstimateMethod method) : method_(method) {}
  EstimateMethod select(const SelectionInput&) override { return method_; }

 private:
  EstimateMethod method_;
};

struct EstimatorOptions {
  // Median of the last median_window estimates (as in the study), each first carried forward to the frame's
  // stamp at the window's velocity: smoother, without lagging a steady motion.
  bool median_filter = false;
  int median_window = 5;  // frames, odd
  double velocity_smoothing =
      0.5;  // weight of the new difference in the velocity's exponential smoothing, 0..1
  // The same for the rotation rate, which starts at zero (after a prior, LOST or a DEGRADED estimate) and
  // learns from TRACKING pairs: a relative rotation rate changes slowly, while a single frame's attitude
  // error, taken as a rate, puts the next prediction further off the other way. By target: 0.5 (the ISS),
  // 0.2 (Hubble: at 30-50 m a frame's tilt is good to ~0.02-0.05 deg, and with the first pair taken whole,
  // as before, one frame 0.05 deg off turned the next prediction 0.07 deg the other way and that frame ended
  // 6 mm off; approach datasets, 30-50 m position within 3x the RMS in 19 -> 24 of 24 runs).
  double angular_velocity_smoothing = 0.5;
  double max_prediction_gap_s = 2.0;  // a longer gap since the last good estimate: predict without velocity
  // A frame stamped more than this before the frame before it: time went back (a bag played again, a
  // simulation restarted), and the history belongs to another run. The estimator starts again from its
  // prior (after LOST it would search only near the last good estimate, which can be 80 m off by then).
  // Less far back, a frame out of order: predicted without velocity, nothing reset.
  double restart_time_jump_s = 1.0;
  // Composite pose, in the band of predicted lidar-to-port ranges [min, max) (both 0: off; makeEstimator
  // turns it off unless the method is auto): ICP and the docking-ring method both run on the frame, and the
  // pose takes the port position from the ring, the tilt across the line of sight from ICP, the rotation
  // about it from the selected method. Each part from the method that measures it best: on Hubble at
  // 20-30 m ICP's port position is ~2 cm off, the ring's a few mm; at 10-20 m the ring's tilt is ~0.05 deg
  // off, ICP's (the whole body, a long lever) ~0.02. Status, flags and covariance stay the selected method's.
  double composite_min_port_range_m = 0.0;
  double composite_max_port_range_m = 0.0;
  // ... and the rotation about the line of sight from ICP too where its TRACKING estimate's standard
  // deviation of it (its covariance: the scan's information, and since session 34 the roll prior where ICP
  // took it) is below this, deg: Hubble with its arrays in ICP's model and in view, ~0.004 (on the masts
  // alone 0.04-0.09). The ring method, blind to it, holds the roll it was handed at 20 m: in
  // hubble_hold_arrays30 10-20 m 0.054 -> 0.037 deg RMS. 0: never.
  double composite_icp_roll_max_sigma_deg = 0.01;
};
void validate(const EstimatorOptions& options);

struct EstimatorOutput {
  PoseResult result;                                                 // after the median filter when it is on
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();            // target origin, in lidar_optical
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();  // in lidar_optical
  bool velocity_valid = false;
  // This frame went back in time by more than EstimatorOptions::restart_time_jump_s (s before the frame
  // before; 0 otherwise): the estimator started again from its prior.
  double restarted_back_s = 0.0;
  // Frames that should have come between this one and the newest before it, going by the shortest interval
  // between frames seen (the sensor's period, kept through a restart: the stream's, not the history's):
  // dropped on the way (a subscriber's queue that a player outran, most often while an acquisition search
  // takes its few hundred ms) or never sent. 0 for the first frame, one out of order and one after a restart.
  int frames_missing = 0;
  double compute_ms = 0.0;  // wall clock of this frame, diagnostic only
};

class PoseEstimator {
 public:
  using Methods = std::map<EstimateMethod, std::unique_ptr<PoseMethod>>;
  // T_target_port: where the composite pose's port position is taken (see EstimatorOptions); with the
  // composite on, methods must hold ICP and the ring method.
  PoseEstimator(const EstimatorOptions& options, Methods methods, std::unique_ptr<MethodSelector> selector,
                const Eigen::Isometry3d& T_target_port = Eigen::Isometry3d::Identity());

  // The pose to start from (initial estimate or prior); forgets all history and resets the methods.
  void setPrior(const Eigen::Isometry3d& T_lidar_target);
  EstimatorOutput process(const OrganizedCloud& cloud);
  // The pose the next frame at stamp_s will start from.
  Eigen::Isometry3d predict(double stamp_s) const;

 private:
  void updateVelocity(const PoseResult& result, double stamp_s);
  // Whether the composite pose applies at the predicted pose.
  bool compositeAt(const Eigen::Isometry3d& T_lidar_target_predicted) const;
  // result with the port position of ring and the tilt across the line of sight of icp.
  void compose(const PoseResult& icp, const PoseResult& ring, PoseResult* result) const;
  // The filtered pose at stamp_s from (stamp, raw estimate) pairs.
  Eigen::Isometry3d medianOf(const std::deque<std::pair<double, Eigen::Isometry3d>>& recent,
                             double stamp_s) const;

  EstimatorOptions options_;
  Methods methods_;
  std::unique_ptr<MethodSelector> selector_;
  Eigen::Isometry3d T_target_port_;
  // ICP, once LOST as the composite's second method, would start an acquisition search (tens to hundreds of
  // ms) on every later frame: it is not run as the second method again until it is selected.
  bool icp_second_lost_ = false;
  Eigen::Isometry3d prior_ = Eigen::Isometry3d::Identity();
  bool have_good_ = false;  // a TRACKING or DEGRADED estimate since the prior
  Eigen::Isometry3d last_good_ = Eigen::Isometry3d::Identity();
  bool last_good_tracking_ = false;
  bool last_good_acquiring_ = false;  // made while acquiring (its jump from the one before is no motion)
  double last_good_stamp_s = 0.0;
  Eigen::Vector3d velocity_mps_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps_ = Eigen::Vector3d::Zero();
  bool velocity_valid_ = false;
  PoseResult previous_;
  double previous_stamp_s_ = 0.0;
  bool have_previous_ = false;  // a frame since the prior
  // For frames_missing: the newest stamp since the prior (a frame out of order leaves a gap after it that is
  // none) and the shortest interval between frames seen (0: none yet).
  double newest_stamp_s_ = 0.0;
  double frame_interval_s_ = 0.0;
  std::deque<std::pair<double, Eigen::Isometry3d>> recent_;  // (stamp s, good raw estimate), for the filter
};

}  // namespace ardsim_pose
