// Open3D's point-to-plane ICP (Debian libopen3d-dev 0.16) behind a header free of Open3D, so that its
// compile flags stay in open3d_peer.cpp. Benchmark peer only.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Geometry>

namespace ardsim_pose {

class Open3dPointToPlane {
 public:
  Open3dPointToPlane();
  ~Open3dPointToPlane();
  // The scan (source, lidar frame) and the model with normals (target, target frame). Not timed.
  void setFrame(const std::vector<Eigen::Vector3d>& scan, const std::vector<Eigen::Vector3d>& model_points,
                const std::vector<Eigen::Vector3d>& model_normals);
  // registration::RegistrationICP from the guess; returns T_target_lidar. Builds its KD-tree over the model.
  Eigen::Isometry3d align(const Eigen::Isometry3d& T_target_lidar_guess, double max_distance_m,
                          int max_iterations);

 private:
  struct Clouds;
  std::unique_ptr<Clouds> clouds_;
};

}  // namespace ardsim_pose
