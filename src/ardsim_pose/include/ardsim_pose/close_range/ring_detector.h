// The docking-ring detector: finds the soft-capture ring in an organized frame by point clustering and shape
// metrics, without a docking cross, then hands the ring's pixels to the shared back end (adapter_fit.h) for
// the plane and circle fit. ROS-free.
//
// Clustering: region growing over the 4-neighbour grid of every stride-th pixel (in u and v); neighbours join
// when their ranges differ by less than connect_step_m plus a slope allowance (the ring's face and the tunnel
// face 0.12 m behind it stay apart). Metrics per cluster, each with its criterion:
//   size         pixel count >= min_cluster_pixels, in-plane extent (sqrt of the largest covariance
//   eigenvalue)
//                within [min_extent_m, max_extent_m] (a full annulus 0.42-0.60 m has 0.37 m)
//   planarity    rms distance from the cluster's own plane <= max_planarity_m; normal within
//   max_normal_angle_deg
//                of the boresight
//   circularity  an algebraic circle fit of the cluster's in-plane points: radius within [min_radius_m,
//                max_radius_m] (a full annulus gives its rms radius, 0.52 m; the tunnel face around it 0.7
//                m), rms radial spread <= max_radial_spread_m (an annulus 0.18 m wide has 0.052 m), and a
//                hole: fewer than max_hole_fraction of the points within hole_radius_m of the centre
//   depth step   the pixels at the projected centre lie min_depth_step_m or more behind the ring plane (the
//                passage to the hatch; a flat disc or a bulkhead has none), and across the cluster's inner
//                boundary the view falls back (at most 30 % of those neighbours in front: the tunnel face
//                seen around the ring has the ring in front of it there)
// The largest cluster meeting all of them is the ring. Without one (closer than ~1.4 m port to port, where
// the ring leaves the view, or when it is hidden) the back end runs on the hatch and the centreline target
// alone, from the prediction; with neither the result is LOST.
#pragma once

#include <vector>

#include "ardsim_pose/close_range/adapter_fit.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {
namespace close_range {

struct RingDetectorOptions {
  int stride = 1;  // clusters grow over every stride-th pixel in u and v (speed; 2 loses the ring at times)
  double connect_step_m = 0.04;  // plus range * pixel pitch * slope_allowance
  double slope_allowance = 0.8;
  int min_cluster_pixels = 40;
  double min_extent_m = 0.12;
  double max_extent_m = 0.5;
  double max_planarity_m = 0.035;
  double max_normal_angle_deg = 30.0;
  double min_radius_m = 0.40;
  double max_radius_m = 0.62;
  double max_radial_spread_m = 0.09;
  double hole_radius_m = 0.3;
  double max_hole_fraction = 0.02;
  double min_depth_step_m = 0.3;
  AdapterFitOptions fit;
};

struct RingDetection {
  bool found = false;
  int clusters = 0;                                  // clusters large enough to be scored
  std::vector<int> pixels;                           // the ring's pixels
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // out of the port, towards the lidar
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // in lidar_optical
  double radius_m = 0.0;
  double planarity_m = 0.0;
  double radial_spread_m = 0.0;
  double depth_step_m = 0.0;
};

// Buffers of detectRing, reused between frames (no allocation per frame).
struct RingDetectorScratch {
  std::vector<int> label, members, rows;
};

// Cluster and score; fills detection (found false when no cluster meets the criteria).
void detectRing(const PreparedFrame& frame, const RingDetectorOptions& options, RingDetection* detection,
                RingDetectorScratch* scratch);

class RingMethod : public PoseMethod {
 public:
  explicit RingMethod(const AdapterGeometry& geometry = issAdapterGeometry(),
                      const RingDetectorOptions& options = {});
  PoseResult estimate(const OrganizedCloud& cloud,
                      const Eigen::Isometry3d& T_lidar_target_predicted) override;
  void reset() override {}

  const RingDetection& lastDetection() const { return detection_; }
  const AdapterFitReport& lastReport() const { return report_; }

 private:
  RingDetectorOptions options_;
  AdapterFitter fitter_;
  PreparedFrame frame_;
  RingDetection detection_;
  RingDetectorScratch scratch_;
  AdapterFitReport report_;
};

}  // namespace close_range
}  // namespace ardsim_pose
