// Chooses the pose method per frame: ICP far out, a close-range method (ring or pyramid) near, switched by
// the range to the target port and by how much of the view the target fills, with hysteresis; and blends the
// old method's estimate into the new one's over a few frames after a switch so that the output does not jump.
// ROS-free; called by the estimator facade once per frame.
//
// To close range: port range < close_enter_range_m and view fill >= close_enter_fill. At 12 m the modules
// around the port fill the view and the ring is found with sub-millimetre lateral error, while ICP's lateral
// error grows inside ~11 m (spikes of 3 cm in closed loop), so the switch happens while ICP is still good.
// Back to ICP: port range > close_exit_range_m (so ranges between the two thresholds never toggle), or the
// close-range method has been LOST for lost_frames_to_exit frames while beyond close_enter_range_m.
#pragma once

#include <Eigen/Geometry>

#include "ardsim_pose/pose_estimator.h"
#include "ardsim_pose/pose_types.h"

namespace ardsim_pose {
namespace close_range {

struct ModeManagerOptions {
  double close_enter_range_m = 12.0;
  double close_enter_fill = 0.5;
  double close_exit_range_m = 14.0;
  int lost_frames_to_exit = 3;
  int blend_frames = 5;  // frames over which the new method's weight ramps from 1/blend_frames to 1
  EstimateMethod close_method = EstimateMethod::kRing;
};

// Throws std::invalid_argument naming the option, its value and the allowed range.
void validate(const ModeManagerOptions& options);

// Fraction of the frame's pixels with a return.
double viewFill(const OrganizedCloud& cloud);

class ModeManager {
 public:
  struct Decision {
    EstimateMethod method = EstimateMethod::kIcp;    // the method to run and report this frame
    EstimateMethod previous = EstimateMethod::kIcp;  // the method being blended out (== method when none)
    double weight = 1.0;                             // weight of method's estimate in the blend; 1 = none
    bool switched = false;                           // true on the frame of a switch
    bool blending() const { return weight < 1.0; }
  };

  explicit ModeManager(const ModeManagerOptions& options = {}, EstimateMethod initial = EstimateMethod::kIcp);

  // Once per frame, before estimating: port_range_m from the latest estimate (or the prediction), view_fill
  // of this frame, and whether the method in use lost the target on the last frame.
  Decision update(double port_range_m, double view_fill, bool last_lost = false);

  EstimateMethod current() const { return current_; }
  void reset(EstimateMethod initial = EstimateMethod::kIcp);

 private:
  ModeManagerOptions options_;
  EstimateMethod current_;
  EstimateMethod previous_;
  int frames_since_switch_;
  int lost_frames_ = 0;
};

// Pose between `from` (weight 0) and `to` (weight 1): translation interpolated linearly, rotation by slerp.
Eigen::Isometry3d blendPoses(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double weight);

// The estimator facade's "auto" selector: the mode manager fed from the facade's prediction (range of the
// target port, geometry.T_target_port), the frame's view fill and whether the last frame was LOST.
class ModeSelector : public MethodSelector {
 public:
  ModeSelector(const ModeManagerOptions& options, const Eigen::Isometry3d& T_target_port);
  EstimateMethod select(const SelectionInput& input) override;
  bool blending(EstimateMethod* from, double* weight) const override;
  void reset() override;
  const ModeManager::Decision& lastDecision() const { return decision_; }

 private:
  ModeManager manager_;
  Eigen::Isometry3d T_target_port_;
  ModeManager::Decision decision_;
};

}  // namespace close_range
}  // namespace ardsim_pose
