#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/close_range/mode_manager.h"

namespace ardsim_pose {
namespace close_range {
namespace {

// Counts the switches along a range profile, fill 1 (the adapter fills the view at close range).
int countSwitches(ModeManager& manager, const std::vector<double>& ranges,
                  std::vector<EstimateMethod>* methods) {
  int switches = 0;
  for (double range : ranges) {
    const ModeManager::Decision d = manager.update(range, 1.0);
    switches += d.switched ? 1 : 0;
    methods->push_back(d.method);
  }
  return switches;
}

TEST(ModeManager, SwitchesOnceOnApproachAndBackWhenTheRangeOpens) {
  ModeManager manager;
  // Approach from 20 m to contact with 5 cm of range noise on the estimate, then open back out to 20 m.
  std::vector<double> approach, retreat;
  for (int k = 0; k <= 400; ++k) approach.push_back(21.0 - 0.05 * k + 0.05 * ((k % 3) - 1));
  for (int k = 0; k <= 400; ++k) retreat.push_back(1.0 + 0.05 * k + 0.05 * ((k % 3) - 1));
  std::vector<EstimateMethod> methods;
  EXPECT_EQ(countSwitches(manager, approach, &methods), 1);
  EXPECT_EQ(methods.front(), EstimateMethod::kIcp);
  EXPECT_EQ(methods.back(), EstimateMethod::kRing);
  methods.clear();
  EXPECT_EQ(countSwitches(manager, retreat, &methods), 1);
  EXPECT_EQ(methods.back(), EstimateMethod::kIcp);
}

TEST(ModeManager, DoesNotOscillateBetweenTheThresholds) {
  const ModeManagerOptions options;
  ModeManager manager(options);
  std::vector<double> ranges;
  // Hovering around each threshold with +-0.5 m of noise: one switch in, none out.
  for (int k = 0; k < 200; ++k) ranges.push_back(options.close_enter_range_m + ((k % 2) ? 0.5 : -0.5));
  for (int k = 0; k < 200; ++k) ranges.push_back(options.close_exit_range_m - ((k % 2) ? 0.4 : 0.0));
  std::vector<EstimateMethod> methods;
  EXPECT_EQ(countSwitches(manager, ranges, &methods), 1);
}

TEST(ModeManager, NeedsTheTargetToFillTheView) {
  ModeManager manager;
  EXPECT_EQ(manager.update(6.0, 0.2).method, EstimateMethod::kIcp);
  EXPECT_EQ(manager.update(6.0, 0.9).method, EstimateMethod::kRing);
}

TEST(ModeManager, BlendsOverTheConfiguredFrames) {
  ModeManagerOptions options;
  options.blend_frames = 4;
  options.close_method = EstimateMethod::kPyramid;
  ModeManager manager(options);
  EXPECT_FALSE(manager.update(12.0, 1.0).blending());
  const ModeManager::Decision first = manager.update(7.0, 1.0);
  EXPECT_TRUE(first.switched);
  EXPECT_EQ(first.method, EstimateMethod::kPyramid);
  EXPECT_EQ(first.previous, EstimateMethod::kIcp);
  EXPECT_DOUBLE_EQ(first.weight, 0.25);
  EXPECT_DOUBLE_EQ(manager.update(7.0, 1.0).weight, 0.5);
  EXPECT_DOUBLE_EQ(manager.update(7.0, 1.0).weight, 0.75);
  const ModeManager::Decision last = manager.update(7.0, 1.0);
  EXPECT_DOUBLE_EQ(last.weight, 1.0);
  EXPECT_FALSE(last.blending());
}

TEST(ModeManager, LeavesCloseRangeWhenLostBeyondTheEntryRange) {
  ModeManager manager(ModeManagerOptions{}, EstimateMethod::kRing);
  EXPECT_EQ(manager.update(13.0, 1.0, true).method, EstimateMethod::kRing);
  EXPECT_EQ(manager.update(13.0, 1.0, true).method, EstimateMethod::kRing);
  EXPECT_EQ(manager.update(13.0, 1.0, true).method, EstimateMethod::kIcp);
  // Lost near the port: stay (ICP cannot do better there); the facade reports LOST.
  ModeManager near(ModeManagerOptions{}, EstimateMethod::kRing);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(near.update(3.0, 1.0, true).method, EstimateMethod::kRing);
}

TEST(ModeManager, RejectsBadOptions) {
  ModeManagerOptions options;
  options.close_exit_range_m = 7.0;  // below the entry range: no hysteresis
  EXPECT_THROW(validate(options), std::invalid_argument);
  options = ModeManagerOptions();
  options.close_method = EstimateMethod::kIcp;
  EXPECT_THROW(ModeManager{options}, std::invalid_argument);
}

TEST(ModeManager, BlendPosesInterpolates) {
  const Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d b =
      Eigen::Translation3d(1.0, 2.0, 3.0) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ());
  const Eigen::Isometry3d half = blendPoses(a, b, 0.5);
  EXPECT_NEAR((half.translation() - Eigen::Vector3d(0.5, 1.0, 1.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(half.linear()).angle(), 0.1, 1e-12);
  EXPECT_TRUE(blendPoses(a, b, 1.0).isApprox(b, 1e-12));
}

}  // namespace
}  // namespace close_range
}  // namespace ardsim_pose
