// Nodelet "ardsim_pose/PoseNodelet": the pose estimator in the lidar's nodelet manager, so that clouds arrive
// by pointer.
#include <memory>

#include <ardsim_msgs/startup_error.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "pose_driver.h"

namespace ardsim_pose {

class PoseNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      driver_ = std::make_unique<PoseDriver>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      ardsim_msgs::reportStartupError(getNodeHandle(), getName(), e.what());
      throw;
    }
  }
  std::unique_ptr<PoseDriver> driver_;
};

}  // namespace ardsim_pose

PLUGINLIB_EXPORT_CLASS(ardsim_pose::PoseNodelet, nodelet::Nodelet)
