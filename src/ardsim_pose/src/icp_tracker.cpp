#include "ardsim_pose/icp_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "ardsim_pose/require_option.h"
#include "tukey_weight.h"

namespace ardsim_pose {

namespace {

// The acquisition search aligns and scores every kSearchStride-th scan point (speed); the final alignment
// all.
constexpr int kSearchStride = 3;
// A full alignment starts on every kCoarseStride-th scan point (a third of the nearest-neighbour queries,
// which are most of the cost) while the pose still moves by more than kCoarseFactor x the convergence
// thresholds, then goes on with all of them (at least kFineIterations of the iteration limit), so that it
// ends at the full scan's fixed point. Long slides along a weakly constrained direction (the adapter
// filling the view at 10 m) take most iterations: they run at a third of the cost.
constexpr int kCoarseStride = 3;
constexpr double kCoarseFactor = 10.0;
constexpr int kFineIterations = 3;
// How far along a contour pair's line the model's contour is looked for, px (OccludingContours' default
// window): also Tukey's limit of the contours' offsets (beyond it no pair counts anyway).
constexpr double kContourWindowPx = 3.0;
// The contours' consensus (IcpOptions::contour_consensus_min_depth_m): the translations voted over, px either
// way (a tracking prediction is millimetres off); the floor of its spread, px (the model's and the other
// unknowns' part: 0.02 and 0.04 alike on Hubble's approach datasets, 0.01 put the worst frame at 30-50 m over
// 3x the RMS in 16 of 24 runs instead of 5-6; HISTORY.md, session 37); and how far the pose moves, px, before
// the pairs vote again.
constexpr double kConsensusReachPx = 2.0;
constexpr double kConsensusFloorPx = 0.02;
// Two nested lateral lines agree below this chi^2 of their difference (position and rate: 4 degrees of
// freedom, ~14 % of agreeing pairs beyond it).
constexpr double kLateralLinesAgreeChi2 = 7.0;
constexpr double kConsensusRevotePx = 0.25;
// The first coarse iteration's sparse start (IcpOptions::sparse_start_residual_m): every
// kSparseFirstStride-th scan point.
constexpr int kSparseFirstStride = 9;
// The balls of model points kept per scan point reach this far beyond its nearest (IcpTracker::
// nearestVisible): wide enough that the iterations after the first few stay inside, narrow enough to hold
// few points.
constexpr float kNeighbourhoodMarginM = 0.03f;
// A visibility prediction's grid of visible points (VisiblePointGrid) is built once the nearest-point
// searches it would answer (the tree's so far and the ones due) times this reach its visible points: binning
// costs ~7-10 ns a point, a search answered by the grid instead of the tree saves ~0.6-0.9 us, and on the ISS
// approach dataset 60 left no range band slower than the tree alone (100: acquisition frames 5-10 % slower).
constexpr int kGridBuildRatio = 60;
// The coverage and silhouette checks of a final pose take a visibility prediction made at a pose that moves
// every visible model point less than one of its 4 px cells in the image (they allow a cell or more).
constexpr double kVisibilityTolerancePx = 4.0;
// An acquisition hypothesis aligned to an attitude further than this from the prior (good to 10 deg, and
// turned by at most search_rotation_rad) is not one of it.
constexpr double kMaxAcquisitionTurnRad = 0.5;

bool positive(double v) {
  return std::isfinite(v) && v > 0.0;
}
bool fraction(double v) {
  return std::isfinite(v) && v >= 0.0 && v <= 1.0;
}

double median(std::vector<double>* values) {
  if (values->empty()) return 0.0;
  auto middle = values->begin() + values->size() / 2;
  std::nth_element(values->begin(), middle, values->end());
  return *middle;
}

// A return is an edge pixel of a surface at least three pixels across when, along a row or a column, one
// neighbour has no return (or one more than kEdgeDepthJumpM away in depth) and the other two on the far side
// have.
constexpr float kEdgeDepthJumpM = 0.5f;
bool onWideEdge(const OrganizedCloud& cloud, int u, int v) {
  const float z = cloud.points[static_cast<std::size_t>(v) * cloud.width + u].z();
  const auto returns = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= cloud.width || y >= cloud.height) return false;
    const Eigen::Vector3f& p = cloud.points[static_cast<std::size_t>(y) * cloud.width + x];
    return isReturn(p) && std::abs(p.z() - z) < kEdgeDepthJumpM;
  };
  const auto edgeAlong = [&](int du, int dv) {
    const bool before = returns(u - du, v - dv), after = returns(u + du, v + dv);
    if (before == after) return false;
    return before ? returns(u - 2 * du, v - 2 * dv) : returns(u + 2 * du, v + 2 * dv);
  };
  return edgeAlong(1, 0) || edgeAlong(0, 1);
}

std::string format(const char* pattern, double a, double b = 0.0) {
  char text[160];
  std::snprintf(text, sizeof(text), pattern, a, b);
  return text;
}

}  // namespace

void validate(const IcpOptions& o) {
  requireOption(o.max_points >= 50 && o.max_points <= 100000, "icp/max_points", o.max_points, "50 .. 100000");
  requireOption(o.max_points_near >= 50 && o.max_points_near <= 100000, "icp/max_points_near",
                o.max_points_near, "50 .. 100000");
  requireOption(std::isfinite(o.near_depth_m) && o.near_depth_m >= 0.0 && o.near_depth_m <= 1000.0,
                "icp/near_depth_m", o.near_depth_m, "0 .. 1000");
  requireOption(o.max_iterations_tracking >= 1 && o.max_iterations_tracking <= 200,
                "icp/max_iterations_tracking", o.max_iterations_tracking, "1 .. 200");
  requireOption(o.max_iterations_acquisition >= 1 && o.max_iterations_acquisition <= 500,
                "icp/max_iterations_acquisition", o.max_iterations_acquisition, "1 .. 500");
  requireOption(positive(o.gate_min_m), "icp/gate_min_m", o.gate_min_m, "> 0");
  requireOption(positive(o.gate_tracking_m) && o.gate_tracking_m >= o.gate_min_m, "icp/gate_tracking_m",
                o.gate_tracking_m, ">= gate_min_m");
  requireOption(positive(o.gate_acquisition_m) && o.gate_acquisition_m >= o.gate_min_m,
                "icp/gate_acquisition_m", o.gate_acquisition_m, ">= gate_min_m");
  requireOption(positive(o.tukey_c), "icp/tukey_c", o.tukey_c, "> 0");
  requireOption(fraction(o.weak_direction_condition), "icp/weak_direction_condition",
                o.weak_direction_condition, "0 .. 1");
  requireOption(positive(o.degraded_weak_slide_px), "icp/degraded_weak_slide_px", o.degraded_weak_slide_px,
                "> 0");
  requireOption(std::isfinite(o.contour_sigma_px) && o.contour_sigma_px >= 0.0 && o.contour_sigma_px <= 10.0,
                "icp/contour_sigma_px", o.contour_sigma_px, "0 .. 10");
  requireOption(o.max_contour_pairs >= 0 && o.max_contour_pairs <= 1000000, "icp/max_contour_pairs",
                o.max_contour_pairs, "0 .. 1000000");
  requireOption(std::isfinite(o.contour_wait_px) && o.contour_wait_px >= 0.0 && o.contour_wait_px <= 100.0,
                "icp/contour_wait_px", o.contour_wait_px, "0 .. 100");
  requireOption(std::isfinite(o.contour_max_depth_m) && o.contour_max_depth_m >= 0.0,
                "icp/contour_max_depth_m", o.contour_max_depth_m, ">= 0");
  requireOption(!std::isnan(o.contour_consensus_min_depth_m) && o.contour_consensus_min_depth_m >= 0.0,
                "icp/contour_consensus_min_depth_m", o.contour_consensus_min_depth_m, ">= 0 (inf: never)");
  requireOption(o.lateral_history_frames >= 0 && o.lateral_history_frames <= 1000,
                "icp/lateral_history_frames", o.lateral_history_frames, "0 .. 1000");
  requireOption(o.lateral_line_frames >= 3 && o.lateral_line_frames <= 1000, "icp/lateral_line_frames",
                o.lateral_line_frames, "3 .. 1000");
  requireOption(o.lateral_line_sigma_m >= 0.0 && o.lateral_line_sigma_m <= 1.0, "icp/lateral_line_sigma_m",
                o.lateral_line_sigma_m, "0 .. 1");
  requireOption(o.lateral_gate_frames >= 1 && o.lateral_gate_frames <= 1000, "icp/lateral_gate_frames",
                o.lateral_gate_frames, "1 .. 1000");
  requireOption(o.lateral_acceleration_chi2 >= 0.0 && o.lateral_acceleration_chi2 <= 1e6,
                "icp/lateral_acceleration_chi2", o.lateral_acceleration_chi2, "0 .. 1e6");
  requireOption(o.lateral_vote_weight >= 0.0 && o.lateral_vote_weight <= 100.0, "icp/lateral_vote_weight",
                o.lateral_vote_weight, "0 .. 100");
  requireOption(positive(o.min_sigma_m), "icp/min_sigma_m", o.min_sigma_m, "> 0");
  requireOption(
      std::isfinite(o.boresight_prior_deg) && o.boresight_prior_deg >= 0.0 && o.boresight_prior_deg <= 180.0,
      "icp/boresight_prior_deg", o.boresight_prior_deg, "0 .. 180");
  requireOption(std::isfinite(o.boresight_prior_max_information) &&
                    o.boresight_prior_max_information >= 0.0 && o.boresight_prior_max_information <= 1.0,
                "icp/boresight_prior_max_information", o.boresight_prior_max_information, "0 .. 1");
  requireOption(o.boresight_prior_frames >= 0 && o.boresight_prior_frames <= 1000000,
                "icp/boresight_prior_frames", o.boresight_prior_frames, "0 .. 1000000");
  requireOption(std::isfinite(o.boresight_prior_min_deg) && o.boresight_prior_min_deg >= 0.0 &&
                    (o.boresight_prior_frames == 0 || o.boresight_prior_min_deg <= o.boresight_prior_deg),
                "icp/boresight_prior_min_deg", o.boresight_prior_min_deg,
                "0 .. boresight_prior_deg (with boresight_prior_frames > 0)");
  requireOption(std::isfinite(o.acquisition_boresight_gate_deg) && o.acquisition_boresight_gate_deg >= 0.0 &&
                    o.acquisition_boresight_gate_deg <= 180.0,
                "icp/acquisition_boresight_gate_deg", o.acquisition_boresight_gate_deg, "0 .. 180");
  requireOption(std::isfinite(o.crop_reuse_px) && o.crop_reuse_px >= 0.0 && o.crop_reuse_px <= 4.0,
                "icp/crop_reuse_px", o.crop_reuse_px, "0 .. 4");
  requireOption(std::isfinite(o.sparse_start_residual_m) && o.sparse_start_residual_m >= 0.0 &&
                    o.sparse_start_residual_m <= 1.0,
                "icp/sparse_start_residual_m", o.sparse_start_residual_m, "0 .. 1");
  requireOption(positive(o.converged_translation_m), "icp/converged_translation_m", o.converged_translation_m,
                "> 0");
  requireOption(positive(o.converged_rotation_rad), "icp/converged_rotation_rad", o.converged_rotation_rad,
                "> 0");
  requireOption(positive(o.revisibility_translation_m), "icp/revisibility_translation_m",
                o.revisibility_translation_m, "> 0");
  requireOption(positive(o.revisibility_rotation_rad), "icp/revisibility_rotation_rad",
                o.revisibility_rotation_rad, "> 0");
  requireOption(std::isfinite(o.silhouette_margin_px) && o.silhouette_margin_px >= 0.0 &&
                    o.silhouette_margin_px <= 256.0,
                "icp/silhouette_margin_px", o.silhouette_margin_px, "0 .. 256");
  requireOption(o.min_points >= 6 && o.min_points <= std::min(o.max_points, o.max_points_near),
                "icp/min_points", o.min_points, "6 .. max_points and max_points_near");
  requireOption(fraction(o.lost_inlier_fraction), "icp/lost_inlier_fraction", o.lost_inlier_fraction,
                "0 .. 1");
  requireOption(fraction(o.degraded_inlier_fraction) && o.degraded_inlier_fraction >= o.lost_inlier_fraction,
                "icp/degraded_inlier_fraction", o.degraded_inlier_fraction, "lost_inlier_fraction .. 1");
  requireOption(positive(o.lost_fit_rms_m), "icp/lost_fit_rms_m", o.lost_fit_rms_m, "> 0");
  requireOption(positive(o.degraded_fit_rms_m) && o.degraded_fit_rms_m <= o.lost_fit_rms_m,
                "icp/degraded_fit_rms_m", o.degraded_fit_rms_m, "> 0 .. lost_fit_rms_m");
  requireOption(fraction(o.lost_coverage), "icp/lost_coverage", o.lost_coverage, "0 .. 1");
  requireOption(fraction(o.degraded_coverage) && o.degraded_coverage >= o.lost_coverage,
                "icp/degraded_coverage", o.degraded_coverage, "lost_coverage .. 1");
  requireOption(fraction(o.degraded_condition), "icp/degraded_condition", o.degraded_condition, "0 .. 1");
  requireOption(positive(o.confirm_translation_m), "icp/confirm_translation_m", o.confirm_translation_m,
                "> 0");
  requireOption(positive(o.confirm_rotation_rad), "icp/confirm_rotation_rad", o.confirm_rotation_rad, "> 0");
  requireOption(positive(o.max_correction_m), "icp/max_correction_m", o.max_correction_m, "> 0");
  requireOption(positive(o.max_correction_rad), "icp/max_correction_rad", o.max_correction_rad, "> 0");
  requireOption(o.search_iterations >= 1 && o.search_iterations <= o.max_iterations_acquisition,
                "icp/search_iterations", o.search_iterations, "1 .. max_iterations_acquisition");
  requireOption(std::isfinite(o.search_offset_m) && o.search_offset_m >= 0.0 && o.search_offset_m <= 20.0,
                "icp/search_offset_m", o.search_offset_m, "0 .. 20");
  requireOption(std::isfinite(o.search_lateral_m) && o.search_lateral_m >= 0.0 && o.search_lateral_m <= 20.0,
                "icp/search_lateral_m", o.search_lateral_m, "0 .. 20");
  requireOption(positive(o.search_lateral_step_m) && o.search_lateral_step_m >= o.search_lateral_m / 20.0,
                "icp/search_lateral_step_m", o.search_lateral_step_m, "> 0, >= search_lateral_m / 20");
  requireOption(
      std::isfinite(o.search_rotation_rad) && o.search_rotation_rad >= 0.0 && o.search_rotation_rad <= 1.0,
      "icp/search_rotation_rad", o.search_rotation_rad, "0 .. 1");
  requireOption(positive(o.explained_distance_m), "icp/explained_distance_m", o.explained_distance_m, "> 0");
}

IcpTracker::IcpTracker(std::shared_ptr<const ReferenceModel> model,
                       const ardsim_lidar::Intrinsics& intrinsics, const IcpOptions& options,
                       const VisibilityOptions& visibility)
    : model_(std::move(model)),
      intrinsics_(intrinsics),
      options_(options),
      slots_{VisibilitySlot(intrinsics, visibility), VisibilitySlot(intrinsics, visibility)},
      contours_(intrinsics, options.max_contour_pairs) {
  validate(options_);
  if (!model_) throw std::invalid_argument("IcpTracker: no reference model");
  // The cell of each pixel column once (the frame's width is the sensor's, checked per frame), not two
  // integer divisions per pixel (0.1-0.2 ms a frame).
  column_cells_.resize(intrinsics_.width);
  for (int u = 0; u < intrinsics_.width; ++u) column_cells_[u] = this->visibility().cellOfPixel(u, 0);
}

void IcpTracker::replaceModel(std::shared_ptr<const ReferenceModel> model) {
  model_ = std::move(model);
  for (VisibilitySlot& slot : slots_) slot.valid = false;
  ++visibility_generation_;
}

double IcpTracker::coverage() const {
  // Of the cells where the model is predicted (inside the image), the fraction where the scan has a return
  // near the predicted depth: a different object, or the right object at a wrong pose, leaves most of them
  // empty.
  const std::vector<float>& model_depth = visibility().modelDepth();
  int predicted = 0;
  int confirmed = 0;
  const double cell_angle = visibility().cellPx() / intrinsics_.fx;
  for (std::size_t c = 0; c < model_depth.size(); ++c) {
    if (!std::isfinite(model_depth[c])) continue;
    ++predicted;
    const double tolerance = std::max(0.5, 5.0 * cell_angle * model_depth[c]);
    if (std::isfinite(scan_depth_[c]) && std::abs(scan_depth_[c] - model_depth[c]) < tolerance) ++confirmed;
  }
  return predicted > 0 ? static_cast<double>(confirmed) / predicted : 0.0;
}

void IcpTracker::alignRange(Eigen::Isometry3d* T) {
  // A prior's range can be 10 % off: metres at 100 m, more than nearest-point correspondences can pull. Move
  // the target along the line of sight by the ratio of the median scan depth to the median predicted model
  // depth, over the cells where both are present (twice: the visible model changes with the range).
  for (int pass = 0; pass < 2; ++pass) {
    predictVisibility(*T);
    const std::vector<float>& model_depth = visibility().modelDepth();
    scratch_.clear();
    std::vector<double> model_values;
    for (std::size_t c = 0; c < model_depth.size(); ++c) {
      if (!std::isfinite(model_depth[c]) || !std::isfinite(scan_depth_[c])) continue;
      scratch_.push_back(scan_depth_[c]);
      model_values.push_back(model_depth[c]);
    }
    if (scratch_.size() < 20) return;
    const double ratio = median(&scratch_) / median(&model_values);
    if (!(ratio > 0.5 && ratio < 2.0)) return;
    T->translation() *= ratio;
  }
}

Eigen::Matrix<double, 6, 1> IcpTracker::leverScale(const Eigen::Vector3d& centre) const {
  // Rotations scaled by the correspondences' lever arm about centre, so that units compare.
  double lever_sq = 0.0;
  for (const Correspondence& c : correspondences_) lever_sq += (c.model - centre).squaredNorm();
  const double lever = std::sqrt(lever_sq / std::max<std::size_t>(1, correspondences_.size()));
  Eigen::Matrix<double, 6, 1> scale;
  scale << 1, 1, 1, 1.0 / lever, 1.0 / lever, 1.0 / lever;
  return scale;
}

Eigen::Matrix<double, 6, 6> IcpTracker::leverScaled(const Eigen::Matrix<double, 6, 6>& H,
                                                    const Eigen::Vector3d& centre) const {
  const Eigen::Matrix<double, 6, 1> scale = leverScale(centre);
  return scale.asDiagonal() * H * scale.asDiagonal();
}

double IcpTracker::boresightInformation(const Eigen::Matrix<double, 6, 6>& H_scaled, double largest) const {
  // The information about the boresight rotation once the other five are free, against the largest
  // eigenvalue.
  const Eigen::Matrix<double, 6, 1> column = H_scaled.ldlt().solve(Eigen::Matrix<double, 6, 1>::Unit(5));
  return largest > 0.0 && column(5) > 0.0 ? 1.0 / column(5) / largest : 0.0;
}

bool IcpTracker::boresightObserved(const Eigen::Matrix<double, 6, 6>& H_scaled, double largest) const {
  return boresightInformation(H_scaled, largest) > options_.degraded_condition;
}

void IcpTracker::stepWeakDirections(const Eigen::Matrix<double, 6, 6>& H_scaled, double largest,
                                    const Alignment& a, double gate_m, bool with_planes,
                                    Eigen::Matrix<double, 6, 1>* delta,
                                    Eigen::Matrix<double, 6, 1>* weak_step) const {
  // The plane fit's directions (lever-scaled) with less than weak_direction_condition of its largest
  // information: the step there comes from the tangential offsets instead (none: held). Among the first five
  // unknowns only: the boresight rotation keeps its own treatment (solved, or held when unobserved); on the
  // near-symmetric docking adapter the tangential offsets turned it by 0.2 deg.
  constexpr int kFree = 5;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kFree, kFree>> eigen(
      H_scaled.topLeftCorner<kFree, kFree>());
  int weak = 0;
  while (weak < kFree && eigen.eigenvalues()(weak) < options_.weak_direction_condition * largest) ++weak;
  if (weak == 0) return;

  // Normal equations of the offsets to the nearest model points across their normals, e = P (s - m) with
  // P = 1 - n n^T, counted beyond the model's sample spacing and half the pixel's footprint (inside a surface
  // the offset is only the sampling: points past a rim or an edge give it; a rim seen by many pixels is
  // placed better than a whole footprint: with a whole one Hubble's lateral error was 3.9 cm RMS on the
  // approach dataset, with half 3.0, hubble_hold 3.2 -> 2.2 cm), Tukey-weighted as the plane residuals; a
  // twist moves e by -A (v, w), A = [P, -P [m - c]x]. Built only here: most ISS iterations have no weak
  // direction.
  const double pixel_pitch_rad = 1.0 / std::min(intrinsics_.fx, intrinsics_.fy);
  const Eigen::Isometry3f T_target_lidar = a.T.inverse().cast<float>();
  Eigen::Matrix<double, 6, 6> H_tangential = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g_tangential = Eigen::Matrix<double, 6, 1>::Zero();
  double largest_offset_m = 0.0;  // beyond the sampling
  for (const Correspondence& c : correspondences_) {
    const double w = tukeyWeight(c.residual, a.limit_m);
    if (w == 0.0) continue;
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - c.normal * c.normal.transpose();
    const Eigen::Vector3d e = P * (c.scan - c.model);
    const double e_norm = e.norm();
    const double sampling = std::max(c.spacing, 0.5 * c.scan.norm() * pixel_pitch_rad);
    if (e_norm <= sampling) continue;
    // Where the visibility crop left out nearer samples of the model (a patch judged hidden), the offset to
    // the nearest visible one is the crop's, not the pose's: only where the model really ends is it
    // information. (A single ISS frame at 30 m slid 0.12 m on such offsets.)
    const float sampling_sq = static_cast<float>(sampling * sampling);
    if (model_->anyWithin(T_target_lidar * c.scan.cast<float>(), sampling_sq)) continue;
    Eigen::Matrix<double, 3, 6> A;
    A.leftCols<3>() = P;
    A.rightCols<3>() = -P * skew(c.model - a.centre);
    H_tangential.noalias() += w * A.transpose() * A;
    g_tangential.noalias() += (w * (1.0 - sampling / e_norm)) * A.transpose() * e;
    largest_offset_m = std::max(largest_offset_m, e_norm - sampling);
  }

  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(6, weak);  // scaled coordinates
  U.topRows(kFree) = eigen.eigenvectors().leftCols(weak);
  const Eigen::Matrix<double, 6, 1> scale = leverScale(a.centre);
  const Eigen::MatrixXd D = scale.asDiagonal() * U;  // the same directions, unscaled
  // The plane step's part in those directions, removed (in scaled coordinates, where U is orthonormal).
  Eigen::Matrix<double, 6, 1> y = delta->cwiseQuotient(scale);
  const Eigen::VectorXd y_weak = U.transpose() * y;
  y -= U * y_weak;
  *delta = y.cwiseProduct(scale);
  Eigen::MatrixXd H_weak = D.transpose() * H_tangential * D;
  const double tangential_trace = H_weak.trace();
  Eigen::VectorXd g_weak = D.transpose() * g_tangential;
  if (with_planes) {
    // The plane fit's own step there (y_weak, information its eigenvalue) weighs in with the offsets': from
    // 0.2 m off at 30 m the offsets alone crept 1-2 cm an iteration and a benchmark frame stopped 6.6 cm
    // short after 15 (with both: 0.8 mm).
    for (int k = 0; k < weak; ++k) {
      H_weak(k, k) += eigen.eigenvalues()(k);
      g_weak(k) += eigen.eigenvalues()(k) * y_weak(k);
    }
  }
  const Eigen::VectorXd z = H_weak.ldlt().solve(g_weak);
  if (z.allFinite() && tangential_trace > 0.0) {
    *weak_step = D * z;
    // A few offsets that barely constrain a weak direction make their normal equations near singular: the
    // step then ran to hundreds of metres (Hubble end-on, 27 m). A step (lever-scaled) beyond the
    // correspondence gate is that, not data: it is cut to the largest offset (closing the offsets never
    // takes more), or held where the offsets weigh less than a third of one fully weighted offset: a stray
    // point (a mixed pixel past a rim), not a rim (one such, 0.39 m off, slid an ISS frame at 7 m by 0.3 m).
    const double size_m = weak_step->cwiseQuotient(scale).norm();
    if (size_m > gate_m) {
      if (tangential_trace < 0.3) {
        weak_step->setZero();
        return;
      }
      *weak_step *= largest_offset_m / size_m;
    }
    *delta += *weak_step;
  }
}

bool IcpTracker::addContours(const Alignment& a, bool with_boresight_rotation, double min_information,
                             Eigen::Matrix<double, 6, 6>* H, Eigen::Matrix<double, 6, 1>* g,
                             bool* consensus) {
  *consensus = false;
  if (cloud_ == nullptr || slots_[current_].depth_only) return false;
  if (!contours_extracted_) {
    contours_.extract(*cloud_, gated_);
    contours_extracted_ = true;
    contour_generation_ = -1;
  }
  if (contours_.pairs() == 0) return false;
  // The model points are chosen two pixels beyond the window around each pair: again after a pixel's move.
  if (contour_generation_ != visibility_generation_ ||
      imageMotionPx(T_contours_, a.T, visibility().nearestDepth()) > 1.0) {
    contours_.selectCandidates(*model_, visibility().visiblePatches(), a.T);
    contour_generation_ = visibility_generation_;
    T_contours_ = a.T;
  }
  const double sigma_m = a.limit_m / options_.tukey_c;
  if (!with_boresight_rotation && visibility().nearestDepth() >= options_.contour_consensus_min_depth_m) {
    *consensus = true;
    // The vote again after the pose moved a quarter pixel (the members chosen there may not hold at the new
    // pose: from an approach dataset's predictions 0.5 m off in range, two of 24 runs slid 1-2 cm off), else
    // the same members: a vote at every iteration moved the winner from cell to cell with the pose, and the
    // members with it (the datasets at 30-50 m, 32 of 960 frames at the iteration limit).
    const bool vote = !consensus_voted_ ||
                      imageMotionPx(T_consensus_vote_, a.T, visibility().nearestDepth()) > kConsensusRevotePx;
    if (vote) consensus_voted_ = true, T_consensus_vote_ = a.T;
    // The line through the history (IcpOptions::lateral_history_frames), of the point it follows: the
    // consensus's translation moves every point alike.
    if (lateral_history_.empty() && !lateral_this_frame_)
      lateral_reference_target_ = a.T.inverse() * a.centre;
    const Eigen::Vector2d reference_m = (a.T * lateral_reference_target_).head<2>();
    Eigen::Vector2d prior_m;
    Eigen::Matrix2d prior_covariance_m2;
    const bool prior = lateralPrior(cloud_->stamp_s, &prior_m, &prior_covariance_m2);
    OccludingContours::VotePrior vote_prior;
    if (prior) vote_prior = {prior_m - reference_m, prior_covariance_m2, options_.lateral_vote_weight};
    if (contours_.accumulateConsensus(a.T, sigma_m, kConsensusReachPx, kConsensusFloorPx, min_information,
                                      vote, H, g, prior ? &vote_prior : nullptr) == 0)
      return false;
    // This frame's own measurement, for the history.
    lateral_this_frame_ = LateralMeasurement{cloud_->stamp_s, reference_m + contours_.consensusMean(),
                                             contours_.consensusCovariance()};
    lateral_beyond_this_frame_ = false;
    if (prior) {
      const Eigen::Vector2d disagreement = lateral_this_frame_->position_m - prior_m;
      const Eigen::Matrix2d combined = prior_covariance_m2 + lateral_this_frame_->covariance_m2;
      lateral_beyond_this_frame_ = disagreement.dot(combined.ldlt().solve(disagreement)) >= 9.0;  // 3 sigma
      // Beyond it, the line still counts in a first frame (IcpOptions::lateral_gate_frames): there it was the
      // vote that went wrong, not the path.
      if (!lateral_beyond_this_frame_ || lateral_disagreeing_frames_ + 1 < options_.lateral_gate_frames) {
        const Eigen::Matrix2d information = (sigma_m * sigma_m) * prior_covariance_m2.inverse();
        H->topLeftCorner<2, 2>() += information;
        g->head<2>() += information * (prior_m - reference_m);
      }
    }
    return true;
  }
  return contours_.accumulate(with_boresight_rotation, a.T, a.centre, sigma_m, options_.contour_sigma_px,
                              kContourWindowPx, H, g) > 0;
}

bool IcpTracker::lateralPrior(double stamp_s, Eigen::Vector2d* position_m,
                              Eigen::Matrix2d* covariance_m2) const {
  if (lateral_history_.size() < 3) return false;
  // position(t) = p + (t - stamp_s) v [+ (t - stamp_s)^2 / 2 a], weighted by each measurement's information;
  // the unknowns (p, v[, a]) in the first 4 [6] of line and C.
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  auto design = [&](const LateralMeasurement& m) {
    const double dt = m.stamp_s - stamp_s;
    Eigen::Matrix<double, 2, 6> J;
    J << Eigen::Matrix2d::Identity(), dt * Eigen::Matrix2d::Identity(),
        0.5 * dt * dt * Eigen::Matrix2d::Identity();
    return J;
  };
  // Fixed-size inverses: this runs in every alignment iteration of a frame with the consensus.
  auto invert = [](const auto& N, auto* C) {
    const Eigen::FullPivLU<std::decay_t<decltype(N)>> lu(N);
    if (!lu.isInvertible()) return false;
    *C = lu.inverse();
    return true;
  };
  auto fit = [&](std::size_t first, bool accelerating, Vector6d* line, Matrix6d* C) {
    if (lateral_history_.size() - first < (accelerating ? 4u : 3u)) return false;
    Matrix6d N = Matrix6d::Zero();
    Vector6d b = Vector6d::Zero();
    for (std::size_t k = first; k < lateral_history_.size(); ++k) {
      const LateralMeasurement& m = lateral_history_[k];
      const Eigen::Matrix<double, 2, 6> J = design(m);
      const Eigen::Matrix2d W = m.covariance_m2.inverse();
      N += J.transpose() * W * J;
      b += J.transpose() * W * m.position_m;
    }
    C->setZero();
    line->setZero();
    if (accelerating) {
      if (!invert(N, C)) return false;
      *line = *C * b;
    } else {
      Eigen::Matrix4d C_line;
      if (!invert(Eigen::Matrix4d(N.topLeftCorner<4, 4>()), &C_line)) return false;
      C->topLeftCorner<4, 4>() = C_line;
      line->head<4>() = C_line * b.head<4>();
    }
    return line->allFinite() && C->allFinite();
  };
  // The fit's chi^2 over the frames from first on.
  auto misfit = [&](std::size_t first, const Vector6d& line) {
    double chi2 = 0.0;
    for (std::size_t k = first; k < lateral_history_.size(); ++k) {
      const LateralMeasurement& m = lateral_history_[k];
      const Eigen::Vector2d r = m.position_m - design(m) * line;
      chi2 += r.dot(m.covariance_m2.ldlt().solve(r));
    }
    return chi2;
  };
  // The newest lateral_line_frames' line; the whole history's where that one is weak and the two agree
  // (IcpOptions::lateral_line_sigma_m).
  const std::size_t newest = static_cast<std::size_t>(options_.lateral_line_frames);
  const std::size_t first = lateral_history_.size() > newest ? lateral_history_.size() - newest : 0;
  Vector6d line;
  Matrix6d C;
  if (!fit(first, false, &line, &C)) return false;
  if (first > 0 && std::sqrt(0.5 * C.topLeftCorner<2, 2>().trace()) > options_.lateral_line_sigma_m) {
    Vector6d line_all;
    Matrix6d C_all;
    if (fit(0, false, &line_all, &C_all)) {
      // The longer line's estimate is the more precise of two nested ones, so their difference has the
      // covariance C - C_all (Hausman); position and rate both, or two lines through a jump cross.
      const Eigen::Vector4d d = (line - line_all).head<4>();
      const Eigen::LLT<Eigen::Matrix4d> llt((C - C_all).topLeftCorner<4, 4>());
      if (llt.info() == Eigen::Success && d.dot(llt.solve(d)) < kLateralLinesAgreeChi2)
        line = line_all, C = C_all;
    }
  }
  // Where the whole history accelerates and its parabola fits it (IcpOptions::lateral_acceleration_chi2), the
  // newest frames' parabola.
  if (options_.lateral_acceleration_chi2 > 0.0) {
    Vector6d parabola;
    Matrix6d C_parabola;
    if (fit(0, true, &parabola, &C_parabola)) {
      const Eigen::Vector2d a = parabola.tail<2>();
      const Eigen::LLT<Eigen::Matrix2d> llt(C_parabola.bottomRightCorner<2, 2>());
      const double dof = 2.0 * static_cast<double>(lateral_history_.size()) - 6.0;
      if (llt.info() == Eigen::Success && a.dot(llt.solve(a)) > options_.lateral_acceleration_chi2 &&
          misfit(0, parabola) < dof + 3.0 * std::sqrt(2.0 * dof) && fit(first, true, &parabola, &C_parabola))
        line = parabola, C = C_parabola;
    }
  }
  *position_m = line.head<2>();
  *covariance_m2 = C.topLeftCorner<2, 2>();
  return true;
}

double IcpTracker::weakestOfFive(const Eigen::Matrix<double, 6, 6>& H_scaled) const {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>>(H_scaled.topLeftCorner<5, 5>(),
                                                                    Eigen::EigenvaluesOnly)
      .eigenvalues()(0);
}

double IcpTracker::weakPart(const Eigen::Isometry3d& T_from, const Eigen::Isometry3d& T_to,
                            const Eigen::Vector3d& centre,
                            const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>>& eigen,
                            double largest) const {
  // The twist (v, w) about centre from T_from to T_to (p' = p + w x (p - centre) + v, as the steps), in the
  // lever-scaled coordinates of the normal equations, projected on the eigenvectors of the first five
  // unknowns whose information is below weak_direction_condition of the largest.
  const Eigen::AngleAxisd turn(T_to.linear() * T_from.linear().transpose());
  const Eigen::Vector3d w = turn.angle() * turn.axis();
  const Eigen::Vector3d v =
      T_to.translation() - T_from.translation() - w.cross(T_from.translation() - centre);
  Eigen::Matrix<double, 6, 1> twist;
  twist << v, w;
  const Eigen::Matrix<double, 6, 1> scaled = twist.cwiseQuotient(leverScale(centre));
  Eigen::Matrix<double, 5, 1> weak = Eigen::Matrix<double, 5, 1>::Zero();
  for (int k = 0; k < 5 && eigen.eigenvalues()(k) < options_.weak_direction_condition * largest; ++k)
    weak += eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).dot(scaled.head<5>());
  return weak.norm();
}

double IcpTracker::imageMotionPx(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b,
                                 double near_m) const {
  // A point p moves by (R - 1) p + t from pose a to b: at most angle |p| + |t|, and |p| <= k z with k the
  // secant of the image corner's ray; over its depth z (at least near_m) in pixels. (Not the nearest
  // return's depth: background returns and hot pixels a metre away made every pose change "large".)
  // A prediction with no model surface in view (infinite depth) serves no other pose.
  if (!std::isfinite(near_m)) return std::numeric_limits<double>::infinity();
  const Eigen::Isometry3d moved = T_b * T_a.inverse();
  const double tan_x = (intrinsics_.cx + 0.5) / intrinsics_.fx,
               tan_y = (intrinsics_.cy + 0.5) / intrinsics_.fy;
  const double secant = std::sqrt(1.0 + tan_x * tan_x + tan_y * tan_y);
  const double angle = Eigen::AngleAxisd(moved.linear()).angle();
  return std::max(intrinsics_.fx, intrinsics_.fy) *
         (secant * angle + moved.translation().norm() / std::max(near_m, 1e-3));
}

void IcpTracker::predictVisibility(const Eigen::Isometry3d& T, double tolerance_px, bool depth_only) {
  // Acquiring, from a pose good to ~10 deg, the surfaces seen too obliquely to return are not known: a
  // crop without them lost the ISS from the coarse prior at 9 m (VisibilityOptions::max_incidence_deg).
  const bool oblique = acquiring_;
  auto serves = [&](const VisibilitySlot& slot) {
    return slot.valid && (depth_only || (!slot.depth_only && slot.oblique == oblique)) &&
           (T.matrix() == slot.pose.matrix() ||
            (tolerance_px > 0.0 &&
             imageMotionPx(slot.pose, T, slot.predictor.nearestDepth()) <= tolerance_px));
  };
  if (serves(slots_[current_])) return;
  current_ = 1 - current_;
  ++visibility_generation_;
  VisibilitySlot& slot = slots_[current_];
  if (serves(slot)) return;
  slot.visible_points = slot.predictor.predict(*model_, T, !depth_only, oblique);
  slot.pose = T;
  slot.valid = true;
  slot.depth_only = depth_only;
  slot.oblique = oblique;
  slot.grid_built = false;
  slot.tree_searches = 0;
}

void IcpTracker::markSilhouette(int r) {
  const std::vector<float>& model_depth = visibility().modelDepth();
  const int w = visibility().gridWidth(), h = visibility().gridHeight();
  // Square dilation of the silhouette's cells by r, separably: each cell ORs the cells up to r either side
  // along its row, then along its column, a shift at a time (byte loops the compiler vectorizes).
  silhouette_cells_.resize(model_depth.size());
  for (std::size_t i = 0; i < model_depth.size(); ++i) silhouette_cells_[i] = std::isfinite(model_depth[i]);
  silhouette_rows_.assign(model_depth.size(), 0);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* in = silhouette_cells_.data() + y * w;
    std::uint8_t* out = silhouette_rows_.data() + y * w;
    for (int d = -std::min(r, w - 1); d <= std::min(r, w - 1); ++d)
      for (int x = std::max(0, -d); x < std::min(w, w - d); ++x) out[x] |= in[x + d];
  }
  silhouette_.assign(model_depth.size(), 0);
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = silhouette_.data() + y * w;
    for (int row = std::max(0, y - r); row <= std::min(h - 1, y + r); ++row) {
      const std::uint8_t* in = silhouette_rows_.data() + row * w;
      for (int x = 0; x < w; ++x) out[x] |= in[x];
    }
  }
}

double IcpTracker::silhouetteInlierFraction(double limit_m) {
  markSilhouette(1);
  auto on_silhouette = [&](const Eigen::Vector3d& p) {
    if (!(p.z() > 0.0)) return false;
    const double u = intrinsics_.fx * p.x() / p.z() + intrinsics_.cx + 0.5;
    const double v = intrinsics_.fy * p.y() / p.z() + intrinsics_.cy + 0.5;
    if (!(u >= 0.0 && v >= 0.0 && u < intrinsics_.width && v < intrinsics_.height)) return false;
    return silhouette_[visibility().cellOfPixel(static_cast<int>(u), static_cast<int>(v))] != 0;
  };
  int on = 0, inliers = 0;
  for (const Eigen::Vector3f& s : scan_) on += on_silhouette(s.cast<double>()) ? 1 : 0;
  for (const Correspondence& c : correspondences_) {
    if (std::abs(c.residual) < limit_m && on_silhouette(c.scan)) ++inliers;
  }
  return on > 0 ? static_cast<double>(inliers) / on : 0.0;
}

void IcpTracker::gateToSilhouette(const Eigen::Isometry3d& T, double margin_px, double tolerance_px) {
  const auto keepAll = [&] { gated_.assign(valid_.begin(), valid_.begin() + valid_count_); };
  if (!(margin_px > 0.0)) return keepAll();
  predictVisibility(T, tolerance_px);
  const int r = static_cast<int>(std::ceil(margin_px / visibility().cellPx()));
  if (r >= std::max(visibility().gridWidth(), visibility().gridHeight())) return keepAll();
  markSilhouette(r);
  // Written by index, the count advanced by the flag (no branch, no capacity check per pixel).
  gated_.resize(valid_count_);
  std::size_t count = 0;
  for (std::size_t k = 0; k < valid_count_; ++k) {
    gated_[count] = valid_[k];
    count += silhouette_[valid_cells_[k]];
  }
  gated_.resize(count);
  if (static_cast<int>(gated_.size()) < options_.min_points) keepAll();
}

const VisiblePointGrid* IcpTracker::grid() {
  VisibilitySlot& slot = slots_[current_];
  if (!slot.grid_built) {
    // Worth building once the searches it would answer outweigh binning every visible point.
    if ((slot.tree_searches + pending_searches_) * kGridBuildRatio < slot.visible_points) {
      ++slot.tree_searches;
      return nullptr;
    }
    slot.grid.build(*model_, slot.predictor.visibleRanges(), slot.pose, slot.predictor.nearestDepth());
    slot.grid_built = true;
  }
  return &slot.grid;
}

int IcpTracker::nearestVisible(int k, const Eigen::Vector3f& q, float gate_sq, float* distance_sq) {
  Neighbourhood& ball = neighbourhoods_[k];
  if (ball.radius_m > 0.0f) {
    // Points outside the ball lie at least radius - |q - centre| from q (a hair less for rounding).
    const float reach = 0.999f * ball.radius_m - (q - ball.centre).norm();
    if (reach > 0.0f) {
      float best_sq = gate_sq;
      int best = -1;
      for (std::uint32_t i = ball.begin; i < ball.end; ++i) {
        const float d = model_->distanceSq(q, neighbourhood_points_[i]);
        if (d < best_sq) {
          best_sq = d;
          best = static_cast<int>(neighbourhood_points_[i]);
        }
      }
      if (best_sq <= reach * reach) {  // found, or none within a gate inside the ball
        *distance_sq = best_sq;
        return best;
      }
    }
  }
  ball.centre = q;
  ball.begin = static_cast<std::uint32_t>(neighbourhood_points_.size());
  int j = -1;
  const VisiblePointGrid* binned = grid();
  if (binned == nullptr || !binned->nearest(q, gate_sq, &j, distance_sq, kNeighbourhoodMarginM,
                                            &ball.radius_m, &neighbourhood_points_))
    j = model_->nearestVisibleWithNeighbours(q, gate_sq, visible(), kNeighbourhoodMarginM, distance_sq,
                                             &ball.radius_m, &neighbourhood_points_);
  ball.end = static_cast<std::uint32_t>(neighbourhood_points_.size());
  return j;
}

IcpTracker::Alignment IcpTracker::align(const Eigen::Isometry3d& T_start, double gate, int max_iterations,
                                        bool tracking, int stride,
                                        const Eigen::Isometry3d* T_boresight_prior) {
  Alignment a;
  a.T = T_start;
  const auto selectActive = [&](int every) {
    active_.clear();
    for (std::size_t k = 0; k < scan_.size(); k += every) active_.push_back(static_cast<int>(k));
  };
  neighbourhood_generation_ = -1;  // the balls of an earlier alignment are of other scan points
  // Coarse first only where a third of the points is still plenty and the limit leaves room for it.
  bool coarse = stride == 1 && max_iterations > kFineIterations &&
                static_cast<int>(scan_.size()) >= 2 * kCoarseStride * options_.min_points;
  // Tracking beyond near_depth_m, the first coarse iteration searches a third of those first (see
  // kSparseFirstStride), and the rest only when those lie near the model.
  bool sparse_first = coarse && tracking && !scan_near_ && options_.sparse_start_residual_m > 0.0 &&
                      static_cast<int>(scan_.size()) >= 2 * kSparseFirstStride * options_.min_points;
  selectActive(sparse_first ? kSparseFirstStride : coarse ? kCoarseStride : stride);
  Eigen::Isometry3d& T = a.T;
  predictVisibility(T, tracking ? options_.crop_reuse_px : 0.0);  // tracking: the gate's
  Eigen::Isometry3d T_visibility = T;
  bool contours_on = contoursFromStart(T_start, tracking);
  Eigen::Matrix<double, 6, 1> previous_fine_step = Eigen::Matrix<double, 6, 1>::Zero();
  bool previous_was_fine = false;
  for (; a.iterations < max_iterations && !a.converged; ++a.iterations) {
    if (sparse_first && a.iterations == 1 && coarse) selectActive(kCoarseStride);  // after a sparse step
    const Eigen::Isometry3d moved = T_visibility.inverse() * T;
    if (moved.translation().norm() > options_.revisibility_translation_m ||
        Eigen::AngleAxisd(moved.linear()).angle() > options_.revisibility_rotation_rad) {
      predictVisibility(T);
      T_visibility = T;
    }
    const Eigen::Isometry3f T_target_lidar = T.inverse().cast<float>();
    const Eigen::Matrix3d R = T.linear();
    pending_searches_ = 0;  // after the first iteration on a prediction, most answers come from the balls
    if (neighbourhood_generation_ != visibility_generation_) {
      neighbourhoods_.assign(scan_.size(), Neighbourhood{});
      neighbourhood_points_.clear();
      neighbourhood_generation_ = visibility_generation_;
      // Each point searched now, and in the fine stage after a coarse one the rest too.
      pending_searches_ = static_cast<int>(coarse ? scan_.size() : active_.size());
    }
    const float gate_sq = static_cast<float>(gate * gate);
    const auto correspond = [&] {
      correspondences_.clear();
      std::size_t kept = 0;
      for (const int k : active_) {
        const Eigen::Vector3f& s = scan_[k];
        float distance_sq = 0.0f;
        const int j = nearestVisible(k, T_target_lidar * s, gate_sq, &distance_sq);
        if (j < 0) continue;
        // Once tracking, a point with no model point within the (only shrinking) gate stays unmatched: the
        // solar arrays, background returns. Searching for it again each iteration is the costliest query.
        if (tracking) active_[kept++] = k;
        // The edge rows of a turned array (Hubble's, 4 cm thick, seen obliquely) return ~2 cm off the model's
        // planes, one whole pixel row at once where the edge lies along it: with their ~6 m levers they
        // turned the estimate 0.03-0.06 deg about the arrays' in-plane axis over a 0.7 m window of range
        // (noise-free renders at 49 m). Such pixels do not count against a part that turns; thin structures
        // (masts, booms: 1-2 pixels) and the rigid parts' edges do.
        if (scan_on_wide_edge_[k] && model_->pointArticulated(static_cast<std::uint32_t>(j))) continue;
        Correspondence c;
        c.scan = s.cast<double>();
        c.model = T * model_->points()[j].cast<double>();
        c.normal = R * model_->normals()[j].cast<double>();
        c.residual = c.normal.dot(c.scan - c.model);
        c.distance = std::sqrt(static_cast<double>(distance_sq));
        c.spacing = model_->spacing()[j];
        correspondences_.push_back(c);
      }
      if (tracking) active_.resize(kept);
    };
    correspond();
    if (sparse_first && a.iterations == 0) {
      // Where the sparse points' median plane residual is below sparse_start_residual_m, the prediction is
      // good and the first step small: search the whole coarse set now (the sparse points answered by their
      // balls), as with no sparse start. (Not the point distances: far out the model's spacing alone puts
      // the nearest point centimetres away.)
      scratch_.clear();
      for (const Correspondence& c : correspondences_) scratch_.push_back(std::abs(c.residual));
      if (static_cast<int>(correspondences_.size()) < options_.min_points ||
          median(&scratch_) < options_.sparse_start_residual_m) {
        sparse_first = false;
        selectActive(kCoarseStride);
        correspond();
      }
    }
    if (static_cast<int>(correspondences_.size()) < options_.min_points) {
      a.failure = "too few correspondences with the model: " + std::to_string(correspondences_.size()) +
                  " < " + std::to_string(options_.min_points);
      return a;
    }

    scratch_.clear();
    for (const Correspondence& c : correspondences_) scratch_.push_back(std::abs(c.residual));
    const double sigma = std::max(options_.min_sigma_m, 1.4826 * median(&scratch_));
    const double limit = options_.tukey_c * sigma;
    a.limit_m = limit;
    a.centre.setZero();
    for (const Correspondence& c : correspondences_) a.centre += c.model;
    a.centre /= static_cast<double>(correspondences_.size());

    // Normal equations of the point-to-plane residual for a twist (v, w) about `centre` (conditioning):
    // p' = p + w x (p - centre) + v.
    a.H.setZero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    a.inliers = 0;
    a.inlier_sq_sum = 0.0;
    a.weight_sum = 0.0;
    a.weighted_sq_sum = 0.0;
    for (const Correspondence& c : correspondences_) {
      const double w = tukeyWeight(c.residual, limit);
      if (w == 0.0) continue;
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = c.normal;
      J.tail<3>() = (c.model - a.centre).cross(c.normal);
      a.H.noalias() += w * J * J.transpose();
      g.noalias() += w * c.residual * J;
      ++a.inliers;
      a.inlier_sq_sum += c.residual * c.residual;
      a.weight_sum += w;
      a.weighted_sq_sum += w * c.residual * c.residual;
    }
    if (a.inliers < options_.min_points) {
      a.failure =
          "too few inliers: " + std::to_string(a.inliers) + " < " + std::to_string(options_.min_points);
      return a;
    }
    // A rotation about the boresight that the scan does not constrain (the roll of a cylinder such as Hubble
    // about its axis) is held at its prediction: left free it wanders on noise and never converges.
    Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 6> H = a.H;
    Eigen::Matrix<double, 6, 6> H_scaled = leverScaled(H, a.centre);
    double largest =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(H_scaled, Eigen::EigenvaluesOnly)
            .eigenvalues()(5);
    // The planes' information about the boresight rotation decides its prior (the contours add to it below,
    // but whether the roll needs holding was tuned on the planes': Hubble's datasets, with the contours' roll
    // in tracking then, 30-50 m attitude RMS max 0.032 -> 0.027 deg this way).
    const double boresight_information = boresightInformation(H_scaled, largest);
    bool consensus_used = false;
    // Where the planes leave directions weak (Hubble's bulkhead face-on: across it, and its roll), the
    // occluding contours measure them too (IcpOptions::contour_sigma_px). The quality checks stay the
    // planes', and so does the covariance but for the consensus below (the midpoints' residuals are not
    // independent, and a composite pose takes ICP's roll where its covariance says it is good: with the
    // midpoints in it, it took Hubble's at 10-20 m, from contours near the port, 0.14 deg RMS off there
    // instead of 0.02).
    // The boresight rotation from them only while acquiring (from a coarse prior, a dataset run's first
    // frame 1.7 deg off without): tracking, it stays the planes' and the prior's, which average it over
    // frames; the contours' sub-pixel errors last for frames in a slow approach (hubble_hold, lidar seeds 2 /
    // 23: ICP 30-50 m attitude RMS 0.030 / 0.032 deg with them, 0.021 / 0.024 without).
    if (options_.contour_sigma_px > 0.0 && contours_on &&
        (options_.contour_max_depth_m <= 0.0 || visibility().nearestDepth() < options_.contour_max_depth_m) &&
        (weakestOfFive(H_scaled) < options_.weak_direction_condition * largest ||
         (options_.contours_for_boresight &&
          boresight_information < options_.boresight_prior_max_information)) &&
        // The consensus at no less than twice the weak directions' limit: below it the tangential offsets
        // took its directions over (the approach datasets with a floor of 0.02 px and no such bound: frames
        // at 47-50 m 1-4 cm off).
        addContours(a, !tracking, 2.0 * options_.weak_direction_condition * largest, &H, &g,
                    &consensus_used)) {
      H_scaled = leverScaled(H, a.centre);
      largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(H_scaled, Eigen::EigenvaluesOnly)
                    .eigenvalues()(5);
    }
    // The covariance takes the consensus and the line, not the midpoints' rows: those along one edge share
    // its sub-pixel phase, and inside 10 m a pixel is small against the tilt's and the model's errors, so
    // their information overstates (Hubble's approach datasets, ICP alone, 0-10 m: the port's lateral error
    // 2.8-3.6 times the sigma they give).
    if (consensus_used)
      a.H_lateral = H - a.H;
    else
      a.H_lateral.setZero();
    const bool boresight_well_observed = boresight_information >= 10.0 * options_.degraded_condition;
    if (boresight_information > options_.degraded_condition) {
      // Tracking, with the boresight rotation barely observed (below 10 x the observed limit: Hubble's
      // bulkhead end-on, the ISS's docking adapter filling the view; the ISS from 12 m out is above): a prior
      // at the prediction (T_start) of boresight_prior_deg, in the units of the normal equations (the robust
      // sigma squared over the prior's). Without it the rotation wandered 10-20 deg a frame on noise there.
      Eigen::Matrix<double, 6, 6> H_solve = H;
      Eigen::Matrix<double, 6, 1> g_solve = g;
      const Eigen::Isometry3d* T_prior = tracking ? &T_start : T_boresight_prior;
      const bool prior = T_prior != nullptr && options_.boresight_prior_deg > 0.0;
      a.boresight_held = prior && boresight_information < options_.boresight_prior_max_information;
      const double prior_rad =
          tracking ? trackingBoresightPriorRad() : 2.0 * options_.boresight_prior_deg * M_PI / 180.0;
      const Eigen::AngleAxisd turn(prior ? Eigen::Matrix3d(T.linear() * T_prior->linear().transpose())
                                         : Eigen::Matrix3d::Identity());
      bool fused = a.boresight_held;
      if (!fused && prior && tracking && (!coarse || scan_near_) && options_.boresight_prior_when_observed) {
        // Observed, and tracking: the prior fused with the scan's (IcpOptions::boresight_prior_when_observed)
        // in the fine stage (the coarse one finds the alignment: from the benchmark's guesses, 0.2 m and 0.5
        // deg off, the prior there cost the 100 m frames 14 % more instructions; inside near_depth_m it is
        // in the coarse one too, where the docking adapter's roll jumps: session 47's closed loops, 7-12 m,
        // the worst attitude frame 4.97 -> 3.11x the RMS, the 10 m frames' instructions +0.3 %), where the
        // scan's own rotation (a step without the prior) lies within 3 sigma of the prediction's, the two
        // sigmas combined: a prediction that is off (a change of rate, those guesses) is not followed.
        const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt = H.ldlt();
        const double own_rad = turn.angle() * turn.axis().z() + ldlt.solve(g)(5);
        const double own_variance = sigma * sigma * ldlt.solve(Eigen::Matrix<double, 6, 1>::Unit(5))(5);
        fused = own_rad * own_rad < 9.0 * (own_variance + prior_rad * prior_rad);
      }
      a.boresight_prior_rad = fused ? prior_rad : 0.0;
      if (fused) {
        const double information = sigma * sigma / (prior_rad * prior_rad);
        H_solve(5, 5) += information;
        g_solve(5) -= information * turn.angle() * turn.axis().z();
      }
      delta = H_solve.ldlt().solve(g_solve);
    } else {
      a.boresight_held = false;
      a.boresight_prior_rad = 0.0;
      delta.head<5>() = H.topLeftCorner<5, 5>().ldlt().solve(g.head<5>());
    }
    // The weak directions' part of the step (from the tangential offsets), judged on its own below.
    Eigen::Matrix<double, 6, 1> weak_step = Eigen::Matrix<double, 6, 1>::Zero();
    if (options_.weak_direction_condition > 0.0)
      stepWeakDirections(H_scaled, largest, a, gate, boresight_well_observed, &delta, &weak_step);
    if (!delta.allFinite()) {
      a.failure = "diverged: singular normal equations";
      return a;
    }
    // Nearest neighbours that trade places between two poses make a 2-cycle, the same small step back and
    // forth (the ISS 10 m out, acquired from the truth with 5000 scan points: 1.2e-5 rad a step, just over
    // converged_rotation_rad, for 36 iterations, so that the acquisition never converged and every frame
    // acquired again). Two small steps that cancel end at their midpoint.
    const bool cycle = !coarse && previous_was_fine &&
                       delta.head<3>().norm() < kCoarseFactor * options_.converged_translation_m &&
                       delta.tail<3>().norm() < kCoarseFactor * options_.converged_rotation_rad &&
                       (delta + previous_fine_step).head<3>().norm() < options_.converged_translation_m &&
                       (delta + previous_fine_step).tail<3>().norm() < options_.converged_rotation_rad;
    previous_fine_step = delta;
    previous_was_fine = !coarse;
    if (cycle) {
      delta *= 0.5;
      weak_step *= 0.5;
    }

    const Eigen::Vector3d v = delta.head<3>();
    const Eigen::Vector3d w = delta.tail<3>();
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    if (w.norm() > 0.0) step.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    step.translation() = a.centre + v - step.linear() * a.centre;
    contours_on =
        contours_on || imageMotionPx(T, step * T, visibility().nearestDepth()) < options_.contour_wait_px;
    T = step * T;
    if (coarse) {
      if ((v.norm() < kCoarseFactor * options_.converged_translation_m &&
           w.norm() < kCoarseFactor * options_.converged_rotation_rad) ||
          a.iterations + 1 >= max_iterations - kFineIterations) {
        coarse = false;
        selectActive(stride);
      }
    } else {
      // The tangential offsets only creep to their end (a point counts once it is a spacing past the rim):
      // their part of the step converges at kCoarseFactor x the thresholds.
      const Eigen::Matrix<double, 6, 1> strong_step = delta - weak_step;
      a.converged = cycle || (strong_step.head<3>().norm() < options_.converged_translation_m &&
                              strong_step.tail<3>().norm() < options_.converged_rotation_rad &&
                              weak_step.head<3>().norm() < kCoarseFactor * options_.converged_translation_m &&
                              weak_step.tail<3>().norm() < kCoarseFactor * options_.converged_rotation_rad);
    }

    if (gate > options_.gate_min_m) {  // at its floor (most iterations) the gate stays: no median needed
      scratch_.clear();
      for (const Correspondence& c : correspondences_) scratch_.push_back(c.distance);
      gate = std::clamp(4.0 * median(&scratch_), options_.gate_min_m, gate);
    }
  }
  // The visibility of the final pose, for the coverage and silhouette checks: most tracking frames end
  // within the tolerance of their prediction, or of the one before (the pose of the frame before, when the
  // prediction was off). Tracking needs only its depths; the acquisition search scores the visible points.
  predictVisibility(T, kVisibilityTolerancePx, tracking);
  return a;
}

int IcpTracker::explainedPoints(const Eigen::Isometry3d& T, int stride) {
  const Eigen::Isometry3f T_target_lidar = T.inverse().cast<float>();
  const float reach = static_cast<float>(options_.gate_min_m);
  int explained = 0;
  pending_searches_ = static_cast<int>(scan_.size()) / stride;
  for (std::size_t k = 0; k < scan_.size(); k += stride) {
    const Eigen::Vector3f q = T_target_lidar * scan_[k];
    float distance_sq = 0.0f;
    int j = -1;
    const VisiblePointGrid* binned = grid();
    if (binned == nullptr || !binned->nearest(q, reach * reach, &j, &distance_sq))
      j = model_->nearestVisible(q, reach * reach, visible(), &distance_sq);
    if (j >= 0 && std::abs(model_->normals()[j].dot(q - model_->points()[j])) < options_.explained_distance_m)
      ++explained;
  }
  return explained;
}

IcpTracker::Alignment IcpTracker::bestOf(const std::vector<Eigen::Isometry3d>& hypotheses, double gate_m,
                                         const Eigen::Isometry3d& T_prior) {
  Alignment best;
  best.failure = "no hypothesis";
  int best_explained = -1;
  for (const Eigen::Isometry3d& hypothesis : hypotheses) {
    Alignment a = align(hypothesis, gate_m, options_.search_iterations, false, kSearchStride);
    if (!a.failure.empty()) {
      if (best_explained < 0) best = a;
      continue;
    }
    // A near-symmetric target (Hubble end-on) fits as well turned half a turn about its axis, and a brief
    // ICP with the boresight rotation barely observed can swing there (126-174 deg from a 7 deg turn): the
    // prior decides (it is good to 10 deg).
    if (Eigen::AngleAxisd(a.T.linear() * T_prior.linear().transpose()).angle() > kMaxAcquisitionTurnRad) {
      if (best_explained < 0)
        best.failure = format("every hypothesis turned more than %.0f deg from the prior",
                              kMaxAcquisitionTurnRad * 180.0 / M_PI);
      continue;
    }
    const int explained = explainedPoints(a.T, kSearchStride);
    if (explained > best_explained) {
      best_explained = explained;
      best = a;
    }
  }
  return best;
}

bool IcpTracker::contoursFromStart(const Eigen::Isometry3d& T_start, bool tracking) const {
  // A prediction within the contours' window of where the last two TRACKING estimates carry on to finds its
  // model contours there (the closed loop's are millimetres off); others wait for a small step
  // (IcpOptions::contour_wait_px). (Not within the window of the last estimate itself: at 1 m/s, the
  // hand-over gtest's, a good prediction is 6 px from it at 12 m.)
  if (options_.contour_wait_px <= 0.0) return true;
  Eigen::Isometry3d T_carried;
  return tracking && cloud_ != nullptr && extrapolate(tracked_, cloud_->stamp_s, &T_carried) &&
         imageMotionPx(T_carried, T_start, visibility().nearestDepth()) < kContourWindowPx;
}

double IcpTracker::trackingBoresightPriorRad() const {
  double prior_deg = options_.boresight_prior_deg;
  if (options_.boresight_prior_frames > 0 && tracked_frames_ > options_.boresight_prior_frames) {
    prior_deg = std::max(options_.boresight_prior_min_deg,
                         prior_deg * std::sqrt(static_cast<double>(options_.boresight_prior_frames) /
                                               static_cast<double>(tracked_frames_)));
  }
  return prior_deg * M_PI / 180.0;
}

IcpTracker::Alignment IcpTracker::acquire(const Eigen::Isometry3d& T_prior) {
  // 1. Range from the depths, then the prior, lateral offsets of it and turns about the scan's centroid, each
  // aligned briefly with the wide gate; the one that explains most scan points wins.
  Eigen::Isometry3d T0 = T_prior;
  alignRange(&T0);
  std::vector<Eigen::Isometry3d> hypotheses;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      Eigen::Isometry3d T = T0;
      T.translation() += options_.search_offset_m * Eigen::Vector3d(i, j, 0.0);
      hypotheses.push_back(T);
    }
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& s : scan_) centroid += s.cast<double>();
  centroid /= static_cast<double>(scan_.size());
  for (int axis = 0; axis < 3 && options_.search_rotation_rad > 0.0; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
      turn.linear() = Eigen::AngleAxisd(sign * options_.search_rotation_rad, Eigen::Vector3d::Unit(axis))
                          .toRotationMatrix();
      turn.translation() = centroid - turn.linear() * centroid;
      hypotheses.push_back(turn * T0);
    }
  }
  const Alignment coarse = bestOf(hypotheses, options_.gate_acquisition_m, T_prior);
  if (!coarse.failure.empty()) return coarse;

  // 2. The structure repeats itself (truss bays) and slides along itself where the field of view clips it:
  // local minima lie a bay apart across the boresight. Score a dense lateral grid around the coarse pose
  // (without ICP, with its visibility) and align the best few cells.
  struct Cell {
    int explained;
    Eigen::Isometry3d T;
  };
  std::vector<Cell> cells;
  const int steps = static_cast<int>(std::round(options_.search_lateral_m / options_.search_lateral_step_m));
  for (int i = -steps; i <= steps; ++i) {
    for (int j = -steps; j <= steps; ++j) {
      Eigen::Isometry3d T = coarse.T;
      T.translation() += options_.search_lateral_step_m * Eigen::Vector3d(i, j, 0.0);
      cells.push_back({explainedPoints(T, kSearchStride), T});
    }
  }
  const std::size_t keep = std::min<std::size_t>(cells.size(), 3);
  std::partial_sort(cells.begin(), cells.begin() + keep, cells.end(),
                    [](const Cell& a, const Cell& b) { return a.explained > b.explained; });
  hypotheses = {coarse.T};
  for (std::size_t k = 0; k < keep; ++k) hypotheses.push_back(cells[k].T);
  const Alignment fine = bestOf(hypotheses, options_.gate_tracking_m, T_prior);
  if (!fine.failure.empty()) return fine;
  const Alignment own =
      align(fine.T, options_.gate_tracking_m, options_.max_iterations_acquisition, false, 1);
  // 3. From the second acquisition frame on, a barely observed boresight rotation near the prediction's is
  // held near it (IcpOptions::acquisition_boresight_gate_deg).
  if (!own.failure.empty() || acquired_.empty() || options_.acquisition_boresight_gate_deg <= 0.0) return own;
  const Eigen::AngleAxisd turn(own.T.linear() * T_prior.linear().transpose());
  if (std::abs(turn.angle() * turn.axis().z()) > options_.acquisition_boresight_gate_deg * M_PI / 180.0)
    return own;
  const Alignment held =
      align(own.T, options_.gate_tracking_m, options_.max_iterations_acquisition, false, 1, &T_prior);
  return held.failure.empty() ? held : own;
}

bool IcpTracker::extrapolate(const std::vector<std::pair<double, Eigen::Isometry3d>>& poses, double stamp_s,
                             Eigen::Isometry3d* T) {
  if (poses.size() < 2) return false;
  const auto& [t_a, T_a] = poses[poses.size() - 2];
  const auto& [t_b, T_b] = poses.back();
  if (!(t_b > t_a && stamp_s > t_b)) return false;
  const double scale = (stamp_s - t_b) / (t_b - t_a);
  const Eigen::AngleAxisd turn(T_b.linear() * T_a.linear().transpose());
  *T = T_b;
  T->translation() += scale * (T_b.translation() - T_a.translation());
  T->linear() = Eigen::AngleAxisd(scale * turn.angle(), turn.axis()).toRotationMatrix() * T_b.linear();
  return true;
}

PoseResult IcpTracker::estimate(const OrganizedCloud& cloud, const Eigen::Isometry3d& T_predicted) {
  bool aligned = false;
  const PoseResult tracked = processFrame(cloud, T_predicted, &aligned);
  if (tracked.acquiring || tracked.status != EstimateStatus::kLost || !aligned) return tracked;
  // A tracking frame that loses the target (a prediction beyond the tracking gate: a frame dropped, a
  // faster motion than the last two estimates said) searches for it again at once, as the next frame would:
  // the dataset at 1 m a frame lost its second frame (the prediction, with no velocity yet, 1 m off) where
  // the acquisition search finds it (DEGRADED while acquiring, as any acquisition frame).
  PoseResult searched = processFrame(cloud, T_predicted, &aligned);
  searched.reason = "tracking lost (" + tracked.reason + "), searched again: " + searched.reason;
  return searched;
}

PoseResult IcpTracker::processFrame(const OrganizedCloud& cloud, const Eigen::Isometry3d& T_predicted,
                                    bool* aligned) {
  *aligned = false;
  PoseResult result;
  result.method = EstimateMethod::kIcp;
  result.T_lidar_target = T_predicted;
  coverage_ = 0.0;
  scan_.clear();
  const bool acquiring = acquiring_;
  result.acquiring = acquiring;
  auto lost = [&](const std::string& reason) {
    tracked_frames_ = 0;
    tracked_.clear();
    clearLateralHistory();
    result.status = EstimateStatus::kLost;
    result.reason = reason;
    result.covariance.setZero();
    acquiring_ = true;
    acquired_.clear();
    return result;
  };
  if (cloud.points.empty()) return lost("empty frame: no points");
  if (cloud.width != intrinsics_.width || cloud.height != intrinsics_.height ||
      cloud.points.size() != static_cast<std::size_t>(cloud.width) * cloud.height) {
    std::ostringstream reason;
    reason << "frame " << cloud.width << "x" << cloud.height << " with " << cloud.points.size()
           << " points does not match the sensor (" << intrinsics_.width << "x" << intrinsics_.height << ")";
    return lost(reason.str());
  }

  // Valid returns, and the nearest return per visibility cell (for the coverage check).
  scan_depth_.assign(static_cast<std::size_t>(visibility().gridWidth()) * visibility().gridHeight(),
                     std::numeric_limits<float>::infinity());
  // Written by index into vectors sized for every pixel (no capacity check per return: 0.18 -> 0.10 ms a
  // 256 x 256 frame), and not cut to the count after (the next frame's resize would zero what it cut).
  valid_.resize(cloud.points.size());
  valid_cells_.resize(cloud.points.size());
  std::size_t valid_count = 0;
  const Eigen::Vector3f* points = cloud.points.data();
  float* scan_depth = scan_depth_.data();
  for (int v = 0; v < cloud.height; ++v) {
    const int row_cell = visibility().cellOfPixel(0, v);
    const int row = v * cloud.width;
    for (int u = 0; u < cloud.width; ++u) {
      const Eigen::Vector3f& p = points[row + u];
      if (!isReturn(p)) continue;
      const int cell = row_cell + column_cells_[u];
      valid_[valid_count] = row + u;
      valid_cells_[valid_count] = cell;
      ++valid_count;
      scan_depth[cell] = std::min(scan_depth[cell], p.z());
    }
  }
  valid_count_ = valid_count;
  if (valid_count == 0) return lost("empty frame: no valid returns");
  if (static_cast<int>(valid_count) < options_.min_points)
    return lost("too few points: " + std::to_string(valid_count) + " valid returns < " +
                std::to_string(options_.min_points));
  // Every k-th valid pixel near the predicted silhouette (evenly spread, deterministic), at most max_points.
  double margin_px = options_.silhouette_margin_px;
  if (acquiring && margin_px > 0.0) {
    const double range_m = std::max(1.0, T_predicted.translation().norm());
    margin_px += (options_.search_lateral_m + options_.search_offset_m) / range_m * intrinsics_.fx;
  }
  // Tracking: a visibility prediction (and its grid) made at a pose near enough serves this frame's gate and
  // crop too (IcpOptions::crop_reuse_px).
  gateToSilhouette(T_predicted, margin_px, acquiring ? 0.0 : options_.crop_reuse_px);
  // The gate's visibility prediction (or, with no gate, the last one) says how near the model is. Tracking
  // only: the acquisition search, ~25 alignments, would cost twice as much (9 m frames from the coarse
  // prior).
  const bool near =
      !acquiring && slots_[current_].valid && visibility().nearestDepth() < options_.near_depth_m;
  scan_near_ = near;
  const std::size_t count =
      std::min<std::size_t>(gated_.size(), near ? options_.max_points_near : options_.max_points);
  scan_.reserve(count);
  scan_on_wide_edge_.clear();
  const bool parts_turn = model_->hasArticulatedParts();  // the edge flags matter only against those
  for (std::size_t k = 0; k < count; ++k) {
    const int i = gated_[k * gated_.size() / count];
    scan_.push_back(cloud.points[i]);
    scan_on_wide_edge_.push_back(parts_turn && onWideEdge(cloud, i % cloud.width, i / cloud.width) ? 1 : 0);
  }

  cloud_ = &cloud;
  contours_extracted_ = false;
  consensus_voted_ = false;
  lateral_this_frame_.reset();
  lateral_beyond_this_frame_ = false;
  *aligned = true;
  const Alignment a =
      acquiring ? acquire(T_predicted)
                : align(T_predicted, options_.gate_tracking_m, options_.max_iterations_tracking, true, 1);
  cloud_ = nullptr;
  if (!a.failure.empty()) return lost(a.failure);
  const Eigen::Isometry3d& T = a.T;
  const Eigen::Matrix<double, 6, 6>& H = a.H;
  const Eigen::Vector3d& centre = a.centre;
  const bool converged = a.converged;
  const int iteration = a.iterations;
  const int inliers = a.inliers;
  const double inlier_sq_sum = a.inlier_sq_sum;
  const double weight_sum = a.weight_sum;
  const double weighted_sq_sum = a.weighted_sq_sum;
  result.iterations = iteration;
  result.points_used = static_cast<int>(scan_.size());
  result.T_lidar_target = T;
  result.T_lidar_target.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  result.fit_rms_m = std::sqrt(inlier_sq_sum / std::max(1, inliers));
  result.inlier_fraction = silhouetteInlierFraction(a.limit_m);

  // Covariance of (v, w) about the centre from the last normal equations, the boresight rotation's prior
  // included where the last iteration took it (its sigma then bounds that rotation's: a roll averaged over
  // frames by the prior is known better than one frame's planes say), and the contours' consensus with the
  // lateral line where they were in it (Alignment::H_lateral: Hubble's rim across the boresight to ~0.5 mm,
  // where the planes alone said 2-3 mm), mapped to the target origin's position and the rotation:
  // delta_origin = v + w x (origin - centre). H_lateral was weighed in the robust sigma's units, the
  // covariance is in the residuals' variance: rescaled. (The composite pose, which takes ICP's roll by this
  // covariance, runs nearer than the consensus: 10-20 m for Hubble, and the ISS has none.)
  const double dof = std::max(1.0, weight_sum - 6.0);
  const double variance = std::max(weighted_sq_sum / dof, options_.min_sigma_m * options_.min_sigma_m);
  const double robust_sigma_m = a.limit_m / options_.tukey_c;
  Eigen::Matrix<double, 6, 6> H_posterior = H + (variance / (robust_sigma_m * robust_sigma_m)) * a.H_lateral;
  if (a.boresight_prior_rad > 0.0)
    H_posterior(5, 5) += variance / (a.boresight_prior_rad * a.boresight_prior_rad);
  result.covariance = covarianceAt(
      variance * H_posterior.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity()), T.translation() - centre);

  // Condition of the lever-scaled normal equations.
  const Eigen::Matrix<double, 6, 6> H_scaled = leverScaled(H, centre);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(H_scaled);
  const double largest = eigen.eigenvalues()(5);
  const double condition = largest > 0.0 ? eigen.eigenvalues()(0) / largest : 0.0;
  result.boresight_rotation_observed = boresightObserved(H_scaled, largest);
  result.boresight_rotation_held = !acquiring && a.boresight_held;
  // With the boresight rotation unobserved (held at its prediction, flagged), the pose is still good when
  // the other five are well constrained: judge the condition of those five.
  // The weakest of the five unknowns besides the boresight rotation, relative to the largest: also what
  // says whether the weak-direction step was taken (weak_direction_condition).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> eigen_of_five(
      H_scaled.topLeftCorner<5, 5>());
  const double condition_of_five = largest > 0.0 ? eigen_of_five.eigenvalues()(0) / largest : 0.0;
  const double condition_of_the_rest = result.boresight_rotation_observed ? condition : condition_of_five;

  coverage_ = coverage();
  const double correction_m = (T.translation() - T_predicted.translation()).norm();
  // Rotation between two poses, in lidar axes; the boresight part left out when it is not observed (a
  // symmetric target's roll is arbitrary: acquisition frames may disagree about it and still be right).
  const bool boresight_observed = result.boresight_rotation_observed;
  auto turn_rad = [boresight_observed](const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
    const Eigen::AngleAxisd turn(R_b * R_a.transpose());
    Eigen::Vector3d r = turn.angle() * turn.axis();
    if (!boresight_observed) r.z() = 0.0;
    return r.norm();
  };
  const double correction_rad = turn_rad(T_predicted.linear(), T.linear());
  std::vector<std::string> degraded;
  if (!acquiring &&
      (correction_m > options_.max_correction_m || correction_rad > options_.max_correction_rad))
    return lost(format("diverged: %.2f m / %.2f deg from the prediction", correction_m,
                       correction_rad * 180.0 / M_PI));
  // A boresight rotation judged unobserved at the end may still have turned in the iterations where it was
  // observed: more than the divergence limit, and the frame is not TRACKING (an ISS frame at 7 m rolled 15
  // deg about the docking adapter's near-symmetric axis and was reported TRACKING).
  const double turn_from_prediction_rad =
      Eigen::AngleAxisd(T.linear() * T_predicted.linear().transpose()).angle();
  if (!acquiring && turn_from_prediction_rad > options_.max_correction_rad)
    degraded.push_back(format("boresight rotation barely observed: %.2f deg from the prediction",
                              turn_from_prediction_rad * 180.0 / M_PI));
  if (result.inlier_fraction < options_.lost_inlier_fraction)
    return lost(format("poor fit: inlier fraction %.2f < %.2f", result.inlier_fraction,
                       options_.lost_inlier_fraction));
  if (result.fit_rms_m > options_.lost_fit_rms_m)
    return lost(format("poor fit: rms %.3f m > %.3f m", result.fit_rms_m, options_.lost_fit_rms_m));
  if (coverage_ < options_.lost_coverage)
    return lost(format("model not seen: coverage %.2f < %.2f", coverage_, options_.lost_coverage));
  if (!converged) degraded.push_back("not converged in " + std::to_string(iteration) + " iterations");
  if (result.inlier_fraction < options_.degraded_inlier_fraction)
    degraded.push_back(format("inlier fraction %.2f", result.inlier_fraction));
  if (result.fit_rms_m > options_.degraded_fit_rms_m)
    degraded.push_back(format("fit rms %.3f m", result.fit_rms_m));
  if (coverage_ < options_.degraded_coverage) degraded.push_back(format("coverage %.2f", coverage_));
  const double footprint_m = T.translation().norm() / std::min(intrinsics_.fx, intrinsics_.fy);
  if (options_.weak_direction_condition > 0.0 && largest > 0.0 &&
      condition_of_five < options_.weak_direction_condition) {
    // Only the correction's part in the weak directions counts: a step along a well observed one (Hubble's
    // range, its bulkhead seen face-on) is measured, not slid.
    const double weak_slide_m = weakPart(T_predicted, T, a.centre, eigen_of_five, largest);
    if (weak_slide_m > options_.degraded_weak_slide_px * footprint_m)
      degraded.push_back(format("weakly observed directions: %.3f m from the prediction > %.3f m",
                                weak_slide_m, options_.degraded_weak_slide_px * footprint_m));
  }
  if (condition_of_the_rest < options_.degraded_condition)
    degraded.push_back(format("poorly constrained (condition %.1e)", condition));
  // Acquisition ends when a frame agrees with the one before (its prediction), or with the constant-velocity
  // extrapolation of the two acquisition estimates before (the target moves during acquisition): a local
  // minimum of a single frame is not reported as TRACKING.
  if (degraded.empty() && acquiring) {
    const bool agrees_with_previous =
        correction_m <= options_.confirm_translation_m && correction_rad <= options_.confirm_rotation_rad;
    Eigen::Isometry3d T_extrapolated;
    bool agrees_with_motion = false;
    if (!agrees_with_previous && extrapolate(acquired_, cloud.stamp_s, &T_extrapolated)) {
      agrees_with_motion =
          (T.translation() - T_extrapolated.translation()).norm() <= options_.confirm_translation_m &&
          turn_rad(T_extrapolated.linear(), T.linear()) <= options_.confirm_rotation_rad;
    }
    if (!agrees_with_previous && !agrees_with_motion)
      degraded.push_back(format("acquiring: %.3f m / %.3f deg from the previous frame", correction_m,
                                correction_rad * 180.0 / M_PI));
  }
  if (acquiring) {
    acquired_.push_back({cloud.stamp_s, T});
    if (acquired_.size() > 2) acquired_.erase(acquired_.begin());
  }
  tracked_frames_ = acquiring ? 0 : tracked_frames_ + 1;
  if (!acquiring && degraded.empty()) {
    tracked_.emplace_back(cloud.stamp_s, T);
    if (tracked_.size() > 2) tracked_.erase(tracked_.begin());
  } else {
    tracked_.clear();
  }
  if (!acquiring && degraded.empty() && lateral_this_frame_ && options_.lateral_history_frames > 0) {
    lateral_disagreeing_frames_ = lateral_beyond_this_frame_ ? lateral_disagreeing_frames_ + 1 : 0;
    lateral_history_.push_back(*lateral_this_frame_);
    if (static_cast<int>(lateral_history_.size()) > options_.lateral_history_frames)
      lateral_history_.erase(lateral_history_.begin());
  } else {
    clearLateralHistory();
  }
  if (degraded.empty()) {
    result.status = EstimateStatus::kTracking;
    acquiring_ = false;
    acquired_.clear();
  } else {
    result.status = EstimateStatus::kDegraded;
    for (const std::string& reason : degraded) result.reason += (result.reason.empty() ? "" : "; ") + reason;
  }
  if (panels_) {
    if (std::shared_ptr<const ReferenceModel> model = panels_->update(cloud, result.T_lidar_target))
      replaceModel(std::move(model));
  }
  return result;
}

}  // namespace ardsim_pose
