#include "ardsim_pose/close_range/mode_manager.h"

#include <cmath>

#include "ardsim_pose/require_option.h"

namespace ardsim_pose {
namespace close_range {

void validate(const ModeManagerOptions& o) {
  requireOption(o.close_enter_range_m > 0.0, "mode/close_enter_range_m", o.close_enter_range_m, "> 0");
  requireOption(o.close_exit_range_m > o.close_enter_range_m, "mode/close_exit_range_m", o.close_exit_range_m,
                "> mode/close_enter_range_m (hysteresis)");
  requireOption(o.close_enter_fill >= 0.0 && o.close_enter_fill <= 1.0, "mode/close_enter_fill",
                o.close_enter_fill, "0 .. 1");
  requireOption(o.lost_frames_to_exit >= 1, "mode/lost_frames_to_exit", o.lost_frames_to_exit, ">= 1");
  requireOption(o.blend_frames >= 1, "mode/blend_frames", o.blend_frames, ">= 1");
  requireOption(o.close_method == EstimateMethod::kRing || o.close_method == EstimateMethod::kPyramid,
                "mode/close_method", static_cast<int>(o.close_method), "ring or pyramid");
}

double viewFill(const OrganizedCloud& cloud) {
  if (cloud.points.empty()) return 0.0;
  int returns = 0;
  for (const Eigen::Vector3f& p : cloud.points) returns += p.allFinite() ? 1 : 0;
  return static_cast<double>(returns) / static_cast<double>(cloud.points.size());
}

ModeManager::ModeManager(const ModeManagerOptions& options, EstimateMethod initial) : options_(options) {
  validate(options_);
  reset(initial);
}

void ModeManager::reset(EstimateMethod initial) {
  current_ = initial;
  previous_ = initial;
  frames_since_switch_ = options_.blend_frames;
  lost_frames_ = 0;
}

ModeManager::Decision ModeManager::update(double port_range_m, double view_fill, bool last_lost) {
  const bool close = current_ != EstimateMethod::kIcp;
  lost_frames_ = close && last_lost ? lost_frames_ + 1 : 0;
  EstimateMethod next = current_;
  if (!close && std::isfinite(port_range_m) && port_range_m < options_.close_enter_range_m &&
      view_fill >= options_.close_enter_fill) {
    next = options_.close_method;
  } else if (close &&
             (port_range_m > options_.close_exit_range_m || (lost_frames_ >= options_.lost_frames_to_exit &&
                                                             port_range_m > options_.close_enter_range_m))) {
    next = EstimateMethod::kIcp;
  }
  Decision decision;
  if (next != current_) {
    previous_ = current_;
    current_ = next;
    frames_since_switch_ = 0;
    lost_frames_ = 0;
    decision.switched = true;
  }
  decision.method = current_;
  if (frames_since_switch_ < options_.blend_frames) {
    decision.previous = previous_;
    decision.weight = static_cast<double>(frames_since_switch_ + 1) / options_.blend_frames;
    ++frames_since_switch_;
  } else {
    decision.previous = current_;
    decision.weight = 1.0;
  }
  return decision;
}

Eigen::Isometry3d blendPoses(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double weight) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = (1.0 - weight) * from.translation() + weight * to.translation();
  const Eigen::Quaterniond q_from(from.linear()), q_to(to.linear());
  T.linear() = q_from.slerp(weight, q_to).toRotationMatrix();
  return T;
}

ModeSelector::ModeSelector(const ModeManagerOptions& options, const Eigen::Isometry3d& T_target_port)
    : manager_(options), T_target_port_(T_target_port) {}

EstimateMethod ModeSelector::select(const SelectionInput& input) {
  const double port_range_m = (input.T_lidar_target_predicted * T_target_port_).translation().norm();
  const double fill = input.cloud ? viewFill(*input.cloud) : 0.0;
  const bool last_lost = input.previous && input.previous->status == EstimateStatus::kLost;
  decision_ = manager_.update(port_range_m, fill, last_lost);
  return decision_.method;
}

bool ModeSelector::blending(EstimateMethod* from, double* weight) const {
  if (!decision_.blending()) return false;
  *from = decision_.previous;
  *weight = decision_.weight;
  return true;
}

void ModeSelector::reset() {
  manager_.reset();
  decision_ = ModeManager::Decision();
}

}  // namespace close_range
}  // namespace ardsim_pose
