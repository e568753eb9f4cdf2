// Types shared by every pose method (ICP, pyramid, docking ring), the mode manager and the nodes. ROS-free.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace ardsim_pose {

// One organized LIDAR frame in lidar_optical: row-major, row 0 at the top (y down), a NaN point where there
// was no return. The same layout as lidar/points.
struct OrganizedCloud {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3f> points;  // m
  std::vector<float> intensity;         // same size as points (may be empty)
  double stamp_s = 0.0;
};

// The cross-product matrix: skew(v) u = v x u.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// A pose covariance (x y z, rot x y z; the rotation in lidar axes, on the left) moved from the point it is of
// to one `offset` from it (lidar axes): that point moves with the translation and, for a rotation w, by
// w x offset = -skew(offset) w. The rotation's block stays. PoseResult::covariance is the target origin's;
// a method that measures the port gives the port's and moves it by minus the lever (origin - port).
inline Eigen::Matrix<double, 6, 6> covarianceAt(const Eigen::Matrix<double, 6, 6>& covariance,
                                                const Eigen::Vector3d& offset) {
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Identity();
  J.topRightCorner<3, 3>() = -skew(offset);
  return J * covariance * J.transpose();
}

// Whether a point of such a frame is a return: finite and in front of the sensor. (z first: most pixels of
// a far target's frame have none, and the test runs on every pixel of every frame. Then one test for all
// three finite: v - v is 0 for a finite v and NaN for an infinite or NaN one.)
inline bool isReturn(const Eigen::Vector3f& p) {
  return p.z() > 0.0f && (p.x() - p.x()) + (p.y() - p.y()) + (p.z() - p.z()) == 0.0f;
}

enum class EstimateStatus { kTracking, kDegraded, kLost };
enum class EstimateMethod { kNone, kIcp, kPyramid, kRing };

struct PoseResult {
  EstimateStatus status = EstimateStatus::kLost;
  EstimateMethod method = EstimateMethod::kNone;
  std::string reason;  // why DEGRADED or LOST
  Eigen::Isometry3d T_lidar_target = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance =
      Eigen::Matrix<double, 6, 6>::Zero();  // (x y z, rot x y z) m^2, rad^2
  bool boresight_rotation_observed = true;
  // ... but barely, and held near the prediction by a prior (ICP tracking: IcpOptions::boresight_prior_*):
  // its frame-to-frame change is the prior's and the noise's, not the target's motion.
  bool boresight_rotation_held = false;
  // From a method still acquiring (ICP's search from a prior, after LOST): the estimate may jump from the
  // last one, so it says nothing about the motion. A DEGRADED estimate that is not acquiring still moves with
  // the target.
  bool acquiring = false;
  double fit_rms_m = 0.0;
  double inlier_fraction = 0.0;
  int points_used = 0;
  int iterations = 0;
};

// A method that estimates T_lidar_target in one frame from a prediction (previous estimates or the initial
// prior).
class PoseMethod {
 public:
  virtual ~PoseMethod() = default;
  virtual PoseResult estimate(const OrganizedCloud& cloud,
                              const Eigen::Isometry3d& T_lidar_target_predicted) = 0;
  // Forget any state carried between frames.
  virtual void reset() = 0;
};

}  // namespace ardsim_pose
