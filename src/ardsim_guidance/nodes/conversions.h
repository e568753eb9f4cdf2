// All message <-> core conversions of ardsim_guidance.
#pragma once

#include <string>

#include <ardsim_msgs/GuidanceState.h>
#include <ardsim_msgs/PoseEstimate.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/WrenchStamped.h>
#include <nav_msgs/Odometry.h>
#include <Eigen/Geometry>

#include "ardsim_guidance/guidance.h"
#include "ardsim_guidance/truth_pose.h"

namespace ardsim_guidance {

// Pose -> isometry. Returns false (and says why) for non-finite numbers or a quaternion whose norm is not
// within 1e-3 of one (NaN, zero or garbage quaternions); a slightly off unit quaternion is normalized.
bool toIsometry(const geometry_msgs::Pose& pose, Eigen::Isometry3d* T, std::string* why);
geometry_msgs::Pose toPose(const Eigen::Isometry3d& T);

// The estimate as guidance sees it: malformed poses give well_formed = false with the reason.
EstimateInput fromPoseEstimate(const ardsim_msgs::PoseEstimate& msg);

// Body pose, CoM velocity (eci) and body rates from a truth odometry; false with a reason if malformed.
bool fromOdometry(const nav_msgs::Odometry& msg, OwnState* state, std::string* why);

geometry_msgs::WrenchStamped toWrench(const GuidanceOutput& out, const ros::Time& stamp);
ardsim_msgs::GuidanceState toGuidanceState(const GuidanceOutput& out, const ros::Time& stamp);
ardsim_msgs::PoseEstimate toPoseEstimate(const TruthPoseSample& sample, const TruthPoseOptions& options,
                                         const ros::Time& stamp);

}  // namespace ardsim_guidance
