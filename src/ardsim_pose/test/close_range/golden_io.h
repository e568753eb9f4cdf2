// The close-range golden set: a short noisy approach of the ISS docking adapter stored as the sensor gives
// it, compactly (under 2 MB): per frame a 16-bit PNG of range in millimetres (render_dataset's format, 0 = no
// return) and an 8-bit PNG of intensity (255 = saturated), plus truth.csv and the expected estimates. Points
// are rebuilt through the default sensor's pixel rays.
#pragma once

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "ardsim_lidar/sensor.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {
namespace close_range {
namespace golden {

inline std::string framePath(const std::string& dir, int index, const char* suffix) {
  char name[64];
  std::snprintf(name, sizeof(name), "/frame_%06d%s.png", index, suffix);
  return dir + name;
}

inline void writeFrame(const std::string& dir, int index, const OrganizedCloud& cloud) {
  cv::Mat range_mm(cloud.height, cloud.width, CV_16UC1), intensity(cloud.height, cloud.width, CV_8UC1);
  for (int v = 0; v < cloud.height; ++v) {
    for (int u = 0; u < cloud.width; ++u) {
      const int i = v * cloud.width + u;
      const float r = cloud.points[i].norm();
      const bool valid = std::isfinite(r);
      range_mm.at<std::uint16_t>(v, u) = valid ? static_cast<std::uint16_t>(std::lround(1000.0 * r)) : 0;
      intensity.at<std::uint8_t>(v, u) =
          valid ? static_cast<std::uint8_t>(std::lround(255.0 * std::min(1.0f, cloud.intensity[i]))) : 0;
    }
  }
  cv::imwrite(framePath(dir, index, ""), range_mm);
  cv::imwrite(framePath(dir, index, "_intensity"), intensity);
}

// False when the frame's files are missing.
inline bool readFrame(const std::string& dir, int index, OrganizedCloud* cloud) {
  const cv::Mat range_mm = cv::imread(framePath(dir, index, ""), cv::IMREAD_UNCHANGED);
  const cv::Mat intensity = cv::imread(framePath(dir, index, "_intensity"), cv::IMREAD_UNCHANGED);
  if (range_mm.empty() || intensity.empty() || range_mm.type() != CV_16UC1) return false;
  ardsim_lidar::SensorOptions sensor;
  sensor.width = range_mm.cols;
  sensor.height = range_mm.rows;
  const ardsim_lidar::PixelRays rays(ardsim_lidar::intrinsicsFor(sensor));
  cloud->width = range_mm.cols;
  cloud->height = range_mm.rows;
  cloud->points.assign(rays.size(), Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  cloud->intensity.assign(rays.size(), std::numeric_limits<float>::quiet_NaN());
  for (int i = 0; i < rays.size(); ++i) {
    const std::uint16_t mm = range_mm.at<std::uint16_t>(i / cloud->width, i % cloud->width);
    if (mm == 0) continue;
    cloud->points[i] = rays.ray(i) * (mm / 1000.0f);
    cloud->intensity[i] = intensity.at<std::uint8_t>(i / cloud->width, i % cloud->width) / 255.0f;
  }
  return true;
}

// One row per frame: index, then x y z qx qy qz qw (and for estimates: status, observed flag).
struct Row {
  int index = 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  int status = 0;
  int observed = 0;
};

inline void writeRow(std::ostream& out, const Row& row, bool with_status) {
  const Eigen::Quaterniond q(row.T.linear());
  out << row.index << ' ' << row.T.translation().x() << ' ' << row.T.translation().y() << ' '
      << row.T.translation().z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w();
  if (with_status) out << ' ' << row.status << ' ' << row.observed;
  out << '\n';
}

inline std::vector<Row> readRows(const std::string& path, bool with_status) {
  std::vector<Row> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Row row;
    double x, y, z, qx, qy, qz, qw;
    s >> row.index >> x >> y >> z >> qx >> qy >> qz >> qw;
    if (with_status) s >> row.status >> row.observed;
    if (!s) continue;
    row.T = Eigen::Translation3d(x, y, z) * Eigen::Quaterniond(qw, qx, qy, qz).normalized();
    rows.push_back(row);
  }
  return rows;
}

// The prediction of a golden frame: its truth disturbed as a tracking prior would be (3 cm, 0.6 deg).
inline Eigen::Isometry3d goldenPrediction(const Eigen::Isometry3d& T_truth) {
  return T_truth * Eigen::Translation3d(0.02, 0.03, -0.02) *
         Eigen::AngleAxisd(0.01, Eigen::Vector3d(1.0, 0.5, -0.3).normalized());
}

// Runs a method over the frames in order, each predicted by goldenPrediction of its truth.
inline std::vector<Row> estimateAll(PoseMethod& method, const std::vector<OrganizedCloud>& frames,
                                    const std::vector<Eigen::Isometry3d>& truths) {
  std::vector<Row> rows;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const PoseResult result = method.estimate(frames[k], goldenPrediction(truths[k]));
    Row row;
    row.index = static_cast<int>(k);
    row.T = result.T_lidar_target;
    row.status = static_cast<int>(result.status);
    row.observed = result.boresight_rotation_observed ? 1 : 0;
    rows.push_back(row);
  }
  return rows;
}

// The golden approach: port ranges (m) with the tilts, offsets and roll varying along it.
inline std::vector<double> goldenRanges() {
  return {7.0, 5.0, 4.0, 3.0, 2.4, 2.0, 1.6, 1.3, 1.0, 0.7, 0.4, 0.0};
}

}  // namespace golden
}  // namespace close_range
}  // namespace ardsim_pose
