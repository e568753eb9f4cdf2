#include <gtest/gtest.h>

#include "../nodes/conversions.h"
#include "ardsim_description/frames.h"
#include "ardsim_description/models.h"

using namespace ardsim_description;

TEST(Conversions, TransformRoundTrips) {
  const Eigen::Isometry3d T =
      T_chaser_lidar() * Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  const auto msg = toTransformStamped(T, "chaser", "lidar_optical", ros::Time(12.5));
  EXPECT_EQ(msg.header.frame_id, "chaser");
  EXPECT_EQ(msg.child_frame_id, "lidar_optical");
  EXPECT_EQ(msg.header.stamp, ros::Time(12.5));
  EXPECT_NEAR(msg.transform.translation.x, 2.0, 1e-12);
  EXPECT_TRUE(toIsometry(msg.transform).isApprox(T, 1e-12));
  // The message maps child coordinates to parent coordinates, as T_parent_child does.
  const Eigen::Vector3d boresight_point(0, 0, 10);
  EXPECT_TRUE((toIsometry(msg.transform) * boresight_point).isApprox(T * boresight_point, 1e-12));
}

TEST(Conversions, MarkerDrawsEveryTriangleWithItsColour) {
  const TriangleMesh mesh = buildIss();
  const auto marker = toMarker(mesh, "target", "target", 0.5f);
  EXPECT_EQ(marker.header.frame_id, "target");
  EXPECT_EQ(marker.type, visualization_msgs::Marker::TRIANGLE_LIST);
  ASSERT_EQ(marker.points.size(), 3 * mesh.triangles.size());
  ASSERT_EQ(marker.colors.size(), marker.points.size());
  EXPECT_FLOAT_EQ(marker.points[5].y, mesh.vertices[mesh.triangles[1][2]].y());
  EXPECT_FLOAT_EQ(marker.colors[0].a, 0.5f);
  std::size_t red = 0;
  for (const auto& c : marker.colors) red += (c.r == 1.0f && c.g == 0.0f) ? 1 : 0;
  EXPECT_GT(red, 0u);  // the retro-reflectors
}
