// Solar arrays turn about their masts, so the rigid reference model leaves them out; where the target's
// panels turn on one rotary joint (Hubble's two arrays about one mast axis), the scan measures their angle
// and the reference model carries them at it. Beyond 20 m Hubble seen end-on shows its roll on little else
// (approach datasets: 20-50 m attitude RMS 0.05-0.23 deg without the arrays; with them in the model at the
// true angle, 0.01-0.06). ROS-free.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"
#include "ardsim_pose/pose_types.h"
#include "ardsim_pose/reference_model.h"

namespace ardsim_pose {

// Flat panels centred on a rotary joint's axis, in the target frame. At angle a the panels' direction
// across the axis is zero_direction turned by a about axis; a panel turned by pi is the same panel.
struct PanelJoint {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();           // a point on the axis
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();            // unit
  Eigen::Vector3d zero_direction = Eigen::Vector3d::UnitX();  // unit, across the axis
  double min_axial_m = 0.0;   // the panels lie this far along the axis from origin (either way) ...
  double max_axial_m = 0.0;   // ... to this far
  double half_width_m = 0.0;  // and this far across it
};

// Hubble's solar arrays (ardsim_description's hubble.cpp: 2.6 x 7.1 m, 3.0-10.1 m out on the masts). Throws
// std::invalid_argument for a target whose panels do not turn on one joint (the ISS: ten).
PanelJoint panelJoint(ardsim_description::TargetKind kind);

struct PanelOptions {
  bool enabled = false;  // by target (applyTargetDefaults): Hubble's arrays on; the ISS has no single joint
  int min_points = 100;  // scan points near the panels for a frame's fit
  double min_extent_m = 1.0;  // ... spread at least this far across the axis (edge-on panels show none)
  double max_rms_m = 0.05;    // a fit with a larger residual is not a panel
  // Panels seen at a more grazing angle than this (between the line of sight and their surface) stay out of
  // the model: near edge-on their few returns are edges and mixed pixels (hubble_hold, arrays at 0 deg seen
  // 1-3 deg off edge-on, fitted at ~1 deg: ICP 30-50 m attitude RMS 0.059 -> 0.22 deg with them in), and
  // even at the true angle edge-on arrays in the model cost ICP (approach datasets, arrays at 0 deg put in
  // the model: 20-30 m 0.056 -> 0.068 deg).
  double min_incidence_deg = 6.0;
  int window = 9;  // the panels' angle is the median of the last window frames' fits
  // ... but a model without panels takes them at the median of this many (odd, <= window): from 50 m in
  // the arrays then join the model during Hubble's acquisition, not after it (approach datasets, arrays at
  // 30 deg, 30-50 m attitude RMS 0.020-0.120 -> 0.019-0.040 deg with 3 instead of 9). One fit alone let a
  // poor pose's fit into the model (3 of 24 runs LOST 1-3 frames).
  int first_window = 3;
  // The model is rebuilt with the panels at that median when it differs from the model's angle by more
  // than this: a model panel 2 deg off tilted Hubble's estimate 0.15-0.4 deg (a rotation about the mast
  // axis is a pitch of the whole body to ICP). The fits, made at the estimated pose, follow that pitch back
  // towards the model's angle, so a first angle ~0.1 deg off stayed with 0.1 here (a slow approach, 51 ->
  // 46 m in 5 cm steps: the body 0.03-0.05 deg off, 30-50 m attitude RMS 0.041 deg; 0.022 with 0.03). A
  // rebuild turns the panels' samples (ReferenceModel::withArticulatedTurned, 1-4 ms); sampled anew
  // (70-270 ms) 0.03 put 121 of hubble_hold_arrays30's 7001 frames over 50 ms.
  double rebuild_deg = 0.03;
};
void validate(const PanelOptions& options);

struct PanelFit {
  double angle_rad = 0.0;  // in [-pi/2, pi/2)
  int points = 0;
  double extent_m = 0.0;
  double rms_m = 0.0;
  double incidence_deg = 0.0;  // between the line of sight to the joint and the fitted panels' surface
  bool grazing = false;        // a line was fitted, but the panels are seen nearly edge-on
};

// The panels' angle from the scan points near them (within half_width_m + margin of the axis, along the
// panels' length) with the target at T_lidar_target: a line across the axis, fitted by total least squares
// twice (the second time without the points beyond 3 robust sigmas of the first). false: too few points,
// too little spread, too large a residual, or seen too nearly edge-on (options; fit->grazing).
bool fitPanelAngle(const PanelJoint& joint, const OrganizedCloud& cloud,
                   const Eigen::Isometry3d& T_lidar_target, const PanelOptions& options, PanelFit* fit);

// Keeps the reference model's panels at the angle the scans measure: one fit per estimated frame, the median
// of the last window (of first_window for the first), and a rebuilt model when the median moves
// (PanelOptions). Until the first median the model has no panels (the rigid structure alone), and it returns
// to that after a window of frames in a row whose fits found the panels edge-on (they turned).
class PanelTracker {
 public:
  using ModelBuilder = std::function<std::shared_ptr<const ReferenceModel>(double angle_rad)>;
  // rigid: the model without the panels; build: the model with them at an angle.
  PanelTracker(const PanelJoint& joint, const PanelOptions& options,
               std::shared_ptr<const ReferenceModel> rigid, ModelBuilder build);

  // After a frame ICP estimated (tracking or acquiring: the fit's residual and extent checks and the window's
  // median keep a poor pose's fit out) with the target at T_lidar_target: a new model when one is due, else
  // nullptr. Fitting from the acquisition frames on put the arrays into the model frames earlier (approach
  // datasets, arrays at 30 deg, 30-50 m: within 0.1 deg in 8 -> 10 of 12 runs).
  std::shared_ptr<const ReferenceModel> update(const OrganizedCloud& cloud,
                                               const Eigen::Isometry3d& T_lidar_target);
  bool modelHasPanels() const { return model_has_panels_; }
  const PanelFit& lastFit() const { return last_fit_; }

 private:
  PanelJoint joint_;
  PanelOptions options_;
  std::shared_ptr<const ReferenceModel> rigid_;
  ModelBuilder build_;
  std::vector<double> recent_rad_;  // the last window fits, unwrapped near the first
  int grazing_in_a_row_ = 0;
  bool model_has_panels_ = false;
  double model_angle_rad_ = 0.0;
  PanelFit last_fit_;
};

}  // namespace ardsim_pose
