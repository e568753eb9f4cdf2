// Collision shapes of a vehicle for the contact model (Bullet), built from the same primitives as the visual
// mesh. ROS- and Bullet-free: each kind maps one to one onto a Bullet shape (bullet_shapes.h does the
// mapping).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace ardsim_description {

struct CollisionShape {
  enum class Kind {
    kBox,        // btBoxShape(half_extents)
    kCylinder,   // btCylinderShapeX(half_extents): axis along the shape's x, centred on its origin
    kConvexHull  // btConvexHullShape(hull_points)
  };
  Kind kind = Kind::kBox;
  Eigen::Isometry3d T_body_shape = Eigen::Isometry3d::Identity();  // shape frame in the vehicle body frame
  Eigen::Vector3d half_extents =
      Eigen::Vector3d::Zero();               // box: half sizes; cylinder: (half length, r, r), m
  std::vector<Eigen::Vector3d> hull_points;  // convex hull: points in the shape frame, m
  std::uint16_t part = 0;                    // index into the vehicle mesh's parts
  bool docking_port =
      false;  // soft-capture ring or guide petal: a contact here is judged against the envelope
};

}  // namespace ardsim_description
