// Builds the estimator of a configuration: the reference model of the target's rigid structure, the methods
// and the method selector. Where the node, evaluate_dataset, the tests and the benchmark get theirs.
// ROS-free.
#pragma once

#include <memory>
#include <string>

#include "ardsim_description/frames.h"
#include "ardsim_lidar/sensor.h"
#include "ardsim_pose/close_range/mode_manager.h"
#include "ardsim_pose/close_range/pyramid.h"
#include "ardsim_pose/close_range/ring_detector.h"
#include "ardsim_pose/icp_tracker.h"
#include "ardsim_pose/panel_angle.h"
#include "ardsim_pose/pose_estimator.h"
#include "ardsim_pose/reference_model.h"

namespace ardsim_pose {

struct PoseConfig {
  ardsim_description::TargetKind target = ardsim_description::TargetKind::kIss;
  ardsim_lidar::SensorOptions sensor;  // width, height and fov_deg must match the lidar's
  // "icp", "ring", "pyramid": that method every frame. "auto": the close-range mode manager (ICP far out, the
  // close-range method near: the ISS's docking adapter and Hubble's soft-capture mechanism, the same IDSS
  // ring).
  std::string method = "icp";
  ReferenceModelOptions model;
  VisibilityOptions visibility;
  IcpOptions icp;
  PanelOptions panels;  // ICP's model follows the panels' measured angle (Hubble's arrays)
  EstimatorOptions estimator;
  close_range::RingDetectorOptions ring;
  close_range::PyramidOptions pyramid;
  close_range::ModeManagerOptions mode;
};

// The defaults that depend on config->target, set into config: for Hubble a model sampled twice as finely at
// the port (0.015 m) and 5000 scan points (2500 until session 10: see the .cpp for the roll). Its lateral
// position rests on the rim of its face-on aft bulkhead, whose offsets count only beyond the model's sample
// spacing: with the ISS's 0.03 m and 1000 points the Hubble approach dataset's bands inside 30 m were 1.5-3.5
// cm RMS, with 0.015 m and 2500 1.0-2.0 cm. Then the hand-over to the ring at 20 m and the composite pose at
// 10-20 m (EstimatorOptions; 10-30 m until session 37). The ISS keeps the struct's defaults. Call it after
// choosing the target, before other overrides.
void applyTargetDefaults(PoseConfig* config);

// Throws std::invalid_argument naming the option, its value and the allowed values.
void validate(const PoseConfig& config);

// The rigid structure (articulated parts left out) of the target, sampled.
std::shared_ptr<const ReferenceModel> buildReferenceModel(ardsim_description::TargetKind kind,
                                                          const ReferenceModelOptions& options);
// The rigid structure and the panels of panelJoint(kind) at panel_angle_rad, sampled.
std::shared_ptr<const ReferenceModel> buildReferenceModelWithPanels(ardsim_description::TargetKind kind,
                                                                    const ReferenceModelOptions& options,
                                                                    double panel_angle_rad);

std::unique_ptr<PoseEstimator> makeEstimator(const PoseConfig& config);
// The same with a model already built (it is shared, read-only, between estimators).
std::unique_ptr<PoseEstimator> makeEstimator(const PoseConfig& config,
                                             std::shared_ptr<const ReferenceModel> model);

}  // namespace ardsim_pose
