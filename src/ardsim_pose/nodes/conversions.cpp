#include "conversions.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <sensor_msgs/PointField.h>

namespace ardsim_pose {

namespace {

bool quaternionOk(const geometry_msgs::Quaternion& q, std::string* error) {
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
    *error = "quaternion norm " + std::to_string(norm) + " is not 1";
    return false;
  }
  return true;
}

Eigen::Isometry3d toIsometry(const geometry_msgs::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::Quaterniond(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z)
          .normalized()
          .toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return T;
}

bool poseOk(const geometry_msgs::Pose& pose, std::string* error) {
  if (!std::isfinite(pose.position.x) || !std::isfinite(pose.position.y) || !std::isfinite(pose.position.z)) {
    *error = "position is not finite";
    return false;
  }
  return quaternionOk(pose.orientation, error);
}

}  // namespace

bool fromPointCloud2(const sensor_msgs::PointCloud2& msg, const std::string& sensor_frame_id,
                     OrganizedCloud* cloud, std::string* error) {
  cloud->width = static_cast<int>(msg.width);
  cloud->height = static_cast<int>(msg.height);
  cloud->stamp_s = msg.header.stamp.toSec();
  cloud->points.clear();
  cloud->intensity.clear();
  if (msg.header.frame_id != sensor_frame_id) {
    *error = "cloud in frame '" + msg.header.frame_id + "', not the sensor's '" + sensor_frame_id + "'";
    return false;
  }
  const std::size_t count = static_cast<std::size_t>(msg.width) * msg.height;
  if (count == 0) return true;
  if (msg.height < 2) {
    *error = "cloud is not organized (height " + std::to_string(msg.height) + ")";
    return false;
  }
  if (msg.is_bigendian) {
    *error = "big-endian clouds are not supported";
    return false;
  }
  int offsets[4] = {-1, -1, -1, -1};
  const char* names[4] = {"x", "y", "z", "intensity"};
  for (const sensor_msgs::PointField& field : msg.fields)
    for (int k = 0; k < 4; ++k)
      if (field.name == names[k]) {
        if (field.datatype != sensor_msgs::PointField::FLOAT32) {
          *error = "field " + field.name + " is not FLOAT32";
          return false;
        }
        offsets[k] = static_cast<int>(field.offset);
      }
  for (int k = 0; k < 3; ++k)
    if (offsets[k] < 0) {
      *error = std::string("cloud has no field ") + names[k];
      return false;
    }
  for (int k = 0; k < 4; ++k)
    if (offsets[k] >= 0 && offsets[k] + 4 > static_cast<int>(msg.point_step)) {
      *error = std::string("field ") + names[k] + " lies outside point_step";
      return false;
    }
  // In 64 bits: a header's width x point_step can pass 2^32 and would wrap past the checks.
  const std::uint64_t row_bytes = static_cast<std::uint64_t>(msg.width) * msg.point_step;
  if (msg.row_step < row_bytes) {
    *error = "row_step " + std::to_string(msg.row_step) + " is shorter than width x point_step (" +
             std::to_string(row_bytes) + ")";
    return false;
  }
  if (msg.data.size() < static_cast<std::uint64_t>(msg.row_step) * msg.height) {
    *error = "cloud data is shorter than its row_step x height";
    return false;
  }
  cloud->points.resize(count);
  if (offsets[3] >= 0) cloud->intensity.resize(count);
  for (std::uint32_t v = 0; v < msg.height; ++v) {
    for (std::uint32_t u = 0; u < msg.width; ++u) {
      const std::uint8_t* point = msg.data.data() + static_cast<std::size_t>(v) * msg.row_step +
                                  static_cast<std::size_t>(u) * msg.point_step;
      const std::size_t i = static_cast<std::size_t>(v) * msg.width + u;
      float xyz[3];
      for (int k = 0; k < 3; ++k) std::memcpy(&xyz[k], point + offsets[k], sizeof(float));
      cloud->points[i] = Eigen::Vector3f(xyz[0], xyz[1], xyz[2]);
      if (offsets[3] >= 0) std::memcpy(&cloud->intensity[i], point + offsets[3], sizeof(float));
    }
  }
  return true;
}

ardsim_msgs::PoseEstimatePtr toPoseEstimate(const EstimatorOutput& output, const std_msgs::Header& header) {
  ardsim_msgs::PoseEstimatePtr msg(new ardsim_msgs::PoseEstimate);
  const PoseResult& r = output.result;
  msg->header = header;
  const Eigen::Quaterniond q(r.T_lidar_target.linear());
  msg->pose.pose.position.x = r.T_lidar_target.translation().x();
  msg->pose.pose.position.y = r.T_lidar_target.translation().y();
  msg->pose.pose.position.z = r.T_lidar_target.translation().z();
  msg->pose.pose.orientation.x = q.x();
  msg->pose.pose.orientation.y = q.y();
  msg->pose.pose.orientation.z = q.z();
  msg->pose.pose.orientation.w = q.w();
  const bool lost = r.status == EstimateStatus::kLost;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) msg->pose.covariance[6 * i + j] = lost ? 0.0 : r.covariance(i, j);
  msg->velocity.linear.x = output.velocity_mps.x();
  msg->velocity.linear.y = output.velocity_mps.y();
  msg->velocity.linear.z = output.velocity_mps.z();
  msg->velocity.angular.x = output.angular_velocity_radps.x();
  msg->velocity.angular.y = output.angular_velocity_radps.y();
  msg->velocity.angular.z = output.angular_velocity_radps.z();
  msg->velocity_valid = output.velocity_valid;
  switch (r.method) {
    case EstimateMethod::kIcp:
      msg->method = ardsim_msgs::PoseEstimate::METHOD_ICP;
      break;
    case EstimateMethod::kPyramid:
      msg->method = ardsim_msgs::PoseEstimate::METHOD_PYRAMID;
      break;
    case EstimateMethod::kRing:
      msg->method = ardsim_msgs::PoseEstimate::METHOD_RING;
      break;
    default:
      msg->method = ardsim_msgs::PoseEstimate::METHOD_NONE;
  }
  msg->status = r.status == EstimateStatus::kTracking   ? ardsim_msgs::PoseEstimate::STATUS_TRACKING
                : r.status == EstimateStatus::kDegraded ? ardsim_msgs::PoseEstimate::STATUS_DEGRADED
                                                        : ardsim_msgs::PoseEstimate::STATUS_LOST;
  msg->reason = r.reason;
  msg->boresight_rotation_observed = r.boresight_rotation_observed;
  msg->fit_rms_m = static_cast<float>(r.fit_rms_m);
  msg->inlier_fraction = static_cast<float>(r.inlier_fraction);
  msg->points_used = static_cast<std::uint32_t>(std::max(0, r.points_used));
  msg->iterations = static_cast<std::uint16_t>(std::clamp(r.iterations, 0, 65535));
  msg->compute_time_ms = static_cast<float>(output.compute_ms);
  return msg;
}

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& T, const std_msgs::Header& header,
                                            const std::string& child_frame_id) {
  geometry_msgs::TransformStamped msg;
  msg.header = header;
  msg.child_frame_id = child_frame_id;
  const Eigen::Quaterniond q(T.linear());
  msg.transform.translation.x = T.translation().x();
  msg.transform.translation.y = T.translation().y();
  msg.transform.translation.z = T.translation().z();
  msg.transform.rotation.x = q.x();
  msg.transform.rotation.y = q.y();
  msg.transform.rotation.z = q.z();
  msg.transform.rotation.w = q.w();
  return msg;
}

bool poseFromEstimate(const ardsim_msgs::PoseEstimate& msg, Eigen::Isometry3d* T, std::string* error) {
  if (!poseOk(msg.pose.pose, error)) return false;
  *T = toIsometry(msg.pose.pose);
  return true;
}

bool poseFromOdometry(const nav_msgs::Odometry& msg, Eigen::Isometry3d* T, std::string* error) {
  if (!poseOk(msg.pose.pose, error)) return false;
  *T = toIsometry(msg.pose.pose);
  return true;
}

ardsim_msgs::PoseErrorPtr toPoseError(const PoseErrorValue& e, const ardsim_msgs::PoseEstimate& estimate) {
  ardsim_msgs::PoseErrorPtr msg(new ardsim_msgs::PoseError);
  msg->header = estimate.header;
  msg->method = estimate.method;
  msg->status = estimate.status;
  msg->range_m = e.range_m;
  msg->port_position_error.x = e.port_position_error_m.x();
  msg->port_position_error.y = e.port_position_error_m.y();
  msg->port_position_error.z = e.port_position_error_m.z();
  msg->port_position_error_m = e.port_position_error_m.norm();
  msg->attitude_error.x = e.attitude_error_rad.x();
  msg->attitude_error.y = e.attitude_error_rad.y();
  msg->attitude_error.z = e.attitude_error_rad.z();
  msg->attitude_error_rad = e.attitude_error_angle_rad;
  return msg;
}

}  // namespace ardsim_pose
