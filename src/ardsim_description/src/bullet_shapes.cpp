#include "ardsim_description/bullet_shapes.h"

namespace ardsim_description {

btTransform toBullet(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d& R = T.linear();
  const Eigen::Vector3d& t = T.translation();
  return btTransform(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      btVector3(t.x(), t.y(), t.z()));
}

namespace {

btVector3 toBullet(const Eigen::Vector3d& v) {
  return btVector3(v.x(), v.y(), v.z());
}

}  // namespace

BulletVehicleShape::BulletVehicleShape(std::vector<CollisionShape> shapes, double margin_m)
    : shapes_(std::move(shapes)),
      compound_(std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/true)) {
  for (const CollisionShape& shape : shapes_) {
    std::unique_ptr<btCollisionShape> child;
    switch (shape.kind) {
      case CollisionShape::Kind::kBox:
        child = std::make_unique<btBoxShape>(toBullet(shape.half_extents));
        break;
      case CollisionShape::Kind::kCylinder:
        child = std::make_unique<btCylinderShapeX>(toBullet(shape.half_extents));
        break;
      case CollisionShape::Kind::kConvexHull: {
        auto hull = std::make_unique<btConvexHullShape>();
        for (const auto& p : shape.hull_points) hull->addPoint(toBullet(p), false);
        hull->recalcLocalAabb();
        child = std::move(hull);
        break;
      }
    }
    child->setMargin(static_cast<btScalar>(margin_m));
    compound_->addChildShape(ardsim_description::toBullet(shape.T_body_shape), child.get());
    children_.push_back(std::move(child));
  }
}

}  // namespace ardsim_description
