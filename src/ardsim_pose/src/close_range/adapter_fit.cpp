#include "ardsim_pose/close_range/adapter_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "ardsim_description/frames.h"

namespace ardsim_pose {
namespace close_range {

namespace {

constexpr double kDeg = M_PI / 180.0;

double wrapPi(double a) {
  return std::remainder(a, 2.0 * M_PI);
}

// Of the angles base + k * period, the one nearest to target.
double nearestBranch(double base, double period, double target) {
  return base + period * std::round(wrapPi(target - base) / period);
}

// A pixel of a three-fold feature (a guide petal, a reflector disc) at an angle about the port's axis.
struct AnglePoint {
  double angle;
  std::complex<double>
      unit3;    // at 3 x angle (half a turn on for the reflectors), for the sums (a sincos each)
  bool border;  // touches the image border
};

// Per feature (three, 120 deg apart, the first at first_rad): the sum of unit3, the count and whether any
// touches the border, of the points nearest to it and within half_width_rad of it.
struct PerFeature {
  std::array<std::complex<double>, 3> sum{};
  std::array<int, 3> count{};
  std::array<bool, 3> border{};
};
PerFeature perFeature(const std::vector<AnglePoint>& points, double first_rad, double half_width_rad) {
  PerFeature f;
  for (const AnglePoint& p : points) {
    const int branch = static_cast<int>(std::lround(wrapPi(p.angle - first_rad) / (2.0 * M_PI / 3.0)));
    if (std::abs(wrapPi(p.angle - first_rad - branch * 2.0 * M_PI / 3.0)) > half_width_rad) continue;
    const int k = ((branch % 3) + 3) % 3;
    f.sum[k] += p.unit3;
    ++f.count[k];
    f.border[k] = f.border[k] || p.border;
  }
  return f;
}

// Largest empty gap (rad) between sorted angles on the circle; 2 pi when there are none.
double largestGap(std::vector<double>& angles) {
  if (angles.empty()) return 2.0 * M_PI;
  std::sort(angles.begin(), angles.end());
  double gap = angles.front() + 2.0 * M_PI - angles.back();
  for (std::size_t i = 1; i < angles.size(); ++i) gap = std::max(gap, angles[i] - angles[i - 1]);
  return gap;
}

}  // namespace

AdapterGeometry issAdapterGeometry() {
  AdapterGeometry g;
  g.T_target_port = ardsim_description::T_target_port(ardsim_description::TargetKind::kIss);
  return g;
}

AdapterGeometry hubbleAdapterGeometry() {
  AdapterGeometry g;
  // No hatch: the aft bulkhead closes the passage 0.30 m behind the docking plane (ardsim_description
  // hubble.cpp, the tunnel's depth with hatch_depth_m = 0); no centreline target (its plate and cross lie
  // where the bulkhead hides them: no points there).
  g.hatch_face_x_m = -0.30;
  g.plate_radius_m = 0.0;
  g.T_target_port = ardsim_description::T_target_port(ardsim_description::TargetKind::kHubble);
  return g;
}

AdapterGeometry adapterGeometry(ardsim_description::TargetKind kind) {
  return kind == ardsim_description::TargetKind::kIss ? issAdapterGeometry() : hubbleAdapterGeometry();
}

void prepareFrame(const OrganizedCloud& cloud, const AdapterFitOptions& options, PreparedFrame* frame) {
  const int n = cloud.width * cloud.height;
  frame->width = cloud.width;
  frame->height = cloud.height;
  frame->points.resize(n);
  frame->range_m.resize(n);
  frame->saturated.resize(n);
  frame->valid_count = 0;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const bool has_intensity = cloud.intensity.size() == cloud.points.size();
  frame->has_intensity = has_intensity;
  if (static_cast<int>(cloud.points.size()) != n) {
    std::fill(frame->range_m.begin(), frame->range_m.end(), nan);
    return;
  }
  const bool correct = has_intensity && options.saturated_range_bias_m != 0.0;
  const float bias = static_cast<float>(options.saturated_range_bias_m);
  int valid_count = 0;
  // Selects rather than branches (returns, misses and saturated pixels interleave unpredictably); a scale of
  // 1 leaves a point as it is.
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    const float r = p.norm();
    const bool valid = std::isfinite(r) && r > 0.0f;
    frame->saturated[i] = has_intensity && cloud.intensity[i] >= 1.0f;
    // Saturated returns read short by the detector walk: put it back along the ray.
    const bool saturated = correct && frame->saturated[i];
    const float range = saturated ? r - bias : r;
    const float scale = saturated ? range / r : 1.0f;
    frame->points[i] = valid ? Eigen::Vector3f(p * scale) : Eigen::Vector3f::Constant(nan);
    frame->range_m[i] = valid ? range : nan;
    valid_count += valid ? 1 : 0;
  }
  frame->valid_count = valid_count;
}

double boresightAngle(const Eigen::Matrix3d& R_lidar_port) {
  const Eigen::Matrix3d R0 = portRotation(R_lidar_port.col(0), 0.0);
  const Eigen::Vector3d y = R_lidar_port.col(1);
  return std::atan2(y.dot(R0.col(2)), y.dot(R0.col(1)));
}

Eigen::Matrix3d portRotation(const Eigen::Vector3d& normal, double boresight_rad) {
  const Eigen::Vector3d n = normal.normalized();
  // Reference direction on the plane: the lidar x axis projected (the normal is within a few tens of degrees
  // of the boresight here, never along x).
  const Eigen::Vector3d e1 = (Eigen::Vector3d::UnitX() - n.x() * n).normalized();
  const Eigen::Vector3d e2 = n.cross(e1);
  Eigen::Matrix3d R;
  R.col(0) = n;
  R.col(1) = std::cos(boresight_rad) * e1 + std::sin(boresight_rad) * e2;
  R.col(2) = n.cross(R.col(1));
  return R;
}

AdapterFitter::AdapterFitter(const AdapterGeometry& geometry, const AdapterFitOptions& options)
    : geometry_(geometry), options_(options) {}

void AdapterFitter::labelPlanePoints(const PreparedFrame& frame, const std::vector<int>& ring_face_pixels,
                                     const Eigen::Isometry3d& T_lidar_port, double band,
                                     const Sampling& sampling) {
  const AdapterGeometry& g = geometry_;
  const double face_x[kFaces] = {0.0, g.tunnel_face_x_m, g.hatch_face_x_m, g.plate_face_x_m,
                                 g.cross_face_x_m};
  // Radius windows (squared) of each face, a little inside its edges.
  const auto sq = [](double x) { return x * x; };
  const double ring_in = sq(g.ring_inner_radius_m + 0.01), ring_out = sq(g.ring_outer_radius_m - 0.01);
  const double tunnel_in = sq(g.ring_outer_radius_m + 0.03), tunnel_out = sq(g.tunnel_outer_radius_m - 0.03);
  const double hatch_in = sq(g.plate_radius_m + 0.03), hatch_out = sq(g.hatch_radius_m - 0.025);
  const double plate_out = sq(g.plate_radius_m - 0.02);
  // At the cross's depth inside the passage there is nothing but the cross: take it all, however far the
  // guess's centre is off.
  const double cross_out = sq(g.hatch_radius_m - 0.02);
  const Eigen::Isometry3d T_port_lidar = T_lidar_port.inverse();
  const Eigen::Matrix3d R = T_port_lidar.linear();
  const Eigen::Vector3d t = T_port_lidar.translation();
  const int n = frame.width * frame.height;
  plane_points_.clear();
  cross_face_points_.clear();
  is_ring_.assign(n, 0);
  for (int i : ring_face_pixels) is_ring_[i] = 1;
  const bool ring_from_model = ring_face_pixels.empty();
  for (int v = 0; v < frame.height; v += sampling.row_step) {
    for (int u = sampling.firstColumn(v); u < frame.width; u += sampling.col_step) {
      const int i = v * frame.width + u;
      if (!frame.isValid(i)) continue;
      // The front end's ring pixels (a good part of the frame) need no transform.
      if (is_ring_[i]) {
        plane_points_.push_back({frame.points[i], 0, face_x[0]});
        continue;
      }
      const Eigen::Vector3d p = frame.points[i].cast<double>();
      const Eigen::Vector3d q = R * p + t;
      const double r2 = q.y() * q.y() + q.z() * q.z();
      const bool off_cross = std::abs(q.y()) > 0.04 && std::abs(q.z()) > 0.04;
      int face = -1;
      if (ring_from_model && std::abs(q.x()) < band && r2 > ring_in && r2 < ring_out) {
        face = 0;
        is_ring_[i] = 1;
      } else if (std::abs(q.x() - face_x[1]) < band && r2 > tunnel_in && r2 < tunnel_out) {
        face = 1;
      } else if (std::abs(q.x() - face_x[2]) < band && r2 > hatch_in && r2 < hatch_out && off_cross) {
        face = 2;
      } else if (std::abs(q.x() - face_x[3]) < band && r2 < plate_out && off_cross) {
        face = 3;
      } else if (std::abs(q.x() - face_x[4]) < band && r2 < cross_out) {
        face = 4;
      }
      if (face == 4) cross_face_points_.push_back(static_cast<int>(plane_points_.size()));
      if (face >= 0) plane_points_.push_back({frame.points[i], face, face_x[face]});
    }
  }
}

bool AdapterFitter::fitPlanes(std::vector<PlanePoint>& points, int pixels_per_point, Eigen::Vector3d* normal,
                              double* offset, double* rms, int* used) {
  // Each face's points enter the least squares only through their sums (count, sum of p, sum of p p^T), so
  // the Gauss-Newton steps cost nothing per point; the points are visited once per rejection scale: wide
  // first (the seed may be off by centimetres), then a few sigma.
  struct FaceSums {
    double x = 0.0;  // the face's x in the port frame
    double count = 0.0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::array<double, 6> upper{};  // the scatter's upper triangle, row by row (p p^T is symmetric)
    Eigen::Matrix3d scatter;
  };
  Eigen::Vector3d n = *normal;
  double d = *offset;
  const double sigma = options_.range_sigma_m;
  const double rejects[3] = {2.0 * options_.plane_band_m, 4.0 * sigma, 3.0 * sigma};
  for (int pass = 0; pass < 3; ++pass) {
    const double reject = rejects[pass];
    // The first two passes only bring the plane near: every 4th point; the last one all.
    const std::size_t step = pass < 2 && points.size() > 4u * options_.min_plane_points ? 4 : 1;
    std::array<FaceSums, kFaces> faces;
    double sum_sq = 0.0;
    int inliers = 0;
    // The current face's sums in local scalars (faces[face] in memory made each step wait on the previous
    // store), swapped in and out where the face changes (a few times per image row); every face's sums still
    // add its points in the same order.
    int current = -1;
    double count = 0.0, s0 = 0.0, s1 = 0.0, s2 = 0.0, u0 = 0.0, u1 = 0.0, u2 = 0.0, u3 = 0.0, u4 = 0.0,
           u5 = 0.0;
    const auto store = [&]() {
      if (current < 0) return;
      FaceSums& f = faces[current];
      f.count = count;
      f.sum = Eigen::Vector3d(s0, s1, s2);
      f.upper = {u0, u1, u2, u3, u4, u5};
    };
    for (std::size_t k = 0; k < points.size(); k += step) {
      const PlanePoint& pp = points[k];
      const Eigen::Vector3d p = pp.p.cast<double>();
      const double residual = n.dot(p) - d - pp.face_x;
      if (std::abs(residual) > reject) continue;
      if (pp.face != current) {
        store();
        current = pp.face;
        FaceSums& f = faces[current];
        f.x = pp.face_x;
        count = f.count;
        s0 = f.sum.x();
        s1 = f.sum.y();
        s2 = f.sum.z();
        u0 = f.upper[0];
        u1 = f.upper[1];
        u2 = f.upper[2];
        u3 = f.upper[3];
        u4 = f.upper[4];
        u5 = f.upper[5];
      }
      count += 1.0;
      s0 += p.x();
      s1 += p.y();
      s2 += p.z();
      u0 += p.x() * p.x();
      u1 += p.x() * p.y();
      u2 += p.x() * p.z();
      u3 += p.y() * p.y();
      u4 += p.y() * p.z();
      u5 += p.z() * p.z();
      sum_sq += residual * residual;
      ++inliers;
    }
    store();
    for (FaceSums& f : faces) {
      const std::array<double, 6>& u = f.upper;
      f.scatter << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
    }
    if (inliers * static_cast<int>(step) * pixels_per_point < options_.min_plane_points) return false;
    *rms = std::sqrt(sum_sq / inliers);
    *used = inliers;
    for (int step = 0; step < 3; ++step) {
      // Residual e = n.p - d - x of a face's point, Jacobian J = (t1.p, t2.p, -1) for n + a t1 + b t2, d + c.
      const Eigen::Matrix3d R = portRotation(n, 0.0);
      const Eigen::Vector3d t1 = R.col(1), t2 = R.col(2);
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      Eigen::Vector3d b = Eigen::Vector3d::Zero();
      for (const FaceSums& f : faces) {
        if (f.count == 0.0) continue;
        const double offset_f = d + f.x;
        const Eigen::Vector3d Mt1 = f.scatter * t1, Mt2 = f.scatter * t2, Mn = f.scatter * n;
        A(0, 0) += t1.dot(Mt1);
        A(0, 1) += t1.dot(Mt2);
        A(1, 1) += t2.dot(Mt2);
        A(0, 2) -= t1.dot(f.sum);
        A(1, 2) -= t2.dot(f.sum);
        A(2, 2) += f.count;
        b(0) -= t1.dot(Mn) - offset_f * t1.dot(f.sum);
        b(1) -= t2.dot(Mn) - offset_f * t2.dot(f.sum);
        b(2) += n.dot(f.sum) - offset_f * f.count;
      }
      A(1, 0) = A(0, 1);
      A(2, 0) = A(0, 2);
      A(2, 1) = A(1, 2);
      const Eigen::Vector3d delta = A.ldlt().solve(b);
      n = (n + delta(0) * t1 + delta(1) * t2).normalized();
      d += delta(2);
    }
  }
  *normal = n;
  *offset = d;
  return true;
}

Eigen::Vector2d AdapterFitter::crossStart(const std::vector<Eigen::Vector2d>& points, double angle) const {
  // Each arm piles its points up at one offset across it (the other arm spreads along): the mode of the
  // offsets across each arm's axis, refined by the mean near it, is where that arm's centre line lies.
  constexpr double kBin = 0.01, kHalfSpan = 0.5;
  constexpr int kBins = static_cast<int>(2 * kHalfSpan / kBin);
  Eigen::Vector2d centre;
  for (int arm = 0; arm < 2; ++arm) {
    const Eigen::Vector2d across = arm == 0 ? Eigen::Vector2d(-std::sin(angle), std::cos(angle))
                                            : Eigen::Vector2d(std::cos(angle), std::sin(angle));
    std::array<int, kBins> histogram{};
    for (const Eigen::Vector2d& s : points) {
      const int bin = static_cast<int>(std::floor((s.dot(across) + kHalfSpan) / kBin));
      if (bin >= 0 && bin < kBins) ++histogram[bin];
    }
    int best = 0, best_count = -1;
    for (int bin = 1; bin + 1 < kBins; ++bin) {
      const int count = histogram[bin - 1] + histogram[bin] + histogram[bin + 1];
      if (count > best_count) {
        best_count = count;
        best = bin;
      }
    }
    const double peak = (best + 0.5) * kBin - kHalfSpan;
    double sum = 0.0;
    int n = 0;
    for (const Eigen::Vector2d& s : points) {
      if (std::abs(s.dot(across) - peak) < 0.03) {
        sum += s.dot(across);
        ++n;
      }
    }
    centre(arm) = n > 0 ? sum / n : peak;  // offset across arm `arm`
  }
  // centre(0): offset across arm 0 (along arm 1's axis), centre(1): offset across arm 1 (along arm 0's axis).
  return centre(1) * Eigen::Vector2d(std::cos(angle), std::sin(angle)) +
         centre(0) * Eigen::Vector2d(-std::sin(angle), std::cos(angle));
}

bool AdapterFitter::fitCross(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d* centre,
                             double* angle) const {
  const AdapterGeometry& g = geometry_;
  const double half_width = 0.035;  // the arms are 0.04 m wide; the window allows for the guess's error
  for (int iteration = 0; iteration < 3; ++iteration) {
    const Eigen::Vector2d axis[2] = {{std::cos(*angle), std::sin(*angle)},
                                     {-std::sin(*angle), std::cos(*angle)}};
    Eigen::Vector2d mean[2] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
    Eigen::Matrix2d scatter[2] = {Eigen::Matrix2d::Zero(), Eigen::Matrix2d::Zero()};
    int count[2] = {0, 0};
    double reach[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
    for (int arm = 0; arm < 2; ++arm) {
      for (const Eigen::Vector2d& s : points) {
        const Eigen::Vector2d offset = s - *centre;
        const double along = offset.dot(axis[arm]), across = offset.dot(axis[1 - arm]);
        // Outside the central square, where both arms overlap.
        if (std::abs(across) > half_width || std::abs(along) < 0.03) continue;
        mean[arm] += s;
        scatter[arm] += s * s.transpose();
        ++count[arm];
        reach[arm][along > 0 ? 0 : 1] = std::max(reach[arm][along > 0 ? 0 : 1], std::abs(along));
      }
    }
    for (int arm = 0; arm < 2; ++arm) {
      // Each arm seen along a good part of its length.
      if (count[arm] < options_.min_cross_points / 2 ||
          reach[arm][0] + reach[arm][1] < g.cross_half_length_m) {
        return false;
      }
    }
    Eigen::Vector2d direction[2];
    for (int arm = 0; arm < 2; ++arm) {
      mean[arm] /= count[arm];
      const Eigen::Matrix2d cov = scatter[arm] / count[arm] - mean[arm] * mean[arm].transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
      direction[arm] = eig.eigenvectors().col(1);
      if (direction[arm].dot(axis[arm]) < 0.0) direction[arm] = -direction[arm];
    }
    // Intersection of mean0 + a direction0 and mean1 + b direction1.
    Eigen::Matrix2d A;
    A << direction[0], -direction[1];
    if (std::abs(A.determinant()) < 0.5) return false;  // not a cross
    const Eigen::Vector2d ab = A.lu().solve(mean[1] - mean[0]);
    *centre = mean[0] + ab(0) * direction[0];
    // The arms' directions give the angle of the port's y axis (arm 0) modulo 90 deg; average the two.
    const double a0 = std::atan2(direction[0].y(), direction[0].x());
    const double a1 = std::atan2(direction[1].y(), direction[1].x()) - M_PI / 2.0;
    *angle = a0 + 0.5 * wrapPi(a1 - a0);
  }
  // A cross, not a blob at the cross's depth: most points within an arm's width of its centre line (a disc:
  // 25 %).
  const Eigen::Vector2d axis0(std::cos(*angle), std::sin(*angle)), axis1(-std::sin(*angle), std::cos(*angle));
  int on_arms = 0;
  for (const Eigen::Vector2d& s : points) {
    const Eigen::Vector2d offset = s - *centre;
    if (std::abs(offset.dot(axis0)) < half_width || std::abs(offset.dot(axis1)) < half_width) ++on_arms;
  }
  return on_arms >= 0.6 * points.size();
}

bool AdapterFitter::fitRound(const PreparedFrame& frame, const std::vector<int>& ring_face_pixels,
                             const Eigen::Isometry3d& T_lidar_port_guess, double band,
                             const Sampling& sampling, RoundResult* out, std::string* reason) {
  const AdapterGeometry& g = geometry_;
  RoundResult& r = *out;
  r = RoundResult();

  // 1. The adapter's faces and the joint plane fit.
  labelPlanePoints(frame, ring_face_pixels, T_lidar_port_guess, band, sampling);
  r.n = T_lidar_port_guess.linear().col(0);
  r.d = r.n.dot(T_lidar_port_guess.translation());
  if (!fitPlanes(plane_points_, sampling.pixelsPerSample(), &r.n, &r.d, &r.report.plane_rms_m,
                 &r.report.plane_points)) {
    *reason = "adapter faces not found (" + std::to_string(plane_points_.size()) + " points)";
    return false;
  }
  if (r.n.z() > 0.0) {  // the port faces the lidar
    r.n = -r.n;
    r.d = -r.d;
  }
  const Eigen::Vector3d& n = r.n;
  const double d = r.d;
  const Eigen::Vector3d guess = T_lidar_port_guess.translation();
  r.origin = guess - (n.dot(guess) - d) * n;
  const Eigen::Matrix3d R0 = portRotation(n, 0.0);
  r.e1 = R0.col(1);
  r.e2 = R0.col(2);
  const auto inPlane = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d v = p - r.origin;
    return Eigen::Vector2d(v.dot(r.e1), v.dot(r.e2));
  };
  const double boresight_guess = boresightAngle(T_lidar_port_guess.linear());
  const double pixel_m = std::abs(d) * options_.pixel_pitch_rad;
  const double on_plane = 3.0 * options_.range_sigma_m + 0.01;
  const double edge_window = 0.06;  // how far the guess's centre may be off

  // 2. Ring edges: a ring pixel next to one that is not on the ring (behind it, or no return: the passage's
  // wall seen at grazing incidence). The edge lies between the two pixel centres: take the midpoint of their
  // rays' intersections with the docking plane (unbiased to a fraction of a pixel). A neighbour without a
  // return gets its ray by extrapolation in normalized image coordinates (linear in the pixel index for a
  // pinhole).
  inner_edge_.clear();
  outer_edge_.clear();
  const int width = frame.width, height = frame.height;
  // n.p of every pixel scanned and of its four neighbours, once: each is read again as a neighbour of four.
  // The edge points keep full resolution at any sampling: a scanned pixel is paired with its adjacent
  // pixels (in a checkerboard, or with every row scanned, that is every pixel).
  along_.resize(frame.points.size());
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; u += v % sampling.row_step == 0 ? 1 : sampling.col_step) {
      along_[v * width + u] = n.dot(frame.points[v * width + u].cast<double>());
    }
  }
  const int steps[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  // Whether the neighbour in direction step can make pixel (u, v) an edge: behind the plane, or no return
  // with a return beyond it to extrapolate from.
  const auto edgeNeighbour = [&](int u, int v, const int* step) {
    const int uj = u + step[0], vj = v + step[1], uk = u - step[0], vk = v - step[1];
    if (uj < 0 || uj >= width || vj < 0 || vj >= height) return false;
    const int j = vj * width + uj;
    if (frame.isValid(j)) return d - along_[j] >= on_plane;
    return uk >= 0 && uk < width && vk >= 0 && vk < height && frame.isValid(vk * width + uk);
  };
  for (int v = 0; v < height; v += sampling.row_step) {
    for (int u = sampling.firstColumn(v); u < width; u += sampling.col_step) {
      const int i = v * width + u;
      if (!frame.isValid(i)) continue;
      if (std::abs(along_[i] - d) > on_plane) continue;
      // Most plane pixels are inside the ring's face: skip them before the projection.
      if (!edgeNeighbour(u, v, steps[0]) && !edgeNeighbour(u, v, steps[1]) &&
          !edgeNeighbour(u, v, steps[2]) && !edgeNeighbour(u, v, steps[3])) {
        continue;
      }
      const Eigen::Vector3d p = frame.points[i].cast<double>();
      const Eigen::Vector2d si = inPlane(p * (d / along_[i]));
      // On the docking plane and near the ring (the labels stop short of the edges, so go by geometry here).
      const double radius = (si - r.centre_guess).norm();
      if (radius < g.ring_inner_radius_m - edge_window || radius > g.ring_outer_radius_m + edge_window)
        continue;
      for (const auto& step : steps) {
        if (!edgeNeighbour(u, v, step)) continue;
        const int uj = u + step[0], vj = v + step[1], uk = u - step[0], vk = v - step[1];
        const int j = vj * width + uj;
        Eigen::Vector3d ray_j;
        if (frame.isValid(j)) {
          ray_j = frame.points[j].cast<double>();
        } else {
          const Eigen::Vector3d pk = frame.points[vk * width + uk].cast<double>();
          ray_j = 2.0 * p / p.z() - pk / pk.z();
        }
        const double along = n.dot(ray_j);
        if (std::abs(along) < 1e-9) continue;
        const Eigen::Vector2d sj = inPlane(ray_j * (d / along));
        const Eigen::Vector2d mid = 0.5 * (si + sj);
        // Inner edge when the neighbour's ray meets the plane nearer the centre.
        const bool inner = (sj - r.centre_guess).squaredNorm() < (si - r.centre_guess).squaredNorm();
        (inner ? inner_edge_ : outer_edge_).push_back(mid);
      }
    }
  }
  r.report.edge_points = static_cast<int>(inner_edge_.size());

  // 3. Circle fit: centre shared by the inner and outer edges, each its own radius (a radial bias of the edge
  // samples then moves the radius, not the centre).
  if (static_cast<int>(inner_edge_.size()) >= options_.min_edge_points) {
    // Start: Kasa's algebraic fit of the inner edge, x^2 + y^2 + D x + E y + F = 0.
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (const Eigen::Vector2d& s : inner_edge_) {
      const Eigen::Vector3d row(s.x(), s.y(), 1.0);
      A += row * row.transpose();
      b -= row * s.squaredNorm();
    }
    const Eigen::Vector3d k = A.ldlt().solve(b);
    Eigen::Vector4d x(-k(0) / 2, -k(1) / 2, g.ring_inner_radius_m, g.ring_outer_radius_m);
    if (!x.allFinite() || (x.head<2>() - r.centre_guess).norm() > edge_window) {
      x.head<2>() = r.centre_guess;
    }
    const bool use_outer = static_cast<int>(outer_edge_.size()) >= options_.min_edge_points;
    double reject = 3.0 * pixel_m + 0.03;
    double rms = 0.0;
    int used = 0;
    Eigen::Matrix4d H = Eigen::Matrix4d::Identity();
    for (int iteration = 0; iteration < 8; ++iteration) {
      H.setZero();
      Eigen::Vector4d grad = Eigen::Vector4d::Zero();
      double sum_sq = 0.0;
      used = 0;
      int outer_used = 0;
      const auto add = [&](const std::vector<Eigen::Vector2d>& pts, int radius_index) {
        // J = (jx, jy, -1 at radius_index, 0): only H's nonzero terms, in local scalars (H and grad captured
        // by reference stay in memory and each step waits on the previous store), summed in the same order.
        double h00 = H(0, 0), h01 = H(0, 1), h11 = H(1, 1), h0r = H(0, radius_index),
               h1r = H(1, radius_index), hrr = H(radius_index, radius_index);
        double g0 = grad(0), g1 = grad(1), gr = grad(radius_index);
        const double x0 = x(0), x1 = x(1), radius_model = x(radius_index);
        for (const Eigen::Vector2d& s : pts) {
          const Eigen::Vector2d offset = s - Eigen::Vector2d(x0, x1);
          const double radius = offset.norm();
          if (radius < 1e-6) continue;
          const double residual = radius - radius_model;
          if (std::abs(residual) > reject) continue;
          const double jx = -offset.x() / radius, jy = -offset.y() / radius;
          h00 += jx * jx;
          h01 += jx * jy;
          h11 += jy * jy;
          h0r -= jx;
          h1r -= jy;
          hrr += 1.0;
          g0 += jx * residual;
          g1 += jy * residual;
          gr -= residual;
          sum_sq += residual * residual;
          ++used;
          outer_used += radius_index == 3 ? 1 : 0;
        }
        H(0, 0) = h00;
        H(0, 1) = H(1, 0) = h01;
        H(1, 1) = h11;
        H(0, radius_index) = H(radius_index, 0) = h0r;
        H(1, radius_index) = H(radius_index, 1) = h1r;
        H(radius_index, radius_index) = hrr;
        grad(0) = g0;
        grad(1) = g1;
        grad(radius_index) = gr;
      };
      add(inner_edge_, 2);
      if (use_outer) add(outer_edge_, 3);
      if (outer_used == 0) H(3, 3) += 1.0;  // the outer radius is then not observed: keep it
      if (used < options_.min_edge_points) break;
      x -= H.ldlt().solve(grad);
      rms = std::sqrt(sum_sq / used);
      reject = std::max(3.0 * rms, 0.5 * pixel_m + 0.003);
    }
    std::vector<double> angles;
    angles.reserve(inner_edge_.size());
    for (const Eigen::Vector2d& s : inner_edge_) {
      const Eigen::Vector2d offset = s - x.head<2>();
      if (std::abs(offset.norm() - x(2)) < reject) angles.push_back(std::atan2(offset.y(), offset.x()));
    }
    r.report.edge_arc_deg = (2.0 * M_PI - largestGap(angles)) / kDeg;
    r.report.inner_radius_m = x(2);
    if (used >= options_.min_edge_points && r.report.edge_arc_deg >= options_.min_edge_arc_deg &&
        std::abs(x(2) - g.ring_inner_radius_m) < options_.max_radius_error_m) {
      r.report.circle = true;
      r.circle_centre = x.head<2>();
      r.circle_cov = (rms * rms + 1e-8) * H.inverse().topLeftCorner<2, 2>();
      // Whether the field of view cuts the inner edge (within 2 px of the frame's border: an edge pixel
      // needs its neighbour). What it leaves of the circle is biased: the ISS's closed loop at 2.6-2.2 m,
      // 3-5.5 mm off (the inner edge's arc 300-330 deg) where the centreline cross was within 1 mm.
      const double half_width = (0.5 * width - 2.0) * options_.pixel_pitch_rad,
                   half_height = (0.5 * height - 2.0) * options_.pixel_pitch_rad;
      for (int k = 0; k < 72 && !r.report.circle_clipped; ++k) {
        const double angle = k * M_PI / 36.0;
        const Eigen::Vector3d p =
            r.origin + (x(0) + x(2) * std::cos(angle)) * r.e1 + (x(1) + x(2) * std::sin(angle)) * r.e2;
        r.report.circle_clipped =
            p.z() <= 0.0 || std::abs(p.x()) > half_width * p.z() || std::abs(p.y()) > half_height * p.z();
      }
    }
  }

  // 4. The centreline cross: its front-face points. Each arm's centre line is fitted (principal axis of the
  // points near it), and the cross's centre is where the two lines meet: unbiased when the field of view
  // clips the arms' ends, as it does near contact with the chaser tilted.
  cross_points_.clear();
  for (int k : cross_face_points_) {
    const PlanePoint& pp = plane_points_[k];
    const Eigen::Vector3d p = pp.p.cast<double>();
    if (std::abs(n.dot(p) - d - pp.face_x) <= on_plane) cross_points_.push_back(inPlane(p));
  }
  r.report.cross_points = static_cast<int>(cross_points_.size());
  Eigen::Vector2d cross_centre = r.centre_guess;
  double cross_angle = boresight_guess;
  if (r.report.cross_points >= options_.min_cross_points) {
    cross_centre = r.report.circle ? r.circle_centre : crossStart(cross_points_, boresight_guess);
    r.report.cross = fitCross(cross_points_, &cross_centre, &cross_angle);
    r.cross_angle = cross_angle;
  }
  const int cross_count = r.report.cross_points;

  // 5. Lateral position: the two measurements weighted by their variances.
  if (!r.report.circle && !r.report.cross) {
    *reason = "neither the ring's edge (" + std::to_string(r.report.edge_points) + " points, arc " +
              std::to_string(static_cast<int>(r.report.edge_arc_deg)) + " deg) nor the centreline target (" +
              std::to_string(r.report.cross_points) + " points) found";
    return false;
  }
  const double cross_sigma = std::max(0.5 * pixel_m / std::sqrt(std::max(1, cross_count)), 5e-4);
  const Eigen::Matrix2d cross_cov = cross_sigma * cross_sigma * Eigen::Matrix2d::Identity();
  if (r.report.circle && r.report.cross && r.report.circle_clipped) {
    r.lateral = cross_centre;
    r.lateral_cov = cross_cov;
  } else if (r.report.circle && r.report.cross) {
    const Eigen::Matrix2d info = r.circle_cov.inverse() + cross_cov.inverse();
    r.lateral_cov = info.inverse();
    r.lateral =
        r.lateral_cov * (r.circle_cov.inverse() * r.circle_centre + cross_cov.inverse() * cross_centre);
  } else if (r.report.circle) {
    r.lateral = r.circle_centre;
    r.lateral_cov = r.circle_cov;
  } else {
    r.lateral = cross_centre;
    r.lateral_cov = cross_cov;
  }
  r.centre = r.origin + r.lateral.x() * r.e1 + r.lateral.y() * r.e2;
  return true;
}

double AdapterFitter::reflectorAngle(const PreparedFrame& frame, const Eigen::Isometry3d& T_port0_lidar,
                                     double d, AdapterFitReport* report) const {
  const AdapterGeometry& g = geometry_;
  // Points on the discs' faces: from 2.5 cm behind (the brackets' faces lie 3 cm behind) to 10 cm in front,
  // within a disc radius (and 2 cm) of the reflectors' circle. Each disc's angle is the circular mean of its
  // points' angles (on three times the angle, less 180 deg: the discs sit 60 deg off the petals).
  const double face_min = g.reflector_face_x_m - 0.025, face_max = g.reflector_face_x_m + 0.1;
  const double radius_min = g.reflector_radius_m - g.reflector_disc_radius_m - 0.02;
  const double radius_max = g.reflector_radius_m + g.reflector_disc_radius_m + 0.02;
  std::vector<AnglePoint> points;
  std::complex<double> total = 0.0;
  const double along_min = d + face_min - 1e-6, along_max = d + face_max + 1e-6;
  const int pixels = frame.width * frame.height;
  for (int i = 0; i < pixels; ++i) {
    if (!frame.isValid(i) || along_[i] <= along_min || along_[i] >= along_max) continue;
    // The blooming around a disc (its range on neighbouring pixels, weaker) would widen it at random.
    if (frame.has_intensity && !frame.saturated[i]) continue;
    const Eigen::Vector3d q = T_port0_lidar * frame.points[i].cast<double>();
    if (q.x() <= face_min || q.x() >= face_max) continue;
    const double radius = std::sqrt(q.y() * q.y() + q.z() * q.z());
    if (radius <= radius_min || radius >= radius_max) continue;
    const double angle = std::atan2(q.z(), q.y());
    points.push_back({angle, -std::polar(1.0, 3.0 * angle), onBorder(frame, i)});
    total += points.back().unit3;
  }
  // Per disc (nearest of the discs at the first estimate), those touching the border left out. Only points
  // on a disc's face at the first estimate count: a spurious return elsewhere on the circle (background,
  // hot pixels) would pull a disc's mean by its whole angle / count (0.3 deg seen at 10 m).
  const double first_disc = std::arg(total) / 3.0 + M_PI / 3.0;
  const double half_width =
      std::asin(std::min(1.0, (g.reflector_disc_radius_m + 0.04) / g.reflector_radius_m));
  const PerFeature per_disc = perFeature(points, first_disc, half_width);
  std::complex<double> sum = 0.0;
  int discs = 0, count = 0;
  for (int k = 0; k < 3; ++k) {
    if (per_disc.border[k] || per_disc.count[k] < options_.min_reflector_points) continue;
    sum += per_disc.sum[k] / static_cast<double>(per_disc.count[k]);  // each disc counts once
    ++discs;
    count += per_disc.count[k];
  }
  report->reflector_points = count;
  report->reflectors = discs >= 2 && std::abs(sum) >= options_.min_resultant * discs;
  return std::arg(sum) / 3.0;
}

bool AdapterFitter::onBorder(const PreparedFrame& frame, int pixel) const {
  const int u = pixel % frame.width, v = pixel / frame.width;
  return u < 2 || v < 2 || u >= frame.width - 2 || v >= frame.height - 2;
}

PoseResult AdapterFitter::fit(const PreparedFrame& frame, const std::vector<int>& ring_face_pixels,
                              const Eigen::Isometry3d& T_lidar_port_seed,
                              const Eigen::Isometry3d& T_lidar_port_prior, EstimateMethod method,
                              AdapterFitReport* report_out) {
  const AdapterGeometry& g = geometry_;
  PoseResult result;
  result.method = method;
  RoundResult r;
  const auto finish = [&](PoseResult out) {
    if (report_out) *report_out = r.report;
    return out;
  };
  if (frame.valid_count < options_.min_plane_points) {
    result.reason = "too few returns";
    return finish(result);
  }

  // Two rounds: labels from the seed, then from the first round's plane and centre with a narrower band.
  const double seed_boresight = boresightAngle(T_lidar_port_seed.linear());
  Eigen::Isometry3d T_guess = T_lidar_port_seed;
  // A first round that found the plane but not the centre (the seed's range or tilt was off by a good part of
  // the band) gets a second chance with the plane it found.
  for (int round = 0; round < 2; ++round) {
    // The first round only brings the guess near: every second pixel in u and v, a quarter of the cost (its
    // minimum edge and cross counts are not scaled down: a circle or cross it cannot back well enough leaves
    // the plane-only second chance). The second: a checkerboard (options_.fine_checkerboard) or every pixel.
    const Sampling sampling =
        round == 0 ? Sampling{2, 2, 0} : (options_.fine_checkerboard ? Sampling{1, 2, 1} : Sampling{});
    const bool ok = fitRound(frame, ring_face_pixels, T_guess,
                             round == 0 ? options_.plane_band_m : 0.6 * options_.plane_band_m, sampling, &r,
                             &result.reason);
    if (!ok && (round == 1 || r.report.plane_points == 0)) return finish(result);
    T_guess.linear() = portRotation(r.n, seed_boresight);
    T_guess.translation() = ok ? r.centre : r.origin;
  }
  result.reason.clear();  // a first round's failure that the second made good

  // 6. Rotation about the boresight: the petals repeat every 120 deg (the first on the port's +y), the
  // cross's arms every 90 deg (on +-y, +-z). Each is a circular mean of k * angle; together they leave one
  // answer, alone the branch nearest the prior. A petal clipped by the image border is left out (its centroid
  // would be biased).
  const double on_plane = 3.0 * options_.range_sigma_m + 0.01;
  Eigen::Isometry3d T_plane = Eigen::Isometry3d::Identity();
  T_plane.linear() = portRotation(r.n, 0.0);
  T_plane.translation() = r.centre;
  const Eigen::Isometry3d T_port0_lidar = T_plane.inverse();
  std::vector<AnglePoint> petal_points;
  std::complex<double> petal_sum = 0.0;
  // q.x() below is n.p - d up to rounding, and the last round left n.p of every pixel in along_: most pixels
  // are rejected on it (with a margin far above the rounding) before the transform.
  const double along_min = r.d + on_plane - 1e-6, along_max = r.d + g.petal_top_x_m + 0.02 + 1e-6;
  const int pixels = frame.width * frame.height;
  for (int i = 0; i < pixels; ++i) {
    if (!frame.isValid(i) || along_[i] <= along_min || along_[i] >= along_max) continue;
    const Eigen::Vector3d q = T_port0_lidar * frame.points[i].cast<double>();
    if (q.x() <= on_plane || q.x() >= g.petal_top_x_m + 0.02) continue;
    const double radius = std::sqrt(q.y() * q.y() + q.z() * q.z());
    if (radius > g.petal_min_radius_m && radius < g.petal_max_radius_m) {
      const double angle = std::atan2(q.z(), q.y());
      petal_points.push_back({angle, std::polar(1.0, 3.0 * angle), onBorder(frame, i)});
      petal_sum += petal_points.back().unit3;
    }
  }
  // Per petal (nearest branch of the first estimate), drop those touching the border, then the mean again.
  const PerFeature per_petal =
      perFeature(petal_points, std::arg(petal_sum) / 3.0, std::numeric_limits<double>::infinity());
  petal_sum = 0.0;
  int petal_count = 0;
  for (int k = 0; k < 3; ++k) {
    if (per_petal.border[k]) continue;
    petal_sum += per_petal.sum[k];
    petal_count += per_petal.count[k];
  }
  r.report.petal_points = petal_count;
  const double prior_angle = boresightAngle(T_lidar_port_prior.linear());
  r.report.petals =
      petal_count >= options_.min_petal_points && std::abs(petal_sum) >= options_.min_resultant * petal_count;
  r.report.cross_angle = r.report.cross;
  const double petal_angle = std::arg(petal_sum) / 3.0;
  const double cross_angle = r.cross_angle;
  const double cross_pixel_m = (std::abs(r.d) - g.cross_face_x_m) * options_.pixel_pitch_rad;
  const bool cross_fine = cross_pixel_m < 0.006;  // arms 6.7+ pixels wide (at 4-5 the angle is biased ~1 deg)
  double boresight = prior_angle;
  if (r.report.petals && r.report.cross_angle) {
    // The one petal branch that agrees with a cross branch (wrong pairs differ by 30 deg or more).
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double candidate = petal_angle + k * 2.0 * M_PI / 3.0;
      const double partner = nearestBranch(cross_angle, M_PI / 2.0, candidate);
      if (std::abs(wrapPi(candidate - partner)) < best) {
        best = std::abs(wrapPi(candidate - partner));
        // The cross's arms are a few pixels wide only when near (cross_fine): then the two are averaged,
        // otherwise the cross only picks the petals' branch.
        boresight = cross_fine ? candidate + 0.5 * wrapPi(partner - candidate) : candidate;
      }
    }
  } else if (r.report.petals) {
    boresight = nearestBranch(petal_angle, 2.0 * M_PI / 3.0, prior_angle);
  } else if (r.report.cross_angle) {
    boresight = nearestBranch(cross_angle, M_PI / 2.0, prior_angle);
  }
  // The reflector targets lie three times further out than the petals: their discs' angles, where two or
  // more are whole in the view (inside ~7 m they leave it), refine the branch chosen above.
  const double reflector_angle = reflectorAngle(frame, T_port0_lidar, r.d, &r.report);
  if (r.report.reflectors) {
    const double reference = r.report.petals || r.report.cross_angle ? boresight : prior_angle;
    boresight = nearestBranch(reflector_angle, 2.0 * M_PI / 3.0, reference);
  }
  result.boresight_rotation_observed = r.report.petals || r.report.cross_angle || r.report.reflectors;
  // Tracking: a measurement close to the prediction only pulls it part of the way (the angle changes slowly,
  // the petals' centroids are noisy at several metres); a far one (a new prior, a hand-over) is taken as it
  // is.
  if (result.boresight_rotation_observed &&
      std::abs(wrapPi(boresight - prior_angle)) < options_.boresight_gate_deg * kDeg) {
    boresight = prior_angle + options_.boresight_gain * wrapPi(boresight - prior_angle);
  }

  // 7. The pose.
  Eigen::Isometry3d T_lidar_port = Eigen::Isometry3d::Identity();
  T_lidar_port.linear() = portRotation(r.n, boresight);
  T_lidar_port.translation() = r.centre;
  result.T_lidar_target = T_lidar_port * g.T_target_port.inverse();
  result.fit_rms_m = r.report.plane_rms_m;
  result.points_used = r.report.plane_points + r.report.edge_points + r.report.cross_points;
  result.inlier_fraction =
      static_cast<double>(r.report.plane_points) / std::max<std::size_t>(1, plane_points_.size());
  result.iterations = 2;

  // Covariance of the port's pose, in lidar axes (x y z, rot x y z): lateral from the circle / cross fit,
  // along the normal and the two tilts from the plane fit, the boresight angle from whether it was observed;
  // then moved to the target origin, as PoseResult::covariance is (as the port's, the origin's said the
  // port's position where its roll and tilt move the origin: the ISS's 4.5 m off the docking axis, 39 mm on
  // lidar x from a 0.5 deg roll sigma).
  const double plane_sigma =
      std::max(r.report.plane_rms_m, 1e-4) / std::sqrt(static_cast<double>(r.report.plane_points));
  Eigen::Matrix3d position_cov = plane_sigma * plane_sigma * r.n * r.n.transpose();
  Eigen::Matrix<double, 3, 2> E;
  E << r.e1, r.e2;
  position_cov += E * r.lateral_cov * E.transpose();
  const double tilt_sigma = plane_sigma / g.ring_outer_radius_m;
  const double spin_sigma = result.boresight_rotation_observed ? 0.5 * kDeg : M_PI;
  const Eigen::Matrix3d rotation_cov =
      tilt_sigma * tilt_sigma * (E * E.transpose()) + spin_sigma * spin_sigma * r.n * r.n.transpose();
  Eigen::Matrix<double, 6, 6> port_cov = Eigen::Matrix<double, 6, 6>::Zero();
  port_cov.topLeftCorner<3, 3>() = position_cov;
  port_cov.bottomRightCorner<3, 3>() = rotation_cov;
  result.covariance =
      covarianceAt(port_cov, -(result.T_lidar_target.linear() * g.T_target_port.translation()));

  // 8. A pose far from the prediction is more likely a wrong detection than a real jump between frames.
  const Eigen::Vector3d jump = T_lidar_port.translation() - T_lidar_port_prior.translation();
  const double tilt_change =
      std::acos(std::clamp(r.n.dot(T_lidar_port_prior.linear().col(0)), -1.0, 1.0)) / kDeg;
  if (jump.norm() > options_.max_step_from_prediction_m ||
      tilt_change > options_.max_tilt_from_prediction_deg) {
    result.reason = "fit " + std::to_string(jump.norm()) + " m / " + std::to_string(tilt_change) +
                    " deg away from the prediction";
    return finish(result);
  }
  const bool strong =
      r.report.circle || (r.report.cross && r.report.cross_points >= 3 * options_.min_cross_points);
  result.status = strong ? EstimateStatus::kTracking : EstimateStatus::kDegraded;
  if (!strong) result.reason = "lateral position from a small centreline target";
  return finish(result);
}

}  // namespace close_range
}  // namespace ardsim_pose
