// The render_dataset tool's pose list: one pose of `target` in `lidar_optical` (T_lidar_target) per row,
// "x y z qx qy qz qw" (metres, Hamilton quaternion), separated by spaces, tabs or commas. ROS-free.
#pragma once

#include <istream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace ardsim_lidar {

struct PoseRow {
  int line_number = 0;  // 1-based, in the input file
  Eigen::Isometry3d T_lidar_target = Eigen::Isometry3d::Identity();
};

struct PoseRowError {
  int line_number = 0;
  std::string message;
};

// Blank lines and lines starting with '#' are skipped, and so is a header line: the first other line when its
// first field is not a number. Rows with the wrong number of fields, a non-number, a non-finite value or a
// quaternion whose norm is not 1 within 1e-3 are reported in `errors` and skipped; the others are kept.
void parsePoses(std::istream& input, std::vector<PoseRow>* poses, std::vector<PoseRowError>* errors);

}  // namespace ardsim_lidar
