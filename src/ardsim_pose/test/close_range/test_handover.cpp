// The hand-over from ICP to the close-range method in the estimator facade (method "auto"): an approach along
// the docking axis, tilted and offset a little, through the switch at 11 m port to port (12 m from the
// lidar), on rendered noisy frames.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"
#include "rendering.h"

namespace ardsim_pose {
namespace close_range {
namespace {

using ardsim_description::TargetKind;

double rms(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / values.size());
}

// An approach with every quantity of the state linear in the frame index.
struct Sweep {
  testing::ApproachState first;
  testing::ApproachState per_frame;
  int frames = 0;
  TargetKind kind = TargetKind::kIss;
};

struct SweepFrame {
  Eigen::Isometry3d truth;
  PoseResult result;
};

// The sweep's frames rendered and estimated in order, 0.1 s apart, from the first frame's truth; fails at a
// LOST frame.
void runSweep(const Sweep& sweep, testing::TargetRenderer* renderer, PoseEstimator* estimator,
              std::vector<SweepFrame>* out) {
  for (int k = 0; k < sweep.frames; ++k) {
    testing::ApproachState s;
    const testing::ApproachState &a = sweep.first, &b = sweep.per_frame;
    s.port_range_m = a.port_range_m + k * b.port_range_m;
    s.lateral_y_m = a.lateral_y_m + k * b.lateral_y_m;
    s.lateral_z_m = a.lateral_z_m + k * b.lateral_z_m;
    s.tilt_y_deg = a.tilt_y_deg + k * b.tilt_y_deg;
    s.tilt_z_deg = a.tilt_z_deg + k * b.tilt_z_deg;
    s.roll_deg = a.roll_deg + k * b.roll_deg;
    const Eigen::Isometry3d truth = testing::T_lidar_target(s, sweep.kind);
    if (k == 0) estimator->setPrior(truth);
    OrganizedCloud cloud = renderer->render(truth, k);
    cloud.stamp_s = 0.1 * k;
    const EstimatorOutput estimate = estimator->process(cloud);
    ASSERT_NE(estimate.result.status, EstimateStatus::kLost)
        << "frame " << k << ": " << estimate.result.reason;
    out->push_back({truth, estimate.result});
  }
}

TEST(CloseRangeHandover, FromIcpWithoutJumpOrLostFrame) {
  testing::TargetRenderer renderer(true, 11);
  PoseConfig config;
  config.method = "auto";
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(config);
  // Port range 13.5 m to 10.0 m, 0.1 m per 0.1 s frame.
  const Sweep sweep{{13.5, 0.05, -0.03, 1.5, -1.0, 5.0}, {-0.1, -0.001, 0.0, -0.03, 0.02, 0.0}, 36};
  std::vector<SweepFrame> run;
  ASSERT_NO_FATAL_FAILURE(runSweep(sweep, &renderer, estimator.get(), &run));
  const int frames = sweep.frames;
  std::vector<double> position_error, attitude_error;
  std::vector<EstimateMethod> methods;
  for (const SweepFrame& f : run) {
    methods.push_back(f.result.method);
    const testing::PortError e = testing::portError(f.result.T_lidar_target, f.truth);
    position_error.push_back(std::sqrt(e.lateral() * e.lateral() + e.range_m * e.range_m));
    attitude_error.push_back(e.rotation_deg.norm());
  }
  // One switch, from ICP to the ring method.
  int switch_frame = -1, switches = 0;
  for (int k = 1; k < frames; ++k) {
    if (methods[k] != methods[k - 1]) {
      ++switches;
      switch_frame = k;
    }
  }
  ASSERT_EQ(switches, 1);
  EXPECT_EQ(methods.front(), EstimateMethod::kIcp);
  EXPECT_EQ(methods.back(), EstimateMethod::kRing);
  // Around the switch (+-10 frames), the worst frame within 3 x the RMS of the window.
  const int begin = std::max(0, switch_frame - 10), end = std::min(frames, switch_frame + 11);
  const std::vector<double> p(position_error.begin() + begin, position_error.begin() + end);
  const std::vector<double> a(attitude_error.begin() + begin, attitude_error.begin() + end);
  EXPECT_LE(*std::max_element(p.begin(), p.end()), 3.0 * rms(p));
  EXPECT_LE(*std::max_element(a.begin(), a.end()), 3.0 * rms(a));
  std::printf(
      "hand-over at frame %d: position worst %.4f m rms %.4f m, attitude worst %.3f deg rms %.3f deg\n",
      switch_frame, *std::max_element(p.begin(), p.end()), rms(p), *std::max_element(a.begin(), a.end()),
      rms(a));
}

// The close-range methods take the configured sensor's pixel size: a 128 x 128 sensor (pixels twice as wide
// as the default's) from 6 m to 1.5 m port to port, `method: ring`, noise on, within the close-range goals.
TEST(CloseRangeSensor, ALowerResolutionSensorsPixels) {
  ardsim_lidar::SensorOptions sensor;
  sensor.width = sensor.height = 128;
  testing::TargetRenderer renderer(true, 7, TargetKind::kIss, sensor);
  PoseConfig config;
  config.sensor = sensor;
  config.method = "ring";
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(config);
  const Sweep sweep{{6.0, 0.01, -0.01, 0.3, -0.2, 2.0}, {-0.1, 0.0, 0.0, 0.0, 0.0, 0.0}, 46};
  std::vector<SweepFrame> run;
  ASSERT_NO_FATAL_FAILURE(runSweep(sweep, &renderer, estimator.get(), &run));
  double lateral_max_m = 0.0, range_max_m = 0.0;
  for (const SweepFrame& f : run) {
    const testing::PortError e = testing::portError(f.result.T_lidar_target, f.truth);
    lateral_max_m = std::max(lateral_max_m, e.lateral());
    range_max_m = std::max(range_max_m, std::abs(e.range_m));
  }
  std::printf("128 x 128, 6-1.5 m, ring: lateral max %.2f mm, range max %.2f mm\n", lateral_max_m * 1e3,
              range_max_m * 1e3);
  EXPECT_LT(lateral_max_m, 0.02);
  EXPECT_LT(range_max_m, 0.01);
}

// Hubble in `auto` with its target defaults over the sweep, rendered with noise (renderer_seed).
void runHubbleAuto(std::uint64_t renderer_seed, const Sweep& sweep, std::vector<SweepFrame>* run) {
  testing::TargetRenderer renderer(true, renderer_seed, TargetKind::kHubble);
  PoseConfig config;
  config.target = TargetKind::kHubble;
  applyTargetDefaults(&config);
  config.method = "auto";
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(config);
  runSweep(sweep, &renderer, estimator.get(), run);
}

// Hubble in auto from 28 m through the hand-over at 20 m to 18.4 m (port to port; 0.2 m a 0.1 s frame),
// tilted, offset and rolled a little, from an acquisition at the first frame: ICP's pose to 20 m (its
// lateral position from the face-on bulkhead's rim: the occluding contours, by consensus from 25 m out),
// then the composite pose (EstimatorOptions), the port position from the ring method and the tilt from ICP
// (the ring alone tilts ~0.05 deg). Until session 37 the composite began at 30 m: port position RMS 1.9 mm,
// worst 4.0 mm here; since, 1.0 / 2.9 mm.
TEST(CloseRangeHandover, HubbleCompositePortFromTheRingTiltFromIcp) {
  const Sweep sweep{
      {28.0, 0.12, -0.06, 0.8, -0.5, 3.0}, {-0.2, -0.002, 0.0, -0.016, 0.012, 0.0}, 49, TargetKind::kHubble};
  std::vector<SweepFrame> run;
  ASSERT_NO_FATAL_FAILURE(runHubbleAuto(13, sweep, &run));
  std::vector<double> position_error, tilt_error;
  double position_max_m = 0.0;
  for (const SweepFrame& f : run) {
    const testing::PortError e = testing::portError(f.result.T_lidar_target, f.truth, TargetKind::kHubble);
    const double position_m = std::sqrt(e.lateral() * e.lateral() + e.range_m * e.range_m);
    position_error.push_back(position_m);
    position_max_m = std::max(position_max_m, position_m);
    tilt_error.push_back(e.rotation_deg.tail<2>().norm());  // about the port's y and z: across the axis
  }
  std::printf("Hubble 28-18.4 m, auto: port position rms %.4f m max %.4f m, tilt rms %.4f deg\n",
              rms(position_error), position_max_m, rms(tilt_error));
  EXPECT_LT(rms(position_error), 0.003);
  EXPECT_LT(position_max_m, 0.006);
  EXPECT_LT(rms(tilt_error), 0.03);
}

// The composite's covariance is its parts': the ring's port position, ICP's tilt (and its roll where taken),
// moved to the target origin. With the ring's whole (the ring's tilt sigma where ICP's tilt was taken) the
// tilt's error over its sigma was 0.34 on the Hubble dataset at 10-20 m (evaluate_dataset --method auto).
// Hubble from 16 to 11.5 m port to port, the composite throughout.
TEST(CloseRangeHandover, HubbleCompositeCovarianceIsItsParts) {
  const Sweep sweep{
      {16.0, 0.05, -0.03, 0.6, -0.4, 2.0}, {-0.15, -0.001, 0.001, -0.01, 0.01, 0.0}, 31, TargetKind::kHubble};
  std::vector<SweepFrame> run;
  ASSERT_NO_FATAL_FAILURE(runHubbleAuto(17, sweep, &run));
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kHubble);
  std::vector<double> z_lateral, z_tilt;
  for (std::size_t k = 1; k < run.size(); ++k) {  // the first frame is the acquisition's
    const SweepFrame& f = run[k];
    EXPECT_EQ(f.result.method, EstimateMethod::kRing) << "frame " << k;
    const NormalizedError z = normalizedError(poseError(f.result.T_lidar_target, f.truth, T_target_port),
                                              f.result.covariance, f.result.T_lidar_target, T_target_port);
    z_lateral.insert(z_lateral.end(), {z.port_position.x(), z.port_position.y()});
    z_tilt.insert(z_tilt.end(), {z.attitude.x(), z.attitude.y()});
  }
  std::printf("the composite's %zu frames: error over sigma RMS across the boresight %.2f, tilt %.2f\n",
              z_tilt.size() / 2, rms(z_lateral), rms(z_tilt));
  // Measured 1.18 / 0.95 (the ring's whole: 1.17 / 0.33).
  for (const double z : {rms(z_lateral), rms(z_tilt)}) {
    EXPECT_GT(z, 0.5);
    EXPECT_LT(z, 2.0);
  }
}

}  // namespace
}  // namespace close_range
}  // namespace ardsim_pose
