#include "ardsim_pose/occluding_contours.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tukey_weight.h"

namespace ardsim_pose {

namespace {
// A saturated return reads intensity 1; its blooming reaches this far (the sensor's bloom radius,
// ardsim_lidar's default).
constexpr float kSaturatedIntensity = 0.99f;
constexpr int kBloomRadiusPx = 2;

// The pixel a projection falls in (pixel centres at integer coordinates); std::lround is a library call.
int pixelOf(float coordinate) {
  return static_cast<int>(std::floor(coordinate + 0.5f));
}
}  // namespace

OccludingContours::OccludingContours(const ardsim_lidar::Intrinsics& intrinsics, double depth_jump_m,
                                     int window_px)
    : intrinsics_(intrinsics), depth_jump_m_(static_cast<float>(depth_jump_m)), window_px_(window_px) {}

void OccludingContours::extract(const OrganizedCloud& cloud, const std::vector<int>& pixels) {
  const int w = cloud.width, h = cloud.height;
  depth_.assign(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::infinity());
  for (int i = 0; i < w * h; ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (isReturn(p)) depth_[i] = p.z();
  }
  // Saturated returns (retro-reflectors) bloom into the pixels around them at their own range: near one,
  // an edge is not where the surface ends. (Hubble's few reflector pixels left the approach datasets' bands
  // the same either way.)
  near_saturated_.assign(static_cast<std::size_t>(w) * h, 0);
  if (cloud.intensity.size() == cloud.points.size()) {
    for (int i = 0; i < w * h; ++i) {
      if (!(cloud.intensity[i] >= kSaturatedIntensity)) continue;
      const int u = i % w, v = i / w;
      for (int y = std::max(0, v - kBloomRadiusPx); y <= std::min(h - 1, v + kBloomRadiusPx); ++y)
        for (int x = std::max(0, u - kBloomRadiusPx); x <= std::min(w - 1, u + kBloomRadiusPx); ++x)
          near_saturated_[y * w + x] = 1;
    }
  }
  pairs_.clear();
  // The model's contour is looked for window_px either side of the pair, inside the image.
  const int reach = window_px_ + 1;
  for (const int i : pixels) {
    const int u = i % w, v = i / w;
    if (near_saturated_[i]) continue;
    const float z = depth_[i];
    constexpr int kSteps[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (const auto& s : kSteps) {
      // The window along the pair's line and the pixels beside it, inside the image.
      const int ru = reach * std::abs(s[0]) + std::abs(s[1]), rv = reach * std::abs(s[1]) + std::abs(s[0]);
      if (u - ru < 0 || u + ru >= w || v - rv < 0 || v + rv >= h) continue;
      // No return, or one far behind (no return is +inf): across an edge of the surface at z.
      if (depth_[(v + s[1]) * w + u + s[0]] > z + depth_jump_m_) pairs_.push_back({u, v, s[0], s[1], z});
    }
  }
}

void OccludingContours::selectCandidates(const ReferenceModel& model,
                                         const std::vector<std::uint32_t>& patches,
                                         const Eigen::Isometry3d& T_lidar_target) {
  const int w = intrinsics_.width, h = intrinsics_.height;
  // The pixels along each pair's line, two more either way than the window (the pose moves meanwhile).
  bucket_of_.assign(static_cast<std::size_t>(w) * h, -1);
  const int reach = window_px_ + 3;
  buckets_ = 0;
  for (const Pair& p : pairs_) {
    for (int across = -1; across <= 1; ++across) {
      for (int k = -reach; k <= reach; ++k) {
        const int u = p.u + k * p.du + across * p.dv, v = p.v + k * p.dv + across * p.du;
        if (u < 0 || v < 0 || u >= w || v >= h) continue;
        std::int32_t& b = bucket_of_[v * w + u];
        if (b < 0) b = buckets_++;
      }
    }
  }
  candidates_.clear();
  if (pairs_.empty()) return;
  const Eigen::Matrix3f R = T_lidar_target.linear().cast<float>();
  const Eigen::Vector3f t = T_lidar_target.translation().cast<float>();
  const float fx = static_cast<float>(intrinsics_.fx), fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx), cy = static_cast<float>(intrinsics_.cy);
  for (const std::uint32_t patch : patches) {
    const ReferenceModel::Patch& range = model.patches()[patch];
    // Not the edges of what turns: Hubble's arrays in the model sit at the angle the scans measure, and their
    // edges, metres off the axis, moved the estimate across it by that angle's error, which the planes then
    // answered with a tilt (hubble_hold_arrays30, 20-30 m tilt RMS 0.013 -> 0.029 deg with them).
    if (model.patchArticulated(patch)) continue;
    for (std::uint32_t j = range.begin; j < range.end; ++j) {
      const Eigen::Vector3f X = R * model.points()[j] + t;
      if (!(X.z() > 0.0f)) continue;
      const int u = pixelOf(fx * X.x() / X.z() + cx);
      const int v = pixelOf(fy * X.y() / X.z() + cy);
      if (u < 0 || v < 0 || u >= w || v >= h || bucket_of_[v * w + u] < 0) continue;
      candidates_.push_back(j);
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(candidates_.size());
  candidate_x_.resize(n);
  candidate_y_.resize(n);
  candidate_z_.resize(n);
  candidate_radius_.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const std::uint32_t j = candidates_[k];
    candidate_x_[k] = model.points()[j].x();
    candidate_y_[k] = model.points()[j].y();
    candidate_z_[k] = model.points()[j].z();
    candidate_radius_[k] = 0.5f * model.spacing()[j];
  }
}

void OccludingContours::project(const Eigen::Isometry3d& T_lidar_target) {
  const int w = intrinsics_.width, h = intrinsics_.height;
  const Eigen::Matrix3f R = T_lidar_target.linear().cast<float>();
  const Eigen::Vector3f t = T_lidar_target.translation().cast<float>();
  const float fx = static_cast<float>(intrinsics_.fx), fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx), cy = static_cast<float>(intrinsics_.cy);
  scratch_.clear();
  bucket_scratch_.clear();
  bucket_begin_.assign(buckets_ + 1, 0);
  largest_radius_px_ = 0.0f;
  // The candidates' projections as array expressions (vectorized), then their buckets.
  const Eigen::Index n = static_cast<Eigen::Index>(candidates_.size());
  z_ = R(2, 0) * candidate_x_ + R(2, 1) * candidate_y_ + R(2, 2) * candidate_z_ + t(2);
  u_ = (R(0, 0) * candidate_x_ + R(0, 1) * candidate_y_ + R(0, 2) * candidate_z_ + t(0)) * fx / z_ + cx;
  v_ = (R(1, 0) * candidate_x_ + R(1, 1) * candidate_y_ + R(1, 2) * candidate_z_ + t(1)) * fy / z_ + cy;
  const float f = std::max(fx, fy);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!(z_[k] > 0.0f)) continue;
    const int iu = pixelOf(u_[k]), iv = pixelOf(v_[k]);
    if (iu < 0 || iv < 0 || iu >= w || iv >= h) continue;
    const std::int32_t b = bucket_of_[iv * w + iu];
    if (b < 0) continue;
    const float radius_px = candidate_radius_[k] * f / z_[k];
    largest_radius_px_ = std::max(largest_radius_px_, radius_px);
    scratch_.push_back({u_[k], v_[k], z_[k], radius_px});
    bucket_scratch_.push_back(b);
    ++bucket_begin_[b + 1];
  }
  for (int b = 0; b < buckets_; ++b) bucket_begin_[b + 1] += bucket_begin_[b];
  projected_.resize(scratch_.size());
  bucket_next_.assign(bucket_begin_.begin(), bucket_begin_.end() - 1);
  for (std::size_t k = 0; k < scratch_.size(); ++k)
    projected_[bucket_next_[bucket_scratch_[k]]++] = scratch_[k];
}

OccludingContours::Found OccludingContours::find(const Pair& pair) const {
  // Each model sample stands for the surface within half its spacing: the model's contour along the pair's
  // line is the outermost reach of those discs (the samples alone lie inside it by up to a spacing, more
  // than a pixel from 15 m in: all contours 0.6-0.75 px inside at 12-15 m), among the samples at the
  // return's depth (structure far behind is what the scan saw across the edge), window_px either side of
  // the return, in the line's pixels and the two beside it.
  const int w = intrinsics_.width;
  Found found;
  float best = -std::numeric_limits<float>::infinity();
  const Projected* best_point = nullptr;
  // A sample in the next row reaches the line only with a radius over half a pixel (near: Hubble's rim,
  // sampled every 2.3 cm, inside ~17 m).
  const int beside = largest_radius_px_ > 0.5f ? 1 : 0;
  for (int across = -beside; across <= beside; ++across) {
    for (int k = -window_px_; k <= window_px_ + 1; ++k) {
      const int u = pair.u + k * pair.du + across * pair.dv, v = pair.v + k * pair.dv + across * pair.du;
      const std::int32_t b = bucket_of_[v * w + u];
      if (b < 0) continue;
      for (std::uint32_t i = bucket_begin_[b]; i < bucket_begin_[b + 1]; ++i) {
        const Projected& p = projected_[i];
        if (std::abs(p.z - pair.depth_m) > depth_jump_m_) continue;
        const float off_line = pair.dv * (p.u - pair.u) + pair.du * (p.v - pair.v);
        const float reach_sq = p.radius_px * p.radius_px - off_line * off_line;
        if (reach_sq < 0.0f) continue;
        const float along = pair.du * (p.u - pair.u) + pair.dv * (p.v - pair.v) + std::sqrt(reach_sq);
        if (along > best) {
          best = along;
          best_point = &p;
        }
      }
    }
  }
  // None near, or the model's surface goes on past the window (another edge, or none): no information.
  if (best_point == nullptr || best > window_px_ + 0.5f) return found;
  found.ok = true;
  found.offset_px = best - 0.5;
  found.point = Eigen::Vector3d(best_point->u, best_point->v, best_point->z);
  return found;
}

int OccludingContours::accumulate(bool with_boresight_rotation, const Eigen::Isometry3d& T_lidar_target,
                                  const Eigen::Vector3d& centre, double sigma_m, double sigma_px,
                                  double limit_px, Eigen::Matrix<double, 6, 6>* H,
                                  Eigen::Matrix<double, 6, 1>* g) {
  if (pairs_.empty() || candidates_.empty()) return 0;
  project(T_lidar_target);
  int rows = 0;
  for (const Pair& pair : pairs_) {
    const Found f = find(pair);
    if (!f.ok) continue;
    const double tukey = tukeyWeight(f.offset_px, limit_px);
    if (tukey == 0.0) continue;
    // Back from the image to the contour point (lidar frame) at its depth.
    const double Z = f.point.z();
    const Eigen::Vector3d X((f.point.x() - intrinsics_.cx) * Z / intrinsics_.fx,
                            (f.point.y() - intrinsics_.cy) * Z / intrinsics_.fy, Z);
    // The contour's image motion along d = (du, dv) for a twist, in metres at its depth:
    // d^T dpi/dX [1, -[X - c]x].
    const double f_along = pair.du != 0 ? intrinsics_.fx : intrinsics_.fy;
    const Eigen::Vector3d dpi(
        pair.du * intrinsics_.fx / Z, pair.dv * intrinsics_.fy / Z,
        -(pair.du * intrinsics_.fx * X.x() + pair.dv * intrinsics_.fy * X.y()) / (Z * Z));
    const Eigen::Vector3d row_v = dpi * (Z / f_along);
    Eigen::Matrix<double, 6, 1> row;
    row.head<3>() = row_v;
    row.tail<3>() = (X - centre).cross(row_v);  // row_v^T (-[X - c]x) w = ((X - c) x row_v) . w
    // Never the tilt across the boresight: the planes measure it far better (a tilted Hubble sweep at 28-18
    // m, CloseRangeHandover: tilt RMS 0.013 -> 0.042 deg with the contours' part in it).
    row.segment<2>(3).setZero();
    if (!with_boresight_rotation) row(5) = 0.0;
    const double metres_per_px = Z / f_along;
    const double e_m = -f.offset_px * metres_per_px;  // the scan's contour minus the model's
    const double sigma_contour_m = sigma_px * metres_per_px;
    const double weight = tukey * (sigma_m * sigma_m) / (sigma_contour_m * sigma_contour_m);
    H->noalias() += weight * row * row.transpose();
    g->noalias() += (weight * e_m) * row;
    ++rows;
  }
  return rows;
}

}  // namespace ardsim_pose
