#include <gtest/gtest.h>

#include <stdexcept>

#include "ardsim_description/frames.h"

using namespace ardsim_description;

TEST(Frames, LidarLooksOutOfThePort) {
  const Eigen::Vector3d boresight_in_chaser = T_chaser_lidar().linear() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d port_axis_in_chaser = T_chaser_port().linear() * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(boresight_in_chaser.dot(port_axis_in_chaser), 1.0, 1e-12);
  EXPECT_NEAR(T_chaser_lidar().linear().determinant(), 1.0, 1e-12);
}

TEST(Frames, IssPortFacesVelocityDirection) {
  const Eigen::Isometry3d T = T_target_port(TargetKind::kIss);
  EXPECT_NEAR((T.linear() * Eigen::Vector3d::UnitX()).x(), 1.0, 1e-12);
  EXPECT_GT(T.translation().x(), 10.0);
}

TEST(Frames, DockedPortsFaceEachOtherAndShareZ) {
  const Eigen::Matrix3d R = T_port_port_docked().linear();
  EXPECT_NEAR((R * Eigen::Vector3d::UnitX()).x(), -1.0, 1e-12);
  EXPECT_NEAR((R * Eigen::Vector3d::UnitZ()).z(), 1.0, 1e-12);
  EXPECT_NEAR(T_port_port_docked().translation().norm(), 0.0, 1e-12);
}

TEST(Frames, ParseTargetKindRejectsUnknownNames) {
  EXPECT_EQ(parseTargetKind("hubble"), TargetKind::kHubble);
  EXPECT_EQ(targetKindName(parseTargetKind("iss")), "iss");
  EXPECT_THROW(parseTargetKind("mir"), std::invalid_argument);
}
