#include "pose_driver.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/param_read.h>

#include "ardsim_dynamics/scenario.h"
#include "ardsim_pose/require_option.h"
#include "conversions.h"

namespace ardsim_pose {

namespace {

template <typename T>
void read(const ros::NodeHandle& nh, const std::string& name, T* value) {
  ardsim_msgs::readParam(nh, name, value, "config/pose.yaml");
}

void readVector(const ros::NodeHandle& nh, const std::string& name, Eigen::Vector3d* value) {
  std::vector<double> v(value->data(), value->data() + 3);
  read(nh, name, &v);
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw std::invalid_argument("parameter " + name + " is out of range: a list of 3 finite numbers");
  *value = Eigen::Vector3d(v[0], v[1], v[2]);
}

}  // namespace

PoseNodeOptions loadOptions(const ros::NodeHandle& nh) {
  PoseNodeOptions o;
  PoseConfig& c = o.config;
  std::string target = ardsim_description::targetKindName(c.target);
  read(nh, "target", &target);
  ardsim_msgs::validateParameters([&] { c.target = ardsim_description::parseTargetKind(target); },
                                  "target: ");
  applyTargetDefaults(&c);  // the parameters below override them
  read(nh, "method", &c.method);
  read(nh, "width", &c.sensor.width);
  read(nh, "height", &c.sensor.height);
  read(nh, "fov_deg", &c.sensor.fov_deg);
  read(nh, "frame_id", &o.frame_id);
  read(nh, "child_frame_id", &o.child_frame_id);
  read(nh, "publish_tf", &o.publish_tf);
  read(nh, "cloud_queue_size", &o.cloud_queue_size);
  requireParameter(o.cloud_queue_size >= 1 && o.cloud_queue_size <= 1000, "cloud_queue_size",
                   o.cloud_queue_size, "1 .. 1000");

  read(nh, "model/spacing_at_port_m", &c.model.spacing_at_port_m);
  read(nh, "model/spacing_growth_per_m", &c.model.spacing_growth_per_m);
  read(nh, "model/max_spacing_m", &c.model.max_spacing_m);
  read(nh, "model/patch_spacings", &c.model.patch_spacings);
  read(nh, "model/chunk_size_m", &c.model.chunk_size_m);
  read(nh, "visibility/cell_px", &c.visibility.cell_px);
  read(nh, "visibility/margin_px", &c.visibility.margin_px);
  read(nh, "visibility/depth_tolerance_m", &c.visibility.depth_tolerance_m);
  read(nh, "visibility/max_incidence_deg", &c.visibility.max_incidence_deg);
  IcpOptions& i = c.icp;
  read(nh, "icp/max_points", &i.max_points);
  read(nh, "icp/max_points_near", &i.max_points_near);
  read(nh, "icp/near_depth_m", &i.near_depth_m);
  read(nh, "icp/silhouette_margin_px", &i.silhouette_margin_px);
  read(nh, "icp/max_iterations_tracking", &i.max_iterations_tracking);
  read(nh, "icp/max_iterations_acquisition", &i.max_iterations_acquisition);
  read(nh, "icp/gate_tracking_m", &i.gate_tracking_m);
  read(nh, "icp/gate_acquisition_m", &i.gate_acquisition_m);
  read(nh, "icp/gate_min_m", &i.gate_min_m);
  read(nh, "icp/tukey_c", &i.tukey_c);
  read(nh, "icp/weak_direction_condition", &i.weak_direction_condition);
  read(nh, "icp/degraded_weak_slide_px", &i.degraded_weak_slide_px);
  read(nh, "icp/contour_sigma_px", &i.contour_sigma_px);
  read(nh, "icp/contours_for_boresight", &i.contours_for_boresight);
  read(nh, "icp/max_contour_pairs", &i.max_contour_pairs);
  read(nh, "icp/contour_wait_px", &i.contour_wait_px);
  read(nh, "icp/contour_max_depth_m", &i.contour_max_depth_m);
  read(nh, "icp/contour_consensus_min_depth_m", &i.contour_consensus_min_depth_m);
  read(nh, "icp/lateral_history_frames", &i.lateral_history_frames);
  read(nh, "icp/lateral_line_frames", &i.lateral_line_frames);
  read(nh, "icp/lateral_line_sigma_m", &i.lateral_line_sigma_m);
  read(nh, "icp/lateral_gate_frames", &i.lateral_gate_frames);
  read(nh, "icp/lateral_acceleration_chi2", &i.lateral_acceleration_chi2);
  read(nh, "icp/lateral_vote_weight", &i.lateral_vote_weight);
  read(nh, "icp/min_sigma_m", &i.min_sigma_m);
  read(nh, "icp/boresight_prior_deg", &i.boresight_prior_deg);
  read(nh, "icp/boresight_prior_max_information", &i.boresight_prior_max_information);
  read(nh, "icp/boresight_prior_when_observed", &i.boresight_prior_when_observed);
  read(nh, "icp/boresight_prior_frames", &i.boresight_prior_frames);
  read(nh, "icp/boresight_prior_min_deg", &i.boresight_prior_min_deg);
  read(nh, "icp/acquisition_boresight_gate_deg", &i.acquisition_boresight_gate_deg);
  read(nh, "icp/crop_reuse_px", &i.crop_reuse_px);
  read(nh, "icp/sparse_start_residual_m", &i.sparse_start_residual_m);
  read(nh, "icp/converged_translation_m", &i.converged_translation_m);
  read(nh, "icp/converged_rotation_rad", &i.converged_rotation_rad);
  read(nh, "icp/revisibility_translation_m", &i.revisibility_translation_m);
  read(nh, "icp/revisibility_rotation_rad", &i.revisibility_rotation_rad);
  read(nh, "icp/min_points", &i.min_points);
  read(nh, "icp/lost_inlier_fraction", &i.lost_inlier_fraction);
  read(nh, "icp/degraded_inlier_fraction", &i.degraded_inlier_fraction);
  read(nh, "icp/lost_fit_rms_m", &i.lost_fit_rms_m);
  read(nh, "icp/degraded_fit_rms_m", &i.degraded_fit_rms_m);
  read(nh, "icp/lost_coverage", &i.lost_coverage);
  read(nh, "icp/degraded_coverage", &i.degraded_coverage);
  read(nh, "icp/degraded_condition", &i.degraded_condition);
  read(nh, "icp/confirm_translation_m", &i.confirm_translation_m);
  read(nh, "icp/confirm_rotation_rad", &i.confirm_rotation_rad);
  read(nh, "icp/max_correction_m", &i.max_correction_m);
  read(nh, "icp/max_correction_rad", &i.max_correction_rad);
  read(nh, "icp/search_iterations", &i.search_iterations);
  read(nh, "icp/search_offset_m", &i.search_offset_m);
  read(nh, "icp/search_rotation_rad", &i.search_rotation_rad);
  read(nh, "icp/search_lateral_m", &i.search_lateral_m);
  read(nh, "icp/search_lateral_step_m", &i.search_lateral_step_m);
  read(nh, "icp/explained_distance_m", &i.explained_distance_m);
  PanelOptions& panels = c.panels;
  read(nh, "panels/enabled", &panels.enabled);
  read(nh, "panels/min_points", &panels.min_points);
  read(nh, "panels/min_extent_m", &panels.min_extent_m);
  read(nh, "panels/max_rms_m", &panels.max_rms_m);
  read(nh, "panels/min_incidence_deg", &panels.min_incidence_deg);
  read(nh, "panels/window", &panels.window);
  read(nh, "panels/first_window", &panels.first_window);
  read(nh, "panels/rebuild_deg", &panels.rebuild_deg);
  read(nh, "estimator/median_filter", &c.estimator.median_filter);
  read(nh, "estimator/median_window", &c.estimator.median_window);
  read(nh, "estimator/velocity_smoothing", &c.estimator.velocity_smoothing);
  read(nh, "estimator/angular_velocity_smoothing", &c.estimator.angular_velocity_smoothing);
  read(nh, "estimator/max_prediction_gap_s", &c.estimator.max_prediction_gap_s);
  read(nh, "estimator/restart_time_jump_s", &c.estimator.restart_time_jump_s);
  read(nh, "estimator/composite_min_port_range_m", &c.estimator.composite_min_port_range_m);
  read(nh, "estimator/composite_max_port_range_m", &c.estimator.composite_max_port_range_m);
  read(nh, "estimator/composite_icp_roll_max_sigma_deg", &c.estimator.composite_icp_roll_max_sigma_deg);
  close_range::ModeManagerOptions& m = c.mode;
  read(nh, "mode/close_enter_range_m", &m.close_enter_range_m);
  read(nh, "mode/close_enter_fill", &m.close_enter_fill);
  read(nh, "mode/close_exit_range_m", &m.close_exit_range_m);
  read(nh, "mode/lost_frames_to_exit", &m.lost_frames_to_exit);
  read(nh, "mode/blend_frames", &m.blend_frames);
  std::string close_method = m.close_method == EstimateMethod::kPyramid ? "pyramid" : "ring";
  read(nh, "mode/close_method", &close_method);
  if (close_method != "ring" && close_method != "pyramid")
    throw std::invalid_argument("parameter mode/close_method = '" + close_method +
                                "' is not allowed: ring or pyramid");
  m.close_method = close_method == "pyramid" ? EstimateMethod::kPyramid : EstimateMethod::kRing;
  // The core names the option (e.g. "icp/max_points = 3 is out of range: ...").
  ardsim_msgs::validateParameters([&] { validate(c); });

  read(nh, "initial/source", &o.initial_source);
  if (o.initial_source != "docking_axis" && o.initial_source != "parameters" &&
      o.initial_source != "scenario")
    throw std::invalid_argument("parameter initial/source = '" + o.initial_source +
                                "' is not allowed: docking_axis, parameters or scenario");
  read(nh, "initial/port_distance_m", &o.initial_port_distance_m);
  requireParameter(std::isfinite(o.initial_port_distance_m) && o.initial_port_distance_m > 0.0,
                   "initial/port_distance_m", o.initial_port_distance_m, "> 0");
  readVector(nh, "initial/position_m", &o.initial_position_m);
  readVector(nh, "initial/rpy_deg", &o.initial_rpy_deg);
  read(nh, "initial/scenario_file", &o.initial_scenario_file);
  if (o.initial_source == "scenario" && o.initial_scenario_file.empty())
    throw std::invalid_argument(
        "parameter initial/scenario_file is required when initial/source is scenario");
  read(nh, "initial/perturb", &o.initial_perturb);
  read(nh, "initial/attitude_deg", &o.perturbation.attitude_deg);
  read(nh, "initial/range_fraction", &o.perturbation.range_fraction);
  read(nh, "initial/lateral_m", &o.perturbation.lateral_m);
  const PriorPerturbation& p = o.perturbation;
  requireParameter(std::isfinite(p.attitude_deg) && p.attitude_deg >= 0.0 && p.attitude_deg <= 180.0,
                   "initial/attitude_deg", p.attitude_deg, "0 .. 180");
  requireParameter(std::isfinite(p.range_fraction) && p.range_fraction >= 0.0 && p.range_fraction < 1.0,
                   "initial/range_fraction", p.range_fraction, "0 .. < 1");
  requireParameter(std::isfinite(p.lateral_m) && p.lateral_m >= 0.0, "initial/lateral_m", p.lateral_m,
                   ">= 0");
  read(nh, "initial/seed", &o.initial_seed);
  requireParameter(o.initial_seed >= 0, "initial/seed", o.initial_seed, ">= 0");
  return o;
}

Eigen::Isometry3d initialEstimate(const PoseNodeOptions& o) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (o.initial_source == "docking_axis") {
    T = dockingAxisPose(o.config.target, o.initial_port_distance_m);
  } else if (o.initial_source == "parameters") {
    T.linear() = ardsim_dynamics::rotationFromRollPitchYaw(o.initial_rpy_deg * M_PI / 180.0);
    T.translation() = o.initial_position_m;
  } else {
    const ardsim_dynamics::Scenario scenario = ardsim_dynamics::loadScenario(o.initial_scenario_file);
    if (scenario.target_kind != o.config.target)
      throw std::invalid_argument("parameter initial/scenario_file: the scenario's target is " +
                                  ardsim_description::targetKindName(scenario.target_kind) +
                                  ", parameter target is " +
                                  ardsim_description::targetKindName(o.config.target));
    T = initialFromScenario(scenario);
  }
  if (o.initial_perturb)
    T = perturbPrior(T, ardsim_description::T_target_port(o.config.target), o.perturbation,
                     static_cast<std::uint64_t>(o.initial_seed));
  return T;
}

PoseDriver::PoseDriver(ros::NodeHandle nh, const ros::NodeHandle& private_nh)
    : options_(loadOptions(private_nh)), estimator_(makeEstimator(options_.config)) {
  const Eigen::Isometry3d initial = initialEstimate(options_);
  estimator_->setPrior(initial);
  // Latched: a subscriber that connects late still gets the current step's estimate. A deep queue per
  // subscriber: a recorder stalled by its disk must not lose estimates (with 2 it lost runs of ~80).
  estimate_publisher_ = nh.advertise<ardsim_msgs::PoseEstimate>("pose/estimate", 1000, true);
  cloud_subscriber_ = nh.subscribe("lidar/points", static_cast<std::uint32_t>(options_.cloud_queue_size),
                                   &PoseDriver::onCloud, this);
  ROS_INFO("pose: %s, method %s, %dx%d %.1f deg, initial %s (%.2f %.2f %.2f m)%s",
           ardsim_description::targetKindName(options_.config.target).c_str(), options_.config.method.c_str(),
           options_.config.sensor.width, options_.config.sensor.height, options_.config.sensor.fov_deg,
           options_.initial_source.c_str(), initial.translation().x(), initial.translation().y(),
           initial.translation().z(), options_.initial_perturb ? ", perturbed" : "");
}

void PoseDriver::onCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
  if (last_estimate_ && msg->header.stamp == last_estimate_->header.stamp) {
    estimate_publisher_.publish(last_estimate_);
    return;
  }
  std_msgs::Header header;
  header.stamp = msg->header.stamp;
  header.frame_id = options_.frame_id;
  std::string error;
  EstimatorOutput output;
  if (!fromPointCloud2(*msg, options_.frame_id, &cloud_, &error)) {
    ARDSIM_WARN_THROTTLE(5.0, "pose: bad cloud at t = %.6f: %s; answering LOST", msg->header.stamp.toSec(),
                         error.c_str());
    // Keep the stamp and an empty frame: the estimator answers LOST and keeps its state.
    cloud_ = OrganizedCloud();
    cloud_.stamp_s = msg->header.stamp.toSec();
    output = estimator_->process(cloud_);
    output.result.reason = "bad cloud: " + error;
  } else {
    output = estimator_->process(cloud_);
  }
  if (output.frames_missing > 0) {
    frames_missing_total_ += output.frames_missing;
    ARDSIM_WARN_THROTTLE(5.0,
                         "pose: %d frame(s) missing before t = %.6f (%ld since the start): dropped from the "
                         "lidar/points queue (cloud_queue_size %d) or never published",
                         output.frames_missing, msg->header.stamp.toSec(), frames_missing_total_,
                         options_.cloud_queue_size);
  }
  if (output.restarted_back_s > 0.0)
    ARDSIM_WARN_THROTTLE(5.0,
                         "pose: t = %.6f is %.3f s before the frame before: time went back, started again "
                         "from the initial estimate",
                         msg->header.stamp.toSec(), output.restarted_back_s);
  if (output.result.status == EstimateStatus::kLost)
    ARDSIM_WARN_THROTTLE(5.0, "pose: LOST at t = %.6f: %s", msg->header.stamp.toSec(),
                         output.result.reason.c_str());
  last_estimate_ = toPoseEstimate(output, header);
  estimate_publisher_.publish(last_estimate_);
  if (options_.publish_tf && output.result.status != EstimateStatus::kLost)
    tf_broadcaster_.sendTransform(toTransform(output.result.T_lidar_target, header, options_.child_frame_id));
}

}  // namespace ardsim_pose
