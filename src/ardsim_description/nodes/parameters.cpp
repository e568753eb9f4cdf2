#include "parameters.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ardsim_description {

StaticFramesOptions loadStaticFramesOptions(const ros::NodeHandle& private_nh) {
  StaticFramesOptions options;
  const std::string ns = private_nh.getNamespace();
  std::string target = targetKindName(options.target);
  private_nh.param("target", target, target);
  try {
    options.target = parseTargetKind(target);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("parameter " + ns + "/target = '" + target + "' is not one of: iss, hubble");
  }
  private_nh.param("publish_meshes", options.publish_meshes, options.publish_meshes);
  private_nh.param("estimated_mesh_alpha", options.estimated_mesh_alpha, options.estimated_mesh_alpha);
  if (!(options.estimated_mesh_alpha >= 0.0 && options.estimated_mesh_alpha <= 1.0)) {
    std::ostringstream message;
    message << "parameter " << ns << "/estimated_mesh_alpha = " << options.estimated_mesh_alpha
            << " is outside 0..1";
    throw std::invalid_argument(message.str());
  }
  return options;
}

}  // namespace ardsim_description
