#include "ardsim_pose/close_range/ring_detector.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace ardsim_pose {
namespace close_range {

namespace {

struct ClusterMetrics {
  Eigen::Vector3d normal, centre;
  double radius = 0.0, planarity = 0.0, spread = 0.0, depth_step = 0.0;
};

// Scores one cluster against the ring's criteria (ring_detector.h); false as soon as one fails.
bool scoreCluster(const PreparedFrame& frame, const int* all_members, std::size_t member_count,
                  const std::vector<int>& label, int cluster, const RingDetectorOptions& options,
                  ClusterMetrics* m) {
  // The metrics are statistics over the cluster: a spread sample of at most ~2000 of its pixels (in growth
  // order) is enough and keeps the cost per cluster bounded.
  const std::size_t step = std::max<std::size_t>(1, member_count / 2000);
  std::vector<int> members;
  members.reserve(member_count / step + 1);
  for (std::size_t k = 0; k < member_count; k += step) members.push_back(all_members[k]);
  // Plane of the cluster, twice: the second time without the members far from the first plane (a cluster can
  // leak onto a steep surface next to the ring, the passage's wall).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  double count = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    // Sums in scalars, the scatter's upper triangle only: a Matrix3d accumulator stays in memory and every
    // step waits on the previous store.
    double sx = 0.0, sy = 0.0, sz = 0.0, sxx = 0.0, sxy = 0.0, sxz = 0.0, syy = 0.0, syz = 0.0, szz = 0.0;
    double n = 0.0;
    for (int i : members) {
      const Eigen::Vector3d p = frame.points[i].cast<double>();
      if (pass == 1 && std::abs(normal.dot(p - mean)) > 3.0 * options.max_planarity_m) continue;
      sx += p.x();
      sy += p.y();
      sz += p.z();
      sxx += p.x() * p.x();
      sxy += p.x() * p.y();
      sxz += p.x() * p.z();
      syy += p.y() * p.y();
      syz += p.y() * p.z();
      szz += p.z() * p.z();
      n += 1.0;
    }
    if (n * options.stride * options.stride * step < options.min_cluster_pixels) return false;
    Eigen::Matrix3d scatter;
    scatter << sxx, sxy, sxz, sxy, syy, syz, sxz, syz, szz;
    mean = Eigen::Vector3d(sx, sy, sz) / n;
    eig.compute(scatter / n - mean * mean.transpose());
    normal = eig.eigenvectors().col(0);
    count = n;
  }
  if (count < 0.7 * members.size()) return false;
  const double extent = std::sqrt(std::max(0.0, eig.eigenvalues()(2)));
  m->planarity = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
  if (extent < options.min_extent_m || extent > options.max_extent_m ||
      m->planarity > options.max_planarity_m) {
    return false;
  }
  m->normal = eig.eigenvectors().col(0);
  if (m->normal.z() > 0.0) m->normal = -m->normal;
  if (std::acos(std::min(1.0, -m->normal.z())) > options.max_normal_angle_deg * M_PI / 180.0) return false;

  // Circularity: Kasa fit in the cluster's plane, then again without the members far from that circle (a few
  // petal pixels join the ring's cluster at their roots).
  const Eigen::Matrix3d R = portRotation(m->normal, 0.0);
  const auto planar = [&](int i) {
    const Eigen::Vector3d d = frame.points[i].cast<double>() - mean;
    return Eigen::Vector2d(d.dot(R.col(1)), d.dot(R.col(2)));
  };
  const auto onPlane = [&](int i) {
    return std::abs(m->normal.dot(frame.points[i].cast<double>() - mean)) <= 3.0 * options.max_planarity_m;
  };
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int pass = 0; pass < 2; ++pass) {
    // The normal equations' sums in scalars (see the plane above).
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0, n = 0.0, bx = 0.0, by = 0.0, b1 = 0.0;
    for (int i : members) {
      if (!onPlane(i)) continue;
      const Eigen::Vector2d s = planar(i);
      if (pass == 1 && std::abs((s - c).norm() - m->radius) > 0.12) continue;
      const double s2 = s.squaredNorm();
      sx += s.x();
      sy += s.y();
      sxx += s.x() * s.x();
      sxy += s.x() * s.y();
      syy += s.y() * s.y();
      n += 1.0;
      bx -= s.x() * s2;
      by -= s.y() * s2;
      b1 -= s2;
    }
    Eigen::Matrix3d A;
    A << sxx, sxy, sx, sxy, syy, sy, sx, sy, n;
    const Eigen::Vector3d b(bx, by, b1);
    const Eigen::Vector3d k = A.ldlt().solve(b);
    c = Eigen::Vector2d(-k(0) / 2, -k(1) / 2);
    m->radius = std::sqrt(std::max(0.0, c.squaredNorm() - k(2)));
  }
  if (!std::isfinite(m->radius) || m->radius < options.min_radius_m || m->radius > options.max_radius_m) {
    return false;
  }
  double spread = 0.0;
  int in_hole = 0;
  for (int i : members) {
    if (!onPlane(i)) continue;
    const double r = (planar(i) - c).norm();
    spread += (r - m->radius) * (r - m->radius);
    if (r < options.hole_radius_m) ++in_hole;
  }
  m->spread = std::sqrt(spread / count);
  if (m->spread > options.max_radial_spread_m || in_hole > options.max_hole_fraction * count) return false;

  // The frontmost annulus: across its inner boundary the view falls back into the passage. Seen through the
  // ring, the tunnel face behind it would have the ring in front across its inner boundary instead.
  int inner_boundary = 0, in_front = 0;
  const double plane_offset = m->normal.dot(mean);
  for (int i : members) {
    if (!onPlane(i)) continue;
    const int u = i % frame.width, v = i / frame.width;
    const int neighbours[4] = {u > 0 ? i - 1 : -1, u + 1 < frame.width ? i + 1 : -1,
                               v > 0 ? i - frame.width : -1, v + 1 < frame.height ? i + frame.width : -1};
    const double r_i = (planar(i) - c).norm();
    for (int j : neighbours) {
      if (j < 0 || label[j] == cluster || !frame.isValid(j)) continue;
      if ((planar(j) - c).norm() >= r_i) continue;
      ++inner_boundary;
      if (m->normal.dot(frame.points[j].cast<double>()) - plane_offset > 0.06) ++in_front;
    }
  }
  if (in_front > 0.3 * inner_boundary) return false;
  m->centre = mean + c.x() * R.col(1) + c.y() * R.col(2);

  // Depth step: project the centre into the image with the pinhole fitted to the members' own pixels (u = fx
  // x/z
  // + cx, v likewise), then look at the pixels around it.
  double su = 0.0, suu = 0.0, sv = 0.0, svv = 0.0, n = 0.0, bu0 = 0.0, bu1 = 0.0, bv0 = 0.0, bv1 = 0.0;
  for (int i : members) {
    const Eigen::Vector3f& p = frame.points[i];
    const double xu = p.x() / p.z(), xv = p.y() / p.z();
    const double u = i % frame.width, v = i / frame.width;
    su += xu;
    suu += xu * xu;
    sv += xv;
    svv += xv * xv;
    n += 1.0;
    bu0 += xu * u;
    bu1 += u;
    bv0 += xv * v;
    bv1 += v;
  }
  Eigen::Matrix2d Au, Av;
  Au << suu, su, su, n;
  Av << svv, sv, sv, n;
  const Eigen::Vector2d bu(bu0, bu1), bv(bv0, bv1);
  const Eigen::Vector2d pu = Au.ldlt().solve(bu), pv = Av.ldlt().solve(bv);
  const int uc = static_cast<int>(std::lround(pu(0) * m->centre.x() / m->centre.z() + pu(1)));
  const int vc = static_cast<int>(std::lround(pv(0) * m->centre.y() / m->centre.z() + pv(1)));
  const double d_plane = m->normal.dot(m->centre);
  std::vector<double> behind;
  for (int v = vc - 2; v <= vc + 2; ++v) {
    for (int u = uc - 2; u <= uc + 2; ++u) {
      if (u < 0 || v < 0 || u >= frame.width || v >= frame.height) continue;
      const int j = v * frame.width + u;
      if (frame.isValid(j)) behind.push_back(d_plane - m->normal.dot(frame.points[j].cast<double>()));
    }
  }
  if (behind.size() < 5) return false;
  std::nth_element(behind.begin(), behind.begin() + behind.size() / 2, behind.end());
  m->depth_step = behind[behind.size() / 2];
  return m->depth_step >= options.min_depth_step_m;
}

}  // namespace

void detectRing(const PreparedFrame& frame, const RingDetectorOptions& options, RingDetection* detection,
                RingDetectorScratch* scratch) {
  *detection = RingDetection();
  const int width = frame.width, height = frame.height, n = width * height;
  // Clusters grow over every stride-th pixel in both directions (the ring is tens of pixels wide down to 7
  // m); the ring's pixels are filled in at full resolution at the end.
  const int stride = options.stride;
  // -1: a return in no cluster yet, -2: no return (one test per neighbour instead of two).
  std::vector<int>& label = scratch->label;
  label.resize(n);
  for (int i = 0; i < n; ++i) label[i] = frame.isValid(i) ? -1 : -2;
  // The cluster's members in growth order, members[0, tail): sized once for the largest cluster, so adding
  // one is a store.
  std::vector<int>& members = scratch->members;
  members.resize(n);
  // Each member's image row, kept beside it: an integer division per pixel cost as much as the growing.
  std::vector<int>& rows = scratch->rows;
  rows.resize(n);
  int next_label = 0;
  for (int v0 = 0; v0 < height; v0 += stride) {
    for (int u0 = 0; u0 < width; u0 += stride) {
      // The next seed by a scan in locals of its own (u0, live across the growing, sat on the stack and each
      // step of the scan waited on its store): most pixels are in a cluster by the time the scan reaches
      // them.
      const int* row_labels = label.data() + v0 * width;
      int u = u0;
      while (u < width && row_labels[u] != -1) u += stride;
      if (u >= width) break;
      u0 = u;
      const int seed = v0 * width + u0;
      std::size_t tail = 0;
      members[tail] = seed;
      rows[tail++] = v0;
      label[seed] = next_label;
      for (std::size_t head = 0; head < tail; ++head) {
        const int i = members[head];
        const int v = rows[head], u = i - v * width;
        const float r = frame.range_m[i];
        const float step = static_cast<float>(
            options.connect_step_m + stride * r * options.fit.pixel_pitch_rad * options.slope_allowance);
        const int neighbours[4] = {u >= stride ? i - stride : -1, u + stride < width ? i + stride : -1,
                                   v >= stride ? i - stride * width : -1,
                                   v + stride < height ? i + stride * width : -1};
        const int neighbour_rows[4] = {v, v, v - stride, v + stride};
        for (int k = 0; k < 4; ++k) {
          const int j = neighbours[k];
          if (j < 0 || label[j] != -1) continue;
          if (std::abs(frame.range_m[j] - r) > step) continue;
          label[j] = next_label;
          members[tail] = j;
          rows[tail++] = neighbour_rows[k];
        }
      }
      ++next_label;
      if (static_cast<int>(tail) * stride * stride < options.min_cluster_pixels) continue;
      ++detection->clusters;
      ClusterMetrics metrics;
      if (!scoreCluster(frame, members.data(), tail, label, next_label - 1, options, &metrics)) continue;
      if (detection->found && tail <= detection->pixels.size()) continue;
      detection->found = true;
      detection->pixels.clear();
      for (std::size_t m = 0; m < tail; ++m) {
        const int i = members[m];
        // The stride x stride block of each member, where on the cluster's plane.
        for (int dv = 0; dv < stride && i / width + dv < height; ++dv) {
          for (int du = 0; du < stride && i % width + du < width; ++du) {
            const int j = i + dv * width + du;
            if (frame.isValid(j) &&
                std::abs(metrics.normal.dot(frame.points[j].cast<double>() - metrics.centre)) <=
                    3.0 * options.max_planarity_m) {
              detection->pixels.push_back(j);
            }
          }
        }
      }
      detection->normal = metrics.normal;
      detection->centre = metrics.centre;
      detection->radius_m = metrics.radius;
      detection->planarity_m = metrics.planarity;
      detection->radial_spread_m = metrics.spread;
      detection->depth_step_m = metrics.depth_step;
    }
  }
}

RingMethod::RingMethod(const AdapterGeometry& geometry, const RingDetectorOptions& options)
    : options_(options), fitter_(geometry, options.fit) {}

PoseResult RingMethod::estimate(const OrganizedCloud& cloud,
                                const Eigen::Isometry3d& T_lidar_target_predicted) {
  prepareFrame(cloud, options_.fit, &frame_);
  const Eigen::Isometry3d T_lidar_port_prior = T_lidar_target_predicted * fitter_.geometry().T_target_port;
  detectRing(frame_, options_, &detection_, &scratch_);
  if (!detection_.found) {
    // The terminal stage: hatch and centreline target from the prediction.
    return fitter_.fit(frame_, {}, T_lidar_port_prior, T_lidar_port_prior, EstimateMethod::kRing, &report_);
  }
  // The detection gives the plane and the centre; the boresight angle comes from the prior.
  Eigen::Isometry3d T_seed = Eigen::Isometry3d::Identity();
  T_seed.linear() = portRotation(detection_.normal, boresightAngle(T_lidar_port_prior.linear()));
  T_seed.translation() = detection_.centre;
  return fitter_.fit(frame_, detection_.pixels, T_seed, T_lidar_port_prior, EstimateMethod::kRing, &report_);
}

}  // namespace close_range
}  // namespace ardsim_pose
