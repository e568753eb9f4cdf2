#include "ardsim_pose/estimator_factory.h"

#include <cmath>
#include <stdexcept>

#include "ardsim_description/mesh_tools.h"
#include "ardsim_description/models.h"
#include "ardsim_pose/require_option.h"

namespace ardsim_pose {

void validate(const PoseConfig& c) {
  if (c.method != "icp" && c.method != "auto" && c.method != "ring" && c.method != "pyramid")
    throw std::invalid_argument("method = '" + c.method + "' is not allowed: icp, auto, ring or pyramid");
  close_range::validate(c.mode);
  // The pyramid's cells, sized for the ring at 12 m and nearer, gave Hubble poses 7 cm off from 15.5 m (gtest
  // CloseRangeHubble): a clear error, not a wrong pose.
  requireOption(c.mode.close_method != EstimateMethod::kPyramid || c.mode.close_enter_range_m <= 12.0,
                "mode/close_enter_range_m", c.mode.close_enter_range_m,
                "<= 12 with mode/close_method pyramid");
  ardsim_lidar::validate(c.sensor);
  validate(c.model);
  validate(c.visibility);
  validate(c.icp);
  validate(c.panels);
  if (c.panels.enabled) panelJoint(c.target);  // throws for a target without one panel joint
  validate(c.estimator);
}

void applyTargetDefaults(PoseConfig* config) {
  const PoseConfig defaults;
  const bool hubble = config->target == ardsim_description::TargetKind::kHubble;
  config->model.spacing_at_port_m = hubble ? 0.015 : defaults.model.spacing_at_port_m;
  // Hubble's roll about its axis rests end-on on a few small features (the antenna booms, the soft-capture
  // mechanism's edges; since session 15 the solar-array masts too, which measure it): with 2500 points single
  // noisy frames turned it 0.3-1.5 deg, where the boresight prior then held it (20-30 m band, 13 render seeds
  // x truth / coarse prior, auto: within 0.05 deg in 3 of 26 runs, worst 1.46 deg RMS); with 5000 (every
  // gated pixel out to ~40 m) in 21 of 26, worst 0.94 deg, at ~11-13 ms a frame instead of 7-9.
  config->icp.max_points = hubble ? 5000 : defaults.icp.max_points;
  config->icp.max_points_near = hubble ? 5000 : defaults.icp.max_points_near;
  // Its roll, held at the prediction end-on, follows the few pixels a reused visibility prediction changes.
  config->icp.crop_reuse_px = hubble ? 0.0 : defaults.icp.crop_reuse_px;
  // Its first tracking frames' roll follows the path a sparse first step takes.
  config->icp.sparse_start_residual_m = hubble ? 0.0 : defaults.icp.sparse_start_residual_m;
  // Its roll, measured on the solar-array masts from 50 m in, wobbles ~1e-4 rad between iterations (a frame's
  // roll is good to ~1e-3): chasing 1e-5 left most frames DEGRADED "not converged". With 1e-4 (approach
  // datasets, 24 runs, auto): 30-50 m attitude RMS 0.11 -> 0.093 deg mean, within 0.1 deg in 13 -> 17 runs,
  // the rest within +-0.002 deg; ICP frames 30-50 m twice as fast.
  config->icp.converged_rotation_rad = hubble ? 1e-4 : defaults.icp.converged_rotation_rad;
  // Hubble's two arrays turn on one joint, which the scans measure (PanelTracker): from 50 m in they show its
  // roll (approach datasets, arrays at 30 deg, 24 runs -> 12: 20-30 m attitude RMS 0.050-0.070 -> 0.012-0.015
  // deg). The ISS's ten joints are not fitted (its goals are met on the rigid structure alone).
  config->panels.enabled = hubble;
  // Edge-on arrays (at 0 deg) show nothing, and a frame's roll on the masts alone is noisy (~1e-3 rad): held
  // to the constant-velocity prediction with 0.05 deg instead of 0.2, 20-30 m attitude RMS 0.045-0.063 ->
  // 0.025-0.046 deg (arrays at 0 deg, 12 runs, within 0.05 deg: 2 -> 12; with 0.1 deg: 6); arrays at 30 deg
  // unchanged (their fit measures the roll).
  config->icp.boresight_prior_deg = hubble ? 0.05 : defaults.icp.boresight_prior_deg;
  // ... also where a frame counts its roll as observed up to 0.03 (not 0.01): there single frames on the
  // masts jumped 0.6 deg and kept it for a second. hubble_hold, two lidar seeds: ICP 30-50 m attitude RMS
  // 0.060 / 0.039 -> 0.030 / 0.034 deg, worst frame 0.58 / 0.40 -> 0.14 / 0.23; approach datasets 20-30 m
  // 0.012-0.046 -> 0.012-0.039 deg, 30-50 m 0.018-0.053 -> 0.019-0.045.
  config->icp.boresight_prior_max_information = hubble ? 0.03 : defaults.icp.boresight_prior_max_information;
  // ... and tightens to 0.02 deg once tracked for 36 frames (IcpOptions::boresight_prior_frames): hubble_hold
  // over lidar seeds 2, 11, 23, 37, 51, ICP 30-50 m attitude RMS 0.030-0.082 -> 0.018-0.026 deg, worst frame
  // 0.14-0.52 -> 0.050-0.17; the approach datasets' bands as before (at 0.5 m a frame, 36 frames take them
  // from 51 to 33 m). Down to 0.01 deg (session 22; 0.02 from 225 frames, 0.01 from 900): a frame's roll,
  // measured on the masts at 30-50 m, is good to ~0.025 deg when a row of pixels falls on a mast's grazing
  // side and to ~0.07 when not, which changes with the sub-pixel phase over seconds; averaged longer, the
  // same five seeds 0.019-0.022 -> 0.016-0.017 deg, worst frame 0.051-0.10 -> 0.038-0.055 (a 2 deg roll
  // offset at the start, turning at 0.05 deg/s: seed 2 0.020 -> 0.016, worst 0.076 -> 0.043). These are
  // the defaults (IcpOptions::boresight_prior_frames), the ISS's too since session 32.
  // Its aft bulkhead face-on leaves ICP's planes blind across it: its rim's occluding contours place it
  // (IcpOptions::contour_sigma_px; approach datasets, 24 runs, 30-50 m: port position RMS 0.8-2.3 ->
  // 0.18-0.44 cm, worst frame 5.0 -> 0.84 cm, attitude RMS 0.019-0.045 -> 0.021-0.042 deg, both within 3x in
  // every run; without the arrays' edges, session 22: 0.15-0.21 cm, 0.016-0.033 deg). The ISS's weak
  // direction, across the boresight inside ~16 m once the visibility crop leaves out the walls its lidar
  // sees too obliquely to return (VisibilityOptions::max_incidence_deg), takes them too since session 33
  // (the fine approach datasets, 16 -> 6 m, six render seeds: 7-10 m port position RMS 6.2-10.4 -> 1.4-1.8
  // mm), but never its roll (contours_for_boresight: inside 2 m the docking port's inner contours kept
  // ICP-alone frames from converging), at most 500 pairs a frame (speed), from a prediction far off only
  // after a small step (contour_wait_px), and inside 16 m only (contour_max_depth_m); Hubble as tuned before
  // (all pairs, from the first iteration, at any range, its roll too).
  config->icp.contours_for_boresight = hubble;
  config->icp.max_contour_pairs = hubble ? 0 : defaults.icp.max_contour_pairs;
  config->icp.contour_wait_px = hubble ? 0.0 : defaults.icp.contour_wait_px;
  config->icp.contour_max_depth_m = hubble ? 0.0 : defaults.icp.contour_max_depth_m;
  // Hubble end-on gives ICP little (a face-on bulkhead, the roll on a few edges: 1.6-2.2 cm and 0.11-0.43
  // deg RMS at 10-20 m on the approach datasets) while the docking ring is found from 20 m (its bulkhead then
  // fills a quarter of the view): the close-range method takes over there (10-20 m: 0.3-0.6 cm, 0.05-0.10
  // deg; from 16 m: 1.2-1.6 cm, 0.08-0.31 deg; from 30 m its roll, on 4-pixel reflectors and petals, was 0.9
  // deg off). With close_method pyramid set these back to the ISS's (validate: at most 12 m).
  config->mode.close_enter_range_m = hubble ? 20.0 : defaults.mode.close_enter_range_m;
  config->mode.close_exit_range_m = hubble ? 22.0 : defaults.mode.close_exit_range_m;
  config->mode.close_enter_fill = hubble ? 0.25 : defaults.mode.close_enter_fill;
  // Hubble's port from 20 m in is placed by the ring (from 30 m until session 37, when ICP's ~2 cm there
  // had long become ~1 mm), its tilt down to 10 m by ICP (the ring's ~0.05 deg become ~0.02): the composite
  // pose (EstimatorOptions). The ISS's from the
  // hand-over at 12 m to 7 m: there the ring's roll, from the reflector targets, is 0.06 deg RMS at 10-12 m
  // in the closed loop (four lidar seeds: the goal is 0.05), ICP's, on the docking adapter's asymmetric
  // features, 0.018 with a sigma under 0.03 deg; so the ISS takes ICP's roll up to that sigma. Hubble takes
  // ICP's held roll whenever ICP tracks (session 22): its covariance, the planes' alone, says 0.04-0.4 deg on
  // the masts, but the roll is an average over hundreds of frames by its prior, and the ring's, from
  // petals and reflectors a few pixels wide at 15-20 m, is worse: hubble_hold's five lidar seeds, 10-20 m
  // attitude RMS 0.051-0.053 -> 0.014-0.022 deg (with the composite's flags of ICP's roll; 0.1 deg:
  // 0.025-0.031).
  // Hubble's band ends at the hand-over, 20 m, since session 37: beyond, ICP's own port position (its
  // contours' consensus from 25 m out) is better than the ring's (hubble_hold, lidar seeds 2 / 11, 20-30 m:
  // 2.16 / 2.18 -> 0.80 / 0.82 mm RMS, worst frame 7.0 / 11.0 -> 2.4 / 2.3 mm).
  config->estimator.composite_min_port_range_m = hubble ? 10.0 : 7.0;
  config->estimator.composite_max_port_range_m = hubble ? 20.0 : 12.5;
  // Since session 34 ICP's covariance takes in its roll prior (held, or fused where observed:
  // IcpOptions::boresight_prior_when_observed), so a roll averaged over a long track passes the ISS's 0.03
  // (`auto`, five lidar seeds: 7-8 m attitude RMS 0.026-0.029 -> 0.018-0.022 deg, 8-9 m 0.025-0.038 ->
  // 0.015-0.022), one over a few hundred frames mostly not (the README's dataset at 0.5 m a frame: its 7-10 m
  // stays the ring's; with 1 deg there, 0.016 -> 0.024 deg).
  config->estimator.composite_icp_roll_max_sigma_deg = hubble ? 1.0 : 0.03;
  // Hubble's tilt at 30-50 m is a frame's to ~0.02-0.05 deg: its rotation rate learns from several
  // (EstimatorOptions::angular_velocity_smoothing).
  config->estimator.angular_velocity_smoothing = hubble ? 0.2 : 0.5;
}

std::shared_ptr<const ReferenceModel> buildReferenceModel(ardsim_description::TargetKind kind,
                                                          const ReferenceModelOptions& options) {
  return std::make_shared<const ReferenceModel>(
      ardsim_description::rigidStructure(ardsim_description::buildTarget(kind)),
      ardsim_description::T_target_port(kind), options);
}

std::shared_ptr<const ReferenceModel> buildReferenceModelWithPanels(ardsim_description::TargetKind kind,
                                                                    const ReferenceModelOptions& options,
                                                                    double panel_angle_rad) {
  panelJoint(kind);  // throws for a target without one panel joint (only Hubble has one)
  ardsim_description::HubbleOptions hubble;
  hubble.solar_array_deg = panel_angle_rad * 180.0 / M_PI;
  const ardsim_description::TriangleMesh mesh = ardsim_description::buildHubble(hubble);
  return std::make_shared<const ReferenceModel>(
      ardsim_description::selectParts(mesh,
                                      [](const ardsim_description::Part& part) {
                                        return !part.articulated || part.name == "solar_arrays";
                                      }),
      ardsim_description::T_target_port(kind), options);
}

std::unique_ptr<PoseEstimator> makeEstimator(const PoseConfig& config) {
  validate(config);
  return makeEstimator(config, buildReferenceModel(config.target, config.model));
}

std::unique_ptr<PoseEstimator> makeEstimator(const PoseConfig& config,
                                             std::shared_ptr<const ReferenceModel> model) {
  validate(config);
  PoseEstimator::Methods methods;
  auto icp = std::make_unique<IcpTracker>(model, ardsim_lidar::intrinsicsFor(config.sensor), config.icp,
                                          config.visibility);
  if (config.panels.enabled) {
    // The panels are sampled once, at the first angle measured; later angles turn the model before
    // (ReferenceModel::withArticulatedTurned: a rebuild costs its frame 1-4 ms, not 70-270).
    const PanelJoint joint = panelJoint(config.target);
    icp->trackPanels(std::make_unique<PanelTracker>(
        joint, config.panels, std::move(model),
        [target = config.target, options = config.model, joint,
         last = std::shared_ptr<const ReferenceModel>(), last_angle_rad = 0.0](double angle_rad) mutable {
          last = last ? last->withArticulatedTurned(joint.origin, joint.axis, angle_rad - last_angle_rad)
                      : buildReferenceModelWithPanels(target, options, angle_rad);
          last_angle_rad = angle_rad;
          return last;
        }));
  }
  methods[EstimateMethod::kIcp] = std::move(icp);
  const close_range::AdapterGeometry geometry = close_range::adapterGeometry(config.target);
  // The close-range fits' pixel size is the sensor's (AdapterFitOptions' default is the default sensor's:
  // with another, their pixel-scaled thresholds and the field of view they test were another sensor's).
  const double pixel_pitch_rad = config.sensor.fov_deg * M_PI / 180.0 / config.sensor.width;
  close_range::RingDetectorOptions ring = config.ring;
  close_range::PyramidOptions pyramid = config.pyramid;
  ring.fit.pixel_pitch_rad = pyramid.fit.pixel_pitch_rad = pixel_pitch_rad;
  methods[EstimateMethod::kRing] = std::make_unique<close_range::RingMethod>(geometry, ring);
  methods[EstimateMethod::kPyramid] = std::make_unique<close_range::PyramidMethod>(geometry, pyramid);
  std::unique_ptr<MethodSelector> selector = std::make_unique<FixedMethodSelector>(EstimateMethod::kIcp);
  if (config.method == "ring") selector = std::make_unique<FixedMethodSelector>(EstimateMethod::kRing);
  if (config.method == "pyramid") selector = std::make_unique<FixedMethodSelector>(EstimateMethod::kPyramid);
  EstimatorOptions estimator = config.estimator;
  if (config.method == "auto") {
    selector = std::make_unique<close_range::ModeSelector>(config.mode, geometry.T_target_port);
  } else {
    // One method asked for: that method's pose alone.
    estimator.composite_min_port_range_m = 0.0;
    estimator.composite_max_port_range_m = 0.0;
  }
  return std::make_unique<PoseEstimator>(estimator, std::move(methods), std::move(selector),
                                         geometry.T_target_port);
}

}  // namespace ardsim_pose
