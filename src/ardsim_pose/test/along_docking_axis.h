// A target along its docking axis, rendered (with noise, by default) by the lidar core in-process, through an
// estimator from the first frame's truth: the rendered tests' approaches, frame by frame.
#pragma once

#include <cstdint>
#include <memory>

#include "ardsim_description/frames.h"
#include "ardsim_lidar/lidar_simulator.h"
#include "ardsim_pose/dataset.h"
#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"

namespace ardsim_pose {

class AlongTheDockingAxis {
 public:
  // config: the estimator's (its target's kind and sensor); target: the mesh rendered.
  AlongTheDockingAxis(const PoseConfig& config, const ardsim_description::TriangleMesh& target,
                      std::uint64_t simulator_seed, double frame_period_s = 0.1,
                      const ardsim_lidar::NoiseOptions& noise = {})
      : config_(config),
        frame_period_s_(frame_period_s),
        simulator_(config.sensor, noise, simulator_seed),
        estimator_(makeEstimator(config)) {
    simulator_.setTarget(target);
  }
  const PoseConfig& config() const { return config_; }
  // Frame k (its noise seeded by k, stamped k frame periods) at dockingAxisPose(port_distance_m): the
  // estimate, and its error.
  EstimatorOutput frame(int k, double port_distance_m, PoseErrorValue* error) {
    const Eigen::Isometry3d truth = dockingAxisPose(config_.target, port_distance_m);
    if (k == 0) estimator_->setPrior(truth);
    simulator_.simulate(truth, static_cast<std::uint64_t>(k), &rendered_);
    const EstimatorOutput out =
        estimator_->process(fromLidarFrame(rendered_, simulator_.rays(), frame_period_s_ * k));
    *error = poseError(out.result.T_lidar_target, truth, ardsim_description::T_target_port(config_.target));
    return out;
  }

 private:
  PoseConfig config_;
  double frame_period_s_;
  ardsim_lidar::LidarSimulator simulator_;
  std::unique_ptr<PoseEstimator> estimator_;
  ardsim_lidar::LidarFrame rendered_;
};

}  // namespace ardsim_pose
