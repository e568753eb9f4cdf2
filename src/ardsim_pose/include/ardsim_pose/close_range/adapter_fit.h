// The close-range back end shared by the pyramid and docking-ring methods: the docking adapter's geometry as
// the sensor sees it, frame preparation, and the fits that turn labelled pixels into T_lidar_target (a joint
// plane fit over the adapter's parallel faces, a circle fit to the ring's edges, the centreline target's
// centroid, and the rotation about the boresight from the petals and the cross). ROS-free.
//
// Everything is in the target port frame (ardsim_description frames.h): x out of the port towards the chaser,
// origin at the centre of the docking plane. The front ends (pyramid.h, ring_detector.h) decide which pixels
// are the ring's front face; this back end does the rest.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {
namespace close_range {

// Dimensions of the IDSS interface on the ISS's IDA-2 as ardsim_description builds it (model_builder.cpp
// addIdssInterface with iss.cpp's IDA-2 options; the test renders the mesh and checks the fits against it).
struct AdapterGeometry {
  double ring_inner_radius_m = 0.42;  // soft-capture ring, front face on the docking plane (x = 0)
  double ring_outer_radius_m = 0.60;
  double tunnel_face_x_m = -0.12;  // annular face of the tunnel behind the ring, out to the tunnel radius
  double tunnel_outer_radius_m = 0.80;
  double hatch_face_x_m = -0.90;  // hatch disc closing the passage
  double hatch_radius_m = 0.415;
  double plate_face_x_m = -0.89;  // black back plate of the centreline docking target
  double plate_radius_m = 0.20;
  double cross_face_x_m = -0.57;      // front face of the white standoff cross
  double cross_half_length_m = 0.15;  // arms along the port's y and z axes
  double petal_top_x_m = 0.28;        // guide petals stand out of the docking plane, inside the passage
  double petal_min_radius_m = 0.26;
  double petal_max_radius_m = 0.40;
  // Three peripheral retro-reflector targets at 60 + 120 k deg (between the petals), on brackets from the
  // tunnel: discs facing out of the port, their centres reflector_radius_m from the axis.
  double reflector_radius_m = 1.125;
  double reflector_disc_radius_m = 0.075;
  double reflector_face_x_m = -0.27;
  Eigen::Isometry3d T_target_port = Eigen::Isometry3d::Identity();  // from ardsim_description::T_target_port
};

// The ISS geometry with its T_target_port.
AdapterGeometry issAdapterGeometry();
// Hubble's soft-capture mechanism (the same IDSS ring, petals and reflectors; the aft bulkhead instead of a
// hatch, no centreline target) with its T_target_port.
AdapterGeometry hubbleAdapterGeometry();
AdapterGeometry adapterGeometry(ardsim_description::TargetKind kind);

struct AdapterFitOptions {
  // The sensor's calibrated detector walk: saturated returns (intensity 1) read short by this much
  // (ardsim_lidar NoiseOptions::saturation_range_bias_m, -0.02 m); added back along the ray. 0 switches the
  // correction off.
  double saturated_range_bias_m = -0.02;
  // The sensor's angular pixel size (the default sensor's; makeEstimator sets PoseConfig::sensor's).
  double pixel_pitch_rad = 20.0 / 256.0 * 3.14159265358979 / 180.0;
  double plane_band_m = 0.05;    // a point belongs to a face when within this of it (prediction-based labels)
  double range_sigma_m = 0.012;  // expected range noise: robust weights and rejection scale with it
  double edge_step_min_m = 0.25;   // an inner ring edge: the neighbour lies this much behind the ring plane
  double outer_step_min_m = 0.07;  // an outer edge: the neighbour on the tunnel face (0.12 m behind)
  double outer_step_max_m = 0.18;
  int min_plane_points = 150;       // fewer plane points: LOST
  int min_edge_points = 24;         // fewer inner-edge points: no circle
  double min_edge_arc_deg = 150.0;  // the inner-edge points must span at least this much of the circle
  double max_radius_error_m =
      0.03;                   // fitted inner radius within this of the model, or the circle is rejected
  int min_cross_points = 20;  // cross-face points for the lateral position and the boresight angle
  int min_petal_points = 12;
  int min_reflector_points = 20;  // per reflector disc; the boresight angle needs two whole discs
  double boresight_gain =
      0.3;  // a boresight measurement within the gate of the prediction moves it this much
  double boresight_gate_deg = 1.5;  // beyond: the measurement is taken as it is
  double min_resultant = 0.6;       // circular concentration of the petals' angles to count as observed
  double max_step_from_prediction_m = 0.5;  // a larger jump from the prediction is not trusted: LOST
  double max_tilt_from_prediction_deg = 10.0;
  // The final round labels the faces and scans for ring edges on every second pixel in a checkerboard (half
  // the cost; tilt noise up by ~sqrt 2, far inside the goals); false: on every pixel.
  bool fine_checkerboard = true;
};

// A frame made ready for the fits: points corrected for detector walk, ranges, validity.
struct PreparedFrame {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3f> points;  // NaN where no return
  std::vector<float> range_m;           // NaN where no return
  // Saturated returns (intensity 1): a retro-reflector's own pixels, not the weaker spill of its blooming
  // around it. All 0 when the cloud has no intensity (has_intensity false).
  std::vector<std::uint8_t> saturated;
  bool has_intensity = false;
  int valid_count = 0;
  bool isValid(int i) const { return range_m[i] == range_m[i]; }
};
void prepareFrame(const OrganizedCloud& cloud, const AdapterFitOptions& options, PreparedFrame* frame);

// Angle (rad) of the port's +y axis about the port normal n (pointing out of the port, towards the lidar),
// from the lidar x axis projected on the docking plane: the boresight rotation the study left undetermined.
double boresightAngle(const Eigen::Matrix3d& R_lidar_port);
// R_lidar_port from the port normal and that angle.
Eigen::Matrix3d portRotation(const Eigen::Vector3d& normal, double boresight_rad);

// What the fits found, for tests and diagnostics.
struct AdapterFitReport {
  bool circle = false;  // the ring's inner edge (and outer when seen) fitted
  bool cross = false;   // the centreline cross seen well enough for the lateral position
  // The field of view cuts the inner edge's circle: where the cross is seen, the lateral position is the
  // cross's alone (the circle's arc biased).
  bool circle_clipped = false;
  bool petals = false;       // boresight angle measured from the petals
  bool cross_angle = false;  // boresight angle measured from the cross
  bool reflectors = false;   // boresight angle measured from the peripheral reflector targets
  int plane_points = 0;
  int edge_points = 0;
  int cross_points = 0;
  int petal_points = 0;
  int reflector_points = 0;
  double inner_radius_m = 0.0;
  double edge_arc_deg = 0.0;
  double plane_rms_m = 0.0;
};

// The back end. Stateless apart from scratch buffers (reused between frames, so one instance per thread).
class AdapterFitter {
 public:
  explicit AdapterFitter(const AdapterGeometry& geometry = issAdapterGeometry(),
                         const AdapterFitOptions& options = {});

  // T_lidar_target from the frame. ring_face_pixels: pixels a front end labelled as the ring's front face
  // (may be empty: then only the hatch and the centreline target are used, the terminal stage down to
  // contact). T_lidar_port_seed: the front end's coarse pose of the port (its normal and centre), or the
  // prediction. T_lidar_port_prior: the prediction, whose boresight angle resolves the petals' 120 deg
  // ambiguity and is held when neither petals nor cross are seen. method goes into the result.
  PoseResult fit(const PreparedFrame& frame, const std::vector<int>& ring_face_pixels,
                 const Eigen::Isometry3d& T_lidar_port_seed, const Eigen::Isometry3d& T_lidar_port_prior,
                 EstimateMethod method, AdapterFitReport* report = nullptr);

  const AdapterGeometry& geometry() const { return geometry_; }
  const AdapterFitOptions& options() const { return options_; }

 private:
  // The adapter's faces parallel to the docking plane: ring, tunnel, hatch, target plate, cross.
  static constexpr int kFaces = 5;
  // 24 bytes (the frame's float point, cast where used: the same values): each round writes one per pixel on
  // a face and the plane fit reads them back, so their size is memory traffic.
  struct PlanePoint {
    Eigen::Vector3f p;
    int face;       // 0..kFaces-1
    double face_x;  // the face's x in the port frame
  };
  // One pass of labels, plane fit, ring edges, circle and cross from a guess of the port's pose.
  struct RoundResult {
    AdapterFitReport report;
    Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  // port normal (out of the port) in lidar_optical
    double d = 0.0;                                // n . port origin
    Eigen::Vector3d origin = Eigen::Vector3d::Zero(), e1 = Eigen::Vector3d::UnitX(),
                    e2 =
                        Eigen::Vector3d::UnitY();  // in-plane frame: origin below the guess, basis of angle 0
    Eigen::Vector2d centre_guess = Eigen::Vector2d::Zero();  // the guess's centre in that frame
    Eigen::Vector2d circle_centre = Eigen::Vector2d::Zero();
    Eigen::Matrix2d circle_cov = Eigen::Matrix2d::Identity();
    Eigen::Vector2d lateral = Eigen::Vector2d::Zero();
    Eigen::Matrix2d lateral_cov = Eigen::Matrix2d::Identity();
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the port origin found, in lidar_optical
    double cross_angle = 0.0;  // boresight angle from the cross's arms (modulo 90 deg), when report.cross
  };
  // Centre and arm angle of the centreline cross from its front-face points (in-plane coordinates), starting
  // from the guesses in centre and angle; false when the two arms are not both seen well.
  bool fitCross(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d* centre, double* angle) const;
  // A start for fitCross that does not need the centre: where the points pile up across each arm.
  Eigen::Vector2d crossStart(const std::vector<Eigen::Vector2d>& points, double angle) const;
  // The pixels a round labels and scans for edges: every row_step-th row, in it every col_step-th pixel from
  // column (v / row_step * shift) % col_step (row_step 1, col_step 2, shift 1: a checkerboard).
  struct Sampling {
    int row_step = 1, col_step = 1, shift = 0;
    int firstColumn(int v) const { return (v / row_step * shift) % col_step; }
    int pixelsPerSample() const { return row_step * col_step; }
  };
  bool fitRound(const PreparedFrame& frame, const std::vector<int>& ring_face_pixels,
                const Eigen::Isometry3d& T_lidar_port_guess, double band, const Sampling& sampling,
                RoundResult* out, std::string* reason);
  bool onBorder(const PreparedFrame& frame, int pixel) const;
  // Boresight angle (rad, modulo 120 deg) from the peripheral reflector targets' discs, in the frame of the
  // fitted plane (T_port0_lidar: port frame at boresight angle 0; d: the plane's offset along its normal,
  // with along_ from the last round); sets report's reflectors and reflector_points.
  double reflectorAngle(const PreparedFrame& frame, const Eigen::Isometry3d& T_port0_lidar, double d,
                        AdapterFitReport* report) const;
  // Joint fit of the unit normal n and offset d with n.p = d + face_x for every point (robust, a few
  // Gauss-Newton steps); returns false with too few inliers (each point standing for pixels_per_point).
  bool fitPlanes(std::vector<PlanePoint>& points, int pixels_per_point, Eigen::Vector3d* normal,
                 double* offset, double* rms, int* used);
  void labelPlanePoints(const PreparedFrame& frame, const std::vector<int>& ring_face_pixels,
                        const Eigen::Isometry3d& T_lidar_port, double band, const Sampling& sampling);

  AdapterGeometry geometry_;
  AdapterFitOptions options_;
  std::vector<PlanePoint> plane_points_;
  std::vector<int> cross_face_points_;  // indices into plane_points_ of the cross face's points
  std::vector<std::uint8_t> is_ring_;
  std::vector<double> along_;  // n.p of each pixel for the ring-edge scan
  std::vector<Eigen::Vector2d> inner_edge_, outer_edge_, cross_points_;
};

}  // namespace close_range
}  // namespace ardsim_pose
