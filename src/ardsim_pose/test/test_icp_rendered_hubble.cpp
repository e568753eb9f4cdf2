// ICP on Hubble frames rendered in-process by the lidar core (the ISS's are in test_icp_rendered.cpp; two
// programs so that make test runs them side by side): end-on with a prediction off across the boresight, the
// approach and acquisition along the docking axis, and the hold at 40 m: the roll prior's tightening, the
// lateral history's line and parabola, its vote and its gate, and the covariance across the boresight.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "along_docking_axis.h"
#include "ardsim_description/models.h"
#include "ardsim_lidar/lidar_simulator.h"
#include "ardsim_pose/dataset.h"
#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"
#include "ardsim_pose/icp_tracker.h"

namespace ardsim_pose {
namespace {

using ardsim_description::TargetKind;

PoseConfig hubbleDefaults() {
  PoseConfig config;
  config.target = TargetKind::kHubble;
  applyTargetDefaults(&config);
  return config;
}

TEST(HubbleEndOn, APredictionOffAcrossTheBoresightIsCorrected) {
  const PoseConfig config = hubbleDefaults();
  const std::shared_ptr<const ReferenceModel> model = buildReferenceModel(TargetKind::kHubble, config.model);
  ardsim_lidar::LidarSimulator simulator(config.sensor, ardsim_lidar::NoiseOptions{}, 7);
  simulator.setTarget(ardsim_description::buildHubble());
  IcpTracker tracker(model, ardsim_lidar::intrinsicsFor(config.sensor), config.icp, config.visibility);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kHubble);
  ardsim_lidar::LidarFrame frame;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Isometry3d truth = dockingAxisPose(TargetKind::kHubble, 29.0 - 0.01 * k);
    simulator.simulate(truth, static_cast<std::uint64_t>(k), &frame);
    Eigen::Isometry3d prediction = truth;
    if (k >= 4) prediction.translation() += Eigen::Vector3d(0.12, -0.09, 0.0);  // lidar x, y
    const PoseResult result = tracker.estimate(fromLidarFrame(frame, simulator.rays(), 0.1 * k), prediction);
    SCOPED_TRACE("frame " + std::to_string(k));
    ASSERT_NE(result.status, EstimateStatus::kLost) << result.reason;
    if (k < 4) continue;
    const PoseErrorValue e = poseError(result.T_lidar_target, truth, T_target_port);
    EXPECT_LT(e.port_position_error_m.norm(), 0.05);
    if (result.status == EstimateStatus::kTracking) {
      EXPECT_LT(e.port_position_error_m.norm(), 0.02);
    }
  }
}

// Hubble (its arrays edge-on) along its docking axis with Hubble's defaults, 0.1 s a frame.
AlongTheDockingAxis hubbleAlongItsAxis(std::uint64_t simulator_seed) {
  return AlongTheDockingAxis(hubbleDefaults(), ardsim_description::buildHubble(), simulator_seed);
}

// Hubble end-on from 40 to 30 m, 0.5 m a frame (as approach_poses --target hubble makes them), tracked from
// the truth: the roll about Hubble's axis is barely observed. Left to wander (10-20 deg a frame) it took
// frames to LOST ("diverged") and kept the rest DEGRADED, in acquisition at ~100 ms each. Checked directly:
// no frame LOST, acquisition over within the first frames and never again, every attitude within 0.5 deg.
// (Until session 10 this counted TRACKING frames instead, at least 10 of 21: 19 with 2500 scan points; with
// Hubble's 5000 since, 8, the others "not converged in 15 iterations" by a few tenths of a millimetre of the
// weak directions' creep, and at 0.5 m a frame without a velocity, which only TRACKING pairs teach. Over the
// 91-frame approach datasets 5000 points give more TRACKING frames than 2500, 58-67 against 48-57, and
// hubble_hold 1526 against 1323 beyond 30 m.)
TEST(HubbleApproach, TracksWithoutLosingAFrame) {
  AlongTheDockingAxis hubble = hubbleAlongItsAxis(1);
  double attitude_max_deg = 0.0;
  int tracked_from = -1;  // the first frame past the acquisition
  for (int k = 0; k < 21; ++k) {
    PoseErrorValue e;
    const EstimatorOutput out = hubble.frame(k, 39.0 - 0.5 * k, &e);
    ASSERT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    if (!out.result.acquiring && tracked_from < 0) tracked_from = k;
    if (tracked_from >= 0) {
      EXPECT_FALSE(out.result.acquiring) << "frame " << k << " back in acquisition: " << out.result.reason;
    }
    EXPECT_LT(e.port_position_error_m.norm(), 0.1) << "frame " << k;
    attitude_max_deg = std::max(attitude_max_deg, e.attitude_error_angle_rad * 180.0 / M_PI);
  }
  EXPECT_GE(tracked_from, 0);
  EXPECT_LE(tracked_from, 3);  // acquisition confirmed within the first frames
  EXPECT_LT(attitude_max_deg, 0.5);
}

// Hubble from 49 m, its arrays edge-on (0 deg), from the truth: in acquisition each frame searches and aligns
// on its own, and its roll rests on the masts alone (sub-pixel there). Each such frame's roll alone was up to
// 0.92 deg off here (frame 1; 0.17 with the gate), as 0.3-0.86 deg over the approach datasets' acquisition
// frames. From the second acquisition frame on a barely observed roll near the prediction's is held near it
// (icp/acquisition_boresight_gate_deg).
TEST(HubbleAcquisition, BarelyObservedRollHeldNearThePreviousFrame) {
  AlongTheDockingAxis hubble = hubbleAlongItsAxis(4);
  ASSERT_GT(hubble.config().icp.acquisition_boresight_gate_deg, 0.0);
  for (int k = 0; k < 10; ++k) {
    PoseErrorValue e;
    const EstimatorOutput out = hubble.frame(k, 49.0 - 0.5 * k, &e);
    ASSERT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    EXPECT_LT(e.attitude_error_angle_rad * 180.0 / M_PI, 0.3) << "frame " << k << ": " << out.result.reason;
    EXPECT_LT(e.port_position_error_m.norm(), 0.1) << "frame " << k;
  }
}

// Hubble held end-on at 40 m (1 mm closer a frame), its arrays edge-on, tracked from the truth: the roll
// rests on the masts, and each frame's fit of it scatters. Once tracked for icp/boresight_prior_frames frames
// the prior tightens (down to icp/boresight_prior_min_deg), so the held roll moves less from frame to frame
// than with the prior kept at icp/boresight_prior_deg (same frames, same noise).
double hubbleHoldRollStepRmsDeg(bool tightening) {
  PoseConfig config = hubbleDefaults();
  if (!tightening) config.icp.boresight_prior_frames = 0;
  AlongTheDockingAxis hubble(config, ardsim_description::buildHubble(), 5);
  double previous_roll_rad = 0.0, sum_sq = 0.0;
  int count = 0;
  for (int k = 0; k < 150; ++k) {
    PoseErrorValue e;
    const EstimatorOutput out = hubble.frame(k, 40.0 - 0.001 * k, &e);
    EXPECT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    const double roll_rad = e.attitude_error_rad.z();
    if (k >= 75) {  // past the tightening's start
      sum_sq += (roll_rad - previous_roll_rad) * (roll_rad - previous_roll_rad);
      ++count;
    }
    previous_roll_rad = roll_rad;
  }
  return std::sqrt(sum_sq / count) * 180.0 / M_PI;
}

TEST(HubbleHold, RollPriorTightensOnceTracked) {
  ASSERT_GT(hubbleDefaults().icp.boresight_prior_frames, 0);
  ASSERT_LT(hubbleDefaults().icp.boresight_prior_frames, 75);
  const double tightened_deg = hubbleHoldRollStepRmsDeg(true);
  const double kept_deg = hubbleHoldRollStepRmsDeg(false);
  EXPECT_LT(tightened_deg, 0.8 * kept_deg) << kept_deg;  // measured 0.011 vs 0.024 deg
}

// Hubble end-on from 41.2 to 40.1 m (as hubble_hold's chaser sees it there, 1.9 m off its axis, 8 mm closer a
// frame, 0.1 s a frame), noise on, with `method: icp` from the truth: the contours' consensus places the rim
// across the boresight from each frame's hit / miss pattern, and with icp/lateral_history_frames the line
// through the last frames' own measurements is a prior on it too (and, icp/lateral_vote_weight, on the vote).
// Port position error over the frames after the first 20 (same frames, same noise).
constexpr int kHubbleHoldPathFrames = 140;
// Frame k of the path (T_lidar_target).
Eigen::Isometry3d hubbleHoldPath(int k) {
  const Eigen::Quaterniond q_first(0.499996175573, -0.499999683429, -0.50000362977, -0.5000005112);
  const Eigen::Quaterniond q_last(0.499995679814, -0.49999906807, -0.500004046558, -0.500001205521);
  const Eigen::Vector3d first(-0.000468111, -1.934572598, 47.78981401),
      last(-0.00049601, -1.993476443, 46.601086132);
  const double s = static_cast<double>(k) / (kHubbleHoldPathFrames - 1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q_first.slerp(s, q_last).toRotationMatrix();
  T.translation() = first + s * (last - first);
  return T;
}
// What the target does on top of the path: in frames [jump_first, jump_end) it is 20 mm across the boresight,
// and from frame burn_first on it accelerates across it at burn_mps2 (a manoeuvre).
struct HubbleHoldMotion {
  int jump_first = 0, jump_end = 0;
  int burn_first = 0;
  double burn_mps2 = 0.0;
};
// Frame k as rendered.
Eigen::Isometry3d hubbleHoldRendered(int k, const HubbleHoldMotion& motion) {
  Eigen::Isometry3d T = hubbleHoldPath(k);
  if (k >= motion.jump_first && k < motion.jump_end) T.translation().x() += 0.02;
  const double burn_s = 0.1 * (k - motion.burn_first);
  if (motion.burn_mps2 != 0.0 && burn_s > 0.0)
    T.translation().y() += 0.5 * motion.burn_mps2 * burn_s * burn_s;
  return T;
}
// The estimates (T_lidar_target) along the path's first `frames` frames, `method: icp` from the truth, noise
// on (simulator_seed), none of them LOST; with covariances, their covariances too.
std::vector<Eigen::Isometry3d> hubbleHoldEstimates(
    PoseConfig config, int simulator_seed, int frames, const HubbleHoldMotion& motion = {},
    std::vector<Eigen::Matrix<double, 6, 6>>* covariances = nullptr) {
  config.method = "icp";
  ardsim_lidar::LidarSimulator simulator(config.sensor, ardsim_lidar::NoiseOptions{}, simulator_seed);
  simulator.setTarget(ardsim_description::buildHubble());
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(config);
  ardsim_lidar::LidarFrame rendered;
  std::vector<Eigen::Isometry3d> estimates;
  for (int k = 0; k < frames; ++k) {
    const Eigen::Isometry3d truth = hubbleHoldRendered(k, motion);
    if (k == 0) estimator->setPrior(truth);
    simulator.simulate(truth, static_cast<std::uint64_t>(k), &rendered);
    const EstimatorOutput out = estimator->process(fromLidarFrame(rendered, simulator.rays(), 0.1 * k));
    EXPECT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    estimates.push_back(out.result.T_lidar_target);
    if (covariances != nullptr) covariances->push_back(out.result.covariance);
  }
  return estimates;
}
double hubblePortErrorM(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return poseError(estimate, truth, ardsim_description::T_target_port(TargetKind::kHubble))
      .port_position_error_m.norm();
}
struct PortError {
  double rms_m = 0.0;
  double worst_m = 0.0;
};
// The port position error of estimates[first, end) against the frames as rendered.
PortError hubblePortError(const std::vector<Eigen::Isometry3d>& estimates, int first, int end,
                          const HubbleHoldMotion& motion = {}) {
  PortError error;
  for (int k = first; k < end; ++k) {
    const double e = hubblePortErrorM(estimates[k], hubbleHoldRendered(k, motion));
    error.rms_m += e * e;
    error.worst_m = std::max(error.worst_m, e);
  }
  error.rms_m = std::sqrt(error.rms_m / (end - first));
  return error;
}
PortError hubbleLateralError(int lateral_history_frames, double lateral_vote_weight, int simulator_seed = 3,
                             int lateral_gate_frames = 0 /* 0: the default */) {
  PoseConfig config = hubbleDefaults();
  config.icp.lateral_history_frames = lateral_history_frames;
  config.icp.lateral_vote_weight = lateral_vote_weight;
  if (lateral_gate_frames > 0) config.icp.lateral_gate_frames = lateral_gate_frames;
  return hubblePortError(hubbleHoldEstimates(config, simulator_seed, kHubbleHoldPathFrames), 20,
                         kHubbleHoldPathFrames);
}

// At 47 m each frame's own measurement is weak (its polygon widened by 0.02 px: ~1.3 mm), the newest ten
// frames' line above icp/lateral_line_sigma_m: the whole history's line, where it agrees, averages twice the
// frames.
TEST(HubbleHold, LongerLineWhereEachFrameIsWeak) {
  const IcpOptions defaults = hubbleDefaults().icp;
  ASSERT_GT(defaults.lateral_history_frames, defaults.lateral_line_frames);
  const PortError longer = hubbleLateralError(defaults.lateral_history_frames, defaults.lateral_vote_weight);
  const PortError newest = hubbleLateralError(defaults.lateral_line_frames, defaults.lateral_vote_weight);
  std::printf(
      "port position RMS / worst frame: the longer line where it agrees %.2f / %.2f mm, the newest %d "
      "frames' alone %.2f / %.2f mm\n",
      longer.rms_m * 1e3, longer.worst_m * 1e3, defaults.lateral_line_frames, newest.rms_m * 1e3,
      newest.worst_m * 1e3);
  EXPECT_LT(longer.rms_m, 0.9 * newest.rms_m);
  EXPECT_LT(longer.worst_m, newest.worst_m);
}

TEST(HubbleHold, LateralHistoryPlacesTheRimBetterThanEachFrameAlone) {
  ASSERT_GT(hubbleDefaults().icp.lateral_history_frames, 0);
  const PortError with = hubbleLateralError(hubbleDefaults().icp.lateral_history_frames, 0.0);
  const PortError without = hubbleLateralError(0, 0.0);
  std::printf("port position RMS with the lateral history %.2f mm, each frame alone %.2f mm\n",
              with.rms_m * 1e3, without.rms_m * 1e3);
  EXPECT_LT(with.rms_m, 0.8 * without.rms_m);  // measured 0.52 vs 0.85 mm (0.63 with the newest 10 alone)
}

// The covariance says how well the contours' consensus and the line through its history place the rim across
// the boresight: with the planes' normal equations alone it said 2-3 mm where the port was 0.3-0.5 mm off
// (errors over sigmas, RMS, 0.1-0.2 on Hubble's approach datasets at 30-50 m).
TEST(HubbleHold, CovarianceSaysHowWellTheRimIsPlacedAcrossTheBoresight) {
  std::vector<Eigen::Matrix<double, 6, 6>> covariances;
  const std::vector<Eigen::Isometry3d> estimates =
      hubbleHoldEstimates(hubbleDefaults(), 3, kHubbleHoldPathFrames, {}, &covariances);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kHubble);
  double z_sq = 0.0, sigma_sq = 0.0, error_sq = 0.0;
  int count = 0;
  for (int k = 20; k < kHubbleHoldPathFrames; ++k) {
    const PoseErrorValue e = poseError(estimates[k], hubbleHoldPath(k), T_target_port);
    const NormalizedError z = normalizedError(e, covariances[k], estimates[k], T_target_port);
    z_sq += z.port_position.head<2>().squaredNorm();
    sigma_sq += z.port_sigma_m.head<2>().squaredNorm();
    error_sq += e.port_position_error_m.head<2>().squaredNorm();
    count += 2;
  }
  const double z_rms = std::sqrt(z_sq / count);
  std::printf("port across the boresight: error RMS %.2f mm, sigma RMS %.2f mm, error / sigma RMS %.2f\n",
              std::sqrt(error_sq / count) * 1e3, std::sqrt(sigma_sq / count) * 1e3, z_rms);
  EXPECT_GT(z_rms, 0.3);  // not pessimistic by more than ~3x
  EXPECT_LT(z_rms, 1.5);  // nor optimistic
}

// The frames at ~40.7 m here are those of hubble_hold's worst at 30-50 m (t = 127 s in every lidar seed): the
// vote's top is a plateau a few cells wide there, its most votes a few millimetres off the rim in some noise
// draws, and the history's line breaks the tie. Six noise seeds, the no-breakdown rule in each. With
// the line dropped wherever a frame lies beyond its gate (icp/lateral_gate_frames 1), as session 39 measured
// the vote's weight: since session 40 a single frame beyond the gate takes the line anyway, which on this
// path does most of what the weight does (with the default gate, the strips alone: worst frame 1.19-1.89 mm,
// mean RMS 0.61 mm; with the weight 1.27-1.89, 0.59). And a history of the line's own frames only
// (icp/lateral_line_frames), as then: since session 41 the longer line lowers the RMS, not these frames.
TEST(HubbleHold, LateralLineInTheVoteCutsTheWorstFrames) {
  const IcpOptions defaults = hubbleDefaults().icp;
  ASSERT_GT(defaults.lateral_vote_weight, 0.0);
  double weighed_worst_m = 0.0, counted_worst_m = 0.0, weighed_rms_sum_m = 0.0, counted_rms_sum_m = 0.0;
  for (int seed = 1; seed <= 6; ++seed) {
    const PortError weighed =
        hubbleLateralError(defaults.lateral_line_frames, defaults.lateral_vote_weight, seed, 1);
    const PortError counted = hubbleLateralError(defaults.lateral_line_frames, 0.0, seed, 1);
    std::printf(
        "seed %d: port position RMS / worst frame with the line in the vote %.2f / %.2f mm, the strips "
        "alone %.2f / %.2f mm\n",
        seed, weighed.rms_m * 1e3, weighed.worst_m * 1e3, counted.rms_m * 1e3, counted.worst_m * 1e3);
    EXPECT_LT(weighed.worst_m, 3.0 * weighed.rms_m)
        << "seed " << seed;  // measured 2.21-2.91x (alone 2.29-6.37x)
    weighed_worst_m = std::max(weighed_worst_m, weighed.worst_m);
    counted_worst_m = std::max(counted_worst_m, counted.worst_m);
    weighed_rms_sum_m += weighed.rms_m;
    counted_rms_sum_m += counted.rms_m;
  }
  EXPECT_LT(weighed_worst_m, 0.6 * counted_worst_m);  // measured 1.89 vs 4.84 mm
  EXPECT_LT(weighed_rms_sum_m, counted_rms_sum_m);    // measured 0.59 vs 0.64 mm mean RMS
}

// The same path with the target rendered 20 mm across the boresight from frame 80 on for jump_frames frames:
// there the frame's own measurement lies far beyond 3 sigma of the line. A single such frame is the vote's
// kind of error (icp/lateral_gate_frames), so the line holds the estimate near the path; a jump that lasts
// is followed from its second frame on. Per frame from frame 80: the port position error against the smooth
// path (path_m) and against the pose rendered (rendered_m).
struct JumpErrors {
  std::vector<double> path_m, rendered_m;
};
JumpErrors hubbleErrorsAfterJump(int lateral_gate_frames, int jump_frames) {
  PoseConfig config = hubbleDefaults();
  config.icp.lateral_gate_frames = lateral_gate_frames;
  constexpr int kJumpFrame = 80, kFrames = 90;
  HubbleHoldMotion jump;
  jump.jump_first = kJumpFrame;
  jump.jump_end = kJumpFrame + jump_frames;
  const std::vector<Eigen::Isometry3d> estimates = hubbleHoldEstimates(config, 3, kFrames, jump);
  JumpErrors errors;
  for (int k = kJumpFrame; k < kFrames; ++k) {
    errors.path_m.push_back(hubblePortErrorM(estimates[k], hubbleHoldPath(k)));
    errors.rendered_m.push_back(hubblePortErrorM(estimates[k], hubbleHoldRendered(k, jump)));
  }
  return errors;
}

TEST(HubbleHold, LateralLineHoldsThroughOneFrameAndFollowsAJumpThatLasts) {
  const int gate_frames = hubbleDefaults().icp.lateral_gate_frames;
  ASSERT_GT(gate_frames, 1);
  const JumpErrors held = hubbleErrorsAfterJump(gate_frames, 1), dropped = hubbleErrorsAfterJump(1, 1);
  std::printf(
      "one frame rendered 20 mm off the path: the estimate %.1f mm from the path (the line dropped at "
      "the first such frame: %.1f mm)\n",
      held.path_m[0] * 1e3, dropped.path_m[0] * 1e3);
  EXPECT_LT(held.path_m[0], 0.5 * dropped.path_m[0]);
  // A jump that lasts: followed from its second frame; its 5th-6th frames swing back 3-6 mm while the line,
  // half its history before the jump, comes within 3 sigma again (measured 3.6 / 5.6 mm; with the line
  // dropped at the first frame 3.9 / 1.3), and from the 7th on the line is the new path's.
  const JumpErrors lasting = hubbleErrorsAfterJump(gate_frames, 10);
  std::printf(
      "a 20 mm jump that lasts: the estimate from its first frame on %.1f / %.1f / %.1f / %.1f / %.1f / "
      "%.1f / %.1f mm from the pose rendered\n",
      lasting.rendered_m[0] * 1e3, lasting.rendered_m[1] * 1e3, lasting.rendered_m[2] * 1e3,
      lasting.rendered_m[3] * 1e3, lasting.rendered_m[4] * 1e3, lasting.rendered_m[5] * 1e3,
      lasting.rendered_m[6] * 1e3);
  for (int k = 1; k < 4; ++k) EXPECT_LT(lasting.rendered_m[k], 0.0015) << "frame " << 80 + k;   // 0.4-1.1 mm
  for (int k = 6; k < 10; ++k) EXPECT_LT(lasting.rendered_m[k], 0.0015) << "frame " << 80 + k;  // 0.3-0.9 mm
  EXPECT_LT(*std::max_element(lasting.rendered_m.begin() + 1, lasting.rendered_m.end()), 0.008);
}

// A burn across the boresight (hubble_hold's at 31 m: 0.024 m/s^2, decaying over seconds): the lateral line
// lags it by ~a T^2 / 12 over its span; the newest frames' parabola, once the history's says it accelerates,
// does not (IcpOptions::lateral_acceleration_chi2).
PortError hubbleBurnError(double lateral_acceleration_chi2) {
  PoseConfig config = hubbleDefaults();
  config.icp.lateral_acceleration_chi2 = lateral_acceleration_chi2;
  constexpr int kFrames = 90;
  HubbleHoldMotion burn;
  burn.burn_first = 40;
  burn.burn_mps2 = 0.024;
  // From the burn's 11th frame on: the first ten are the detection's (the parabola's test needs the history).
  return hubblePortError(hubbleHoldEstimates(config, 3, kFrames, burn), burn.burn_first + 10, kFrames, burn);
}

TEST(HubbleHold, ParabolaFollowsABurnTheLineLags) {
  const PortError parabola = hubbleBurnError(hubbleDefaults().icp.lateral_acceleration_chi2),
                  lines = hubbleBurnError(0.0);
  std::printf(
      "a 0.024 m/s^2 burn across the boresight, its frames 11-50: port RMS / worst %.2f / %.2f mm "
      "(lines only: %.2f / %.2f mm)\n",
      parabola.rms_m * 1e3, parabola.worst_m * 1e3, lines.rms_m * 1e3, lines.worst_m * 1e3);
  ASSERT_GT(hubbleDefaults().icp.lateral_acceleration_chi2, 0.0);
  EXPECT_LT(parabola.rms_m, 0.7 * lines.rms_m);
  EXPECT_LT(parabola.worst_m, lines.worst_m);
}

}  // namespace
}  // namespace ardsim_pose
