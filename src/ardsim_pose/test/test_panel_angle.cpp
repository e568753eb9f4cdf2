// Hubble's solar-array angle measured on rendered frames (the lidar core, in-process): a frame's fit at the
// true pose, none when the arrays are edge-on or absent, the tracker's model built at the median of the first
// fits and rebuilt only when the arrays turn, and ICP's attitude with the arrays turned 30 deg from the rigid
// model.
#include <algorithm>
#include <cmath>
#include <limits>
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
#include "ardsim_pose/panel_angle.h"
#include "expect_refused.h"

namespace ardsim_pose {
namespace {

using ardsim_description::TargetKind;

constexpr double kDeg = M_PI / 180.0;

PoseConfig hubbleConfig() {
  PoseConfig config;
  config.target = TargetKind::kHubble;
  applyTargetDefaults(&config);
  return config;
}

// One noisy frame of Hubble with its arrays at arrays_deg, port_distance_m along the docking axis.
OrganizedCloud renderHubble(double arrays_deg, double port_distance_m, std::uint64_t seed,
                            Eigen::Isometry3d* truth) {
  ardsim_lidar::LidarSimulator simulator(ardsim_lidar::SensorOptions{}, ardsim_lidar::NoiseOptions{}, 3);
  ardsim_description::HubbleOptions hubble;
  hubble.solar_array_deg = arrays_deg;
  simulator.setTarget(ardsim_description::buildHubble(hubble));
  *truth = dockingAxisPose(TargetKind::kHubble, port_distance_m);
  ardsim_lidar::LidarFrame frame;
  simulator.simulate(*truth, seed, &frame);
  return fromLidarFrame(frame, simulator.rays(), 0.0);
}

TEST(PanelFit, MeasuresTheArraysAngleAtTheTruePose) {
  const PanelJoint joint = panelJoint(TargetKind::kHubble);
  for (const double arrays_deg : {30.0, -45.0}) {
    for (const double d_m : {40.0, 25.0}) {
      SCOPED_TRACE("arrays " + std::to_string(arrays_deg) + " deg at " + std::to_string(d_m) + " m");
      Eigen::Isometry3d truth;
      const OrganizedCloud cloud = renderHubble(arrays_deg, d_m, 1, &truth);
      PanelFit fit;
      ASSERT_TRUE(fitPanelAngle(joint, cloud, truth, PanelOptions{}, &fit))
          << fit.points << " points, extent " << fit.extent_m << " m, rms " << fit.rms_m << " m";
      // One frame's fit: thousands of points on two 7 m arrays, range noise ~1 cm.
      EXPECT_NEAR(fit.angle_rad / kDeg, arrays_deg, 0.2);
      EXPECT_GT(fit.points, 1000);
      EXPECT_LT(fit.rms_m, 0.02);
    }
  }
}

TEST(PanelFit, NoFitWhereTheArraysShowNothing) {
  const PanelJoint joint = panelJoint(TargetKind::kHubble);
  PanelFit fit;
  // Edge-on from the docking axis: the arrays' 2 cm thickness, no returns across the mast axis.
  Eigen::Isometry3d truth;
  const OrganizedCloud edge_on = renderHubble(0.0, 30.0, 1, &truth);
  EXPECT_FALSE(fitPanelAngle(joint, edge_on, truth, PanelOptions{}, &fit)) << fit.angle_rad / kDeg << " deg";
  OrganizedCloud empty = edge_on;
  std::fill(empty.points.begin(), empty.points.end(),
            Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_FALSE(fitPanelAngle(joint, empty, truth, PanelOptions{}, &fit));
  EXPECT_EQ(fit.points, 0);
  const OrganizedCloud turned = renderHubble(30.0, 30.0, 1, &truth);
  // Arrays at 30 deg, the pose 3 m off across the arrays' plane region: no panel there.
  const Eigen::Isometry3d off = truth * Eigen::Translation3d(0.0, 0.0, 3.0);
  EXPECT_FALSE(fitPanelAngle(joint, turned, off, PanelOptions{}, &fit)) << fit.angle_rad / kDeg << " deg";
}

TEST(PanelTracker, BuildsTheModelAtTheMedianAndRebuildsWhenTheArraysTurn) {
  const PoseConfig config = hubbleConfig();
  const std::shared_ptr<const ReferenceModel> rigid = buildReferenceModel(TargetKind::kHubble, config.model);
  std::vector<double> built_deg;
  PanelTracker tracker(panelJoint(TargetKind::kHubble), config.panels, rigid, [&](double angle_rad) {
    built_deg.push_back(angle_rad / kDeg);
    return rigid;  // the model's content does not matter here
  });
  Eigen::Isometry3d truth;
  const auto frames = [&](double arrays_deg, int count, std::uint64_t seed) {
    for (int k = 0; k < count; ++k) {
      const OrganizedCloud cloud = renderHubble(arrays_deg, 30.0, seed + k, &truth);
      tracker.update(cloud, truth);
    }
  };
  ASSERT_LT(config.panels.first_window, config.panels.window);
  frames(30.0, config.panels.first_window - 1, 1);
  EXPECT_TRUE(built_deg.empty()) << "built before first_window fits";
  EXPECT_FALSE(tracker.modelHasPanels());
  frames(30.0, 1, 20);
  ASSERT_EQ(built_deg.size(), 1u);
  EXPECT_NEAR(built_deg[0], 30.0, 0.1);
  EXPECT_TRUE(tracker.modelHasPanels());
  frames(30.0, config.panels.window, 30);  // the same angle: the window's median stays within rebuild_deg
  EXPECT_EQ(built_deg.size(), 1u);
  frames(32.0, config.panels.window / 2 + 1, 40);  // a majority of the window at 32 deg
  ASSERT_EQ(built_deg.size(), 2u);
  EXPECT_NEAR(built_deg[1], 32.0, 0.1);
}

TEST(PanelTracker, ArraysTurnedNearlyEdgeOnLeaveTheModel) {
  PoseConfig config = hubbleConfig();
  // Arrays at 10 deg seen from the docking axis count as edge-on here (the default limit is 6 deg: the
  // fitted line is then still clean, which makes the mechanism testable).
  config.panels.min_incidence_deg = 15.0;
  const std::shared_ptr<const ReferenceModel> rigid = buildReferenceModel(TargetKind::kHubble, config.model);
  const std::shared_ptr<const ReferenceModel> with_panels =
      buildReferenceModel(TargetKind::kHubble, config.model);  // another object: which one comes back
  PanelTracker tracker(panelJoint(TargetKind::kHubble), config.panels, rigid,
                       [&](double) { return with_panels; });
  Eigen::Isometry3d truth;
  std::shared_ptr<const ReferenceModel> model;
  for (int k = 0; k < config.panels.window; ++k) {
    if (auto built = tracker.update(renderHubble(30.0, 30.0, 1 + k, &truth), truth)) model = built;
  }
  ASSERT_EQ(model, with_panels);
  EXPECT_NEAR(tracker.lastFit().incidence_deg, 30.0, 1.0);
  for (int k = 0; k < config.panels.window; ++k) {
    model = tracker.update(renderHubble(10.0, 30.0, 20 + k, &truth), truth);
    ASSERT_TRUE(tracker.lastFit().grazing) << "frame " << k << ": " << tracker.lastFit().points << " points, "
                                           << tracker.lastFit().incidence_deg << " deg";
    // Seen this obliquely the fit reads ~10.6 deg (the arrays' 4 cm edges join the surface's returns).
    EXPECT_NEAR(tracker.lastFit().angle_rad / kDeg, 10.0, 1.0);
    EXPECT_EQ(model == rigid, k == config.panels.window - 1) << "frame " << k;
  }
  EXPECT_FALSE(tracker.modelHasPanels());
}

// Hubble's arrays 30 deg from the rigid model, 30 -> 22 m along the docking axis at 0.5 m a frame (as the
// approach datasets), the estimator from the truth: beyond 20 m the end-on view shows Hubble's roll on the
// masts and the arrays. Without the arrays in the model the 20-30 m attitude RMS was 0.050-0.070 deg over
// 12 approach runs; with them 0.012-0.015. Here, frames 10-16: 0.048 deg with panels/enabled false, 0.011
// with it.
TEST(PanelTracker, ArraysTurnedFromTheModelAreMeasuredAndTracked) {
  const PoseConfig config = hubbleConfig();
  ASSERT_TRUE(config.panels.enabled);
  ardsim_description::HubbleOptions turned;
  turned.solar_array_deg = 30.0;
  AlongTheDockingAxis hubble(config, ardsim_description::buildHubble(turned), 2, 0.5);
  double sum_sq_deg = 0.0;
  int counted = 0;
  for (int k = 0; k < 17; ++k) {
    PoseErrorValue e;
    const EstimatorOutput out = hubble.frame(k, 30.0 - 0.5 * k, &e);
    ASSERT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    // ICP alone (the ring's position joins from 30 m in only where it finds the ring): the face-on bulkhead
    // leaves the lateral position weakly observed, 1-3 cm.
    EXPECT_LT(e.port_position_error_m.norm(), 0.05) << "frame " << k;
    if (k >= 10) {  // the model has the arrays from the third fitted frame on (first_window)
      sum_sq_deg += std::pow(e.attitude_error_angle_rad / kDeg, 2);
      ++counted;
    }
  }
  EXPECT_LT(std::sqrt(sum_sq_deg / counted), 0.025);
}

// Hubble with its arrays at 30 deg rendered without noise, the ports 50 -> 47.9 m apart in 0.1 m steps (the
// lidar 57.6 -> 55.5 m from Hubble's frame), through the estimator from the truth (the arrays join its model
// at the angle it measures): from 48.7 m on the arrays' edge rows (their 4 cm thickness seen obliquely)
// return ~2 cm off the model's planes, a whole pixel row at once; counted against the arrays they turned the
// estimate 0.008-0.061 deg there (icp_tracker.cpp, align: 0.004-0.006 without them).
TEST(PanelModel, EdgeRowsOfTheArraysDoNotTurnTheEstimate) {
  ardsim_lidar::NoiseOptions noise_free;
  noise_free.enabled = false;
  ardsim_description::HubbleOptions turned;
  turned.solar_array_deg = 30.0;
  AlongTheDockingAxis hubble(hubbleConfig(), ardsim_description::buildHubble(turned), 3, 0.1, noise_free);
  double worst_deg = 0.0;
  for (int k = 0; k <= 21; ++k) {
    PoseErrorValue e;
    const EstimatorOutput out = hubble.frame(k, 50.0 - 0.1 * k, &e);
    ASSERT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    if (k >= 13) worst_deg = std::max(worst_deg, e.attitude_error_angle_rad / kDeg);
  }
  EXPECT_LT(worst_deg, 0.015);
}

TEST(PanelOptionsValidation, NamesTheParameter) {
  PanelOptions options;
  options.window = 4;  // even
  expectRefused(options, "panels/window = 4");
  options.window = 9;
  options.first_window = 11;  // wider than the window
  expectRefused(options, "panels/first_window = 11");
  PoseConfig iss;
  iss.panels.enabled = true;  // the ISS's arrays turn on ten joints
  expectRefused(iss, "panels/enabled");
}

}  // namespace
}  // namespace ardsim_pose
