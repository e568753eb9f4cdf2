// Message <-> core conversions of ardsim_dynamics (the only place they happen).
#pragma once

#include <string>

#include <ardsim_msgs/ContactEvent.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Wrench.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>

#include "ardsim_dynamics/simulation.h"

namespace ardsim_dynamics {

// Odometry of a vehicle's body frame in eci: pose, eci velocity of the CoM, body rate in body axes.
void toOdometry(const VehicleState& state, const ros::Time& stamp, const std::string& child_frame,
                nav_msgs::Odometry& msg);
// Odometry of a relative state (pose and velocities in the parent frame's coordinates).
void toOdometry(const RelativeState& state, const ros::Time& stamp, const std::string& frame,
                const std::string& child_frame, nav_msgs::Odometry& msg);
geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& T_parent_child, const ros::Time& stamp,
                                            const std::string& parent, const std::string& child);
geometry_msgs::Wrench toWrench(const BodyWrench& wrench);
// False (and nothing applied) when any component is not finite.
bool fromWrench(const geometry_msgs::Wrench& msg, BodyWrench& wrench);
// The first contact, stamped with its time, in target_port.
void toContactEvent(const ContactEvent& event, ardsim_msgs::ContactEvent& msg);
// Vehicle state back from odometry (the inverse of the first toOdometry).
VehicleState fromOdometry(const nav_msgs::Odometry& msg);

}  // namespace ardsim_dynamics
