// Bullet shapes of a vehicle from its collision model (collision.h), for the contact model in
// ardsim_dynamics.
#pragma once

#include <memory>
#include <vector>

#include <btBulletCollisionCommon.h>

#include "ardsim_description/collision.h"

namespace ardsim_description {

// A btCompoundShape in the vehicle's body frame, owning its children; child i comes from shapes()[i].
class BulletVehicleShape {
 public:
  // margin_m: Bullet's collision margin on every child. Convex hulls grow by it, so keep it small next to the
  // capture envelope's 0.10 m; boxes and cylinders keep their size.
  explicit BulletVehicleShape(std::vector<CollisionShape> shapes, double margin_m = 0.002);
  BulletVehicleShape(const BulletVehicleShape&) = delete;
  BulletVehicleShape& operator=(const BulletVehicleShape&) = delete;

  btCompoundShape* compound() { return compound_.get(); }
  const std::vector<CollisionShape>& shapes() const { return shapes_; }

 private:
  std::vector<CollisionShape> shapes_;
  std::vector<std::unique_ptr<btCollisionShape>> children_;
  std::unique_ptr<btCompoundShape> compound_;
};

btTransform toBullet(const Eigen::Isometry3d& T);

}  // namespace ardsim_description
