// The visible-point grid against the KD-tree it stands in front of: where it answers, the same nearest
// visible point and a ball that holds every visible point within its radius; and it answers most queries
// near the surface (what makes it worth building). The patches of parts that turn are flagged.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"
#include "ardsim_pose/reference_model.h"

namespace ardsim_pose {
namespace {

using ardsim_description::TargetKind;

struct GridCase {
  double port_distance_m;
  double turn_deg;   // about lidar y: the target partly out of the view
  double lateral_m;  // along lidar x
};

class VisiblePointGridCase : public ::testing::TestWithParam<GridCase> {};

TEST_P(VisiblePointGridCase, AnswersAsTheTreeDoes) {
  const GridCase c = GetParam();
  PoseConfig config;
  const std::shared_ptr<const ReferenceModel> model = buildReferenceModel(TargetKind::kIss, config.model);
  const ardsim_lidar::Intrinsics intrinsics = ardsim_lidar::intrinsicsFor(config.sensor);
  Eigen::Isometry3d T = dockingAxisPose(TargetKind::kIss, c.port_distance_m);
  T.prerotate(Eigen::AngleAxisd(c.turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  T.pretranslate(Eigen::Vector3d(c.lateral_m, 0.0, 0.0));
  VisibilityPredictor predictor(intrinsics, config.visibility);
  std::vector<std::uint8_t> visible;
  ASSERT_GT(predictor.predict(*model, T, &visible), 1000);
  VisiblePointGrid grid(intrinsics, config.visibility.margin_px);
  grid.build(*model, predictor.visiblePatches(), T, predictor.nearestDepth());

  std::vector<std::uint32_t> visible_points;
  for (std::uint32_t i = 0; i < model->size(); ++i)
    if (visible[i]) visible_points.push_back(i);
  std::mt19937 random(17);
  std::uniform_int_distribution<std::size_t> pick(0, visible_points.size() - 1);
  std::normal_distribution<float> offset(0.0f, 0.15f);
  const float gates_m[] = {0.05f, 0.3f, 0.5f, 3.0f};
  int near_surface = 0, answered_near_surface = 0;
  for (int n = 0; n < 3000; ++n) {
    // Near the visible surface (what ICP asks), or anywhere in a box around the target (stray returns).
    Eigen::Vector3f query;
    const bool near = n % 4 != 0;
    if (near) {
      query = model->points()[visible_points[pick(random)]] +
              Eigen::Vector3f(offset(random), offset(random), offset(random));
    } else {
      std::uniform_real_distribution<float> box(-30.0f, 30.0f);
      query = Eigen::Vector3f(box(random), box(random), box(random));
    }
    const float gate = gates_m[n % 4 == 0 ? 3 : n % 3];
    const float gate_sq = gate * gate;
    float tree_distance_sq = 0.0f, tree_radius = 0.0f;
    std::vector<std::uint32_t> tree_near;
    const int tree = model->nearestVisibleWithNeighbours(query, gate_sq, visible, 0.03f, &tree_distance_sq,
                                                         &tree_radius, &tree_near);
    int index = -2;
    float distance_sq = 0.0f, radius = 0.0f;
    std::vector<std::uint32_t> ball;
    const bool answered = grid.nearest(query, gate_sq, &index, &distance_sq, 0.03f, &radius, &ball);
    if (near && gate >= 0.3f) {
      ++near_surface;
      answered_near_surface += answered ? 1 : 0;
    }
    if (!answered) continue;
    ASSERT_EQ(tree < 0, index < 0) << "query " << n;
    if (tree >= 0) {
      EXPECT_EQ(tree_distance_sq, distance_sq) << "query " << n;
    }
    ASSERT_GT(radius, 0.0f);
    ASSERT_LE(radius, gate * 1.0001f);
    if (n % 10 != 0) continue;  // the brute-force ball check on a tenth
    std::vector<std::uint8_t> in_ball(model->size(), 0);
    for (std::uint32_t i : ball) in_ball[i] = 1;
    for (std::uint32_t i : visible_points) {
      if (model->distanceSq(query, i) < 0.999f * radius * radius) {
        ASSERT_TRUE(in_ball[i]) << "query " << n << ": visible point " << i << " missing from the ball";
      }
    }
  }
  EXPECT_GT(answered_near_surface, near_surface / 2)
      << answered_near_surface << " of " << near_surface << " near-surface queries answered";
}

INSTANTIATE_TEST_SUITE_P(Poses, VisiblePointGridCase,
                         ::testing::Values(GridCase{100.0, 0.0, 0.0}, GridCase{30.0, 0.0, 0.0},
                                           GridCase{10.0, 0.0, 0.0}, GridCase{30.0, 8.0, 3.0},
                                           GridCase{10.0, -12.0, -2.0}));

// Hubble's rigid model has no part that turns; with its arrays put in at an angle, exactly the arrays'
// patches (2.6 m wide about the mast axis, x = -1.5 m; 3 to 10.1 m out along y) say they are articulated.
TEST(ReferenceModelPatches, ThoseOfPartsThatTurnAreFlagged) {
  const PoseConfig config;
  const std::shared_ptr<const ReferenceModel> rigid = buildReferenceModel(TargetKind::kHubble, config.model);
  for (std::uint32_t patch = 0; patch < rigid->patches().size(); ++patch)
    ASSERT_FALSE(rigid->patchArticulated(patch));
  const std::shared_ptr<const ReferenceModel> with_arrays =
      buildReferenceModelWithPanels(TargetKind::kHubble, config.model, 30.0 * M_PI / 180.0);
  int articulated = 0;
  for (std::uint32_t k = 0; k < with_arrays->patches().size(); ++k) {
    const ReferenceModel::Patch& patch = with_arrays->patches()[k];
    const bool flagged = with_arrays->patchArticulated(k);
    for (std::uint32_t j = patch.begin; j < patch.end; ++j) {
      const Eigen::Vector3f& p = with_arrays->points()[j];
      if (std::abs(std::abs(p.y()) - 3.0f) < 0.01f) continue;  // where the masts' ends meet the arrays
      const bool on_an_array =
          std::abs(p.y()) > 3.0f && std::abs(p.y()) < 10.11f && std::hypot(p.x() + 1.5f, p.z()) < 1.31f;
      ASSERT_EQ(flagged, on_an_array) << "point (" << p.transpose() << ")";
    }
    articulated += flagged ? 1 : 0;
  }
  EXPECT_GT(articulated, 100);
}

}  // namespace
}  // namespace ardsim_pose
