// static_frames: publishes the description's fixed frames on /tf_static (target -> target_port,
// chaser -> chaser_port, chaser -> lidar_optical) and, latched, the vehicle meshes for rviz. See README.md.
#include <ardsim_msgs/startup_error.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "ardsim_description/frames.h"
#include "ardsim_description/models.h"
#include "conversions.h"
#include "parameters.h"

using namespace ardsim_description;

int main(int argc, char** argv) {
  ros::init(argc, argv, "static_frames");
  ros::NodeHandle nh, private_nh("~");
  StaticFramesOptions options;
  try {
    options = loadStaticFramesOptions(private_nh);
  } catch (const std::invalid_argument& e) {
    ROS_FATAL("static_frames: %s", e.what());
    ardsim_msgs::reportStartupError(nh, "static_frames", e.what());
    return 1;
  }

  tf2_ros::StaticTransformBroadcaster broadcaster;
  const ros::Time stamp = ros::Time::now();
  broadcaster.sendTransform(
      {toTransformStamped(T_target_port(options.target), "target", "target_port", stamp),
       toTransformStamped(T_chaser_port(), "chaser", "chaser_port", stamp),
       toTransformStamped(T_chaser_lidar(), "chaser", "lidar_optical", stamp)});

  ros::Publisher target_mesh, estimated_mesh, chaser_mesh;
  if (options.publish_meshes) {
    const TriangleMesh target = buildTarget(options.target);
    target_mesh = nh.advertise<visualization_msgs::Marker>("description/target_mesh", 1, /*latch=*/true);
    estimated_mesh = nh.advertise<visualization_msgs::Marker>("description/target_estimated_mesh", 1, true);
    chaser_mesh = nh.advertise<visualization_msgs::Marker>("description/chaser_mesh", 1, true);
    target_mesh.publish(toMarker(target, "target", "target", 1.0f));
    estimated_mesh.publish(toMarker(target, "target_estimated", "target_estimated",
                                    static_cast<float>(options.estimated_mesh_alpha)));
    chaser_mesh.publish(toMarker(buildChaser(), "chaser", "chaser", 1.0f));
  }
  ROS_INFO("static_frames: target %s, frames target_port, chaser_port, lidar_optical on /tf_static%s",
           targetKindName(options.target).c_str(), options.publish_meshes ? ", meshes latched" : "");
  ros::spin();
  return 0;
}
