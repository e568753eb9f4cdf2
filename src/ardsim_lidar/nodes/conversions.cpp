#include "conversions.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <sensor_msgs/image_encodings.h>

namespace ardsim_lidar {

bool bodyPoseFromOdometry(const nav_msgs::Odometry& odometry, Eigen::Isometry3d* T_eci_body,
                          std::string* error) {
  const geometry_msgs::Pose& pose = odometry.pose.pose;
  const Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
  const Eigen::Vector3d p(pose.position.x, pose.position.y, pose.position.z);
  if (!p.allFinite() || !q.coeffs().allFinite()) {
    *error = "non-finite pose of '" + odometry.child_frame_id + "'";
    return false;
  }
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    *error = "quaternion of '" + odometry.child_frame_id + "' has norm " + std::to_string(q.norm());
    return false;
  }
  T_eci_body->linear() = q.normalized().toRotationMatrix();
  T_eci_body->translation() = p;
  return true;
}

sensor_msgs::PointCloud2Ptr toPointCloud2(const LidarFrame& frame, const PixelRays& rays,
                                          const std_msgs::Header& header) {
  sensor_msgs::PointCloud2Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header = header;
  cloud->width = static_cast<std::uint32_t>(frame.width);
  cloud->height = static_cast<std::uint32_t>(frame.height);
  const char* names[4] = {"x", "y", "z", "intensity"};
  for (int f = 0; f < 4; ++f) {
    sensor_msgs::PointField field;
    field.name = names[f];
    field.offset = static_cast<std::uint32_t>(4 * f);
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    cloud->fields.push_back(field);
  }
  cloud->is_bigendian = false;
  cloud->point_step = 16;
  cloud->row_step = cloud->point_step * cloud->width;
  cloud->is_dense = false;
  cloud->data.resize(static_cast<std::size_t>(cloud->row_step) * cloud->height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto* out = reinterpret_cast<float*>(cloud->data.data());
  for (std::size_t i = 0; i < frame.range_m.size(); ++i, out += 4) {
    const float range = frame.range_m[i];
    if (std::isnan(range)) {
      out[0] = out[1] = out[2] = out[3] = nan;
      continue;
    }
    const Eigen::Vector3f point = range * rays.ray(static_cast<int>(i));
    out[0] = point.x();
    out[1] = point.y();
    out[2] = point.z();
    out[3] = frame.intensity[i];
  }
  return cloud;
}

sensor_msgs::ImagePtr toRangeImage(const LidarFrame& frame, const std_msgs::Header& header) {
  sensor_msgs::ImagePtr image(new sensor_msgs::Image);
  image->header = header;
  image->width = static_cast<std::uint32_t>(frame.width);
  image->height = static_cast<std::uint32_t>(frame.height);
  image->encoding = sensor_msgs::image_encodings::TYPE_32FC1;
  image->is_bigendian = false;
  image->step = static_cast<std::uint32_t>(sizeof(float) * frame.width);
  image->data.resize(sizeof(float) * frame.range_m.size());
  std::memcpy(image->data.data(), frame.range_m.data(), image->data.size());
  return image;
}

sensor_msgs::CameraInfoPtr toCameraInfo(const Intrinsics& k, const std_msgs::Header& header) {
  sensor_msgs::CameraInfoPtr info(new sensor_msgs::CameraInfo);
  info->header = header;
  info->width = static_cast<std::uint32_t>(k.width);
  info->height = static_cast<std::uint32_t>(k.height);
  info->distortion_model = "plumb_bob";
  info->D.assign(5, 0.0);
  info->K = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  info->R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info->P = {k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

}  // namespace ardsim_lidar
