#include "open3d_peer.h"

#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

namespace ardsim_pose {

struct Open3dPointToPlane::Clouds {
  open3d::geometry::PointCloud source;
  open3d::geometry::PointCloud target;
};

Open3dPointToPlane::Open3dPointToPlane() : clouds_(std::make_unique<Clouds>()) {}
Open3dPointToPlane::~Open3dPointToPlane() = default;

void Open3dPointToPlane::setFrame(const std::vector<Eigen::Vector3d>& scan,
                                  const std::vector<Eigen::Vector3d>& model_points,
                                  const std::vector<Eigen::Vector3d>& model_normals) {
  clouds_->source.points_ = scan;
  clouds_->target.points_ = model_points;
  clouds_->target.normals_ = model_normals;
}

Eigen::Isometry3d Open3dPointToPlane::align(const Eigen::Isometry3d& guess, double max_distance_m,
                                            int max_iterations) {
  namespace reg = open3d::pipelines::registration;
  const reg::RegistrationResult result = reg::RegistrationICP(
      clouds_->source, clouds_->target, max_distance_m, guess.matrix(),
      reg::TransformationEstimationPointToPlane(), reg::ICPConvergenceCriteria(1e-6, 1e-6, max_iterations));
  return Eigen::Isometry3d(result.transformation_);
}

}  // namespace ardsim_pose
