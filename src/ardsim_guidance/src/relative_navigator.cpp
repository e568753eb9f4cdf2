#include "ardsim_guidance/relative_navigator.h"
#include "ardsim_dynamics/orbit.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>

namespace ardsim_guidance {

VelocitySource parseVelocitySource(const std::string& name) {
  if (name == "kalman") return VelocitySource::kKalman;
  if (name == "differencing") return VelocitySource::kDifferencing;
  throw std::invalid_argument("velocity source '" + name + "' is not one of: kalman, differencing");
}

RelativeNavigator::RelativeNavigator(const NavigatorOptions& options) : options_(options) {}

void RelativeNavigator::predict(double dt, double n, const Eigen::Vector3d& offset,
                                const Eigen::Vector3d& accel) {
  if (!initialized_ || !(dt > 0.0)) return;
  time_s_ += dt;
  Vector6d x;
  x << position_ - offset, velocity_;
  const Matrix6d phi = ardsim_dynamics::cwTransition(n, dt);
  x = phi * x;
  // The commanded acceleration over one short step: its CW coupling (order n dt) is negligible.
  x.head<3>() += 0.5 * dt * dt * accel + offset;
  x.tail<3>() += dt * accel;
  position_ = x.head<3>();
  velocity_ = x.tail<3>();
  if (options_.velocity_source == VelocitySource::kKalman) {
    Eigen::Matrix<double, 6, 3> g;
    g << 0.5 * dt * dt * Eigen::Matrix3d::Identity(), dt * Eigen::Matrix3d::Identity();
    const double q = options_.process_accel_sigma_mps2 * options_.process_accel_sigma_mps2;
    covariance_ = phi * covariance_ * phi.transpose() + q * g * g.transpose();
  }
}

void RelativeNavigator::update(const Eigen::Vector3d& position_m, double sigma_scale) {
  if (options_.velocity_source == VelocitySource::kKalman) {
    updateKalman(position_m, sigma_scale);
  } else {
    updateDifferencing(position_m);
  }
}

void RelativeNavigator::updateKalman(const Eigen::Vector3d& z, double sigma_scale) {
  const double sigma = options_.measurement_sigma_m * sigma_scale;
  if (!initialized_) {
    position_ = z;
    velocity_.setZero();
    covariance_.setZero();
    covariance_.topLeftCorner<3, 3>() = sigma * sigma * Eigen::Matrix3d::Identity();
    const double sv = options_.initial_velocity_sigma_mps;
    covariance_.bottomRightCorner<3, 3>() = sv * sv * Eigen::Matrix3d::Identity();
    initialized_ = true;
    return;
  }
  // H = [I 0]: the gain is the first three columns of P over (P_rr + R).
  const Eigen::Matrix3d s = covariance_.topLeftCorner<3, 3>() + sigma * sigma * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 6, 3> pht = covariance_.leftCols<3>();
  const Eigen::Matrix<double, 6, 3> gain = s.ldlt().solve(pht.transpose()).transpose();
  Vector6d x;
  x << position_, velocity_;
  x += gain * (z - position_);
  position_ = x.head<3>();
  velocity_ = x.tail<3>();
  covariance_ -= gain * pht.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose()).eval();
}

void RelativeNavigator::updateDifferencing(const Eigen::Vector3d& z) {
  if (!initialized_ || (!raw_.empty() && time_s_ - raw_.back().time_s > options_.history_reset_gap_s)) {
    raw_.clear();
    medians_.clear();
  }
  raw_.push_back({time_s_, z});
  while (static_cast<int>(raw_.size()) > options_.median_window) raw_.pop_front();
  Eigen::Vector3d median;
  std::vector<double> values(raw_.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < raw_.size(); ++i) values[i] = raw_[i].position_m[axis];
    const auto mid = values.begin() + static_cast<long>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    median[axis] = *mid;
  }
  medians_.push_back({time_s_, median});
  while (static_cast<int>(medians_.size()) > options_.difference_span + 1) medians_.pop_front();
  position_ = median;
  const double span_s = medians_.back().time_s - medians_.front().time_s;
  if (medians_.size() >= 2 && span_s > 0.0) {
    velocity_ = (medians_.back().position_m - medians_.front().position_m) / span_s;
  } else if (!initialized_) {
    velocity_.setZero();
  }
  initialized_ = true;
}

}  // namespace ardsim_guidance
