#include "ardsim_pose/dataset.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

namespace ardsim_pose {

std::vector<TruthRow> readTruth(const std::string& path) {
  std::ifstream input(path);
  if (!input) throw std::runtime_error("cannot read " + path);
  std::vector<TruthRow> rows;
  std::string line;
  for (int line_number = 1; std::getline(input, line); ++line_number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    TruthRow row;
    double x, y, z, qx, qy, qz, qw;
    if (!(fields >> row.frame >> x >> y >> z >> qx >> qy >> qz >> qw))
      throw std::runtime_error(path + ":" + std::to_string(line_number) +
                               ": expected frame x y z qx qy qz qw");
    const Eigen::Quaterniond q(qw, qx, qy, qz);
    if (!(std::abs(q.norm() - 1.0) < 1e-3))
      throw std::runtime_error(path + ":" + std::to_string(line_number) + ": quaternion is not of unit norm");
    row.T_lidar_target.linear() = q.normalized().toRotationMatrix();
    row.T_lidar_target.translation() = Eigen::Vector3d(x, y, z);
    rows.push_back(row);
  }
  return rows;
}

std::string framePath(const std::string& directory, int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "/frame_%06d.pcd", frame);
  return directory + name;
}

OrganizedCloud loadFrame(const std::string& pcd_path, double stamp_s) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  if (pcl::io::loadPCDFile(pcd_path, cloud) != 0) throw std::runtime_error("cannot read " + pcd_path);
  if (cloud.height <= 1) throw std::runtime_error(pcd_path + " is not an organized cloud");
  OrganizedCloud out;
  out.width = static_cast<int>(cloud.width);
  out.height = static_cast<int>(cloud.height);
  out.stamp_s = stamp_s;
  out.points.reserve(cloud.size());
  out.intensity.reserve(cloud.size());
  for (const pcl::PointXYZI& p : cloud.points) {
    out.points.emplace_back(p.x, p.y, p.z);
    out.intensity.push_back(p.intensity);
  }
  return out;
}

OrganizedCloud fromLidarFrame(const ardsim_lidar::LidarFrame& frame, const ardsim_lidar::PixelRays& rays,
                              double stamp_s) {
  OrganizedCloud cloud;
  cloud.width = frame.width;
  cloud.height = frame.height;
  cloud.stamp_s = stamp_s;
  const int size = frame.width * frame.height;
  cloud.points.reserve(size);
  cloud.intensity.reserve(size);
  for (int i = 0; i < size; ++i) {
    cloud.points.push_back(frame.range_m[i] * rays.ray(i));
    cloud.intensity.push_back(frame.intensity[i]);
  }
  return cloud;
}

}  // namespace ardsim_pose
