// Nodelet "ardsim_lidar/LidarNodelet": the flash LIDAR in a nodelet manager, so the large clouds reach the
// pose estimator without serialisation.
#include <memory>

#include <ardsim_msgs/startup_error.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "lidar_driver.h"

namespace ardsim_lidar {

class LidarNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      driver_ = std::make_unique<LidarDriver>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      ardsim_msgs::reportStartupError(getNodeHandle(), getName(), e.what());
      throw;
    }
  }
  std::unique_ptr<LidarDriver> driver_;
};

}  // namespace ardsim_lidar

PLUGINLIB_EXPORT_CLASS(ardsim_lidar::LidarNodelet, nodelet::Nodelet)
