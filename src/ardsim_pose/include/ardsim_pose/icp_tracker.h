// Model-based ICP tracking of T_lidar_target from one organized cloud: point-to-plane against the reference
// model cropped to what the sensor can see from the predicted pose, Tukey-weighted residuals, quality checks
// that say TRACKING, DEGRADED or LOST, and the covariance from the final normal equations. ROS-free.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "ardsim_lidar/sensor.h"
#include "ardsim_pose/occluding_contours.h"
#include "ardsim_pose/panel_angle.h"
#include "ardsim_pose/pose_types.h"
#include "ardsim_pose/reference_model.h"

namespace ardsim_pose {

struct IcpOptions {
  // Scan points per frame (evenly spread over the gated valid pixels). The ISS since session 47: 4000
  // instead of 1000 halves its errors from 12 m out (its default closed loop, ICP alone, five lidar seeds:
  // 12-30 m port 2.1-2.2 -> 1.2 mm RMS, attitude 0.012 -> 0.007 deg; 30-100 m 2.0 -> 1.0-1.1 mm, 0.010 ->
  // 0.006 deg), and at 12-16 m the single frames 4 sigma off (a 1000-point draw; 10.5 mm where the RMS was
  // 2.2) are gone (worst / RMS 2.79-4.31 -> 2.55-2.97), for 1.6-1.9x the instructions a frame at 100 and
  // 30 m. 5000 (the benchmark's 10 m frames primed from the truth by an acquisition that then never
  // converged) is not.
  int max_points = 4000;
  // Tracking (not acquiring), where the model's nearest predicted surface is nearer than near_depth_m (0:
  // never), max_points_near instead: there the ISS's docking adapter fills the view and its roll rests on a
  // few asymmetric features (a 16 -> 6 m approach in 2 cm steps, ICP alone from the truth: 6-10 m attitude
  // RMS 0.051 -> 0.038 deg, worst frame 0.186 -> 0.116 deg with 2500 instead of 1000; 1.5 -> 2.8 ms a frame).
  int max_points_near = 2500;
  double near_depth_m = 12.0;
  // Scan points come only from pixels within this of the model's silhouette at the predicted pose (while
  // acquiring, widened by the acquisition search's lateral reach); the rest are parts the rigid model leaves
  // out (the solar arrays and radiators, which fill most of the view at 250 m) or other objects. 0: every
  // valid pixel. When fewer than min_points pixels pass (a prediction far off), every valid pixel is used.
  double silhouette_margin_px = 16.0;
  int max_iterations_tracking = 15;     // per frame once tracking
  int max_iterations_acquisition = 40;  // per frame while acquiring (from a prior or after LOST)
  double gate_tracking_m = 0.5;         // first correspondence gate when tracking
  double gate_acquisition_m = 3.0;      // first correspondence gate while acquiring
  double gate_min_m = 0.3;  // the gate shrinks to 4 x the median correspondence distance, not below
  double tukey_c = 4.685;   // Tukey biweight constant, in robust sigmas of the plane residuals
  // A plane seen face-on (Hubble's aft bulkhead) says nothing about sliding along it: in the directions where
  // the plane residuals' information is below this fraction of the largest (lever-scaled), the step comes
  // from the offsets to the nearest model points across their normals beyond the model's sample spacing
  // (points past a rim or an edge), or is held where there are none. 0: point-to-plane only.
  double weak_direction_condition = 0.01;
  // The offsets stop moving the pose anywhere inside the sampling (they count only beyond it): an estimate
  // with weak directions that moved further from its prediction than this many pixel footprints (at the
  // target's range) has likely stopped short of the truth: DEGRADED. Within it, the frame-to-frame wander of
  // a tracked pose inside the sampling.
  double degraded_weak_slide_px = 1.0;
  // Where the plane residuals leave such weak directions, or the boresight rotation barely observed (below
  // boresight_prior_max_information), the scan's occluding contours are measured with them
  // (OccludingContours: pairs of pixels across a depth edge, the model's contour between their centres),
  // which place a rim to a fraction of a pixel where the offsets stop at half one (and, while acquiring, the
  // roll by the edges of off-axis structure: Hubble's masts): the contour's standard deviation in pixels
  // (half a pixel either way, evenly: 0.29, and the model's sampling). 0: the planes (and offsets) alone.
  // Both targets (the ISS since session 33; applyTargetDefaults says why).
  double contour_sigma_px = 0.3;
  // Whether a barely observed boresight rotation alone calls for the contours too. By target: false (the
  // ISS: inside 2 m, where its roll is barely observed, the contours of the docking port's inside kept most
  // ICP-alone frames from converging, and the guidance held), true (Hubble).
  bool contours_for_boresight = false;
  // At most this many contour pairs a frame (evenly spread; 0: all): each is searched for at every
  // iteration. By target: 500 (the ISS: its docking adapter at 6-16 m gives ~5000, and 500 place its rims
  // within ~1 mm RMS), 0 (Hubble).
  int max_contour_pairs = 500;
  // A tracking frame whose prediction lies beyond the contours' window (3 px) of where the last two TRACKING
  // estimates carry on to, and an acquisition's alignment, take the contours only after an iteration whose
  // step moved the model less than this many pixels: from the benchmark's predictions, 0.2 m off at 10 m, the
  // window holds other edges, and the contours held the pose there (13-16 cm off). 0: from the first
  // iteration. By target: 1.5 (the ISS), 0 (Hubble).
  double contour_wait_px = 1.5;
  // Only where the model's nearest predicted surface is nearer than this (m; 0: everywhere). By target: 16
  // (the ISS: its weak direction is the docking adapter's, inside ~16 m; beyond, where the crop alone leaves
  // the port within ~2 mm, the contours cost a 30 m benchmark frame 10 % of its instructions; with 12, the
  // hand-over gtest's frame at 12 m slid 49 mm on the offsets), 0 (Hubble).
  double contour_max_depth_m = 16.0;
  // Tracking, where the model's nearest predicted surface is at least this far (m), the contours place the
  // lateral translation by consensus, all pairs at once (OccludingContours::accumulateConsensus), instead of
  // each pair's midpoint: a pixel there is large against what the other unknowns' errors move the contours
  // (Hubble's bulkhead rim at 30-50 m, the approach datasets: port position RMS 0.11-0.14 -> 0.07-0.11 cm).
  // Nearer, their exact intersection was biased (Hubble's approach dataset inside 10 m, ICP alone: 1.2 ->
  // 6.6 mm; hubble_hold's roll at 10-20 m, which the composite takes from ICP: worst frame 0.07 -> 0.12 deg).
  double contour_consensus_min_depth_m = 25.0;
  // ... and where it does, a prior on that translation from the consensus's own measurements of the last
  // lateral_history_frames tracking frames in a row: the straight line through the newest lateral_line_frames
  // of them (each weighted by its polygon's covariance) at the frame's stamp, with that fit's covariance,
  // where the frame's own measurement lies within 3 sigma of it (a manoeuvre the line does not follow is not
  // followed). A frame's pixels place Hubble's rim to ~1 mm at 30-50 m, the line through ten frames to ~0.6
  // (hubble_hold, five lidar seeds: ICP 30-50 m port position RMS 0.96-1.02 -> 0.62-0.66 mm). Longer lines
  // lag: in the closed loop the chaser's attitude control swings the target across the lidar frame by
  // millimetres in a second (20 frames always: 25-30 m biased 0.8-0.95 mm). 0: none.
  int lateral_history_frames = 20;
  int lateral_line_frames = 10;
  // ... but through the whole history where the newest frames' line is weaker than this at the frame (sigma,
  // m: each frame's own measurement is weak, Hubble beyond ~35 m) and the two lines agree (position and
  // rate within chi^2 7 of their difference: a manoeuvre the longer line would lag is not averaged in).
  // hubble_hold, five lidar seeds: ICP 30-50 m port position RMS 0.58-0.62 -> 0.50-0.53 mm, worst frame
  // 2.14-3.49 -> 1.81-2.13 mm, 20-30 m as before. 0: wherever they agree.
  double lateral_line_sigma_m = 0.00075;
  // ... where the frame's own measurement lies beyond 3 sigma of the line, the line still counts unless
  // this many frames in a row have: a single such frame was the vote's error (a winner a cell off), not the
  // path's (hubble_hold, lidar seeds 37 and 51: the worst 30-50 m frame, 3.5 mm off where the line was
  // within 0.7 mm of the truth, 3.55 / 3.47 -> 2.92 / 3.11 mm); two in a row are a manoeuvre. 1: the line
  // is dropped at the first.
  int lateral_gate_frames = 2;
  // ... and where the parabola through the whole history says it accelerates (the chi^2 of its acceleration,
  // 2 degrees of freedom, above this) and fits it (its own chi^2 within 3 sigma of its degrees of freedom:
  // a jump is the gate's), the parabola through the newest lateral_line_frames instead: a line lags a steady
  // acceleration a by ~a T^2 / 12 over its span T (hubble_hold's burn at 31 m, 0.024 m/s^2 across the
  // boresight: the 10 frames' line 2-3 mm behind for seconds). 0: lines only.
  double lateral_acceleration_chi2 = 9.0;
  // ... and that line's prediction breaks the vote's near-ties too: a translation there loses
  // lateral_vote_weight / 2 votes per unit of its squared distance from the prediction, in sigmas of the
  // prediction widened by one vote cell (OccludingContours::VotePrior). The vote's top is a plateau a few
  // cells wide whose strips differ by one or two (a pixel's hit or miss at its rim), and its winner there
  // swung the frame's measurement 3-7 mm from one frame to the next where the rim stays put (hubble_hold,
  // five lidar seeds: ICP 30-50 m worst frame 2.95-6.03 -> 2.14-3.55 mm). 0: the strips alone decide.
  double lateral_vote_weight = 3.0;
  double min_sigma_m = 0.01;  // floor of the robust sigma (the sensor's range noise)
  // Tracking: the rotation about the boresight is held near the prediction with this standard deviation
  // (deg; a prior in the normal equations): where the scan barely observes it (a near-symmetric docking
  // adapter filling the view, Hubble end-on) it no longer wanders on noise. 0: no prior.
  double boresight_prior_deg = 0.2;
  // ... where the scan's information about that rotation (with the other five free, against the largest,
  // lever-scaled) is below this (held: the prior's); above it the scan's (and see below). By target: 0.01
  // (the ISS), 0.03 (Hubble: on its masts a frame judged to observe its roll at 0.01-0.03 jumped 0.6 deg in
  // one frame and kept it for a second in hubble_hold, while its covariance said 0.05 deg).
  double boresight_prior_max_information = 0.01;
  // Tracking, that prior also where the scan observes the rotation (above that limit), fused with the scan's
  // in the alignment's fine stage where the two agree (the scan's own within 3 sigma of the prediction's,
  // both sigmas combined: a prediction off in roll is not followed): there the rotation is still measured
  // (not held: the prediction learns its rate from it), but averaged over frames as the prior tightens. The
  // ISS's docking adapter at 7-10 m gives a frame's roll to only ~0.03 deg, above the limit (ICP alone,
  // closed loop, five lidar seeds: 8-9 m attitude RMS 0.025-0.026 -> 0.016-0.019 deg; 3x worst/RMS rule at
  // 7-12 m over in 10 of 40 checks -> 1). false: the scan's alone there.
  bool boresight_prior_when_observed = true;
  // ... and once tracking for more than boresight_prior_frames frames in a row (0: never), that prior
  // tightens as 1 / sqrt(the frames tracked), down to boresight_prior_min_deg: the held rotation is an
  // average over them by then. It sits at the constant-rate prediction: a steady turn is followed, only a
  // change of rate lags. Hubble since session 19 (on its masts, arrays edge-on, frames at 30-50 m fit the
  // roll 0.4-0.5 deg off for seconds on end, and the 0.05 deg prior followed; tight from the start, it held
  // an acquisition's 1 deg error through the 0.5 m a frame approach datasets), the ISS since session 32
  // (inside ~8 m its docking adapter leaves the roll to a few asymmetric features: with the prior at 0.2 deg
  // frames fit it 0.1-0.2 deg off one after another).
  int boresight_prior_frames = 36;
  double boresight_prior_min_deg = 0.01;
  // Acquiring, from the second frame on (the prediction is then the last acquisition estimate): a barely
  // observed boresight rotation that the frame's own alignment leaves within this of the prediction's
  // (deg) is aligned again with a prior at the prediction of twice boresight_prior_deg; beyond it (the gross
  // error of a first frame from a coarse prior) the frame's own stands. Hubble from 50 m with its arrays
  // edge-on: each acquisition frame alone measured the roll 0.02-0.86 deg off (the masts alone, sub-pixel
  // there), so its 30-50 m RMS exceeded 0.1 deg in 4 of 24 runs. 0: off.
  double acquisition_boresight_gate_deg = 2.0;
  // Tracking: the silhouette gate and the crop take a visibility prediction (with its grid of visible points)
  // made at a pose that moves every visible model point less than this many pixels from where the frame's
  // prediction puts it (a fraction of the prediction's 4 px cells), e.g. the frame before's: in the closed
  // loop a prediction moves a fraction of a pixel a frame from 100 m to ~20 m out, so one serves a few
  // frames. ISS approach 99 -> 79 m in 2 cm steps (1001 frames): 1.72 -> 0.62 ms a frame (interleaved), the
  // errors unchanged (position RMS 2.2 mm, max 5.5; attitude RMS 0.0100 deg, max 0.0246). 0: one made at
  // exactly the prediction (Hubble's default: its roll, held at the prediction end-on, follows the few pixels
  // such a crop changes: a 50 -> 20 m approach in 3 cm steps went from 0.26 to 0.29-0.88 deg roll RMS).
  double crop_reuse_px = 2.0;
  // Tracking beyond near_depth_m, the first coarse iteration searches every 9th scan point first; where their
  // median plane residual is at least this (a prediction that is off, like the benchmark's 0.2 m and 0.5 deg:
  // 2.2-4.9 cm at 30 m), the first step is taken from them alone, before the searches of the rest, which it
  // moves out of their balls anyway (the benchmark's 30 m frames 6 % fewer instructions). Below it (a good
  // prediction: 0.5-0.9 cm on the ISS approach dataset, where a sparse step took an iteration more) the
  // iteration goes on with all the coarse points, as with 0 (never). Hubble's default 0: its first tracking
  // frames' roll follows the different path (four approach datasets: one frame TRACKING -> DEGRADED, another
  // 1.3 -> 4.6 mm).
  double sparse_start_residual_m = 0.015;
  double converged_translation_m = 1e-4;  // an update smaller than both ends the iterations
  double converged_rotation_rad = 1e-5;
  double revisibility_translation_m = 0.3;  // recompute the visibility when the pose moved more than this
  double revisibility_rotation_rad = 0.02;
  // Quality: below the `lost_` limits the frame is LOST, below the `degraded_` ones DEGRADED.
  int min_points = 50;  // valid scan points, and correspondences
  // Scan points within the Tukey limit of the model, of those on its silhouette at the estimated pose (the
  // arrays and radiators around it are not in the rigid model).
  double lost_inlier_fraction = 0.15;
  double degraded_inlier_fraction = 0.3;
  double lost_fit_rms_m = 0.15;  // RMS plane residual of the inliers
  double degraded_fit_rms_m = 0.05;
  double lost_coverage = 0.35;  // predicted-visible model cells that the scan confirms
  double degraded_coverage = 0.55;
  double degraded_condition = 1e-3;     // smallest / largest eigenvalue of the scaled normal equations
  double confirm_translation_m = 0.05;  // acquiring: TRACKING once a frame moves less than this from the last
  double confirm_rotation_rad = 0.0035;
  double max_correction_m = 1.5;  // when tracking: a larger jump from the prediction is a divergence
  double max_correction_rad = 0.1;
  // Acquisition search: a single ICP from a coarse prior can settle where the structure repeats or slides
  // along itself (the truss bays, clipped by the field of view at 100 m): a perfect local fit metres off. So
  // the attitude is searched first (brief ICPs from the prior, a 3 x 3 grid of lateral offsets of it and
  // turns about the scan's centroid), then a dense lateral grid around that pose is scored, and the best
  // cells are aligned. The winner of each stage is the pose that explains most scan points (within
  // explained_distance_m of the visible model surface).
  int search_iterations = 8;           // per hypothesis
  double search_offset_m = 1.5;        // step of the 3 x 3 grid of offsets across the boresight
  double search_rotation_rad = 0.12;   // turns about lidar x, y and z, both ways (0: none)
  double search_lateral_m = 2.4;       // half-width of the lateral grid across the boresight
  double search_lateral_step_m = 0.3;  // its step (below the spacing of the repeating structure)
  double explained_distance_m = 0.05;
};

// Throws std::invalid_argument naming the option, its value and the allowed range.
void validate(const IcpOptions& options);

class IcpTracker : public PoseMethod {
 public:
  IcpTracker(std::shared_ptr<const ReferenceModel> model, const ardsim_lidar::Intrinsics& intrinsics,
             const IcpOptions& options = {}, const VisibilityOptions& visibility = {});
  // Tracked frames measure the target's panels and the reference model follows them (PanelTracker): the
  // model given above is then the rigid structure alone.
  void trackPanels(std::unique_ptr<PanelTracker> panels) { panels_ = std::move(panels); }

  // A tracking frame that would be LOST after its alignment is searched again at once as an acquisition
  // frame.
  PoseResult estimate(const OrganizedCloud& cloud,
                      const Eigen::Isometry3d& T_lidar_target_predicted) override;
  // Back to acquisition: the next frame starts from its prediction with the wide gate and more iterations.
  void reset() override {
    acquiring_ = true;
    acquired_.clear();
    tracked_frames_ = 0;
    tracked_.clear();
    clearLateralHistory();
  }

  bool acquiring() const { return acquiring_; }
  // Of the last frame: fraction of the cells where the model is predicted that the scan confirms.
  double lastCoverage() const { return coverage_; }
  // Of the last frame: the visibility mask and the scan subsample (lidar frame), for benchmarks and tests.
  const std::vector<std::uint8_t>& lastVisible() const { return slots_[current_].predictor.visible(); }
  const std::vector<Eigen::Vector3f>& lastScanPoints() const { return scan_; }
  const ReferenceModel& model() const { return *model_; }
  const IcpOptions& options() const { return options_; }

 private:
  // One frame, tracking or acquiring as the tracker stands; *aligned: the frame got as far as an alignment
  // (not refused for its input: empty, the wrong size, too few returns).
  PoseResult processFrame(const OrganizedCloud& cloud, const Eigen::Isometry3d& T_predicted, bool* aligned);
  // ICP from T_start; the gate starts at gate_m. Fills correspondences_ and the visibility of the result.
  struct Alignment {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    std::string failure;  // non-empty: no estimate (LOST reason)
    bool converged = false;
    int iterations = 0;
    int inliers = 0;
    double inlier_sq_sum = 0.0;
    double weight_sum = 0.0;
    double weighted_sq_sum = 0.0;
    double limit_m = 0.0;  // the Tukey limit of the last iteration
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();  // the planes'
    // What the contours' consensus and the lateral line through its history added to H in the last
    // iteration (not the midpoints' rows: below), in the units of the planes' robust sigma (limit_m /
    // tukey_c) squared.
    Eigen::Matrix<double, 6, 6> H_lateral = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    bool boresight_held = false;       // the last iteration held the boresight rotation near a prior
    double boresight_prior_rad = 0.0;  // the last iteration's prior on that rotation (held or fused; 0: none)
  };
  // Uses every stride-th scan point. tracking: from a prediction (T_start): scan points left unmatched are
  // not searched again, and a barely observed boresight rotation is held near T_start (boresight_prior_deg).
  // Not tracking, with T_boresight_prior: such a rotation is held near it with twice that.
  Alignment align(const Eigen::Isometry3d& T_start, double gate_m, int max_iterations, bool tracking,
                  int stride, const Eigen::Isometry3d* T_boresight_prior = nullptr);
  Alignment acquire(const Eigen::Isometry3d& T_prior);
  // Whether an alignment from T_start (tracking) may take the contours from its first iteration
  // (IcpOptions::contour_wait_px).
  bool contoursFromStart(const Eigen::Isometry3d& T_start, bool tracking) const;
  // The boresight prior's standard deviation this tracking frame (IcpOptions::boresight_prior_*), rad.
  double trackingBoresightPriorRad() const;
  // Of the hypotheses, each aligned for search_iterations, the one that explains most scan points (of those
  // that end within kMaxAcquisitionTurnRad of T_prior's attitude).
  Alignment bestOf(const std::vector<Eigen::Isometry3d>& hypotheses, double gate_m,
                   const Eigen::Isometry3d& T_prior);
  // Every stride-th scan point within explained_distance_m of the model surface visible in visible_, at T.
  int explainedPoints(const Eigen::Isometry3d& T, int stride);
  // The pose at stamp_s extrapolated at constant velocity from two (stamp s, pose), the older first; false
  // without two in time order before stamp_s.
  static bool extrapolate(const std::vector<std::pair<double, Eigen::Isometry3d>>& poses, double stamp_s,
                          Eigen::Isometry3d* T);
  double coverage() const;
  void alignRange(Eigen::Isometry3d* T);
  // Makes current a visibility prediction at T: one of the two kept (the last two made) when it was made at
  // exactly T or (tolerance_px > 0) at a pose that puts every visible model point within tolerance_px of
  // where T puts it, else a new one in place of the older. depth_only: only its depths are needed (the
  // coverage and silhouette checks), not the visible points; such a one serves no other request.
  void predictVisibility(const Eigen::Isometry3d& T, double tolerance_px = 0.0, bool depth_only = false);
  const VisibilityPredictor& visibility() const { return slots_[current_].predictor; }
  const std::vector<std::uint8_t>& visible() const { return slots_[current_].predictor.visible(); }
  // The norm (m; rotations times the correspondences' lever arm) of the move from T_from to T_to in the weak
  // directions of the lever-scaled normal equations about centre (eigen: of their first five unknowns).
  double weakPart(const Eigen::Isometry3d& T_from, const Eigen::Isometry3d& T_to,
                  const Eigen::Vector3d& centre,
                  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>>& eigen,
                  double largest) const;
  // An upper bound on how far, in pixels, a model point at a depth of at least near_m at pose a moves in the
  // image between poses a and b.
  double imageMotionPx(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b, double near_m) const;
  // H with its rotation rows and columns scaled by the correspondences' lever arm about centre.
  Eigen::Matrix<double, 6, 6> leverScaled(const Eigen::Matrix<double, 6, 6>& H,
                                          const Eigen::Vector3d& centre) const;
  // The diagonal of that scaling.
  Eigen::Matrix<double, 6, 1> leverScale(const Eigen::Vector3d& centre) const;
  // Replaces delta's part in the weak directions of H_scaled (see weak_direction_condition) by the
  // Gauss-Newton step of the tangential offsets' normal equations there (also into weak_step), from the
  // correspondences and the Tukey limit and centre of the iteration a, with_planes: together with the plane
  // fit's own (where the boresight rotation is well observed; where it is barely, the planes' weak
  // directions carried Hubble's roll 12 deg off over its approach); a step beyond gate_m (a near-singular
  // solve) is cut back, or held where the offsets carry little information.
  void stepWeakDirections(const Eigen::Matrix<double, 6, 6>& H_scaled, double largest, const Alignment& a,
                          double gate_m, bool with_planes, Eigen::Matrix<double, 6, 1>* delta,
                          Eigen::Matrix<double, 6, 1>* weak_step) const;
  // Adds the occluding contours' rows at a.T to the normal equations (H, g) of a twist about a.centre
  // (IcpOptions::contour_sigma_px): the frame's edge pairs once, the model points near them again once the
  // pose moved a pixel or the visibility changed; with_boresight_rotation: the rows measure the rotation
  // about the boresight too (else, at contour_consensus_min_depth_m and beyond, the lateral translation by
  // consensus, with no less information than min_information: *consensus). Whether any row was added.
  bool addContours(const Alignment& a, bool with_boresight_rotation, double min_information,
                   Eigen::Matrix<double, 6, 6>* H, Eigen::Matrix<double, 6, 1>* g, bool* consensus);
  // The smallest eigenvalue of H_scaled's first five unknowns (all but the boresight rotation).
  double weakestOfFive(const Eigen::Matrix<double, 6, 6>& H_scaled) const;
  // Whether lever-scaled normal equations (largest eigenvalue `largest`) constrain the rotation about the
  // boresight: its information with the other five free, over the largest eigenvalue, above
  // degraded_condition.
  bool boresightObserved(const Eigen::Matrix<double, 6, 6>& H_scaled, double largest) const;
  // That information ratio itself (0 when none).
  double boresightInformation(const Eigen::Matrix<double, 6, 6>& H_scaled, double largest) const;
  // silhouette_: the cells with a surface in the last visibility prediction, dilated by r cells.
  void markSilhouette(int r);
  // Of the scan points on the model's silhouette at the pose of the last visibility prediction (a cell with
  // a predicted surface or next to one), the fraction within limit_m of the model in the last iteration.
  double silhouetteInlierFraction(double limit_m);
  // Keeps the valid_ pixels within margin_px of the model's silhouette at T (unless too few would remain), by
  // a visibility prediction within tolerance_px of T (predictVisibility).
  void gateToSilhouette(const Eigen::Isometry3d& T, double margin_px, double tolerance_px);

  // From the next frame on, model in place of model_ (the visibility predictions and balls made with the
  // old one are dropped).
  void replaceModel(std::shared_ptr<const ReferenceModel> model);

  std::shared_ptr<const ReferenceModel> model_;
  std::unique_ptr<PanelTracker> panels_;
  ardsim_lidar::Intrinsics intrinsics_;
  IcpOptions options_;
  // The last two visibility predictions: tracking returns to the pose of the frame before after a
  // correction (a prediction off by a few pixels, then the estimate back near the last one).
  struct VisibilitySlot {
    VisibilitySlot(const ardsim_lidar::Intrinsics& intrinsics, const VisibilityOptions& options)
        : predictor(intrinsics, options), grid(intrinsics, options.margin_px) {}
    VisibilityPredictor predictor;
    int visible_points = 0;
    VisiblePointGrid grid;  // of the visible points, built when enough searches are due (IcpTracker::grid)
    bool grid_built = false;
    int tree_searches = 0;  // since the prediction, while there is no grid
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    bool valid = false;
    bool depth_only = false;  // visible and grid not made
    bool oblique = false;     // made while acquiring: oblique patches count as visible
  };
  std::array<VisibilitySlot, 2> slots_;
  int current_ = 0;
  bool acquiring_ = true;
  // (stamp s, pose) of the last TRACKING estimates in a row, at most two (IcpOptions::contour_wait_px).
  std::vector<std::pair<double, Eigen::Isometry3d>> tracked_;
  int tracked_frames_ = 0;  // tracking frames in a row before this one (IcpOptions::boresight_prior_frames)
  std::vector<std::pair<double, Eigen::Isometry3d>>
      acquired_;  // (stamp s, pose) of the last acquisition frames
  double coverage_ = 0.0;
  std::vector<Eigen::Vector3f> scan_;
  bool scan_near_ = false;  // scan_ is a tracking frame's near one (IcpOptions::max_points_near)
  // Per scan_ point: its pixel is an edge of a surface at least three pixels across (see align()).
  std::vector<std::uint8_t> scan_on_wide_edge_;
  std::vector<int> active_;  // indices of the scan_ points still searched for
  // Per scan_ point, the visible model points in a ball around where it was last searched (target frame):
  // while it stays well inside that ball, its nearest visible model point is among them (exact, and most
  // iterations move the points by millimetres). Valid for the visibility prediction they were built with.
  struct Neighbourhood {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    float radius_m = -1.0f;  // < 0: none
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
  };
  std::vector<Neighbourhood> neighbourhoods_;
  std::vector<std::uint32_t> neighbourhood_points_;  // the balls' model point indices
  int visibility_generation_ = 0;                    // counts the visibility predictions
  int neighbourhood_generation_ = -1;                // the prediction the balls were built with
  // The visible points of the current visibility prediction binned by pixel, when built or worth building
  // for the searches so far and pending_searches_ (counted as one more tree search when not: nullptr).
  const VisiblePointGrid* grid();
  int pending_searches_ = 0;  // nearest-point searches about to be made with no ball to answer them
  // The nearest visible model point to q (target frame) within the gate for scan_ point k, from its ball
  // when that answers exactly, else from the tree (and a new ball).
  int nearestVisible(int k, const Eigen::Vector3f& q, float gate_sq, float* distance_sq);
  std::vector<int> valid_;        // the frame's valid pixels: the first valid_count_
  std::vector<int> valid_cells_;  // their visibility cells
  std::size_t valid_count_ = 0;
  std::vector<int> column_cells_;               // the cell column of each pixel column
  std::vector<int> gated_;                      // the valid_ pixels near the predicted silhouette
  std::vector<std::uint8_t> silhouette_cells_;  // scratch: cells with a predicted surface
  std::vector<std::uint8_t> silhouette_rows_;   // scratch: those dilated along rows
  std::vector<std::uint8_t> silhouette_;        // see markSilhouette
  std::vector<float> scan_depth_;
  struct Correspondence {
    Eigen::Vector3d scan;    // lidar frame
    Eigen::Vector3d model;   // lidar frame, at the current pose
    Eigen::Vector3d normal;  // lidar frame
    double residual;         // along the normal, m
    double distance;         // point to point, m
    double spacing;          // the model's sample spacing there, m
  };
  std::vector<Correspondence> correspondences_;
  std::vector<double> scratch_;
  // The frame being estimated (for its occluding contours, extracted when first needed).
  const OrganizedCloud* cloud_ = nullptr;
  OccludingContours contours_;
  bool contours_extracted_ = false;
  int contour_generation_ = -1;  // the visibility prediction the contours' model points were chosen with
  Eigen::Isometry3d T_contours_ = Eigen::Isometry3d::Identity();  // ... and the pose
  // Whether the contours' consensus voted this frame (IcpOptions::contour_consensus_min_depth_m), and at
  // which pose.
  bool consensus_voted_ = false;
  Eigen::Isometry3d T_consensus_vote_ = Eigen::Isometry3d::Identity();
  // The consensus's own lateral measurements (lidar x, y) of a point of the target (the first frame's
  // correspondence centre: the contours' rotation errors move it least) in the tracking frames in a row that
  // had one, the last IcpOptions::lateral_history_frames: stamp, position (m), covariance (m^2).
  struct LateralMeasurement {
    double stamp_s;
    Eigen::Vector2d position_m;
    Eigen::Matrix2d covariance_m2;
  };
  std::vector<LateralMeasurement> lateral_history_;
  Eigen::Vector3d lateral_reference_target_ = Eigen::Vector3d::Zero();  // the point measured, target frame
  std::optional<LateralMeasurement> lateral_this_frame_;  // by its last consensus (none: no consensus)
  bool lateral_beyond_this_frame_ = false;                // ... beyond 3 sigma of the line
  // The tracking frames in a row before this one whose own measurement lay beyond 3 sigma of the line.
  int lateral_disagreeing_frames_ = 0;
  void clearLateralHistory() {
    lateral_history_.clear();
    lateral_disagreeing_frames_ = 0;
  }
  // The history's weighted straight line at stamp_s (IcpOptions::lateral_line_frames, lateral_line_sigma_m),
  // or its parabola where it accelerates (lateral_acceleration_chi2): the position and its covariance (false:
  // fewer than three measurements, or no spread in time).
  bool lateralPrior(double stamp_s, Eigen::Vector2d* position_m, Eigen::Matrix2d* covariance_m2) const;
};

}  // namespace ardsim_pose
