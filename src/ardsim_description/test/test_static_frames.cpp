// rostest: the static_frames node (launched with target:=hubble) puts the description's frames on tf and
// latches the meshes; its parameter loading rejects bad values by name.
#include <gtest/gtest.h>

#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/Marker.h>

#include "../nodes/conversions.h"
#include "../nodes/parameters.h"
#include "ardsim_description/frames.h"
#include "ardsim_description/models.h"

using namespace ardsim_description;

TEST(StaticFrames, PublishesTheDescriptionFramesOnTf) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const struct {
    const char* parent;
    const char* child;
    Eigen::Isometry3d expected;
  } frames[] = {{"target", "target_port", T_target_port(TargetKind::kHubble)},
                {"chaser", "chaser_port", T_chaser_port()},
                {"chaser", "lidar_optical", T_chaser_lidar()}};
  for (const auto& frame : frames) {
    SCOPED_TRACE(frame.child);
    geometry_msgs::TransformStamped msg;
    ASSERT_NO_THROW(msg =
                        buffer.lookupTransform(frame.parent, frame.child, ros::Time(0), ros::Duration(60.0)));
    EXPECT_TRUE(toIsometry(msg.transform).isApprox(frame.expected, 1e-9));
  }
}

TEST(StaticFrames, LatchesTheVehicleMeshes) {
  ros::NodeHandle nh;
  visualization_msgs::Marker::ConstPtr target = ros::topic::waitForMessage<visualization_msgs::Marker>(
      "description/target_mesh", nh, ros::Duration(60.0));
  ASSERT_TRUE(target);
  EXPECT_EQ(target->header.frame_id, "target");
  EXPECT_EQ(target->points.size(), 3 * buildHubble().triangles.size());
  visualization_msgs::Marker::ConstPtr estimated = ros::topic::waitForMessage<visualization_msgs::Marker>(
      "description/target_estimated_mesh", nh, ros::Duration(60.0));
  ASSERT_TRUE(estimated);
  EXPECT_EQ(estimated->header.frame_id, "target_estimated");
}

TEST(StaticFrames, BadParametersAreNamedWithTheirValue) {
  ros::NodeHandle private_nh("~bad_target");
  private_nh.setParam("target", "mir");
  try {
    loadStaticFramesOptions(private_nh);
    FAIL() << "accepted target 'mir'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bad_target/target = 'mir' is not one of: iss, hubble"),
              std::string::npos)
        << e.what();
  }
  ros::NodeHandle alpha_nh("~bad_alpha");
  alpha_nh.setParam("estimated_mesh_alpha", 1.5);
  try {
    loadStaticFramesOptions(alpha_nh);
    FAIL() << "accepted alpha 1.5";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("estimated_mesh_alpha = 1.5 is outside 0..1"), std::string::npos)
        << e.what();
  }
  ros::NodeHandle defaults_nh("~defaults");
  EXPECT_EQ(loadStaticFramesOptions(defaults_nh).target, TargetKind::kIss);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_static_frames");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
