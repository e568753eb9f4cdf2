// Every conversion between the description's core types and ROS messages.
#pragma once

#include <string>

#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <visualization_msgs/Marker.h>
#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"

namespace ardsim_description {

geometry_msgs::TransformStamped toTransformStamped(const Eigen::Isometry3d& T_parent_child,
                                                   const std::string& parent, const std::string& child,
                                                   const ros::Time& stamp);
Eigen::Isometry3d toIsometry(const geometry_msgs::Transform& transform);

// A TRIANGLE_LIST marker of the mesh in `frame_id` (its body frame): grey by reflectivity, retro-reflectors
// red.
visualization_msgs::Marker toMarker(const TriangleMesh& mesh, const std::string& frame_id,
                                    const std::string& ns, float alpha);

}  // namespace ardsim_description
