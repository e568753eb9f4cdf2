#include "ardsim_pose/panel_angle.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "ardsim_pose/require_option.h"

namespace ardsim_pose {

namespace {

// Scan points this far beyond the panels' half-width still count (the pose and the panels' angle are not
// exact); the fit's second pass drops what is not on them.
constexpr double kMarginM = 0.15;

// angle + k pi nearest to reference.
double nearestTurn(double angle_rad, double reference_rad) {
  return angle_rad - M_PI * std::round((angle_rad - reference_rad) / M_PI);
}

// angle + k pi in [-pi/2, pi/2).
double halfTurnRange(double angle_rad) {
  const double a = nearestTurn(angle_rad, 0.0);
  return a >= M_PI / 2 ? a - M_PI : a;
}

struct LineFit {
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  double rms_m = 0.0;
};

// Total least squares: the direction of the points' largest spread through their centroid.
LineFit fitLine(const std::vector<Eigen::Vector2d>& points) {
  LineFit line;
  for (const Eigen::Vector2d& p : points) line.centroid += p;
  line.centroid /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : points) scatter += (p - line.centroid) * (p - line.centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  line.direction = eigen.eigenvectors().col(1);
  line.rms_m = std::sqrt(std::max(0.0, eigen.eigenvalues()(0)) / static_cast<double>(points.size()));
  return line;
}

double across(const LineFit& line, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - line.centroid;
  return line.direction.x() * d.y() - line.direction.y() * d.x();
}

}  // namespace

PanelJoint panelJoint(ardsim_description::TargetKind kind) {
  if (kind != ardsim_description::TargetKind::kHubble)
    throw std::invalid_argument("panels/enabled is not allowed for target " +
                                ardsim_description::targetKindName(kind) +
                                ": its panels do not turn on one joint (hubble only)");
  PanelJoint joint;  // hubble.cpp: masts along body y at x = -1.5; arrays 2.6 x 7.1 m from 3.0 m out
  joint.origin = Eigen::Vector3d(-1.5, 0.0, 0.0);
  joint.axis = Eigen::Vector3d::UnitY();
  joint.zero_direction = Eigen::Vector3d::UnitX();
  joint.min_axial_m = 3.05;  // past the masts' tips (3.0 m)
  joint.max_axial_m = 10.1;
  joint.half_width_m = 1.3;
  return joint;
}

void validate(const PanelOptions& o) {
  requireOption(o.min_points >= 10, "panels/min_points", o.min_points, ">= 10");
  requireOption(std::isfinite(o.min_extent_m) && o.min_extent_m > 0.0, "panels/min_extent_m", o.min_extent_m,
                "> 0");
  requireOption(std::isfinite(o.max_rms_m) && o.max_rms_m > 0.0, "panels/max_rms_m", o.max_rms_m, "> 0");
  requireOption(
      std::isfinite(o.min_incidence_deg) && o.min_incidence_deg >= 0.0 && o.min_incidence_deg < 90.0,
      "panels/min_incidence_deg", o.min_incidence_deg, "0..90 (exclusive)");
  requireOption(o.window >= 1 && o.window <= 99 && o.window % 2 == 1, "panels/window", o.window,
                "odd, 1..99");
  requireOption(o.first_window >= 1 && o.first_window <= o.window && o.first_window % 2 == 1,
                "panels/first_window", o.first_window, "odd, 1..window");
  requireOption(std::isfinite(o.rebuild_deg) && o.rebuild_deg >= 0.01 && o.rebuild_deg <= 10.0,
                "panels/rebuild_deg", o.rebuild_deg, "0.01..10");
}

bool fitPanelAngle(const PanelJoint& joint, const OrganizedCloud& cloud,
                   const Eigen::Isometry3d& T_lidar_target, const PanelOptions& options, PanelFit* fit) {
  *fit = PanelFit();
  // The lidar frame's points in the joint's plane coordinates (along zero_direction, along axis x
  // zero_direction) by one affine map.
  const Eigen::Vector3d across_axis = joint.axis.cross(joint.zero_direction);
  Eigen::Matrix3d R_joint_target;
  R_joint_target.row(0) = joint.zero_direction.transpose();
  R_joint_target.row(1) = across_axis.transpose();
  R_joint_target.row(2) = joint.axis.transpose();
  const Eigen::Isometry3d T_target_lidar = T_lidar_target.inverse();
  const Eigen::Matrix3f R = (R_joint_target * T_target_lidar.linear()).cast<float>();
  const Eigen::Vector3f t = (R_joint_target * (T_target_lidar.translation() - joint.origin)).cast<float>();
  const float reach_sq =
      static_cast<float>((joint.half_width_m + kMarginM) * (joint.half_width_m + kMarginM));
  const float min_axial = static_cast<float>(joint.min_axial_m);
  const float max_axial = static_cast<float>(joint.max_axial_m);
  std::vector<Eigen::Vector2d> points;
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite()) continue;
    const Eigen::Vector3f q = R * p + t;
    const float axial = std::abs(q.z());
    if (axial < min_axial || axial > max_axial || q.x() * q.x() + q.y() * q.y() > reach_sq) continue;
    points.emplace_back(q.x(), q.y());
  }
  if (static_cast<int>(points.size()) < options.min_points) return false;
  LineFit line = fitLine(points);
  std::vector<double> residuals;
  residuals.reserve(points.size());
  for (const Eigen::Vector2d& p : points) residuals.push_back(std::abs(across(line, p)));
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  const double limit_m = std::max(3.0 * 1.4826 * residuals[residuals.size() / 2], 0.01);
  points.erase(std::remove_if(points.begin(), points.end(),
                              [&](const Eigen::Vector2d& p) { return std::abs(across(line, p)) > limit_m; }),
               points.end());
  fit->points = static_cast<int>(points.size());
  if (fit->points < options.min_points) return false;
  line = fitLine(points);
  double low = 0.0, high = 0.0;
  for (const Eigen::Vector2d& p : points) {
    const double along = line.direction.dot(p - line.centroid);
    low = std::min(low, along);
    high = std::max(high, along);
  }
  fit->extent_m = high - low;
  fit->rms_m = line.rms_m;
  fit->angle_rad = halfTurnRange(std::atan2(line.direction.y(), line.direction.x()));
  if (fit->extent_m < options.min_extent_m || fit->rms_m > options.max_rms_m) return false;
  const Eigen::Vector3d across_panels =
      std::cos(fit->angle_rad) * joint.zero_direction + std::sin(fit->angle_rad) * across_axis;
  const Eigen::Vector3d normal = joint.axis.cross(across_panels);
  const Eigen::Vector3d line_of_sight = (joint.origin - T_target_lidar.translation()).normalized();
  fit->incidence_deg = std::asin(std::min(1.0, std::abs(normal.dot(line_of_sight)))) * 180.0 / M_PI;
  fit->grazing = fit->incidence_deg < options.min_incidence_deg;
  return !fit->grazing;
}

PanelTracker::PanelTracker(const PanelJoint& joint, const PanelOptions& options,
                           std::shared_ptr<const ReferenceModel> rigid, ModelBuilder build)
    : joint_(joint), options_(options), rigid_(std::move(rigid)), build_(std::move(build)) {
  validate(options_);
  if (!rigid_ || !build_) throw std::invalid_argument("PanelTracker: no rigid model or no model builder");
}

std::shared_ptr<const ReferenceModel> PanelTracker::update(const OrganizedCloud& cloud,
                                                           const Eigen::Isometry3d& T_lidar_target) {
  const bool ok = fitPanelAngle(joint_, cloud, T_lidar_target, options_, &last_fit_);
  grazing_in_a_row_ = last_fit_.grazing ? grazing_in_a_row_ + 1 : 0;
  if (!ok) {
    if (!model_has_panels_ || grazing_in_a_row_ < options_.window) return nullptr;
    model_has_panels_ = false;  // they turned edge-on: the rigid structure alone
    recent_rad_.clear();
    return rigid_;
  }
  const double reference_rad = model_has_panels_
                                   ? model_angle_rad_
                                   : (recent_rad_.empty() ? last_fit_.angle_rad : recent_rad_.front());
  recent_rad_.push_back(nearestTurn(last_fit_.angle_rad, reference_rad));
  if (static_cast<int>(recent_rad_.size()) > options_.window) recent_rad_.erase(recent_rad_.begin());
  if (static_cast<int>(recent_rad_.size()) < (model_has_panels_ ? options_.window : options_.first_window))
    return nullptr;
  std::vector<double> sorted = recent_rad_;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median_rad = sorted[sorted.size() / 2];
  if (model_has_panels_ && std::abs(nearestTurn(median_rad, model_angle_rad_) - model_angle_rad_) <=
                               options_.rebuild_deg * M_PI / 180.0)
    return nullptr;
  model_angle_rad_ = halfTurnRange(median_rad);
  model_has_panels_ = true;
  // Keep the window near the new angle (its fits unwrapped against it from now on).
  for (double& a : recent_rad_) a = nearestTurn(a, model_angle_rad_);
  return build_(model_angle_rad_);
}

}  // namespace ardsim_pose
