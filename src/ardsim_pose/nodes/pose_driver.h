// The pose estimator's ROS interface, shared by the nodelet (pose_nodelet.cpp) and the node (pose_node.cpp):
// answers every lidar/points frame with exactly one pose/estimate stamped with the frame's time (LOST with a
// reason when it cannot estimate), and the tf lidar_optical -> target_estimated.
#pragma once

#include <memory>
#include <string>

#include <ardsim_msgs/PoseEstimate.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_broadcaster.h>

#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"

namespace ardsim_pose {

struct PoseNodeOptions {
  PoseConfig config;
  std::string frame_id = "lidar_optical";
  std::string child_frame_id = "target_estimated";
  bool publish_tf = true;
  // lidar/points frames held while one is estimated; beyond it the oldest is dropped (and the next estimate's
  // frames_missing logged). 10 (~10 MB of 256 x 256 clouds) covers an acquisition search's few hundred ms
  // at a bag player's 2x pace; the lockstep loop never queues more than one.
  int cloud_queue_size = 10;
  // Where the first frame starts: "docking_axis" (the chaser on the docking axis, its port
  // initial/port_distance_m out), "parameters" (initial/position_m and initial/rpy_deg: T_lidar_target) or
  // "scenario" (the chaser's initial state in initial/scenario_file).
  std::string initial_source = "docking_axis";
  double initial_port_distance_m = 100.0;
  Eigen::Vector3d initial_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_rpy_deg = Eigen::Vector3d::Zero();  // R = Rz(yaw) Ry(pitch) Rx(roll)
  std::string initial_scenario_file;
  bool initial_perturb = false;  // start from the coarse prior around that pose (seeded)
  PriorPerturbation perturbation;
  int initial_seed = 1;
};

// Reads every private parameter (the struct defaults are the defaults) and validates them. Throws
// std::invalid_argument naming the parameter, its value and the allowed range.
PoseNodeOptions loadOptions(const ros::NodeHandle& private_nh);

// The initial T_lidar_target the options describe. Throws for an unreadable scenario.
Eigen::Isometry3d initialEstimate(const PoseNodeOptions& options);

class PoseDriver {
 public:
  PoseDriver(ros::NodeHandle nh, const ros::NodeHandle& private_nh);

 private:
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& msg);

  PoseNodeOptions options_;
  std::unique_ptr<PoseEstimator> estimator_;
  ros::Subscriber cloud_subscriber_;
  ros::Publisher estimate_publisher_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  OrganizedCloud cloud_;
  // The last answer: a frame delivered twice (a latched publisher resends its last frame to a new connection)
  // is answered again with it, not estimated twice, so the estimator's history does not depend on connection
  // timing.
  ardsim_msgs::PoseEstimateConstPtr last_estimate_;
  long frames_missing_total_ = 0;
};

}  // namespace ardsim_pose
