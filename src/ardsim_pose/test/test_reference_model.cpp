// The visible-point grid against the KD-tree it stands in front of: where it answers, the same nearest
// visible point and a ball that holds every visible point within its radius; and it answers most queries
// near the surface (what makes it worth building). The patches of parts that turn are flagged.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"
#include "ardsim_pose/panel_angle.h"
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
  ASSERT_GT(predictor.predict(*model, T), 1000);
  const std::vector<std::uint8_t>& visible = predictor.visible();
  VisiblePointGrid grid(intrinsics, config.visibility.margin_px);
  grid.build(*model, predictor.visibleRanges(), T, predictor.nearestDepth());

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

// Hubble's model with its arrays sampled at angle_deg, and a model's arrays turned by turn_deg.
std::shared_ptr<const ReferenceModel> hubbleWithArraysAt(double angle_deg) {
  return buildReferenceModelWithPanels(TargetKind::kHubble, PoseConfig().model, angle_deg * M_PI / 180.0);
}
std::shared_ptr<const ReferenceModel> turnedArrays(const ReferenceModel& model, double turn_deg) {
  const PanelJoint joint = panelJoint(TargetKind::kHubble);
  return model.withArticulatedTurned(joint.origin, joint.axis, turn_deg * M_PI / 180.0);
}

// Whether p lies on the triangle (within tolerance_m of its plane, inside its edges).
bool onTriangle(const Eigen::Vector3f& p, const ReferenceModel::Triangle& triangle, float tolerance_m) {
  const Eigen::Vector3f e1 = triangle[1] - triangle[0], e2 = triangle[2] - triangle[0];
  const Eigen::Vector3f normal = e1.cross(e2).normalized();
  const Eigen::Vector3f d = p - triangle[0];
  if (std::abs(normal.dot(d)) > tolerance_m) return false;
  // Barycentric coordinates of p's projection.
  const float d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2), d1 = d.dot(e1), d2 = d.dot(e2);
  const float denominator = d11 * d22 - d12 * d12;
  const float s = (d22 * d1 - d12 * d2) / denominator, t = (d11 * d2 - d12 * d1) / denominator;
  constexpr float kSlack = 1e-3f;
  return s >= -kSlack && t >= -kSlack && s + t <= 1.0f + kSlack;
}

// Hubble's arrays sampled at 30 deg and turned 5 deg about their mast lie where arrays sampled at 35 deg
// do (turned the other way they do not); the rest stays where it was, and every patch's and chunk's bounds
// still hold their samples (the visibility prediction splats and culls by them), as its triangle does (the
// occluding contours read the triangles).
TEST(ReferenceModelPatches, ArticulatedPartsTurnedLieWhereSampledAtThatAngle) {
  const std::shared_ptr<const ReferenceModel> at30 = hubbleWithArraysAt(30.0);
  const std::shared_ptr<const ReferenceModel> at35 = hubbleWithArraysAt(35.0);
  const std::shared_ptr<const ReferenceModel> turned = turnedArrays(*at30, 5.0);
  const std::shared_ptr<const ReferenceModel> turned_back = turnedArrays(*at30, -5.0);
  ASSERT_EQ(turned->size(), at30->size());
  ASSERT_EQ(turned->patches().size(), at30->patches().size());
  const std::vector<std::uint8_t> all(at35->size(), 1);
  int articulated_points = 0, far_when_turned_back = 0;
  for (std::uint32_t k = 0; k < turned->patches().size(); ++k) {
    const ReferenceModel::Patch& patch = turned->patches()[k];
    const Eigen::Vector3f centre(turned->patchCentres(0)[k], turned->patchCentres(1)[k],
                                 turned->patchCentres(2)[k]);
    for (std::uint32_t j = patch.begin; j < patch.end; ++j) {
      const Eigen::Vector3f& p = turned->points()[j];
      ASSERT_LE((p - centre).norm(), turned->patchRadii()[k] + 1e-5f) << "patch " << k;
      ASSERT_TRUE(onTriangle(p, turned->triangle(turned->patchTriangle(k)), 1e-4f)) << "point " << j;
      if (!turned->patchArticulated(k)) {
        ASSERT_EQ(p, at30->points()[j]);
        continue;
      }
      ++articulated_points;
      // Within the sampling's spacing of the arrays sampled at 35 deg (the samples differ, the surface not).
      float distance_sq = 0.0f;
      ASSERT_GE(at35->nearestVisible(p, 1.0f, all, &distance_sq), 0);
      ASSERT_LT(std::sqrt(distance_sq), 0.75f * turned->spacing()[j] + 0.01f) << "point " << j;
      const float normal_dot =
          turned->normals()[j].dot(at35->normals()[at35->nearestVisible(p, 1.0f, all, &distance_sq)]);
      ASSERT_GT(std::abs(normal_dot), 0.999f);
      float back_sq = 0.0f;
      if (at35->nearestVisible(turned_back->points()[j], 1.0f, all, &back_sq) < 0 ||
          std::sqrt(back_sq) > 0.1f)
        ++far_when_turned_back;
    }
  }
  EXPECT_GT(articulated_points, 1000);
  EXPECT_GT(far_when_turned_back, articulated_points / 2);
  for (const ReferenceModel::Chunk& chunk : turned->chunks()) {
    for (std::uint32_t k = chunk.begin; k < chunk.end; ++k) {
      const ReferenceModel::Patch& patch = turned->patches()[k];
      for (std::uint32_t j = patch.begin; j < patch.end; ++j)
        ASSERT_LE((turned->points()[j] - chunk.centre).norm(), chunk.radius + 1e-5f);
    }
  }
}

// A turned model's searches (its trees built where the points were sampled, queries turned there) find
// what a search of every turned point finds: the same nearest visible point at the same distance, and
// anyWithin agrees; turned twice is turned once by the sum.
TEST(ReferenceModelPatches, TurnedModelsSearchesFindTheNearestTurnedPoint) {
  const std::shared_ptr<const ReferenceModel> sampled = hubbleWithArraysAt(30.0);
  const std::shared_ptr<const ReferenceModel> once = turnedArrays(*sampled, 2.0);
  const std::shared_ptr<const ReferenceModel> twice = turnedArrays(*once, 3.0);
  const std::shared_ptr<const ReferenceModel> at_sum = turnedArrays(*sampled, 5.0);
  for (std::size_t j = 0; j < twice->size(); ++j)
    ASSERT_LT((twice->points()[j] - at_sum->points()[j]).norm(), 1e-5f);
  // A turn into the memory of a turned model gone is the same turn.
  turnedArrays(*sampled, -7.0).reset();
  const std::shared_ptr<const ReferenceModel> reusing = turnedArrays(*sampled, 5.0);
  ASSERT_EQ(reusing->points(), at_sum->points());
  ASSERT_EQ(reusing->normals(), at_sum->normals());
  ASSERT_TRUE((reusing->patchRadii() == at_sum->patchRadii()).all());
  ASSERT_TRUE((reusing->patchNormals(2) == at_sum->patchNormals(2)).all());

  std::mt19937 random(7);
  std::uniform_int_distribution<std::size_t> pick(0, twice->size() - 1);
  std::normal_distribution<float> offset(0.0f, 0.05f);
  std::bernoulli_distribution coin(0.7);
  std::vector<std::uint8_t> visible(twice->size());
  for (auto& v : visible) v = coin(random) ? 1 : 0;
  const float gate_sq = 0.2f * 0.2f;
  int found_articulated = 0;
  for (int n = 0; n < 2000; ++n) {
    const Eigen::Vector3f query =
        twice->points()[pick(random)] + Eigen::Vector3f(offset(random), offset(random), offset(random));
    int expected = -1;
    float expected_sq = gate_sq;
    float nearest_any_sq = gate_sq;  // visible or not
    for (std::size_t j = 0; j < twice->size(); ++j) {
      const float d = twice->distanceSq(query, static_cast<std::uint32_t>(j));
      nearest_any_sq = std::min(nearest_any_sq, d);
      if (visible[j] && d < expected_sq) {
        expected_sq = d;
        expected = static_cast<int>(j);
      }
    }
    EXPECT_TRUE(twice->anyWithin(query, nearest_any_sq));
    EXPECT_FALSE(twice->anyWithin(query, 0.99f * nearest_any_sq));
    float distance_sq = 0.0f;
    const int found = twice->nearestVisible(query, gate_sq, visible, &distance_sq);
    ASSERT_EQ(found, expected) << "query " << n;
    if (found < 0) continue;
    ASSERT_EQ(distance_sq, expected_sq);
    float radius_m = 0.0f;
    std::vector<std::uint32_t> near;
    ASSERT_EQ(
        twice->nearestVisibleWithNeighbours(query, gate_sq, visible, 0.02f, &distance_sq, &radius_m, &near),
        expected);
    ASSERT_NE(std::find(near.begin(), near.end(), static_cast<std::uint32_t>(expected)), near.end());
    const std::uint32_t patch_of_found = static_cast<std::uint32_t>(
        std::upper_bound(twice->patches().begin(), twice->patches().end(), static_cast<std::uint32_t>(found),
                         [](std::uint32_t i, const ReferenceModel::Patch& p) { return i < p.end; }) -
        twice->patches().begin());
    if (twice->patchArticulated(patch_of_found)) ++found_articulated;
  }
  EXPECT_GT(found_articulated, 200);
}

}  // namespace
}  // namespace ardsim_pose
