// Reading a render_dataset directory: truth.csv (frame x y z qx qy qz qw, T_lidar_target) and the organized
// PCD of each frame. ROS-free.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {

struct TruthRow {
  int frame = 0;
  Eigen::Isometry3d T_lidar_target = Eigen::Isometry3d::Identity();
};

// Throws std::runtime_error naming the file and line of anything malformed.
std::vector<TruthRow> readTruth(const std::string& path);

// frame_NNNNNN.pcd of a dataset directory.
std::string framePath(const std::string& directory, int frame);

// Throws std::runtime_error when the file cannot be read or is not organized.
OrganizedCloud loadFrame(const std::string& pcd_path, double stamp_s);

}  // namespace ardsim_pose
