#include "ardsim_pose/close_range/pyramid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Eigenvalues>

namespace ardsim_pose {
namespace close_range {

namespace {

// Bounds of part k of n equal parts of [begin, end).
int split(int begin, int end, int k, int n) {
  return begin + (end - begin) * k / n;
}

}  // namespace

PyramidMethod::PyramidMethod(const AdapterGeometry& geometry, const PyramidOptions& options)
    : options_(options), fitter_(geometry, options.fit) {}

PyramidMethod::CellSums& PyramidMethod::CellSums::operator+=(const CellSums& other) {
  s_r += other.s_r;
  s_u += other.s_u;
  s_v += other.s_v;
  s_uu += other.s_uu;
  s_uv += other.s_uv;
  s_vv += other.s_vv;
  s_ur += other.s_ur;
  s_vr += other.s_vr;
  s_p += other.s_p;
  s_pp += other.s_pp;
  count += other.count;
  ring += other.ring;
  behind += other.behind;
  return *this;
}

void PyramidMethod::cellSums(const Eigen::Isometry3d& T_port_lidar, const PyramidCell& cell, CellSums* sums,
                             std::vector<int>* ring_pixels) const {
  const AdapterGeometry& g = fitter_.geometry();
  double s_r = 0, s_ur = 0, s_vr = 0;
  // The pixel coordinates' sums are integers, exact in double too: kept in integer registers (fewer
  // floating-point accumulators to spill, the same sums).
  std::int64_t s_u = 0, s_v = 0, s_uu = 0, s_uv = 0, s_vv = 0;
  Eigen::Vector3d s_p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d s_pp = Eigen::Matrix3d::Zero();
  int count = 0, ring = 0, behind = 0;
  ring_pixels->clear();
  for (int v = cell.v0; v < cell.v1; ++v) {
    for (int u = cell.u0; u < cell.u1; ++u) {
      const int i = v * frame_.width + u;
      if (!frame_.isValid(i)) continue;
      const double r = frame_.range_m[i];
      const Eigen::Vector3d p = frame_.points[i].cast<double>();
      ++count;
      s_r += r;
      s_u += u;
      s_v += v;
      s_uu += u * u;
      s_uv += u * v;
      s_vv += v * v;
      s_ur += u * r;
      s_vr += v * r;
      s_p += p;
      s_pp.noalias() += p * p.transpose();
      const Eigen::Vector3d q = T_port_lidar * p;
      // The square root only for the pixels in the ring's depth band: computed for every pixel, its latency
      // was a third of the pass.
      bool in_ring = false;
      if (std::abs(q.x()) < options_.ring_band_m) {
        const double radius = std::sqrt(q.y() * q.y() + q.z() * q.z());
        in_ring = radius > g.ring_inner_radius_m - options_.lateral_margin_m &&
                  radius < g.ring_outer_radius_m + options_.lateral_margin_m;
      }
      if (in_ring) {
        ++ring;
        ring_pixels->push_back(i);
      } else if (q.x() < -options_.behind_m) {
        ++behind;
      }
    }
  }
  sums->s_r = s_r;
  sums->s_u = static_cast<double>(s_u);
  sums->s_v = static_cast<double>(s_v);
  sums->s_uu = static_cast<double>(s_uu);
  sums->s_uv = static_cast<double>(s_uv);
  sums->s_vv = static_cast<double>(s_vv);
  sums->s_ur = s_ur;
  sums->s_vr = s_vr;
  sums->s_p = s_p;
  sums->s_pp = s_pp;
  sums->count = count;
  sums->ring = ring;
  sums->behind = behind;
}

void PyramidMethod::cellFeatures(const CellSums& sums, PyramidCell* cell) const {
  cell->count = sums.count;
  if (sums.count < options_.min_cell_pixels) return;
  const double n = sums.count;
  cell->mean_range_m = sums.s_r / n;
  // Range slopes: least squares r = a + slope_u (u - mean u) + slope_v (v - mean v).
  Eigen::Matrix2d A;
  A << sums.s_uu - sums.s_u * sums.s_u / n, sums.s_uv - sums.s_u * sums.s_v / n,
      sums.s_uv - sums.s_u * sums.s_v / n, sums.s_vv - sums.s_v * sums.s_v / n;
  const Eigen::Vector2d b(sums.s_ur - sums.s_u * sums.s_r / n, sums.s_vr - sums.s_v * sums.s_r / n);
  const Eigen::Vector2d slope = A.ldlt().solve(b);
  cell->slope_u = slope(0);
  cell->slope_v = slope(1);
  const Eigen::Vector3d mean = sums.s_p / n;
  const Eigen::Matrix3d cov = sums.s_pp / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  cell->normal = eig.eigenvectors().col(0);
  if (cell->normal.z() > 0.0) cell->normal = -cell->normal;
  cell->rms_m = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
  cell->ring_fraction = sums.ring / n;
  cell->behind_fraction = sums.behind / n;
}

Eigen::Isometry3d PyramidMethod::alignRange(const Eigen::Isometry3d& T_lidar_port_predicted) const {
  // Level 0: along the predicted port axis, the depth histogram of the points inside the ring's annulus peaks
  // at the ring's face; move the prediction there (a fast approach outruns the band of the cell features).
  const AdapterGeometry& g = fitter_.geometry();
  // Only while the whole annulus is in view (beyond ~3.4 m); nearer, the passage's wall and the petals fill
  // that window too.
  const double half_view =
      std::tan(0.5 * options_.fit.pixel_pitch_rad * std::min(frame_.width, frame_.height));
  if (T_lidar_port_predicted.translation().z() * half_view < g.ring_outer_radius_m)
    return T_lidar_port_predicted;
  const Eigen::Isometry3d T_port_lidar = T_lidar_port_predicted.inverse();
  constexpr double kBin = 0.01, kHalfSpan = 0.5;
  constexpr int kBins = static_cast<int>(2 * kHalfSpan / kBin);
  std::array<int, kBins> histogram{};
  const double r_in = g.ring_inner_radius_m + 0.02, r_out = g.ring_outer_radius_m - 0.02;
  for (int i = 0; i < frame_.width * frame_.height; ++i) {
    if (!frame_.isValid(i)) continue;
    const Eigen::Vector3d q = T_port_lidar * frame_.points[i].cast<double>();
    const double r2 = q.y() * q.y() + q.z() * q.z();
    if (r2 < r_in * r_in || r2 > r_out * r_out) continue;
    const int bin = static_cast<int>(std::floor((q.x() + kHalfSpan) / kBin));
    if (bin >= 0 && bin < kBins) ++histogram[bin];
  }
  int best = kBins / 2, best_count = 0;
  for (int bin = 1; bin + 1 < kBins; ++bin) {
    const int count = histogram[bin - 1] + histogram[bin] + histogram[bin + 1];
    if (count > best_count) {
      best_count = count;
      best = bin;
    }
  }
  if (best_count < options_.fit.min_edge_points) return T_lidar_port_predicted;
  const double shift = (best + 0.5) * kBin - kHalfSpan;  // ring face at port x = shift
  Eigen::Isometry3d T = T_lidar_port_predicted;
  T.translation() += shift * T.linear().col(0);
  return T;
}

PoseResult PyramidMethod::estimate(const OrganizedCloud& cloud,
                                   const Eigen::Isometry3d& T_lidar_target_predicted) {
  prepareFrame(cloud, options_.fit, &frame_);
  const Eigen::Isometry3d T_lidar_port_predicted =
      T_lidar_target_predicted * fitter_.geometry().T_target_port;
  const Eigen::Isometry3d T_lidar_port_prior = alignRange(T_lidar_port_predicted);
  const Eigen::Isometry3d T_port_lidar = T_lidar_port_prior.inverse();
  const double predicted_range = T_lidar_port_prior.translation().norm();
  const double cell_area = frame_.width * frame_.height / 9.0;

  // Level 1. One pass over the frame sums the fine cells, which tile the coarse ones: a coarse cell's sums
  // are its fine cells' (level 2 then costs nothing per pixel, and the ring-band pixels are kept from the
  // pass).
  fine_.clear();
  const auto fineCell = [](const PyramidCell& coarse, int k) {
    PyramidCell cell;
    cell.u0 = split(coarse.u0, coarse.u1, k % 3, 3);
    cell.u1 = split(coarse.u0, coarse.u1, k % 3 + 1, 3);
    cell.v0 = split(coarse.v0, coarse.v1, k / 3, 3);
    cell.v1 = split(coarse.v0, coarse.v1, k / 3 + 1, 3);
    return cell;
  };
  for (int k = 0; k < 9; ++k) {
    PyramidCell& cell = coarse_[k];
    cell = PyramidCell();
    cell.u0 = split(0, frame_.width, k % 3, 3);
    cell.u1 = split(0, frame_.width, k % 3 + 1, 3);
    cell.v0 = split(0, frame_.height, k / 3, 3);
    cell.v1 = split(0, frame_.height, k / 3 + 1, 3);
    CellSums sums;
    for (int f = 0; f < 9; ++f) {
      cellSums(T_port_lidar, fineCell(cell, f), &fine_sums_[9 * k + f], &fine_ring_pixels_[9 * k + f]);
      sums += fine_sums_[9 * k + f];
    }
    cellFeatures(sums, &cell);
    if (cell.count >= options_.min_fill * cell_area &&
        cell.ring_fraction >= options_.min_ring_fraction_coarse &&
        std::abs(cell.mean_range_m - predicted_range) <= options_.max_range_offset_m) {
      cell.verdict = PyramidCell::Verdict::kPromising;
    }
  }

  // Level 2.
  std::vector<Eigen::Vector3d> candidate_normals;
  std::vector<int> fine_slots;  // fine_[m]'s index into fine_sums_ and fine_ring_pixels_
  for (int c = 0; c < 9; ++c) {
    const PyramidCell& coarse = coarse_[c];
    if (coarse.verdict != PyramidCell::Verdict::kPromising) continue;
    for (int k = 0; k < 9; ++k) {
      PyramidCell cell = fineCell(coarse, k);
      cellFeatures(fine_sums_[9 * c + k], &cell);
      fine_slots.push_back(9 * c + k);
      if (cell.count < options_.min_cell_pixels) {
        fine_.push_back(cell);
        continue;
      }
      if (cell.ring_fraction >= options_.min_face_fraction && cell.rms_m <= options_.max_cell_rms_m) {
        cell.verdict = PyramidCell::Verdict::kFace;
        candidate_normals.push_back(cell.normal);
      } else if (cell.ring_fraction >= options_.min_edge_fraction &&
                 cell.behind_fraction >= options_.min_edge_fraction) {
        cell.verdict = PyramidCell::Verdict::kEdge;
      }
      fine_.push_back(cell);
    }
  }
  // Consensus normal of the face cells: the component-wise median.
  Eigen::Vector3d consensus = T_lidar_port_prior.linear().col(0);
  if (!candidate_normals.empty()) {
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> values;
      for (const Eigen::Vector3d& normal : candidate_normals) values.push_back(normal(axis));
      std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
      consensus(axis) = values[values.size() / 2];
    }
    consensus.normalize();
  }
  const double max_cos = std::cos(options_.max_normal_deviation_deg * M_PI / 180.0);
  ring_pixels_.clear();
  for (std::size_t m = 0; m < fine_.size(); ++m) {
    PyramidCell& cell = fine_[m];
    if (cell.verdict == PyramidCell::Verdict::kFace && cell.normal.dot(consensus) < max_cos) {
      cell.verdict = PyramidCell::Verdict::kRejected;
    }
    if (cell.verdict != PyramidCell::Verdict::kFace && cell.verdict != PyramidCell::Verdict::kEdge) continue;
    const std::vector<int>& pixels = fine_ring_pixels_[fine_slots[m]];
    ring_pixels_.insert(ring_pixels_.end(), pixels.begin(), pixels.end());
  }
  // Too few passing cells (the ring only a few pixels wide, far out, or leaving the view): the back end
  // labels the ring from the prediction instead.
  if (static_cast<int>(ring_pixels_.size()) < options_.fit.min_plane_points) ring_pixels_.clear();
  return fitter_.fit(frame_, ring_pixels_, T_lidar_port_prior, T_lidar_port_prior, EstimateMethod::kPyramid,
                     &report_);
}

}  // namespace close_range
}  // namespace ardsim_pose
