// The static_frames node's options, filled from rosparam in one place and validated there.
#pragma once

#include <string>

#include <ros/node_handle.h>

#include "ardsim_description/frames.h"

namespace ardsim_description {

struct StaticFramesOptions {
  TargetKind target = TargetKind::kIss;  // ~target: iss | hubble
  bool publish_meshes = true;            // ~publish_meshes: latched rviz markers of the vehicles
  double estimated_mesh_alpha =
      0.4;  // ~estimated_mesh_alpha: opacity of the mesh drawn at the estimate, 0..1
};

// Throws std::invalid_argument naming the parameter, its value and the allowed values.
StaticFramesOptions loadStaticFramesOptions(const ros::NodeHandle& private_nh);

}  // namespace ardsim_description
