// The pyramid-of-images method (after the source study): the range image is split into a 3x3 grid of coarse
// cells with cheap features, the promising cells into 3x3 fine cells with more discriminative ones, and only
// the fine cells that pass their criteria feed the pose (through the shared back end, adapter_fit.h).
// ROS-free.
//
// It is a tracking method: the features are judged against the predicted pose of the port (the previous
// estimate, or ICP's at the hand-over). "Ring band": a point within ring_band_m of the predicted docking
// plane and between the ring's inner and outer radius (with lateral_margin_m); "behind": more than behind_m
// behind that plane.
//
// Level 0 aligns the prediction in range: the depth histogram (+-0.5 m) of the points inside the ring's
// annulus around the predicted axis peaks at the ring's face (a fast approach outruns the band otherwise);
// only while the whole annulus is in view. Level 1, coarse cells (~85 x 85 pixels). Features: valid-pixel
// count, mean range, range slopes d range / du and d range / dv (least squares over the cell), the cell's
// plane normal, ring-band fraction.
//   promising: valid fraction >= min_fill, ring-band fraction >= min_ring_fraction_coarse, and a mean range
//   within
//              max_range_offset_m of the predicted port range (a cell of the background modules is not).
// Level 2, fine cells (~28 x 28 pixels) of the promising cells. Features: count, plane fit (normal, rms
// residual), ring-band fraction, behind fraction.
//   face cell: ring-band fraction >= min_face_fraction, rms <= max_cell_rms_m, normal within
//              max_normal_deviation_deg of the consensus (the median normal of the candidate face cells);
//   edge cell: ring-band fraction >= min_edge_fraction and behind fraction >= min_edge_fraction (the ring's
//              inner edge, the passage behind it);
// The ring-band pixels of face and edge cells are the ring's pixels: the plane comes from them (and the
// adapter's other faces), the centre from the edges found in the edge cells. With fewer ring pixels than the
// back end's min_plane_points (beyond ~9 m the annulus is narrower than a fine cell) the ring is labelled
// from the prediction instead. Without any passing cell (the ring out of view near contact) the back end
// tracks the hatch and the centreline target; with neither: LOST.
#pragma once

#include <array>
#include <vector>

#include "ardsim_pose/close_range/adapter_fit.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {
namespace close_range {

struct PyramidOptions {
  double ring_band_m = 0.06;
  double lateral_margin_m = 0.05;
  double behind_m = 0.25;
  double min_fill = 0.1;
  double min_ring_fraction_coarse = 0.02;
  double max_range_offset_m = 1.5;
  double min_face_fraction = 0.8;
  double max_cell_rms_m = 0.03;
  double max_normal_deviation_deg = 4.0;
  double min_edge_fraction = 0.1;
  int min_cell_pixels = 12;
  AdapterFitOptions fit;
};

// Features of one cell, for tests and diagnostics.
struct PyramidCell {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;  // pixel bounds [u0, u1) x [v0, v1)
  int count = 0;
  double mean_range_m = 0.0;
  double slope_u = 0.0, slope_v = 0.0;  // m per pixel
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double rms_m = 0.0;
  double ring_fraction = 0.0;
  double behind_fraction = 0.0;
  enum class Verdict { kRejected, kPromising, kFace, kEdge } verdict = Verdict::kRejected;
};

class PyramidMethod : public PoseMethod {
 public:
  explicit PyramidMethod(const AdapterGeometry& geometry = issAdapterGeometry(),
                         const PyramidOptions& options = {});
  PoseResult estimate(const OrganizedCloud& cloud,
                      const Eigen::Isometry3d& T_lidar_target_predicted) override;
  void reset() override {}

  const std::array<PyramidCell, 9>& coarseCells() const { return coarse_; }
  const std::vector<PyramidCell>& fineCells() const { return fine_; }
  const AdapterFitReport& lastReport() const { return report_; }

 private:
  // Sums over one cell's valid pixels; a coarse cell's are the sums of its nine fine cells'.
  struct CellSums {
    double s_r = 0, s_u = 0, s_v = 0, s_uu = 0, s_uv = 0, s_vv = 0, s_ur = 0, s_vr = 0;
    Eigen::Vector3d s_p = Eigen::Vector3d::Zero();
    Eigen::Matrix3d s_pp = Eigen::Matrix3d::Zero();
    int count = 0, ring = 0, behind = 0;
    CellSums& operator+=(const CellSums& other);
  };
  // The sums of the pixels in the cell's bounds; its ring-band pixels (row by row) into ring_pixels.
  void cellSums(const Eigen::Isometry3d& T_port_lidar, const PyramidCell& cell, CellSums* sums,
                std::vector<int>* ring_pixels) const;
  void cellFeatures(const CellSums& sums, PyramidCell* cell) const;
  Eigen::Isometry3d alignRange(const Eigen::Isometry3d& T_lidar_port_predicted) const;

  PyramidOptions options_;
  AdapterFitter fitter_;
  PreparedFrame frame_;
  std::array<PyramidCell, 9> coarse_;
  std::vector<PyramidCell> fine_;
  // The 81 fine cells' sums and ring-band pixels from the one pass over the frame (coarse cell k's fine cells
  // at 9 k ... 9 k + 8).
  std::array<CellSums, 81> fine_sums_;
  std::array<std::vector<int>, 81> fine_ring_pixels_;
  std::vector<int> ring_pixels_;
  AdapterFitReport report_;
};

}  // namespace close_range
}  // namespace ardsim_pose
