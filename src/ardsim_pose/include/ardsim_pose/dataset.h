// Reading a render_dataset directory: truth.csv (frame x y z qx qy qz qw, T_lidar_target) and the organized
// PCD of each frame; and a frame of the in-process lidar core as the estimator's cloud. ROS-free.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_lidar/noise_model.h"
#include "ardsim_lidar/sensor.h"
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

// A frame simulated in-process (LidarSimulator): point = range x the pixel's unit ray (NaN: no return).
OrganizedCloud fromLidarFrame(const ardsim_lidar::LidarFrame& frame, const ardsim_lidar::PixelRays& rays,
                              double stamp_s);

}  // namespace ardsim_pose
