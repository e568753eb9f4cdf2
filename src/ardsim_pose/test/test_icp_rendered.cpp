// ICP on frames rendered in-process by the lidar core: acquisition from the coarse prior at 100, 30 and 10 m
// with and without noise, within a few frames, to the accuracy goals, never a wrong pose as TRACKING;
// solar arrays turned away from the model, and filling the view at 250 m; LOST (not a wrong pose) on an empty
// frame, a garbage frame and a frame of another object; the benchmark's 0.2 m-off guesses at 30 m corrected
// along a weakly observed direction, with and without the sparse start; an acquisition whose iterations
// cycle between two poses converging; a bag played again (time going back) estimated as the first time.
// Hubble's rendered cases are in test_icp_rendered_hubble.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <utility>
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

class RenderedIcp : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    iss_model_ = buildReferenceModel(TargetKind::kIss, ReferenceModelOptions{});
  }
  static void TearDownTestSuite() { iss_model_.reset(); }

  // Renders `frames` frames closing at 0.1 m/s from port distance d_m and runs the estimator from the prior.
  // Returns the errors of the last frame; *statuses (and *errors) collect every frame's.
  PoseErrorValue track(const ardsim_description::TriangleMesh& mesh, double d_m, bool noise, int frames,
                       const Eigen::Isometry3d& prior, std::vector<EstimateStatus>* statuses,
                       std::string* last_reason = nullptr, std::vector<PoseErrorValue>* errors = nullptr) {
    ardsim_lidar::NoiseOptions noise_options;
    noise_options.enabled = noise;
    ardsim_lidar::LidarSimulator simulator(ardsim_lidar::SensorOptions{}, noise_options, 7);
    simulator.setTarget(mesh);
    std::unique_ptr<PoseEstimator> estimator = makeEstimator(PoseConfig{}, iss_model_);
    estimator->setPrior(prior);
    PoseErrorValue error;
    ardsim_lidar::LidarFrame frame;
    for (int k = 0; k < frames; ++k) {
      const Eigen::Isometry3d truth = dockingAxisPose(TargetKind::kIss, d_m - 0.01 * k);
      simulator.simulate(truth, static_cast<std::uint64_t>(k), &frame);
      const EstimatorOutput out = estimator->process(fromLidarFrame(frame, simulator.rays(), 0.1 * k));
      statuses->push_back(out.result.status);
      if (last_reason) *last_reason = out.result.reason;
      error =
          poseError(out.result.T_lidar_target, truth, ardsim_description::T_target_port(TargetKind::kIss));
      if (errors) errors->push_back(error);
    }
    return error;
  }

  // n noise-free ISS frames of the default sensor closing 1 cm a frame from port distance d_m, with their
  // truths (the benchmark's frames).
  static void renderClosing(double d_m, int n, std::vector<OrganizedCloud>* clouds,
                            std::vector<Eigen::Isometry3d>* truths) {
    ardsim_lidar::LidarSimulator simulator(ardsim_lidar::SensorOptions{}, ardsim_lidar::NoiseOptions{}, 7);
    simulator.setTarget(ardsim_description::buildIss());
    ardsim_lidar::LidarFrame frame;
    for (int k = 0; k < n; ++k) {
      truths->push_back(dockingAxisPose(TargetKind::kIss, d_m - 0.01 * k));
      simulator.simulate(truths->back(), static_cast<std::uint64_t>(k), &frame);
      clouds->push_back(fromLidarFrame(frame, simulator.rays(), 0.1 * k));
    }
  }

  static std::shared_ptr<const ReferenceModel> iss_model_;
};
std::shared_ptr<const ReferenceModel> RenderedIcp::iss_model_;

struct Case {
  double port_distance_m;
  bool noise;
  double position_goal_m;
  double attitude_goal_deg;
};

const PriorPerturbation kCoarse{10.0, 0.1, 2.0};  // the coarse prior
const int kFrames = 6;
const int kFramesToTrack = 3;  // "within a few frames": TRACKING by the third frame

class Acquisition : public RenderedIcp, public ::testing::WithParamInterface<Case> {};

// Seed 1 at 100 m is the case that used to settle a truss bay off (1.7 m, a perfect local fit) and was
// reported TRACKING.
TEST_P(Acquisition, ConvergesFromTheCoarsePriorToTheGoals) {
  const Case c = GetParam();
  const Eigen::Isometry3d truth0 = dockingAxisPose(TargetKind::kIss, c.port_distance_m);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Eigen::Isometry3d prior =
        perturbPrior(truth0, ardsim_description::T_target_port(TargetKind::kIss), kCoarse, seed);
    std::vector<EstimateStatus> statuses;
    std::vector<PoseErrorValue> errors;
    std::string reason;
    track(ardsim_description::buildIss(), c.port_distance_m, c.noise, kFrames, prior, &statuses, &reason,
          &errors);
    SCOPED_TRACE("seed " + std::to_string(seed));
    EXPECT_EQ(statuses.back(), EstimateStatus::kTracking) << reason;
    const auto first_tracking = std::find(statuses.begin(), statuses.end(), EstimateStatus::kTracking);
    EXPECT_LT(first_tracking - statuses.begin(), kFramesToTrack);
    for (std::size_t k = 0; k < statuses.size(); ++k) {
      SCOPED_TRACE("frame " + std::to_string(k));
      EXPECT_NE(statuses[k], EstimateStatus::kLost);
      // Never a wrong pose reported as TRACKING.
      if (statuses[k] != EstimateStatus::kTracking) continue;
      EXPECT_LT(errors[k].port_position_error_m.norm(), c.position_goal_m);
      EXPECT_LT(errors[k].attitude_error_angle_rad * 180.0 / M_PI, c.attitude_goal_deg);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Ranges, Acquisition,
                         ::testing::Values(Case{99.0, false, 0.05, 0.1}, Case{99.0, true, 0.05, 0.1},
                                           Case{29.0, false, 0.02, 0.05}, Case{29.0, true, 0.02, 0.05},
                                           Case{9.0, false, 0.02, 0.05}, Case{9.0, true, 0.02, 0.05}));

// Tracking frames take a visibility prediction made within icp/crop_reuse_px (2) of their prediction: at 59
// m, closing 1 cm a frame, one serves several frames. The estimates stay those of exact predictions, within
// the noise (a crop a pixel off changes a few edge points) and the goals.
TEST_F(RenderedIcp, ReusedVisibilityPredictionsKeepTheEstimates) {
  ardsim_lidar::LidarSimulator simulator(ardsim_lidar::SensorOptions{}, ardsim_lidar::NoiseOptions{}, 7);
  simulator.setTarget(ardsim_description::buildIss());
  PoseConfig exact;
  exact.icp.crop_reuse_px = 0.0;
  std::unique_ptr<PoseEstimator> reusing = makeEstimator(PoseConfig{}, iss_model_);
  std::unique_ptr<PoseEstimator> predicting = makeEstimator(exact, iss_model_);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kIss);
  reusing->setPrior(dockingAxisPose(TargetKind::kIss, 59.0));
  predicting->setPrior(dockingAxisPose(TargetKind::kIss, 59.0));
  ardsim_lidar::LidarFrame frame;
  for (int k = 0; k < 30; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const Eigen::Isometry3d truth = dockingAxisPose(TargetKind::kIss, 59.0 - 0.01 * k);
    simulator.simulate(truth, static_cast<std::uint64_t>(k), &frame);
    const OrganizedCloud cloud = fromLidarFrame(frame, simulator.rays(), 0.1 * k);
    const PoseResult a = reusing->process(cloud).result;
    const PoseResult b = predicting->process(cloud).result;
    ASSERT_EQ(a.status, EstimateStatus::kTracking) << a.reason;
    ASSERT_EQ(b.status, EstimateStatus::kTracking) << b.reason;
    const PoseErrorValue difference = poseError(a.T_lidar_target, b.T_lidar_target, T_target_port);
    EXPECT_LT(difference.port_position_error_m.norm(), 0.005);
    EXPECT_LT(difference.attitude_error_angle_rad * 180.0 / M_PI, 0.02);
    const PoseErrorValue error = poseError(a.T_lidar_target, truth, T_target_port);
    EXPECT_LT(error.port_position_error_m.norm(), 0.05);
    EXPECT_LT(error.attitude_error_angle_rad * 180.0 / M_PI, 0.1);
  }
}

// An acquisition at 9 m from the truth with 5000 scan points: nearest neighbours traded places between two
// poses 1.2e-5 rad apart (just over converged_rotation_rad) for all 40 iterations, so the frame was DEGRADED
// "not converged" and every next frame acquired again (~1 s each). A 2-cycle now ends at its midpoint.
TEST_F(RenderedIcp, AcquisitionThatCyclesBetweenTwoPosesConverges) {
  std::vector<OrganizedCloud> clouds;
  std::vector<Eigen::Isometry3d> truths;
  renderClosing(9.0, 1, &clouds, &truths);
  PoseConfig config;
  config.icp.max_points = 5000;
  IcpTracker tracker(iss_model_, ardsim_lidar::intrinsicsFor(config.sensor), config.icp, config.visibility);
  const PoseResult result = tracker.estimate(clouds[0], truths[0]);
  EXPECT_EQ(result.status, EstimateStatus::kTracking) << result.reason;
  EXPECT_LT(result.iterations, config.icp.max_iterations_acquisition);
  EXPECT_FALSE(tracker.acquiring());
  const PoseErrorValue error =
      poseError(result.T_lidar_target, truths[0], ardsim_description::T_target_port(TargetKind::kIss));
  EXPECT_LT(error.port_position_error_m.norm(), 0.005);
  EXPECT_LT(error.attitude_error_angle_rad * 180.0 / M_PI, 0.02);
}

// At 249 m the arrays and radiators (not in the rigid model) fill most of the view: before the scan was gated
// to the model's silhouette, every frame there was LOST (inlier fraction 0.15).
TEST_F(RenderedIcp, SolarArraysTurnedFromTheModelDoNotMatter) {
  ardsim_description::IssOptions turned;
  turned.sarj_port_deg = 30.0;
  turned.sarj_starboard_deg = 30.0;
  for (const ardsim_description::IssOptions& arrays : {ardsim_description::IssOptions{}, turned}) {
    for (double d : {249.0, 99.0, 29.0}) {
      std::vector<EstimateStatus> statuses;
      const Eigen::Isometry3d truth0 = dockingAxisPose(TargetKind::kIss, d);
      std::string reason;
      const PoseErrorValue e =
          track(ardsim_description::buildIss(arrays), d, true, 5, truth0, &statuses, &reason);
      for (EstimateStatus status : statuses)
        EXPECT_NE(status, EstimateStatus::kLost) << d << " m: " << reason;
      EXPECT_EQ(statuses.back(), EstimateStatus::kTracking) << d << " m: " << reason;
      EXPECT_LT(e.port_position_error_m.norm(), d > 50 ? 0.05 : 0.02) << d << " m";
      EXPECT_LT(e.attitude_error_angle_rad * 180.0 / M_PI, d > 50 ? 0.1 : 0.05) << d << " m";
    }
  }
}

class LostFrames : public RenderedIcp {
 protected:
  EstimatorOutput runOne(const OrganizedCloud& cloud) {
    std::unique_ptr<PoseEstimator> estimator = makeEstimator(PoseConfig{}, iss_model_);
    estimator->setPrior(dockingAxisPose(TargetKind::kIss, 29.0));
    return estimator->process(cloud);
  }
  OrganizedCloud nanCloud() {
    OrganizedCloud cloud;
    cloud.width = 256;
    cloud.height = 256;
    cloud.points.assign(256 * 256, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
    return cloud;
  }
};

TEST_F(LostFrames, EmptyFrameIsLost) {
  const EstimatorOutput out = runOne(nanCloud());
  EXPECT_EQ(out.result.status, EstimateStatus::kLost);
  EXPECT_NE(out.result.reason.find("empty"), std::string::npos) << out.result.reason;
  OrganizedCloud no_points;
  EXPECT_EQ(runOne(no_points).result.status, EstimateStatus::kLost);
}

TEST_F(LostFrames, GarbageFrameIsLost) {
  ardsim_lidar::PixelRays rays(ardsim_lidar::intrinsicsFor(ardsim_lidar::SensorOptions{}));
  OrganizedCloud cloud = nanCloud();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> range(5.0f, 60.0f);
  std::bernoulli_distribution hit(0.3);
  for (int i = 0; i < rays.size(); ++i)
    if (hit(rng)) cloud.points[i] = range(rng) * rays.ray(i);
  const EstimatorOutput out = runOne(cloud);
  EXPECT_EQ(out.result.status, EstimateStatus::kLost) << out.result.reason;
}

TEST_F(LostFrames, AnotherObjectIsLost) {
  // Hubble seen where the ISS tracker expects the ISS port, at several ranges.
  ardsim_lidar::LidarSimulator simulator(ardsim_lidar::SensorOptions{}, ardsim_lidar::NoiseOptions{}, 7);
  simulator.setTarget(ardsim_description::buildHubble());
  ardsim_lidar::LidarFrame frame;
  for (double d : {9.0, 29.0, 49.0}) {
    simulator.simulate(dockingAxisPose(TargetKind::kHubble, d), 0, &frame);
    std::unique_ptr<PoseEstimator> estimator = makeEstimator(PoseConfig{}, iss_model_);
    estimator->setPrior(dockingAxisPose(TargetKind::kIss, d));
    const EstimatorOutput out = estimator->process(fromLidarFrame(frame, simulator.rays(), 0.0));
    EXPECT_EQ(out.result.status, EstimateStatus::kLost) << d << " m: " << out.result.reason;
  }
}

// A tracking frame whose prediction is beyond the tracking gate (1 m a frame along the boresight, no velocity
// yet: the second frame of a dataset at 10 m/s) is searched for again in the same frame: DEGRADED while
// acquiring, within the 100 m goals, where it was LOST before (session 34). A frame of garbage or of another
// object while tracking still ends LOST after that search, never a pose.
// An ISS tracker of config on noisy frames rendered by one simulator (seed 7), frame k stamped k x 0.1 s.
struct RenderedIssTracker {
  explicit RenderedIssTracker(const PoseConfig& config_in,
                              std::shared_ptr<const ReferenceModel> model = nullptr)
      : config(config_in),
        tracker(model ? model : buildReferenceModel(TargetKind::kIss, config.model),
                ardsim_lidar::intrinsicsFor(config.sensor), config.icp, config.visibility) {
    simulator.setTarget(ardsim_description::buildIss());
  }
  OrganizedCloud render(const Eigen::Isometry3d& truth, int k) {
    simulator.simulate(truth, static_cast<std::uint64_t>(k), &frame);
    return fromLidarFrame(frame, simulator.rays(), 0.1 * k);
  }
  PoseConfig config;  // first: the members below are made from it
  ardsim_lidar::LidarSimulator simulator{config.sensor, ardsim_lidar::NoiseOptions{}, 7};
  IcpTracker tracker;
  ardsim_lidar::LidarFrame frame;
};

class TrackingFallsBack : public LostFrames {
 protected:
  // An ISS tracker brought to TRACKING on a noisy frame at port distance 99 m (from the truth).
  void SetUp() override {
    const Eigen::Isometry3d first_truth = dockingAxisPose(TargetKind::kIss, 99.0);
    const PoseResult first = iss_.tracker.estimate(iss_.render(first_truth, 0), first_truth);
    ASSERT_EQ(first.status, EstimateStatus::kTracking) << first.reason;
    first_estimate_ = first.T_lidar_target;
  }
  RenderedIssTracker iss_{PoseConfig{}, iss_model_};
  Eigen::Isometry3d first_estimate_;
};

TEST_F(TrackingFallsBack, PredictionBeyondTheGateIsSearchedForInTheFrame) {
  const Eigen::Isometry3d truth = dockingAxisPose(TargetKind::kIss, 98.0);
  const PoseResult result = iss_.tracker.estimate(iss_.render(truth, 1), first_estimate_);
  EXPECT_EQ(result.status, EstimateStatus::kDegraded) << result.reason;
  EXPECT_TRUE(result.acquiring);
  EXPECT_NE(result.reason.find("tracking lost (too few correspondences"), std::string::npos) << result.reason;
  const PoseErrorValue e =
      poseError(result.T_lidar_target, truth, ardsim_description::T_target_port(TargetKind::kIss));
  EXPECT_LT(e.port_position_error_m.norm(), 0.05);
  EXPECT_LT(e.attitude_error_angle_rad * 180.0 / M_PI, 0.1);
}

TEST_F(TrackingFallsBack, GarbageWhileTrackingIsLost) {
  ardsim_lidar::PixelRays rays(ardsim_lidar::intrinsicsFor(iss_.config.sensor));
  OrganizedCloud cloud = nanCloud();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> range(90.0f, 130.0f);  // around the target: the gate finds points
  std::bernoulli_distribution hit(0.3);
  for (int i = 0; i < rays.size(); ++i)
    if (hit(rng)) cloud.points[i] = range(rng) * rays.ray(i);
  cloud.stamp_s = 0.1;
  const PoseResult result = iss_.tracker.estimate(cloud, first_estimate_);
  EXPECT_EQ(result.status, EstimateStatus::kLost) << result.reason;
  EXPECT_NE(result.reason.find("searched again"), std::string::npos) << result.reason;
}

TEST_F(TrackingFallsBack, AnotherObjectWhileTrackingIsLost) {
  iss_.simulator.setTarget(ardsim_description::buildHubble());
  const PoseResult result =
      iss_.tracker.estimate(iss_.render(dockingAxisPose(TargetKind::kHubble, 99.0), 1), first_estimate_);
  EXPECT_EQ(result.status, EstimateStatus::kLost) << result.reason;
  EXPECT_NE(result.reason.find("searched again"), std::string::npos) << result.reason;
}

// An ISS tracker with the roll prior as tight as after a long track (0.01 deg), on noisy frames closing 2 cm
// a 0.1 s frame from port distance 29 m.
struct TightRollPriorAt29m {
  explicit TightRollPriorAt29m(bool prior_when_observed) : iss(tightRollPrior(prior_when_observed)) {}
  static PoseConfig tightRollPrior(bool prior_when_observed) {
    PoseConfig config;
    config.icp.boresight_prior_deg = 0.01;
    config.icp.boresight_prior_when_observed = prior_when_observed;
    return config;
  }
  Eigen::Isometry3d truth(int k) const { return dockingAxisPose(TargetKind::kIss, 29.0 - 0.02 * k); }
  PoseResult track(int k, const Eigen::Isometry3d& predicted) {
    return iss.tracker.estimate(iss.render(truth(k), k), predicted);
  }
  RenderedIssTracker iss;
};

// ICP's covariance takes in the roll prior where the last iteration took it: a roll averaged over frames is
// known to about the prior's sigma (the composite pose takes ICP's roll by it).
TEST(IssTracking, CovarianceTakesInTheRollPrior) {
  auto rollSigmaDeg = [](bool prior_when_observed) {
    TightRollPriorAt29m iss(prior_when_observed);
    PoseResult result;
    for (int k = 0; k < 2; ++k) {
      result = iss.track(k, iss.truth(k));
      EXPECT_EQ(result.status, EstimateStatus::kTracking) << "frame " << k << ": " << result.reason;
    }
    EXPECT_TRUE(result.boresight_rotation_observed);
    return std::sqrt(result.covariance(5, 5)) * 180.0 / M_PI;
  };
  const double fused_deg = rollSigmaDeg(true), scan_deg = rollSigmaDeg(false);
  EXPECT_LT(fused_deg, 0.01);
  EXPECT_LT(fused_deg, scan_deg);
  std::printf("roll sigma at 29 m: with the prior %.4f deg, the scan's alone %.4f deg\n", fused_deg,
              scan_deg);
}

// ... but not where the scan's own roll disagrees with the prediction's beyond 3 sigma (both combined): a
// prediction turned 0.5 deg about the boresight (a change of rate; the benchmark's guesses) is not followed.
TEST(IssTracking, BoresightPriorDoesNotFollowAPredictionOffInRoll) {
  TightRollPriorAt29m iss(true);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kIss);
  for (int k = 0; k < 3; ++k) {
    Eigen::Isometry3d predicted = iss.truth(k);
    if (k == 2)
      predicted.linear() =
          Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * predicted.linear();
    const PoseResult result = iss.track(k, predicted);
    ASSERT_EQ(result.status, EstimateStatus::kTracking) << "frame " << k << ": " << result.reason;
    // The third frame within the 30 m goal (measured 0.023 deg; following the prediction: 0.40).
    const PoseErrorValue e = poseError(result.T_lidar_target, iss.truth(k), T_target_port);
    EXPECT_LT(e.attitude_error_angle_rad * 180.0 / M_PI, 0.05) << "frame " << k;
  }
}

// Hubble's aft bulkhead seen face-on says nothing about sliding across it through the plane residuals; the
// weak directions take their step from the offsets past its rim and the soft-capture mechanism's edges. The
// tracker, tracking, is given predictions 0.15 m off across the boresight: it must come back to within 5 cm
// (measured 1.8-3.7 cm; point-to-plane alone stayed 0.08-0.58 m off, once reported TRACKING at 0.15 m) and
// never report TRACKING beyond the 2 cm goal.
// The benchmark's frames at 30 m (bench_pose_icp): tracking, each frame from the truth turned 0.5 deg and
// moved 0.2 m across the line of sight. The view (the docking adapter on Harmony's end) has a weakly observed
// direction: with the tangential offsets alone there, one of these frames stopped 6.6 cm short after the 15
// iterations (DEGRADED); with the plane fit's own step combined, every frame ends within millimetres.
TEST_F(RenderedIcp, WeakDirectionFromAGuessOffAcrossTheLineOfSight) {
  PoseConfig config;
  IcpTracker tracker(iss_model_, ardsim_lidar::intrinsicsFor(config.sensor), config.icp, config.visibility);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kIss);
  std::vector<OrganizedCloud> clouds;
  std::vector<Eigen::Isometry3d> truths;
  renderClosing(29.0, 8, &clouds, &truths);
  ASSERT_EQ(tracker.estimate(clouds[0], truths[0]).status, EstimateStatus::kTracking);
  for (int k = 0; k < 8; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const Eigen::Isometry3d guess =
        perturbPrior(truths[k], T_target_port, PriorPerturbation{0.5, 0.0, 0.2}, 100 + k);
    const PoseResult result = tracker.estimate(clouds[k], guess);
    EXPECT_EQ(result.status, EstimateStatus::kTracking) << result.reason;
    const PoseErrorValue e = poseError(result.T_lidar_target, truths[k], T_target_port);
    EXPECT_LT(e.port_position_error_m.norm(), 0.01);
  }
}

// The sparse start (icp/sparse_start_residual_m): from the benchmark's 0.2 m-off guesses at 30 m the first
// coarse step comes from every 9th point, and the estimates stay those without it (within the convergence
// thresholds' reach) and within the goals; from good predictions (the frame before's pose, 1 cm off) it does
// not start sparse, and the estimates are those without it to the bit.
TEST_F(RenderedIcp, SparseStartKeepsTheEstimates) {
  PoseConfig sparse;
  PoseConfig dense;
  dense.icp.sparse_start_residual_m = 0.0;
  ASSERT_GT(sparse.icp.sparse_start_residual_m, 0.0);
  const ardsim_lidar::Intrinsics intrinsics = ardsim_lidar::intrinsicsFor(sparse.sensor);
  IcpTracker with(iss_model_, intrinsics, sparse.icp, sparse.visibility);
  IcpTracker without(iss_model_, intrinsics, dense.icp, dense.visibility);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kIss);
  std::vector<OrganizedCloud> clouds;
  std::vector<Eigen::Isometry3d> truths;
  renderClosing(29.0, 8, &clouds, &truths);
  // Both trackers into tracking from the truth.
  const auto startTracking = [&] {
    for (IcpTracker* tracker : {&with, &without}) {
      tracker->reset();
      ASSERT_EQ(tracker->estimate(clouds[0], truths[0]).status, EstimateStatus::kTracking);
    }
  };
  ASSERT_NO_FATAL_FAILURE(startTracking());
  std::vector<int> iterations_with, iterations_without;
  for (int k = 0; k < 8; ++k) {
    SCOPED_TRACE("off, frame " + std::to_string(k));
    const Eigen::Isometry3d guess =
        perturbPrior(truths[k], T_target_port, PriorPerturbation{0.5, 0.0, 0.2}, 100 + k);
    const PoseResult a = with.estimate(clouds[k], guess);
    const PoseResult b = without.estimate(clouds[k], guess);
    EXPECT_EQ(a.status, EstimateStatus::kTracking) << a.reason;
    EXPECT_EQ(b.status, EstimateStatus::kTracking) << b.reason;
    iterations_with.push_back(a.iterations);
    iterations_without.push_back(b.iterations);
    const PoseErrorValue difference = poseError(a.T_lidar_target, b.T_lidar_target, T_target_port);
    EXPECT_LT(difference.port_position_error_m.norm(), 0.001);
    EXPECT_LT(difference.attitude_error_angle_rad * 180.0 / M_PI, 0.005);
    const PoseErrorValue error = poseError(a.T_lidar_target, truths[k], T_target_port);
    EXPECT_LT(error.port_position_error_m.norm(), 0.02);
    EXPECT_LT(error.attitude_error_angle_rad * 180.0 / M_PI, 0.05);
  }
  // It did start sparse: the frames' iterations differ (in the benchmark's frames 7.8 against 8.6 on average
  // until session 33; since its crop leaves out the walls seen too obliquely, these eight frames' sums
  // happen to be equal, 59 each).
  EXPECT_NE(iterations_with, iterations_without);
  // Again: the frames above left the two trackers' motion and crops apart.
  ASSERT_NO_FATAL_FAILURE(startTracking());
  Eigen::Isometry3d previous_with = truths[0], previous_without = truths[0];
  for (int k = 1; k < 8; ++k) {
    SCOPED_TRACE("good, frame " + std::to_string(k));
    const PoseResult a = with.estimate(clouds[k], previous_with);
    const PoseResult b = without.estimate(clouds[k], previous_without);
    EXPECT_EQ(a.status, EstimateStatus::kTracking) << a.reason;
    EXPECT_TRUE(a.T_lidar_target.matrix() == b.T_lidar_target.matrix());
    EXPECT_EQ(a.iterations, b.iterations);
    previous_with = a.T_lidar_target;
    previous_without = b.T_lidar_target;
  }
}

// The last frames of an approach along the ISS docking axis (0.5 m a frame, as approach_poses --from 99 --to
// 6
// --frames 187 and render_dataset --seed 1 make them), frames 177-186 (port 11.5 -> 7 m), ICP from the truth
// at the first: inside 10 m the view is the near-symmetric docking adapter and the rotation about the
// boresight is barely observed.
struct CloseApproachFrame {
  int k;
  EstimateStatus status;
  std::string reason;
  double position_m;  // port position error
  double attitude_deg;
};
std::vector<CloseApproachFrame> issCloseApproach() {
  PoseConfig config;
  ardsim_lidar::LidarSimulator simulator(config.sensor, ardsim_lidar::NoiseOptions{}, 1);
  simulator.setTarget(ardsim_description::buildIss());
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(config);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(TargetKind::kIss);
  ardsim_lidar::LidarFrame frame;
  std::vector<CloseApproachFrame> frames;
  for (int k = 177; k <= 186; ++k) {
    const Eigen::Isometry3d truth = dockingAxisPose(TargetKind::kIss, 99.0 - 0.5 * k);
    if (k == 177) estimator->setPrior(truth);
    simulator.simulate(truth, static_cast<std::uint64_t>(k), &frame);
    const EstimatorOutput out = estimator->process(fromLidarFrame(frame, simulator.rays(), 0.1 * (k - 177)));
    const PoseErrorValue e = poseError(out.result.T_lidar_target, truth, T_target_port);
    frames.push_back({k, out.result.status, out.result.reason, e.port_position_error_m.norm(),
                      e.attitude_error_angle_rad * 180.0 / M_PI});
  }
  return frames;
}

// At 7 m the rotation once turned 15 deg in the iterations where it counted as observed, and the frame was
// reported TRACKING. Whatever the estimate, a frame reported TRACKING must be right.
TEST(IssCloseApproach, NoFrameFarOffIsTracking) {
  int tracking = 0;
  for (const CloseApproachFrame& f : issCloseApproach()) {
    if (f.status != EstimateStatus::kTracking) continue;
    ++tracking;
    EXPECT_LT(f.position_m, 0.05) << "frame " << f.k;
    EXPECT_LT(f.attitude_deg, 1.0) << "frame " << f.k;
  }
  EXPECT_GE(tracking, 5);  // most of them track
}

// With the barely observed boresight rotation held near its prediction (icp/boresight_prior_deg) no frame,
// whatever its status, turns off (without the prior: 15.5 deg at 7 m).
TEST(IssCloseApproach, BoresightRotationHeldNearThePrediction) {
  double worst_deg = 0.0;
  for (const CloseApproachFrame& f : issCloseApproach()) {
    ASSERT_NE(f.status, EstimateStatus::kLost) << "frame " << f.k << ": " << f.reason;
    worst_deg = std::max(worst_deg, f.attitude_deg);
    EXPECT_LT(f.position_m, 0.03) << "frame " << f.k;
  }
  EXPECT_LT(worst_deg, 0.2);  // measured 0.07 deg
}

// The ISS from 12.4 to 9.6 m (port), 0.1 m a frame, `auto` from the truth: the docking-ring method takes
// over at 12 m, and its roll (from the reflector targets) is its weakest part there (0.06 deg RMS at 10-12 m
// in the default closed loop over four lidar seeds; the goal is 0.05). ICP, run beside it in the ISS's
// composite band (7-12.5 m), measures that roll on the docking adapter's asymmetric features with a sigma
// under 0.03 deg: the composite takes it (0.018 deg RMS in those closed loops).
double issHandOverAttitudeRmsDeg(bool composite) {
  PoseConfig config;
  config.method = "auto";
  applyTargetDefaults(&config);
  if (!composite)
    config.estimator.composite_min_port_range_m = config.estimator.composite_max_port_range_m = 0.0;
  AlongTheDockingAxis iss(config, ardsim_description::buildIss(), 3);
  double sum_sq = 0.0;
  int count = 0;
  for (int k = 0; k < 29; ++k) {
    const double port_m = 12.4 - 0.1 * k;
    PoseErrorValue e;
    const EstimatorOutput out = iss.frame(k, port_m - 1.0, &e);  // the lidar 1 m behind the chaser's port
    EXPECT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    if (port_m > 11.5) continue;  // the hand-over and its blend
    sum_sq += std::pow(e.attitude_error_angle_rad * 180.0 / M_PI, 2);
    ++count;
  }
  return std::sqrt(sum_sq / std::max(1, count));
}

TEST(IssHandOver, CompositeTakesIcpRollWhereTheRingsIsWeak) {
  const double composite_deg = issHandOverAttitudeRmsDeg(true);
  const double ring_deg = issHandOverAttitudeRmsDeg(false);
  EXPECT_LT(composite_deg, 0.05);                         // measured 0.015
  EXPECT_LT(composite_deg, 0.75 * ring_deg) << ring_deg;  // measured 0.038
}

// The ISS's defaults with ICP alone.
PoseConfig issIcpAlone() {
  PoseConfig config;
  config.method = "icp";
  applyTargetDefaults(&config);
  return config;
}

// The ISS along its docking axis from from_port_m (port to port: the lidar is 1 m behind the chaser's port),
// 2 cm a 0.1 s frame for frames + 1 frames, noise on (simulator seed 5), from the truth at the first: each
// frame's error to visit; no frame LOST.
template <typename Visit>
void issIcpAloneApproach(const PoseConfig& config, double from_port_m, int frames, Visit visit) {
  ardsim_lidar::NoiseOptions noise;
  noise.enabled = true;
  AlongTheDockingAxis iss(config, ardsim_description::buildIss(), 5, 0.1, noise);
  for (int k = 0; k <= frames; ++k) {
    PoseErrorValue e;
    const EstimatorOutput out = iss.frame(k, from_port_m - 0.02 * k, &e);
    EXPECT_NE(out.result.status, EstimateStatus::kLost) << "frame " << k << ": " << out.result.reason;
    visit(e);
  }
}

// ICP alone closing on the ISS's docking adapter from 13 to 7 m (lidar to port), noise on, 2 cm a 0.1 s
// frame, from the truth at the first. Inside ~8 m the roll about the boresight rests on a few asymmetric
// features and is held near its prediction; with the prior tightened once tracked for
// icp/boresight_prior_frames frames, the held roll averages over the frames instead of following each frame's
// fit. Returns the attitude RMS at from_m to below_m (7-8 m by default).
double issAdapterAttitudeRmsDeg(int boresight_prior_frames, bool prior_when_observed = true,
                                double from_m = 7.0, double below_m = 8.0) {
  PoseConfig config = issIcpAlone();
  config.icp.boresight_prior_frames = boresight_prior_frames;
  config.icp.boresight_prior_when_observed = prior_when_observed;
  double sum_sq = 0.0;
  int count = 0;
  issIcpAloneApproach(config, 12.0, 300, [&](const PoseErrorValue& e) {
    if (e.range_m >= below_m || e.range_m < from_m) return;
    sum_sq += std::pow(e.attitude_error_angle_rad * 180.0 / M_PI, 2);
    ++count;
  });
  EXPECT_GE(count, 40);
  return std::sqrt(sum_sq / std::max(1, count));
}

// With the prior as tight as after a long track (boresight_prior_frames 1: 0.02 deg by the 100th frame),
// fused where the scan observes the roll too (icp/boresight_prior_when_observed), the docking adapter's roll
// at 8-10 m averages over frames instead of following each frame's fit (measured 0.0166 against 0.0263 deg;
// the closed loop with ICP alone, five lidar seeds: 8-9 m 0.025-0.026 -> 0.016-0.019 deg).
TEST(IssCloseApproach, BoresightPriorFusedWhereTheRollIsObserved) {
  const double fused_deg = issAdapterAttitudeRmsDeg(1, true, 8.0, 10.0);
  const double scan_deg = issAdapterAttitudeRmsDeg(1, false, 8.0, 10.0);
  EXPECT_LT(fused_deg, 0.02);
  EXPECT_LT(fused_deg, 0.8 * scan_deg) << scan_deg;
  std::printf("8-10 m attitude RMS: prior fused where observed %.4f deg, the scan's alone %.4f deg\n",
              fused_deg, scan_deg);
}

TEST(IssCloseApproach, TightenedBoresightPriorMeetsTheAttitudeGoal) {
  ASSERT_GT(PoseConfig{}.icp.boresight_prior_frames, 0);
  const double tightened_deg = issAdapterAttitudeRmsDeg(PoseConfig{}.icp.boresight_prior_frames);
  const double held_deg = issAdapterAttitudeRmsDeg(0);
  EXPECT_LT(tightened_deg, 0.05);
  EXPECT_LT(tightened_deg, 0.75 * held_deg) << held_deg;
  std::printf("7-8 m attitude RMS: tightened %.4f deg, held at 0.2 deg %.4f deg\n", tightened_deg, held_deg);
}

// ICP alone closing on the ISS's docking adapter from 11 to 6 m (lidar to port), noise on, 2 cm a 0.1 s
// frame, from the truth at the first, with max_incidence_deg and contour_sigma_px as given. At 7-10 m the
// adapter's face seen end-on measures the port across the boresight only at its rims. Returns the port
// position error's mean across the boresight (lidar x) and its RMS (all axes), m, at 7-10 m.
std::pair<double, double> issAdapterLateralErrorM(double max_incidence_deg, double contour_sigma_px) {
  PoseConfig config = issIcpAlone();
  config.visibility.max_incidence_deg = max_incidence_deg;
  config.icp.contour_sigma_px = contour_sigma_px;
  double sum_x = 0.0, sum_sq = 0.0;
  int count = 0;
  issIcpAloneApproach(config, 10.0, 250, [&](const PoseErrorValue& e) {
    if (e.range_m >= 10.0 || e.range_m < 7.0) return;
    sum_x += e.port_position_error_m.x();
    sum_sq += e.port_position_error_m.squaredNorm();
    ++count;
  });
  EXPECT_GE(count, 140);
  return {sum_x / std::max(1, count), std::sqrt(sum_sq / std::max(1, count))};
}

// The sensor returns nothing from a surface it sees beyond 80 deg incidence: the walls of the docking adapter
// seen end-on. Kept in the visibility crop, the scan points at the rim of its face matched them, and the port
// came out 6-8 mm off across the boresight on average (position RMS 8-10 mm at 7-10 m). Left out, the rims
// are placed by the occluding contours.
TEST(IssCloseApproach, ObliqueWallsLeftOutAndContoursPlaceThePortAcrossTheBoresight) {
  const PoseConfig defaults;
  ASSERT_LT(defaults.visibility.max_incidence_deg, 90.0);
  ASSERT_GT(defaults.icp.contour_sigma_px, 0.0);
  const auto [mean_x_m, rms_m] =
      issAdapterLateralErrorM(defaults.visibility.max_incidence_deg, defaults.icp.contour_sigma_px);
  const auto [mean_x_before_m, rms_before_m] = issAdapterLateralErrorM(90.0, 0.0);
  EXPECT_LT(std::abs(mean_x_m), 0.002);
  EXPECT_LT(rms_m, 0.004);
  EXPECT_LT(rms_m, 0.5 * rms_before_m);
  std::printf(
      "7-10 m port error across the boresight, mean: %.2f mm (before %.2f); position RMS %.2f mm (before "
      "%.2f)\n",
      mean_x_m * 1e3, mean_x_before_m * 1e3, rms_m * 1e3, rms_before_m * 1e3);
}

// A bag played again into a running pose node: the approach from 99 m to 20 m at 0.5 m a 0.1 s frame, then
// its first frames again (time back 16 s). Without the restart the estimator searched near its 20 m estimate
// and was LOST on every frame (0 correspondences, 79 m off); started again from the prior it estimates the
// replayed frames exactly as the first time.
TEST(TimeGoingBack, ABagPlayedAgainIsEstimatedAsTheFirstTime) {
  ardsim_lidar::LidarSimulator simulator(ardsim_lidar::SensorOptions{}, ardsim_lidar::NoiseOptions{}, 7);
  simulator.setTarget(ardsim_description::buildIss());
  std::unique_ptr<PoseEstimator> estimator = makeEstimator(PoseConfig{});
  estimator->setPrior(dockingAxisPose(TargetKind::kIss, 99.0));
  ardsim_lidar::LidarFrame frame;
  auto frameAt = [&](int k) {
    simulator.simulate(dockingAxisPose(TargetKind::kIss, 99.0 - 0.5 * k), static_cast<std::uint64_t>(k),
                       &frame);
    return fromLidarFrame(frame, simulator.rays(), 0.1 * k);
  };
  constexpr int kFrames = 159, kReplayed = 3;
  std::vector<EstimatorOutput> first;
  for (int k = 0; k < kFrames; ++k) {
    first.push_back(estimator->process(frameAt(k)));
    ASSERT_NE(first.back().result.status, EstimateStatus::kLost) << k << ": " << first.back().result.reason;
    EXPECT_DOUBLE_EQ(first.back().restarted_back_s, 0.0);
  }
  for (int k = 0; k < kReplayed; ++k) {
    const EstimatorOutput again = estimator->process(frameAt(k));
    EXPECT_NEAR(again.restarted_back_s, k == 0 ? 0.1 * (kFrames - 1) : 0.0, 1e-9) << k;
    EXPECT_EQ(again.result.status, first[k].result.status) << k << ": " << again.result.reason;
    EXPECT_TRUE(again.result.T_lidar_target.isApprox(first[k].result.T_lidar_target, 1e-12)) << k;
  }
}

}  // namespace
}  // namespace ardsim_pose
