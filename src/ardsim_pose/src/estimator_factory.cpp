#include "ardsim_pose/estimator_factory.h"

#include <stdexcept>

#include "ardsim_description/mesh_tools.h"
#include "ardsim_description/models.h"

namespace ardsim_pose {

void validate(const PoseConfig& c) {
  if (c.method != "icp" && c.method != "auto")
    throw std::invalid_argument("method = '" + c.method + "' is not allowed: icp or auto");
  ardsim_lidar::validate(c.sensor);
  validate(c.model);
  validate(c.visibility);
  validate(c.icp);
  validate(c.estimator);
}

std::shared_ptr<const ReferenceModel> buildReferenceModel(ardsim_description::TargetKind kind,
                                                          const ReferenceModelOptions& options) {
  return std::make_shared<const ReferenceModel>(
      ardsim_description::rigidStructure(ardsim_description::buildTarget(kind)),
      ardsim_description::T_target_port(kind), options);
}

std::unique_ptr<PoseEstimator> makeEstimator(const PoseConfig& config) {
  validate(config);
  return makeEstimator(config, buildReferenceModel(config.target, config.model));
}

std::unique_ptr<PoseEstimator> makeEstimator(const PoseConfig& config,
                                             std::shared_ptr<const ReferenceModel> model) {
  validate(config);
  PoseEstimator::Methods methods;
  methods[EstimateMethod::kIcp] = std::make_unique<IcpTracker>(
      std::move(model), ardsim_lidar::intrinsicsFor(config.sensor), config.icp, config.visibility);
  // Both "icp" and "auto" select ICP while it is the only method; the close-range mode manager becomes the
  // "auto" selector when its methods join the map.
  return std::make_unique<PoseEstimator>(config.estimator, std::move(methods),
                                         std::make_unique<FixedMethodSelector>(EstimateMethod::kIcp));
}

}  // namespace ardsim_pose
