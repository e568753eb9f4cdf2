#include "ardsim_pose/occluding_contours.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "tukey_weight.h"

namespace ardsim_pose {

namespace {
// A saturated return reads intensity 1; its blooming reaches this far (the sensor's bloom radius,
// ardsim_lidar's default).
constexpr float kSaturatedIntensity = 0.99f;
constexpr int kBloomRadiusPx = 2;
// Pairs side by side in a run at least this long are taken as intervals (accumulate); shorter runs, on
// curved or oblique edges, sample many phases and their midpoints average (hubble_hold's 30-50 m lateral
// position error, an open-loop replay of lidar seed 51: runs of 3 / 4 / 6 / 8 / 12 / 16: RMS 3.03 / 2.83 /
// 2.67 / 2.52 / 3.18 / 3.06 mm, none 3.11).
constexpr int kRunPx = 8;
// Triangle corners nearer the sensor than this are not projected (the triangle is left out).
constexpr float kNearestDepthM = 0.05f;

// The pixel a projection falls in (pixel centres at integer coordinates); std::lround is a library call.
int pixelOf(float coordinate) {
  return static_cast<int>(std::floor(coordinate + 0.5f));
}
}  // namespace

OccludingContours::OccludingContours(const ardsim_lidar::Intrinsics& intrinsics, int max_pairs,
                                     double depth_jump_m, int window_px)
    : intrinsics_(intrinsics),
      depth_jump_m_(static_cast<float>(depth_jump_m)),
      window_px_(window_px),
      max_pairs_(max_pairs) {}

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
  members_.clear();
  votes_this_frame_ = 0;
  column_has_pair_.assign(w, 0);
  row_has_pair_.assign(h, 0);
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
  // Runs: pairs of one direction side by side along the edge (across rows: along the row).
  pair_at_.assign(static_cast<std::size_t>(w) * h * 4, 0);
  auto slot = [&](const Pair& p, int u, int v) {
    return (static_cast<std::size_t>(v) * w + u) * 4 + (p.du == 1 ? 0 : p.du == -1 ? 1 : p.dv == 1 ? 2 : 3);
  };
  for (const Pair& p : pairs_) pair_at_[slot(p, p.u, p.v)] = 1;
  for (Pair& p : pairs_) {
    const int su = p.dv != 0 ? 1 : 0, sv = p.du != 0 ? 1 : 0;  // along the edge
    p.run = 1;
    for (int k = 1;; ++k) {
      const int u = p.u + k * su, v = p.v + k * sv;
      if (u >= w || v >= h || !pair_at_[slot(p, u, v)]) break;
      ++p.run;
    }
    for (int k = 1;; ++k) {
      const int u = p.u - k * su, v = p.v - k * sv;
      if (u < 0 || v < 0 || !pair_at_[slot(p, u, v)]) break;
      ++p.run;
    }
  }
  // Every k-th pair (their runs counted on all of them): each is searched for at every iteration, and the
  // ISS's docking adapter at 6-16 m gives ~5000.
  const std::size_t count = pairs_.size();
  if (max_pairs_ > 0 && count > static_cast<std::size_t>(max_pairs_)) {
    kept_.clear();
    for (std::size_t k = 0; k < static_cast<std::size_t>(max_pairs_); ++k)
      kept_.push_back(pairs_[k * count / max_pairs_]);
    pairs_.swap(kept_);
  }
  for (const Pair& p : pairs_) (p.dv != 0 ? column_has_pair_[p.u] : row_has_pair_[p.v]) = 1;
}

void OccludingContours::selectCandidates(const ReferenceModel& model,
                                         const std::vector<std::uint32_t>& patches,
                                         const Eigen::Isometry3d& T_lidar_target) {
  const int w = intrinsics_.width, h = intrinsics_.height;
  // The pixels along each pair's line, two more either way than the window (the pose moves meanwhile).
  near_pair_.assign(static_cast<std::size_t>(w) * h, 0);
  const int reach = window_px_ + 3;
  for (const Pair& p : pairs_) {
    for (int across = -1; across <= 1; ++across) {
      for (int k = -reach; k <= reach; ++k) {
        const int u = p.u + k * p.du + across * p.dv, v = p.v + k * p.dv + across * p.du;
        if (u >= 0 && v >= 0 && u < w && v < h) near_pair_[v * w + u] = 1;
      }
    }
  }
  candidates_.clear();
  if (pairs_.empty()) return;
  if (candidate_mark_.size() != model.triangleCount()) {
    candidate_mark_.assign(model.triangleCount(), 0);
    selection_ = 0;
  }
  ++selection_;
  const Eigen::Matrix3f R = T_lidar_target.linear().cast<float>();
  const Eigen::Vector3f t = T_lidar_target.translation().cast<float>();
  const float fx = static_cast<float>(intrinsics_.fx), fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx), cy = static_cast<float>(intrinsics_.cy);
  for (const std::uint32_t patch : patches) {
    // Not the edges of what turns: Hubble's arrays in the model sit at the angle the scans measure, and their
    // edges, metres off the axis, moved the estimate across it by that angle's error, which the planes then
    // answered with a tilt (hubble_hold_arrays30, 20-30 m tilt RMS 0.013 -> 0.029 deg with them).
    if (model.patchArticulated(patch)) continue;
    const std::uint32_t triangle = model.patchTriangle(patch);
    if (candidate_mark_[triangle] == selection_) continue;
    const ReferenceModel::Patch& range = model.patches()[patch];
    for (std::uint32_t j = range.begin; j < range.end; ++j) {
      const Eigen::Vector3f X = R * model.points()[j] + t;
      if (!(X.z() > 0.0f)) continue;
      const int u = pixelOf(fx * X.x() / X.z() + cx);
      const int v = pixelOf(fy * X.y() / X.z() + cy);
      if (u < 0 || v < 0 || u >= w || v >= h || !near_pair_[v * w + u]) continue;
      candidate_mark_[triangle] = selection_;
      candidates_.push_back(model.triangle(triangle));
      break;
    }
  }
}

void OccludingContours::project(const Eigen::Isometry3d& T_lidar_target) {
  const int w = intrinsics_.width, h = intrinsics_.height;
  const Eigen::Matrix3f R = T_lidar_target.linear().cast<float>();
  const Eigen::Vector3f t = T_lidar_target.translation().cast<float>();
  const float fx = static_cast<float>(intrinsics_.fx), fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx), cy = static_cast<float>(intrinsics_.cy);
  projected_.clear();
  by_column_.resize(w);
  by_row_.resize(h);
  for (auto& list : by_column_) list.clear();
  for (auto& list : by_row_) list.clear();
  for (const ReferenceModel::Triangle& triangle : candidates_) {
    Projected p;
    bool in_front = true;
    for (int corner = 0; corner < 3; ++corner) {
      const Eigen::Vector3f X = R * triangle[corner] + t;
      in_front = in_front && X.z() > kNearestDepthM;
      p.corners[corner] = Eigen::Vector3f(fx * X.x() / X.z() + cx, fy * X.y() / X.z() + cy, X.z());
    }
    if (!in_front) continue;
    p.u_min = std::min({p.corners[0].x(), p.corners[1].x(), p.corners[2].x()});
    p.u_max = std::max({p.corners[0].x(), p.corners[1].x(), p.corners[2].x()});
    p.v_min = std::min({p.corners[0].y(), p.corners[1].y(), p.corners[2].y()});
    p.v_max = std::max({p.corners[0].y(), p.corners[1].y(), p.corners[2].y()});
    const auto index = static_cast<std::uint32_t>(projected_.size());
    // The pixel centres' lines it crosses (centres at integer coordinates), among the pairs'.
    for (int u = std::max(0, static_cast<int>(std::ceil(p.u_min)));
         u <= std::min(w - 1, static_cast<int>(std::floor(p.u_max))); ++u)
      if (column_has_pair_[u]) by_column_[u].push_back(index);
    for (int v = std::max(0, static_cast<int>(std::ceil(p.v_min)));
         v <= std::min(h - 1, static_cast<int>(std::floor(p.v_max))); ++v)
      if (row_has_pair_[v]) by_row_[v].push_back(index);
    projected_.push_back(p);
  }
}

OccludingContours::Found OccludingContours::find(const Pair& pair) {
  // The model's surface along the pair's line (the column of pixel centres for a pair across rows, the row
  // for one across columns), as the triangles near the return's depth cover it: the union of their spans,
  // in px from the return's centre towards its neighbour. Its contour is the end of the span that covers the
  // return's centre (or, with none covering it at this pose, of the nearest at least a pixel long: a thinner
  // one, a mast between two rows of rays, the sensor may never see). Structure far behind is what the scan
  // saw across the edge.
  Found found;
  const bool across_rows = pair.dv != 0;
  const float line = static_cast<float>(across_rows ? pair.u : pair.v);
  const float origin = static_cast<float>(across_rows ? pair.v : pair.u);
  const float direction = static_cast<float>(across_rows ? pair.dv : pair.du);
  const float window_begin = -static_cast<float>(window_px_), window_end = window_px_ + 1.0f;
  covers_.clear();
  for (const std::uint32_t index : across_rows ? by_column_[pair.u] : by_row_[pair.v]) {
    const Projected& p = projected_[index];
    const float along_min = across_rows ? p.v_min : p.u_min, along_max = across_rows ? p.v_max : p.u_max;
    const float lo = direction > 0 ? (along_min - origin) : (origin - along_max);
    const float hi = direction > 0 ? (along_max - origin) : (origin - along_min);
    if (hi < window_begin || lo > window_end) continue;
    // The triangle's edges crossing the line: the span between the crossings, depth by 1/z (linear in the
    // image) at each.
    float a0 = std::numeric_limits<float>::infinity(), a1 = -a0, inv_z1 = 0.0f, slope1 = 0.0f;
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3f& A = p.corners[e];
      const Eigen::Vector3f& B = p.corners[(e + 1) % 3];
      const float fa = (across_rows ? A.x() : A.y()) - line, fb = (across_rows ? B.x() : B.y()) - line;
      if ((fa > 0.0f && fb > 0.0f) || (fa < 0.0f && fb < 0.0f) || fa == fb) continue;
      const float s = fa / (fa - fb);
      const float along =
          direction * ((across_rows ? A.y() + s * (B.y() - A.y()) : A.x() + s * (B.x() - A.x())) - origin);
      a0 = std::min(a0, along);
      if (along > a1) {
        a1 = along;
        inv_z1 = 1.0f / A.z() + s * (1.0f / B.z() - 1.0f / A.z());
        slope1 = across_rows ? (B.y() - A.y()) / (B.x() - A.x()) : (B.x() - A.x()) / (B.y() - A.y());
      }
    }
    if (!(a1 >= a0) || std::abs(1.0f / inv_z1 - pair.depth_m) > depth_jump_m_) continue;
    covers_.push_back({a0, a1, 1.0f / inv_z1, slope1});
  }
  if (covers_.empty()) return found;
  std::sort(covers_.begin(), covers_.end(),
            [](const Cover& a, const Cover& b) { return a.along0 < b.along0; });
  // Joined into spans (triangles sharing an edge meet to rounding), the chosen one's end kept.
  constexpr float kJoinPx = 1e-3f;
  constexpr float kThinPx = 1.0f;
  bool have = false;
  Cover chosen{0.0f, 0.0f, 0.0f, 0.0f}, span = covers_.front();
  auto consider = [&](const Cover& s) {
    if (s.along0 <= 0.0f && s.along1 >= 0.0f) {  // covers the return's centre
      chosen = s;
      have = true;
      return true;
    }
    if (s.along1 - s.along0 < kThinPx) return false;
    if (!have || std::abs(s.along1 - 0.5f) < std::abs(chosen.along1 - 0.5f)) chosen = s, have = true;
    return false;
  };
  bool covering = false;
  for (std::size_t k = 1; k < covers_.size() && !covering; ++k) {
    const Cover& c = covers_[k];
    if (c.along0 <= span.along1 + kJoinPx) {
      if (c.along1 > span.along1) span.along1 = c.along1, span.depth1 = c.depth1, span.slope1 = c.slope1;
      continue;
    }
    covering = consider(span);
    span = c;
  }
  if (!covering) consider(span);
  // None near, or the model's surface goes on past the window (another edge, or none): no information.
  if (!have || chosen.along1 > window_end - 0.5f || chosen.along1 < window_begin) return found;
  found.ok = true;
  found.offset_px = chosen.along1 - 0.5f;
  found.slope = chosen.slope1;
  const float along = origin + direction * chosen.along1;
  found.point =
      across_rows ? Eigen::Vector3d(line, along, chosen.depth1) : Eigen::Vector3d(along, line, chosen.depth1);
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
    Found f = find(pair);
    if (!f.ok) continue;
    // A long run of pairs along a pixel row or column shares one sub-pixel phase: their midpoints are off
    // together, by up to half a pixel, and held the estimate there while the target drifted across a pixel
    // (hubble_hold, 30-50 m: ramps of 8-10 mm, then a snap back). Such a pair says only that the contour lies
    // between the two pixel centres: no pull inside, the distance to the nearer centre outside. Not while the
    // contours turn the boresight rotation (acquiring): there the long edges are what fix it (first frames
    // 0.07 -> 0.13 deg off about the boresight without their pull).
    if (!with_boresight_rotation && pair.run >= kRunPx) {
      if (std::abs(f.offset_px) <= 0.5) continue;
      f.offset_px -= std::copysign(0.5, f.offset_px);
    }
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

namespace {
// The half-plane n . x <= b of a convex polygon.
void clipPolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& n, double b,
                 std::vector<Eigen::Vector2d>* out) {
  out->clear();
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    const Eigen::Vector2d& p = polygon[k];
    const Eigen::Vector2d& q = polygon[(k + 1) % polygon.size()];
    const double fp = n.dot(p) - b, fq = n.dot(q) - b;
    if (fp <= 0.0) out->push_back(p);
    if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) out->push_back(p + (fp / (fp - fq)) * (q - p));
  }
}
}  // namespace

Eigen::Vector2d OccludingContours::vote(double reach_m, const VotePrior* prior) {
  // Each strip |offset + a . d| <= 1/2 over a grid of translations d within reach_m, by rows of a difference
  // array; the winner has the most votes (less the prior's penalty), the nearest the pose among equals.
  constexpr int kHalfCells = 40, kCells = 2 * kHalfCells + 1;
  const double cell_m = reach_m / kHalfCells;
  const double row0_dy = -kHalfCells * cell_m;
  votes_.assign(static_cast<std::size_t>(kCells) * (kCells + 1), 0);
  for (const Strip& s : strips_) {
    // In cells, with d = 0 at cell kHalfCells: the strip at row j spans columns [first + j * step,
    // first + j * step + width].
    if (std::abs(s.a.x()) * reach_m < 1e-3) {  // parallel to the x axis: whole rows or none
      for (int j = 0; j < kCells; ++j) {
        if (std::abs(s.offset_px + s.a.y() * (row0_dy + j * cell_m)) > 0.5) continue;
        ++votes_[j * (kCells + 1)];
        --votes_[j * (kCells + 1) + kCells];
      }
      continue;
    }
    const double inverse = 1.0 / (s.a.x() * cell_m);
    const double width = std::abs(inverse);
    const double step = -s.a.y() * cell_m * inverse;
    double first = ((s.a.x() > 0.0 ? -0.5 : 0.5) - s.offset_px - s.a.y() * row0_dy) * inverse + kHalfCells;
    for (int j = 0; j < kCells; ++j, first += step) {
      const int i0 = std::max(0, static_cast<int>(std::ceil(first)));
      const int i1 = std::min(kCells - 1, static_cast<int>(std::floor(first + width)));
      if (i0 > i1) continue;
      ++votes_[j * (kCells + 1) + i0];
      --votes_[j * (kCells + 1) + i1 + 1];
    }
  }
  const bool weighed = prior != nullptr && prior->weight > 0.0 && ++votes_this_frame_ <= kMaxVotesWithPrior;
  const Eigen::Matrix2d W =
      weighed
          ? Eigen::Matrix2d(0.5 * prior->weight *
                            (prior->covariance_m2 + cell_m * cell_m * Eigen::Matrix2d::Identity()).inverse())
          : Eigen::Matrix2d::Zero();
  // The winner: the best score, nearest the pose among equals.
  double best = -std::numeric_limits<double>::infinity();
  int best_i = kHalfCells, best_j = kHalfCells, best_r2 = 0;
  for (int j = 0; j < kCells; ++j) {
    int count = 0;
    for (int i = 0; i < kCells; ++i) {
      count += votes_[j * (kCells + 1) + i];
      double score = count;
      if (weighed) {
        const Eigen::Vector2d off =
            Eigen::Vector2d((i - kHalfCells) * cell_m, (j - kHalfCells) * cell_m) - prior->translation_m;
        score -= off.dot(W * off);
      }
      const int r2 = (i - kHalfCells) * (i - kHalfCells) + (j - kHalfCells) * (j - kHalfCells);
      if (score > best || (score == best && r2 < best_r2)) best = score, best_i = i, best_j = j, best_r2 = r2;
    }
  }
  return Eigen::Vector2d((best_i - kHalfCells) * cell_m, (best_j - kHalfCells) * cell_m);
}

int OccludingContours::intersectMembers(double reach_m) {
  polygon_ = {{-reach_m, -reach_m}, {reach_m, -reach_m}, {reach_m, reach_m}, {-reach_m, reach_m}};
  int members = 0;
  for (const Strip& s : strips_) {
    if (!s.member) continue;
    clipPolygon(polygon_, s.a, 0.5 - s.offset_px, &clipped_);
    clipPolygon(clipped_, -s.a, 0.5 + s.offset_px, &polygon_);
    ++members;
  }
  return members;
}

bool OccludingContours::polygonMoments(Eigen::Vector2d* mean, Eigen::Matrix2d* covariance) const {
  // Uniform over the polygon, by a fan of triangles.
  double area = 0.0;
  Eigen::Vector2d moment1 = Eigen::Vector2d::Zero();
  Eigen::Matrix2d moment2 = Eigen::Matrix2d::Zero();
  for (std::size_t k = 1; k + 1 < polygon_.size(); ++k) {
    const Eigen::Vector2d &p0 = polygon_[0], &p1 = polygon_[k], &p2 = polygon_[k + 1];
    const Eigen::Vector2d e1 = p1 - p0, e2 = p2 - p0;
    const double t = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    const Eigen::Vector2d sum = p0 + p1 + p2;
    area += t;
    moment1 += t * sum / 3.0;
    moment2 += (t / 12.0) *
               (p0 * p0.transpose() + p1 * p1.transpose() + p2 * p2.transpose() + sum * sum.transpose());
  }
  if (!(area > 0.0)) return false;
  *mean = moment1 / area;
  *covariance = moment2 / area - *mean * mean->transpose();
  return true;
}

int OccludingContours::accumulateConsensus(const Eigen::Isometry3d& T_lidar_target, double sigma_m,
                                           double reach_px, double floor_px, double min_information,
                                           bool vote_again, Eigen::Matrix<double, 6, 6>* H,
                                           Eigen::Matrix<double, 6, 1>* g, const VotePrior* prior) {
  if (pairs_.empty() || candidates_.empty()) return 0;
  if (vote_again) members_.clear();
  project(T_lidar_target);
  // Steeper contours turn a small error of the pose's rotation into a large one along the pair.
  constexpr double kMaxSlope = 2.0;
  const double f = std::min(intrinsics_.fx, intrinsics_.fy);
  const bool voting = members_.empty();
  strips_.clear();
  double depth_sum = 0.0;
  for (std::size_t index = 0; index < pairs_.size(); ++index) {
    const Pair& pair = pairs_[index];
    if (!voting && !members_[index]) continue;
    const Found found = find(pair);
    if (!found.ok || std::abs(found.slope) > kMaxSlope || std::abs(found.offset_px) > reach_px + 0.5)
      continue;
    const double Z = found.point.z();
    const bool across_rows = pair.dv != 0;
    const double direction = across_rows ? pair.dv : pair.du;
    // A lateral translation moves the model's contour across the pair's line by its image motion along the
    // line's axis, less the contour's slope times its motion along the line.
    const Eigen::Vector2d a =
        direction * (across_rows ? Eigen::Vector2d(-found.slope * intrinsics_.fx / Z, intrinsics_.fy / Z)
                                 : Eigen::Vector2d(intrinsics_.fx / Z, -found.slope * intrinsics_.fy / Z));
    strips_.push_back({a, found.offset_px, index, !voting});
    depth_sum += Z;
  }
  if (strips_.empty()) return 0;
  const double reach_m = reach_px * depth_sum / strips_.size() / f;
  // polygon_ and its moments, of the members' strips as they are (members: how many).
  int members = 0;
  bool moments = false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  if (voting) {
    // The vote once a frame, its winner (a cell's centre) refined: the members are the strips that hold the
    // centroid of their own intersection, until they stay the same. Later calls intersect the same pairs'
    // strips unless told to vote again.
    Eigen::Vector2d point = vote(reach_m, prior);
    for (int round = 0; round < 5; ++round) {
      bool changed = false;
      for (Strip& s : strips_) {
        const bool member = std::abs(s.offset_px + s.a.dot(point)) <= 0.5;
        changed = changed || member != s.member;
        s.member = member;
      }
      if (!changed) break;
      members = intersectMembers(reach_m);
      moments = members > 0 && polygonMoments(&mean, &covariance);
      if (!moments) break;
      point = mean;
    }
    members_.assign(pairs_.size(), 0);
    for (const Strip& s : strips_) members_[s.pair] = s.member;
    if (!moments) return 0;
  } else {
    members = intersectMembers(reach_m);
    if (members == 0) return 0;
    // The members' strips moved apart with the pose (their contours on other triangles): vote again.
    if (!polygonMoments(&mean, &covariance))
      return accumulateConsensus(T_lidar_target, sigma_m, reach_px, floor_px, min_information, true, H, g,
                                 prior);
  }
  const double floor_m = floor_px * depth_sum / strips_.size() / f;
  covariance += floor_m * floor_m * Eigen::Matrix2d::Identity();
  consensus_mean_m_ = mean;
  consensus_covariance_m2_ = covariance;
  // No weaker than min_information in any direction: the caller's limit below which the directions count as
  // unobserved and the planes' coarser means take over.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen((sigma_m * sigma_m) * covariance.inverse());
  const Eigen::Matrix2d information = eigen.eigenvectors() *
                                      eigen.eigenvalues().cwiseMax(min_information).asDiagonal() *
                                      eigen.eigenvectors().transpose();
  H->topLeftCorner<2, 2>() += information;
  g->head<2>() += information * mean;
  return members;
}

}  // namespace ardsim_pose
