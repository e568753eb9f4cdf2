#include "ardsim_pose/pose_estimator.h"

#include "ardsim_pose/close_range/mode_manager.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ardsim_pose/require_option.h"

namespace ardsim_pose {

namespace {

Eigen::Matrix3d rotationOf(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

double medianOfValues(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));  // even: the two middle ones' mean
}

}  // namespace

void validate(const EstimatorOptions& o) {
  requireOption(o.median_window >= 1 && o.median_window <= 51 && o.median_window % 2 == 1,
                "estimator/median_window", o.median_window, "odd, 1 .. 51");
  requireOption(o.velocity_smoothing > 0.0 && o.velocity_smoothing <= 1.0, "estimator/velocity_smoothing",
                o.velocity_smoothing, "> 0 .. 1");
  requireOption(o.angular_velocity_smoothing > 0.0 && o.angular_velocity_smoothing <= 1.0,
                "estimator/angular_velocity_smoothing", o.angular_velocity_smoothing, "> 0 .. 1");
  requireOption(std::isfinite(o.max_prediction_gap_s) && o.max_prediction_gap_s >= 0.0,
                "estimator/max_prediction_gap_s", o.max_prediction_gap_s, ">= 0");
  requireOption(std::isfinite(o.restart_time_jump_s) && o.restart_time_jump_s >= 0.0,
                "estimator/restart_time_jump_s", o.restart_time_jump_s, ">= 0");
  const bool composite_off = o.composite_min_port_range_m == 0.0 && o.composite_max_port_range_m == 0.0;
  requireOption(
      composite_off || (o.composite_min_port_range_m >= 0.0 && o.composite_min_port_range_m <= 1000.0),
      "estimator/composite_min_port_range_m", o.composite_min_port_range_m, "0 .. 1000 (both 0: off)");
  requireOption(composite_off || (o.composite_max_port_range_m > o.composite_min_port_range_m &&
                                  o.composite_max_port_range_m <= 1000.0),
                "estimator/composite_max_port_range_m", o.composite_max_port_range_m,
                "> composite_min_port_range_m .. 1000 (both 0: off)");
  requireOption(std::isfinite(o.composite_icp_roll_max_sigma_deg) &&
                    o.composite_icp_roll_max_sigma_deg >= 0.0 && o.composite_icp_roll_max_sigma_deg <= 180.0,
                "estimator/composite_icp_roll_max_sigma_deg", o.composite_icp_roll_max_sigma_deg, "0 .. 180");
}

PoseEstimator::PoseEstimator(const EstimatorOptions& options, Methods methods,
                             std::unique_ptr<MethodSelector> selector, const Eigen::Isometry3d& T_target_port)
    : options_(options),
      methods_(std::move(methods)),
      selector_(std::move(selector)),
      T_target_port_(T_target_port) {
  validate(options_);
  if (methods_.empty()) throw std::invalid_argument("PoseEstimator: no pose methods");
  if (!selector_) throw std::invalid_argument("PoseEstimator: no method selector");
  if (options_.composite_max_port_range_m > 0.0 &&
      (!methods_.count(EstimateMethod::kIcp) || !methods_.count(EstimateMethod::kRing)))
    throw std::invalid_argument("PoseEstimator: the composite pose needs the ICP and ring methods");
}

bool PoseEstimator::compositeAt(const Eigen::Isometry3d& T_lidar_target_predicted) const {
  const double port_range_m = (T_lidar_target_predicted * T_target_port_.translation()).norm();
  return port_range_m >= options_.composite_min_port_range_m &&
         port_range_m < options_.composite_max_port_range_m;
}

void PoseEstimator::compose(const PoseResult& icp, const PoseResult& ring, PoseResult* result) const {
  // The rotation from the result to ICP's, as a rotation vector in lidar axes: its x and y (across the
  // boresight, lidar z) turn the result's attitude; its z, the rotation about the line of sight, stays the
  // result's. Then the target moves so that its port lies where the ring put it.
  const Eigen::Vector3d turn =
      rotationVector(icp.T_lidar_target.linear() * result->T_lidar_target.linear().transpose());
  // ... unless ICP measured it well (EstimatorOptions::composite_icp_roll_max_sigma_deg).
  const bool icp_roll =
      icp.status == EstimateStatus::kTracking &&
      std::sqrt(icp.covariance(5, 5)) * 180.0 / M_PI < options_.composite_icp_roll_max_sigma_deg;
  const Eigen::Matrix3d R = rotationOf(Eigen::Vector3d(turn.x(), turn.y(), icp_roll ? turn.z() : 0.0)) *
                            result->T_lidar_target.linear();
  const Eigen::Vector3d port_m = ring.T_lidar_target * T_target_port_.translation();
  // The covariance the same way, at the port: its position the ring's, the tilt (and the roll where taken)
  // ICP's; then moved to the origin (PoseResult::covariance). As the ring's alone it said the ring's tilt
  // where ICP's was taken.
  Eigen::Matrix<double, 6, 6> port_cov = Eigen::Matrix<double, 6, 6>::Zero();
  port_cov.topLeftCorner<3, 3>() =
      covarianceAt(ring.covariance, ring.T_lidar_target.linear() * T_target_port_.translation())
          .topLeftCorner<3, 3>();
  Eigen::Matrix3d rotation_cov = icp.covariance.bottomRightCorner<3, 3>();
  if (!icp_roll) {
    const double roll_variance = result->covariance(5, 5);
    rotation_cov.row(2).setZero();
    rotation_cov.col(2).setZero();
    rotation_cov(2, 2) = roll_variance;
  }
  port_cov.bottomRightCorner<3, 3>() = rotation_cov;
  result->T_lidar_target.linear() = R;
  result->T_lidar_target.translation() = port_m - R * T_target_port_.translation();
  result->covariance = covarianceAt(port_cov, -(R * T_target_port_.translation()));
  if (icp_roll) {
    // The roll is ICP's, and so is whether it was observed or held near its prediction: the prediction
    // learns no roll rate from a held roll (with the ring's flags it learnt one from ICP's held roll, and the
    // two methods' held rolls walked off together: Hubble at 10-20 m, 1.5 deg).
    result->boresight_rotation_observed = icp.boresight_rotation_observed;
    result->boresight_rotation_held = icp.boresight_rotation_held;
  }
}

void PoseEstimator::setPrior(const Eigen::Isometry3d& T_lidar_target) {
  prior_ = T_lidar_target;
  have_good_ = false;
  velocity_valid_ = false;
  velocity_mps_.setZero();
  angular_velocity_radps_.setZero();
  have_previous_ = false;
  recent_.clear();
  for (auto& method : methods_) method.second->reset();
  selector_->reset();
  icp_second_lost_ = false;
}

Eigen::Isometry3d PoseEstimator::predict(double stamp_s) const {
  if (!have_good_) return prior_;
  const double dt = stamp_s - last_good_stamp_s;
  if (!velocity_valid_ || dt <= 0.0 || dt > options_.max_prediction_gap_s) return last_good_;
  Eigen::Isometry3d T = last_good_;
  T.translation() += velocity_mps_ * dt;
  T.linear() = rotationOf(angular_velocity_radps_ * dt) * last_good_.linear();
  return T;
}

void PoseEstimator::updateVelocity(const PoseResult& result, double stamp_s) {
  const Eigen::Isometry3d& T = result.T_lidar_target;
  const double dt = stamp_s - last_good_stamp_s;
  const bool valid_pair = have_good_ && dt > 0.0 && dt <= options_.max_prediction_gap_s;
  // The estimate that ends an acquisition agreed with the acquisition estimate before it, or with the motion
  // of the two before: from that pair the linear velocity (the angular one from the next TRACKING pairs).
  // Without it, at the approach datasets' 0.5 m a frame, Hubble's first tracking frames started 0.5 m off.
  if (valid_pair && result.acquiring && last_good_acquiring_ && result.status == EstimateStatus::kTracking) {
    velocity_mps_ = (T.translation() - last_good_.translation()) / dt;
    angular_velocity_radps_.setZero();
    velocity_valid_ = true;
    return;
  }
  // The jumps of an acquisition are no motion: its other estimates reset the velocity.
  if (!valid_pair || result.acquiring) {
    velocity_valid_ = false;
    angular_velocity_radps_.setZero();
    return;
  }
  // Learnt from TRACKING estimates in a row only. A DEGRADED estimate between them keeps the linear velocity
  // (resetting it left Hubble's approach, often DEGRADED "not converged", predicted without velocity: at the
  // approach dataset's 0.5 m a frame the docking-ring method then started 0.5 m off and was LOST) and drops
  // the angular one (a degraded attitude, most often a barely observed rotation about the boresight, would
  // carry its error into the next prediction: kept, ICP alone on the ISS inside 10 m went from 0.043-0.056 to
  // 0.067-0.132 deg RMS on the approach datasets).
  const Eigen::Vector3d v = (T.translation() - last_good_.translation()) / dt;
  if (!last_good_tracking_ || result.status != EstimateStatus::kTracking) {
    angular_velocity_radps_.setZero();
    // With no velocity at all (every estimate since the acquisition DEGRADED: Hubble's ICP frames at 20-50 m,
    // "not converged" as the roll seen on the solar-array masts wanders), a TRACKING one learns the linear
    // velocity from a DEGRADED tracking one before (not an acquisition's): predicted without any, the
    // docking-ring method started 0.5 m off at the approach dataset's 0.5 m a frame, was LOST, and stayed
    // LOST behind its stale prediction.
    if (!velocity_valid_ && !last_good_acquiring_ && result.status == EstimateStatus::kTracking) {
      velocity_mps_ = v;
      velocity_valid_ = true;
    }
    return;
  }
  Eigen::Vector3d w = rotationVector(T.linear() * last_good_.linear().transpose()) / dt;
  // A rotation about the boresight that the method did not observe, or held near its prediction, is no
  // motion: extrapolated, its noise walks the next prediction away (Hubble end-on; hubble_hold, lidar seed 2,
  // with the occluding contours ICP tracked 2841 of 2951 frames instead of 1871, and learnt from those in a
  // row its held roll's noise: 30-50 m attitude RMS 0.034 deg, worst frame 0.124; held roll no motion: 0.030,
  // 0.079).
  if (!result.boresight_rotation_observed || result.boresight_rotation_held) w.z() = 0.0;
  const double a = velocity_valid_ ? options_.velocity_smoothing : 1.0;
  velocity_mps_ = a * v + (1.0 - a) * velocity_mps_;
  // The rotation rate from zero (each reset above), by its own weight (EstimatorOptions).
  const double a_angular = options_.angular_velocity_smoothing;
  angular_velocity_radps_ = a_angular * w + (1.0 - a_angular) * angular_velocity_radps_;
  velocity_valid_ = true;
}

Eigen::Isometry3d PoseEstimator::medianOf(const std::deque<std::pair<double, Eigen::Isometry3d>>& recent,
                                          double stamp_s) const {
  // Each estimate carried forward to stamp_s at the window's own velocity (per axis Siegel's repeated median
  // of the velocities between pairs of estimates: per estimate the median of its velocities to the others,
  // then the median of those; robust to a bad estimate, and there also when DEGRADED frames leave the tracker
  // without one): a plain median of the last five lagged a steady approach by two frames (1 m at 0.5 m a
  // frame). Then per axis: the median position, and the median rotation vector relative to the newest
  // attitude. Fewer than three: no velocity to trust, and a median of two is their mean: the newest as it is.
  if (recent.size() < 3) return recent.back().second;
  // The pairs' velocities once (row i: from estimate i to each other one), then the medians per axis.
  std::vector<std::vector<Eigen::Matrix<double, 6, 1>>> pair_velocities(recent.size());
  for (std::size_t i = 0; i < recent.size(); ++i) {
    for (std::size_t j = 0; j < recent.size(); ++j) {
      const double dt = recent[j].first - recent[i].first;
      if (j == i || !(std::abs(dt) > 0.0)) continue;
      const Eigen::Isometry3d& a = recent[i].second;
      const Eigen::Isometry3d& b = recent[j].second;
      Eigen::Matrix<double, 6, 1> v;
      v << (b.translation() - a.translation()) / dt, rotationVector(b.linear() * a.linear().transpose()) / dt;
      pair_velocities[i].push_back(v);
    }
  }
  Eigen::Matrix<double, 6, 1> velocities = Eigen::Matrix<double, 6, 1>::Zero();  // linear, angular
  for (int axis = 0; axis < 6; ++axis) {
    std::vector<double> row_medians;
    for (const auto& row : pair_velocities) {
      if (row.empty()) continue;
      std::vector<double> values;
      for (const Eigen::Matrix<double, 6, 1>& v : row) values.push_back(v[axis]);
      row_medians.push_back(medianOfValues(values));
    }
    if (!row_medians.empty()) velocities[axis] = medianOfValues(row_medians);
  }
  const Eigen::Vector3d velocity = velocities.head<3>(), angular_velocity = velocities.tail<3>();
  std::vector<Eigen::Isometry3d> poses;
  for (const auto& [t, T] : recent) {
    Eigen::Isometry3d moved = T;
    moved.translation() += velocity * (stamp_s - t);
    moved.linear() = rotationOf(angular_velocity * (stamp_s - t)) * T.linear();
    poses.push_back(moved);
  }
  const Eigen::Isometry3d& newest = poses.back();
  Eigen::Isometry3d out = newest;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> position;
    for (const Eigen::Isometry3d& T : poses) position.push_back(T.translation()[axis]);
    out.translation()[axis] = medianOfValues(position);
  }
  Eigen::Vector3d median_rotation;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> rotation;
    for (const Eigen::Isometry3d& T : poses)
      rotation.push_back(rotationVector(T.linear() * newest.linear().transpose())[axis]);
    median_rotation[axis] = medianOfValues(rotation);
  }
  out.linear() = rotationOf(median_rotation) * newest.linear();
  return out;
}

EstimatorOutput PoseEstimator::process(const OrganizedCloud& cloud) {
  const auto start = std::chrono::steady_clock::now();
  EstimatorOutput out;
  if (have_previous_ && cloud.stamp_s < previous_stamp_s_ - options_.restart_time_jump_s) {
    out.restarted_back_s = previous_stamp_s_ - cloud.stamp_s;
    setPrior(prior_);
  }
  if (have_previous_ && cloud.stamp_s > newest_stamp_s_) {
    const double interval_s = cloud.stamp_s - newest_stamp_s_;
    // Half a period of slack: a frame's stamp is the simulation's step time, exact to the step.
    if (frame_interval_s_ > 0.0 && interval_s > 1.5 * frame_interval_s_)
      out.frames_missing = static_cast<int>(std::lround(interval_s / frame_interval_s_)) - 1;
    frame_interval_s_ = frame_interval_s_ > 0.0 ? std::min(frame_interval_s_, interval_s) : interval_s;
  }
  SelectionInput input;
  input.cloud = &cloud;
  input.T_lidar_target_predicted = predict(cloud.stamp_s);
  input.previous = have_previous_ ? &previous_ : nullptr;
  const EstimateMethod chosen = selector_->select(input);
  const auto method = methods_.find(chosen);
  if (method == methods_.end()) {
    out.result.reason = "the method selector chose a method this estimator does not have";
    out.result.T_lidar_target = input.T_lidar_target_predicted;
  } else {
    out.result = method->second->estimate(cloud, input.T_lidar_target_predicted);
    const PoseResult selected = out.result;  // before a hand-over's blend
    if (chosen == EstimateMethod::kIcp) icp_second_lost_ = false;
    // A hand-over between methods: the old method's estimate blended into the new one's over a few frames.
    EstimateMethod from = chosen;
    double weight = 1.0;
    std::optional<PoseResult> from_result;  // the old method's estimate of this frame, when it ran
    if (selector_->blending(&from, &weight) && methods_.count(from) && from != chosen &&
        out.result.status != EstimateStatus::kLost) {
      from_result = methods_.at(from)->estimate(cloud, input.T_lidar_target_predicted);
      if (from_result->status != EstimateStatus::kLost) {
        out.result.T_lidar_target =
            close_range::blendPoses(from_result->T_lidar_target, out.result.T_lidar_target, weight);
      }
    }
    const bool composite = options_.composite_max_port_range_m > 0.0 &&
                           (chosen == EstimateMethod::kIcp || chosen == EstimateMethod::kRing) &&
                           selected.status != EstimateStatus::kLost &&
                           compositeAt(input.T_lidar_target_predicted);
    if (composite && (chosen == EstimateMethod::kIcp || !icp_second_lost_)) {
      const EstimateMethod second_method =
          chosen == EstimateMethod::kIcp ? EstimateMethod::kRing : EstimateMethod::kIcp;
      // The ring as the second method starts from ICP's estimate of this frame (nearer than the prediction:
      // without a velocity, 0.2 m a frame, it found no faces in its 5 cm band around the prediction). ICP as
      // the second starts from the prediction, as when it is selected (from the ring's estimate: the same
      // figures on the Hubble approach datasets). A method already run for the blend is not run again.
      const Eigen::Isometry3d& second_start =
          second_method == EstimateMethod::kRing ? selected.T_lidar_target : input.T_lidar_target_predicted;
      const PoseResult second = from_result && from == second_method
                                    ? *from_result
                                    : methods_.at(second_method)->estimate(cloud, second_start);
      const PoseResult& icp = chosen == EstimateMethod::kIcp ? selected : second;
      const PoseResult& ring = chosen == EstimateMethod::kRing ? selected : second;
      if (chosen != EstimateMethod::kIcp) icp_second_lost_ = icp.status == EstimateStatus::kLost;
      // A DEGRADED ICP still gives the tilt (most often "not converged": the roll creeping, Hubble end-on); a
      // DEGRADED ring (the lateral position from a small centreline target) no port position. The blend of a
      // hand-over keeps only the roll: position and tilt come from the same methods on both sides.
      if (icp.status != EstimateStatus::kLost && ring.status == EstimateStatus::kTracking)
        compose(icp, ring, &out.result);
    }
  }
  previous_ = out.result;
  previous_stamp_s_ = cloud.stamp_s;
  newest_stamp_s_ = have_previous_ ? std::max(newest_stamp_s_, cloud.stamp_s) : cloud.stamp_s;
  have_previous_ = true;
  if (out.result.status != EstimateStatus::kLost) {
    updateVelocity(out.result, cloud.stamp_s);
    last_good_tracking_ = out.result.status == EstimateStatus::kTracking;
    last_good_acquiring_ = out.result.acquiring;
    last_good_ = out.result.T_lidar_target;
    last_good_stamp_s = cloud.stamp_s;
    have_good_ = true;
    if (options_.median_filter) {
      recent_.emplace_back(cloud.stamp_s, out.result.T_lidar_target);
      while (static_cast<int>(recent_.size()) > options_.median_window) recent_.pop_front();
      out.result.T_lidar_target = medianOf(recent_, cloud.stamp_s);
    }
  } else {
    recent_.clear();  // the filter restarts with the next good estimate
  }
  out.velocity_mps = velocity_mps_;
  out.angular_velocity_radps = angular_velocity_radps_;
  out.velocity_valid = velocity_valid_ && out.result.status != EstimateStatus::kLost;
  out.compute_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace ardsim_pose
