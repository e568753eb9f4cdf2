// The close-range methods on rendered frames of the ISS docking adapter (issue 5 goals) and of Hubble's
// soft-capture mechanism.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_description/frames.h"
#include "ardsim_pose/close_range/pyramid.h"
#include "ardsim_pose/close_range/ring_detector.h"
#include "ardsim_pose/evaluation.h"
#include "rendering.h"

namespace ardsim_pose {
namespace close_range {
namespace {

using testing::ApproachState;
using testing::PortError;
using testing::TargetRenderer;

// The prediction handed to a method: the truth disturbed as a previous estimate or ICP's would be.
Eigen::Isometry3d predictionFrom(ApproachState s) {
  s.lateral_y_m += 0.03;
  s.lateral_z_m -= 0.02;
  s.port_range_m += 0.05;
  s.tilt_y_deg += 0.5;
  s.tilt_z_deg -= 0.4;
  s.roll_deg += 8.0;
  return testing::T_lidar_target(s);
}

// The methods configured for the sensor: the ideal one (noise off) has no detector walk to correct and no
// range noise to allow for.
std::unique_ptr<PoseMethod> makeMethod(EstimateMethod method, bool noise) {
  AdapterFitOptions fit;
  fit.saturated_range_bias_m = noise ? -0.02 : 0.0;
  fit.range_sigma_m = noise ? 0.012 : 0.003;
  if (method == EstimateMethod::kPyramid) {
    PyramidOptions options;
    options.fit = fit;
    return std::make_unique<PyramidMethod>(issAdapterGeometry(), options);
  }
  RingDetectorOptions options;
  options.fit = fit;
  options.connect_step_m = noise ? 0.04 : 0.01;
  return std::make_unique<RingMethod>(issAdapterGeometry(), options);
}

const char* name(EstimateMethod method) {
  return method == EstimateMethod::kPyramid ? "pyramid" : "ring";
}

struct Sweep {
  double lateral_max_m = 0.0, range_max_m = 0.0, tilt_sq = 0.0, roll_max_deg = 0.0;
  int tilt_count = 0, frames = 0, lost = 0, roll_observed = 0;
};

// Port ranges from 7 m to contact, tilts within +-4 deg, lateral offsets and rolls.
std::vector<ApproachState> closeRangeStates() {
  std::vector<ApproachState> states;
  const double ranges[] = {7.0, 6.0, 5.0, 4.0, 3.0, 2.5, 2.0, 1.5, 1.0, 0.6, 0.3, 0.0};
  int k = 0;
  for (double range : ranges) {
    for (int variant = 0; variant < 3; ++variant, ++k) {
      ApproachState s;
      s.port_range_m = range;
      // Tilt up to 4 deg in any direction, lateral offset up to 0.08 m (inside the capture envelope at
      // contact: 4 deg, 0.10 m), roll up to 25 deg.
      const double tilt_deg = 4.0 * std::abs(std::sin(1.3 * k)), tilt_direction = 2.4 * k;
      s.tilt_y_deg = tilt_deg * std::cos(tilt_direction);
      s.tilt_z_deg = tilt_deg * std::sin(tilt_direction);
      const double lateral_m = 0.08 * std::abs(std::cos(0.9 * k)), lateral_direction = 1.7 * k;
      s.lateral_y_m = lateral_m * std::cos(lateral_direction);
      s.lateral_z_m = lateral_m * std::sin(lateral_direction);
      s.roll_deg = 25.0 * std::sin(2.1 * k);
      states.push_back(s);
    }
  }
  return states;
}

Sweep runSweep(EstimateMethod method, bool noise) {
  TargetRenderer renderer(noise);
  std::unique_ptr<PoseMethod> estimator = makeMethod(method, noise);
  Sweep sweep;
  int index = 0;
  for (const ApproachState& s : closeRangeStates()) {
    const Eigen::Isometry3d truth = testing::T_lidar_target(s);
    const OrganizedCloud cloud = renderer.render(truth, index++);
    const PoseResult result = estimator->estimate(cloud, predictionFrom(s));
    ++sweep.frames;
    if (result.status == EstimateStatus::kLost) {
      ++sweep.lost;
      std::printf("%s noise=%d range %.1f: LOST %s\n", name(method), noise, s.port_range_m,
                  result.reason.c_str());
      continue;
    }
    const PortError e = testing::portError(result.T_lidar_target, truth);
    std::printf("%s noise=%d range %.1f: lateral %+.4f %+.4f range %+.4f tilt %+.3f %+.3f roll %+.2f (%s)\n",
                name(method), noise, s.port_range_m, e.lateral_x_m, e.lateral_y_m, e.range_m,
                e.rotation_deg.y(), e.rotation_deg.z(), e.rotation_deg.x(),
                result.boresight_rotation_observed ? "observed" : "held");
    sweep.lateral_max_m =
        std::max(sweep.lateral_max_m, std::max(std::abs(e.lateral_x_m), std::abs(e.lateral_y_m)));
    sweep.range_max_m = std::max(sweep.range_max_m, std::abs(e.range_m));
    sweep.tilt_sq += e.rotation_deg.y() * e.rotation_deg.y() + e.rotation_deg.z() * e.rotation_deg.z();
    sweep.tilt_count += 2;
    if (result.boresight_rotation_observed) {
      ++sweep.roll_observed;
      sweep.roll_max_deg = std::max(sweep.roll_max_deg, std::abs(e.rotation_deg.x()));
    }
  }
  const double tilt_rms = std::sqrt(sweep.tilt_sq / std::max(1, sweep.tilt_count));
  std::printf(
      "%s noise=%d: frames %d lost %d lateral_max %.4f m range_max %.4f m tilt_rms %.4f deg roll_max %.3f "
      "deg "
      "(observed on %d)\n",
      name(method), noise, sweep.frames, sweep.lost, sweep.lateral_max_m, sweep.range_max_m, tilt_rms,
      sweep.roll_max_deg, sweep.roll_observed);
  sweep.tilt_sq = tilt_rms;
  return sweep;
}

class CloseRangeGoals : public ::testing::TestWithParam<std::tuple<EstimateMethod, bool>> {};

TEST_P(CloseRangeGoals, FromSevenMetresToContact) {
  const EstimateMethod method = std::get<0>(GetParam());
  const bool noise = std::get<1>(GetParam());
  const Sweep sweep = runSweep(method, noise);
  EXPECT_EQ(sweep.lost, 0);
  EXPECT_LE(sweep.lateral_max_m, 0.02);
  EXPECT_LE(sweep.range_max_m, 0.01);
  EXPECT_LE(sweep.tilt_sq, noise ? 0.2 : 0.05);  // tilt RMS, deg
  EXPECT_LE(sweep.roll_max_deg, 1.0);
  EXPECT_GE(sweep.roll_observed, sweep.frames / 2);
}

// At port range `range`, frame `index` of a sweep: tilts about both axes and lateral offsets up to tilt_deg
// and lateral_m, a roll up to 25 deg, varying from frame to frame.
ApproachState disturbedState(double range, int index, double tilt_deg, double lateral_m) {
  ApproachState s;
  s.port_range_m = range;
  s.tilt_y_deg = tilt_deg * std::sin(1.3 * index);
  s.tilt_z_deg = tilt_deg * std::cos(1.7 * index);
  s.lateral_y_m = lateral_m * std::sin(0.9 * index);
  s.lateral_z_m = lateral_m * std::cos(1.1 * index);
  s.roll_deg = 25.0 * std::sin(2.1 * index);
  return s;
}

// From 7.5 to 11.5 m (the hand-over from ICP is at 12 m) the three peripheral reflector targets are whole in
// the view: the boresight angle from their discs (1.125 m out) is several times finer than from the petals
// (0.26-0.40 m). The prediction is 8 deg off in roll, so each frame's measurement is taken as it is (no
// tracking filter).
TEST(CloseRangeReflectors, BoresightAngleFromOneFrame) {
  TargetRenderer renderer(true);
  std::unique_ptr<PoseMethod> estimator = makeMethod(EstimateMethod::kRing, true);
  int index = 0;
  double roll_sq = 0.0, roll_max_deg = 0.0;
  for (double range : {7.5, 8.5, 9.5, 10.5, 11.5}) {
    for (int variant = 0; variant < 4; ++variant, ++index) {
      const ApproachState s = disturbedState(range, index, 2.0, 0.05);
      const Eigen::Isometry3d truth = testing::T_lidar_target(s);
      const PoseResult result = estimator->estimate(renderer.render(truth, index), predictionFrom(s));
      ASSERT_NE(result.status, EstimateStatus::kLost) << "range " << range << ": " << result.reason;
      EXPECT_TRUE(result.boresight_rotation_observed);
      const double roll_deg = testing::portError(result.T_lidar_target, truth).rotation_deg.x();
      std::printf("ring range %.1f roll %+.1f: roll error %+.3f deg\n", range, s.roll_deg, roll_deg);
      roll_sq += roll_deg * roll_deg;
      roll_max_deg = std::max(roll_max_deg, std::abs(roll_deg));
    }
  }
  std::printf("roll rms %.4f max %.4f deg over %d frames\n", std::sqrt(roll_sq / index), roll_max_deg, index);
  // Measured: rms 0.056, max 0.113 deg (from the petals and cross alone: 0.46 and 1.8 deg).
  EXPECT_LE(std::sqrt(roll_sq / index), 0.08);
  EXPECT_LE(roll_max_deg, 0.15);
}

// Hubble's soft-capture mechanism: the same IDSS ring, petals and reflectors, the aft bulkhead 0.30 m behind
// the docking plane instead of a hatch, no centreline target (hubbleAdapterGeometry; the detectors' depth
// steps, 0.25-0.3 m, are the ISS's). With tilts, offsets and rolls as above, the ISS's close-range goals: the
// ring from Hubble's 20 m hand-over (applyTargetDefaults), the pyramid from 11.5 m (its cells gave poses 7 cm
// off at 15.5 and 19.5 m, so validate() refuses it beyond 12 m), to 1.5 m.
class CloseRangeHubble : public ::testing::TestWithParam<EstimateMethod> {};

TEST_P(CloseRangeHubble, FromTheHandOverToOneAndAHalfMetres) {
  using ardsim_description::TargetKind;
  TargetRenderer renderer(true, 7, TargetKind::kHubble);
  const bool pyramid = GetParam() == EstimateMethod::kPyramid;
  std::unique_ptr<PoseMethod> method;
  if (pyramid)
    method = std::make_unique<PyramidMethod>(hubbleAdapterGeometry());
  else
    method = std::make_unique<RingMethod>(hubbleAdapterGeometry());
  std::vector<double> ranges = {11.5, 10.0, 8.5, 7.0, 6.0, 5.0, 4.0, 3.0, 2.0, 1.5};
  if (!pyramid) ranges.insert(ranges.begin(), {19.5, 17.0, 14.5});
  int index = 0, lost = 0, lost_beyond_12m = 0, observed = 0;
  double lateral_max_m = 0.0, range_max_m = 0.0, tilt_sq = 0.0, roll_max_deg = 0.0;
  for (double range : ranges) {
    for (int variant = 0; variant < 3; ++variant, ++index) {
      const ApproachState s = disturbedState(range, index, 3.0, 0.06);
      const Eigen::Isometry3d truth = testing::T_lidar_target(s, TargetKind::kHubble);
      ApproachState predicted = s;
      predicted.lateral_y_m += 0.03;
      predicted.port_range_m += 0.05;
      predicted.tilt_y_deg += 0.5;
      // The tracked angle: a jump beyond the 1.5 deg gate would be taken as it is.
      predicted.roll_deg += 0.5;
      const PoseResult result = method->estimate(renderer.render(truth, index),
                                                 testing::T_lidar_target(predicted, TargetKind::kHubble));
      if (result.status == EstimateStatus::kLost) {
        ++(range > 12.0 ? lost_beyond_12m : lost);
        std::printf("hubble %s range %.1f: LOST %s\n", name(GetParam()), range, result.reason.c_str());
        continue;
      }
      const PortError e = testing::portError(result.T_lidar_target, truth, TargetKind::kHubble);
      std::printf("hubble %s range %.1f: lateral %+.4f %+.4f range %+.4f tilt %+.3f %+.3f roll %+.2f (%s)\n",
                  name(GetParam()), range, e.lateral_x_m, e.lateral_y_m, e.range_m, e.rotation_deg.y(),
                  e.rotation_deg.z(), e.rotation_deg.x(),
                  result.boresight_rotation_observed ? "observed" : "held");
      lateral_max_m = std::max(lateral_max_m, e.lateral());
      range_max_m = std::max(range_max_m, std::abs(e.range_m));
      tilt_sq += e.rotation_deg.y() * e.rotation_deg.y() + e.rotation_deg.z() * e.rotation_deg.z();
      if (result.boresight_rotation_observed) {
        ++observed;
        roll_max_deg = std::max(roll_max_deg, std::abs(e.rotation_deg.x()));
      }
    }
  }
  const double tilt_rms_deg = std::sqrt(tilt_sq / std::max(1, 2 * (index - lost - lost_beyond_12m)));
  std::printf(
      "hubble %s: frames %d lost %d (beyond 12 m %d) lateral_max %.4f m range_max %.4f m tilt_rms %.4f deg "
      "roll_max %.3f deg (observed on %d)\n",
      name(GetParam()), index, lost, lost_beyond_12m, lateral_max_m, range_max_m, tilt_rms_deg, roll_max_deg,
      observed);
  EXPECT_EQ(lost, 0);
  // Beyond 12 m (9 frames, tilted up to 3 deg): measured one LOST at 17 m (the ring's edge rejected), never a
  // wrong pose (the bounds below hold for every frame that is not LOST).
  EXPECT_LE(lost_beyond_12m, 1);
  EXPECT_LE(lateral_max_m, 0.02);
  EXPECT_LE(range_max_m, 0.01);
  EXPECT_LE(tilt_rms_deg, 0.2);
  EXPECT_LE(roll_max_deg, 1.0);
  EXPECT_GE(observed, index / 2);
}

// Near contact the field of view cuts the ring's inner edge (0.42 m; here from 1.5 m, in the default
// scenario's closed loop, the lidar off the port's axis, from 2.6 m): what is left of the circle placed the
// port 3-5 mm off there where the centreline cross was within 1 mm; there the lateral position is the cross's
// alone (AdapterFitReport::circle_clipped). Measured: lateral max 1.47 mm for both methods (the cut circle
// fused in: 4.25 / 4.29 mm).
TEST(CloseRangeClippedRing, LateralFromTheCrossWhereTheViewCutsTheRing) {
  TargetRenderer renderer(true);
  for (const EstimateMethod method : {EstimateMethod::kRing, EstimateMethod::kPyramid}) {
    std::unique_ptr<PoseMethod> estimator = makeMethod(method, true);
    double lateral_max_m = 0.0;
    int clipped = 0, index = 0;
    for (const double range : {1.6, 1.5, 1.4, 1.3, 1.2, 1.1}) {
      for (int variant = 0; variant < 3; ++variant, ++index) {
        const ApproachState s = disturbedState(range, index, 0.5, 0.01);
        const Eigen::Isometry3d truth = testing::T_lidar_target(s);
        const PoseResult result = estimator->estimate(renderer.render(truth, index), predictionFrom(s));
        ASSERT_NE(result.status, EstimateStatus::kLost) << name(method) << " range " << range;
        const AdapterFitReport& report = method == EstimateMethod::kRing
                                             ? static_cast<RingMethod&>(*estimator).lastReport()
                                             : static_cast<PyramidMethod&>(*estimator).lastReport();
        clipped += report.circle && report.circle_clipped;
        lateral_max_m = std::max(lateral_max_m, testing::portError(result.T_lidar_target, truth).lateral());
      }
    }
    std::printf("%s: %d of %d frames with the ring's circle clipped, lateral max %.2f mm\n", name(method),
                clipped, index, lateral_max_m * 1e3);
    EXPECT_GE(clipped, index / 2) << name(method);
    EXPECT_LT(lateral_max_m, 0.002) << name(method);
  }
}

// The published covariance is the target origin's (PoseResult::covariance): through the lever to the port it
// must say how far off the port is. The methods measure the port; as the port's, labelled the origin's, the
// ISS's said 39 mm across the boresight where the port was 0.3 mm off (its origin 4.5 m off the docking axis,
// times the roll's 0.5 deg sigma): z 0.02. RMS of each error over its sigma, noise on, 7 to 3 m, tilts and
// lateral offsets as in the closed loop (0.5 deg, 1 cm).
class CloseRangeCovariance : public ::testing::TestWithParam<EstimateMethod> {};

TEST_P(CloseRangeCovariance, SaysHowFarOffThePortIs) {
  TargetRenderer renderer(true);
  std::unique_ptr<PoseMethod> estimator = makeMethod(GetParam(), true);
  const Eigen::Isometry3d T_target_port =
      ardsim_description::T_target_port(ardsim_description::TargetKind::kIss);
  double lateral_sq = 0.0, range_sq = 0.0, tilt_sq = 0.0;
  int frames = 0, index = 0;
  for (const double range : {7.0, 6.0, 5.0, 4.0, 3.0}) {
    for (int variant = 0; variant < 4; ++variant, ++index) {
      const ApproachState s = disturbedState(range, index, 0.5, 0.01);
      const Eigen::Isometry3d truth = testing::T_lidar_target(s);
      const PoseResult result = estimator->estimate(renderer.render(truth, index), predictionFrom(s));
      if (result.status == EstimateStatus::kLost) continue;
      const NormalizedError z = normalizedError(poseError(result.T_lidar_target, truth, T_target_port),
                                                result.covariance, result.T_lidar_target, T_target_port);
      lateral_sq += z.port_position.head<2>().squaredNorm();
      range_sq += z.port_position.z() * z.port_position.z();
      tilt_sq += z.attitude.head<2>().squaredNorm();
      ++frames;
    }
  }
  ASSERT_GT(frames, 0);
  const double z_lat = std::sqrt(lateral_sq / (2 * frames)), z_rng = std::sqrt(range_sq / frames),
               z_tilt = std::sqrt(tilt_sq / (2 * frames));
  std::printf("%s: %d frames, error over sigma RMS: across the boresight %.2f, along it %.2f, tilt %.2f\n",
              name(GetParam()), frames, z_lat, z_rng, z_tilt);
  // Across the boresight within 3x either way (measured: ring 1.65, pyramid 1.61). Along it and in tilt the
  // fits' sigmas are the noise's alone, without the frames' systematic errors: measured ring 3.93 / 2.34,
  // pyramid 1.02 / 1.06 here (the default scenario's closed loop at 3-10 m: ~1 on every axis).
  EXPECT_GT(z_lat, 1.0 / 3.0);
  EXPECT_LT(z_lat, 3.0);
}

INSTANTIATE_TEST_SUITE_P(Methods, CloseRangeCovariance,
                         ::testing::Values(EstimateMethod::kRing, EstimateMethod::kPyramid));

INSTANTIATE_TEST_SUITE_P(Methods, CloseRangeHubble,
                         ::testing::Values(EstimateMethod::kRing, EstimateMethod::kPyramid));

INSTANTIATE_TEST_SUITE_P(Methods, CloseRangeGoals,
                         ::testing::Combine(::testing::Values(EstimateMethod::kRing,
                                                              EstimateMethod::kPyramid),
                                            ::testing::Bool()));

}  // namespace
}  // namespace close_range
}  // namespace ardsim_pose

namespace ardsim_pose {
namespace close_range {
namespace {

// Either LOST, or (if a method still finds the adapter) an estimate within the goals: never a wrong pose.
void expectLostOrRight(PoseMethod& method, const OrganizedCloud& cloud, const Eigen::Isometry3d& prediction,
                       const Eigen::Isometry3d& truth, bool expect_lost) {
  const PoseResult result = method.estimate(cloud, prediction);
  if (expect_lost) {
    EXPECT_EQ(result.status, EstimateStatus::kLost) << result.reason;
  }
  if (result.status == EstimateStatus::kLost) return;
  const testing::PortError e = testing::portError(result.T_lidar_target, truth);
  EXPECT_LT(e.lateral(), 0.02);
  EXPECT_LT(std::abs(e.range_m), 0.01);
}

TEST(CloseRangeLost, RingOutOfViewOccludedOrEmpty) {
  TargetRenderer renderer(true);
  RingMethod ring;
  PyramidMethod pyramid;
  for (double range : {4.0, 2.0, 0.5}) {
    ApproachState s;
    s.port_range_m = range;
    const Eigen::Isometry3d truth = testing::T_lidar_target(s);
    // The chaser turned 25 deg away: the adapter leaves the 20 deg field of view (the modules behind remain).
    ApproachState away = s;
    away.tilt_z_deg = 25.0;
    const Eigen::Isometry3d truth_away = testing::T_lidar_target(away);
    const OrganizedCloud cloud_away = renderer.render(truth_away, 1);
    for (PoseMethod* method : {static_cast<PoseMethod*>(&ring), static_cast<PoseMethod*>(&pyramid)}) {
      SCOPED_TRACE("range " + std::to_string(range));
      // Predicted where it is (a tracker following the turn): the adapter is out of view.
      expectLostOrRight(*method, cloud_away, truth_away, truth_away, true);
      // Occluded: all but a strip along the top of the image blanked (no ring edge, no cross).
      OrganizedCloud occluded = renderer.render(truth, 2);
      for (std::size_t i = 30 * occluded.width; i < occluded.points.size(); ++i) {
        occluded.points[i] = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
      }
      expectLostOrRight(*method, occluded, truth, truth, true);
      OrganizedCloud empty = occluded;
      for (auto& p : empty.points) p = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
      expectLostOrRight(*method, empty, truth, truth, true);
      OrganizedCloud malformed;
      malformed.width = 256;
      malformed.height = 256;  // no points at all
      EXPECT_EQ(method->estimate(malformed, truth).status, EstimateStatus::kLost);
    }
  }
}

}  // namespace
}  // namespace close_range
}  // namespace ardsim_pose
