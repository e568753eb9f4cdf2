// Close-range frames of the ISS or Hubble rendered in-process with ardsim_lidar's LidarSimulator, and the
// error measures of the close-range goals. Shared by the tests and the benchmark.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"
#include "ardsim_description/models.h"
#include "ardsim_lidar/lidar_simulator.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {
namespace close_range {
namespace testing {

constexpr double kDegToRad = M_PI / 180.0;

// The chaser's pose relative to the docked attitude: its port port_range_m out along the target port's x
// axis, offset laterally, tilted about the target port's y and z axes, and rolled about the port axis.
struct ApproachState {
  double port_range_m = 3.0;  // port plane to port plane; the lidar is 1 m further back
  double lateral_y_m = 0.0;
  double lateral_z_m = 0.0;
  double tilt_y_deg = 0.0;
  double tilt_z_deg = 0.0;
  double roll_deg = 0.0;
};

inline Eigen::Isometry3d T_lidar_target(
    const ApproachState& s, ardsim_description::TargetKind kind = ardsim_description::TargetKind::kIss) {
  using namespace ardsim_description;
  const Eigen::Isometry3d T_port_chaser_port =
      Eigen::Translation3d(s.port_range_m, s.lateral_y_m, s.lateral_z_m) *
      Eigen::AngleAxisd(s.tilt_y_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(s.tilt_z_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(s.roll_deg * kDegToRad, Eigen::Vector3d::UnitX()) * T_port_port_docked();
  const Eigen::Isometry3d T_port_lidar = T_port_chaser_port * T_chaser_port().inverse() * T_chaser_lidar();
  return (T_target_port(kind) * T_port_lidar).inverse();
}

class TargetRenderer {
 public:
  explicit TargetRenderer(bool noise, std::uint64_t seed = 7,
                          ardsim_description::TargetKind kind = ardsim_description::TargetKind::kIss,
                          const ardsim_lidar::SensorOptions& sensor = {}) {
    ardsim_lidar::NoiseOptions noise_options;
    noise_options.enabled = noise;
    simulator_ = std::make_unique<ardsim_lidar::LidarSimulator>(sensor, noise_options, seed);
    simulator_->setTarget(ardsim_description::buildTarget(kind));
  }

  OrganizedCloud render(const Eigen::Isometry3d& T, std::uint64_t frame_index) {
    simulator_->simulate(T, frame_index, &frame_);
    OrganizedCloud cloud;
    cloud.width = frame_.width;
    cloud.height = frame_.height;
    cloud.points.resize(frame_.range_m.size());
    cloud.intensity = frame_.intensity;
    for (std::size_t i = 0; i < frame_.range_m.size(); ++i) {
      cloud.points[i] = simulator_->rays().ray(static_cast<int>(i)) * frame_.range_m[i];
    }
    return cloud;
  }

 private:
  std::unique_ptr<ardsim_lidar::LidarSimulator> simulator_;
  ardsim_lidar::LidarFrame frame_;
};

// Errors of an estimate of the target port: position in lidar_optical (range along the boresight, lateral
// across it), rotation in the target port's axes (x: about the boresight, y and z: the two tilts).
struct PortError {
  double range_m = 0.0;
  double lateral_x_m = 0.0;
  double lateral_y_m = 0.0;
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();
  double lateral() const { return std::hypot(lateral_x_m, lateral_y_m); }
};

inline PortError portError(const Eigen::Isometry3d& T_estimate, const Eigen::Isometry3d& T_truth,
                           ardsim_description::TargetKind kind = ardsim_description::TargetKind::kIss) {
  const Eigen::Isometry3d T_port = ardsim_description::T_target_port(kind);
  const Eigen::Isometry3d estimate = T_estimate * T_port, truth = T_truth * T_port;
  PortError e;
  const Eigen::Vector3d dp = estimate.translation() - truth.translation();
  e.lateral_x_m = dp.x();
  e.lateral_y_m = dp.y();
  e.range_m = dp.z();
  const Eigen::AngleAxisd rotation(truth.linear().transpose() * estimate.linear());
  e.rotation_deg = rotation.angle() * rotation.axis() / kDegToRad;
  return e;
}

}  // namespace testing
}  // namespace close_range
}  // namespace ardsim_pose
