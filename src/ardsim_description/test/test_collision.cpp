#include <gtest/gtest.h>

#include <memory>

#include "ardsim_description/bullet_shapes.h"
#include "ardsim_description/mesh_tools.h"
#include "ardsim_description/models.h"

using namespace ardsim_description;

namespace {

// Corners (or hull points) of a shape in the body frame, to compare with the mesh.
std::vector<Eigen::Vector3d> extremePoints(const CollisionShape& shape) {
  std::vector<Eigen::Vector3d> local;
  if (shape.kind == CollisionShape::Kind::kConvexHull) {
    local = shape.hull_points;
  } else {
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d sign((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
      local.push_back(sign.cwiseProduct(shape.half_extents));
    }
  }
  for (auto& p : local) p = shape.T_body_shape * p;
  return local;
}

struct Contact {
  bool target_port;
  bool chaser_port;
  std::uint16_t target_part;
  std::uint16_t chaser_part;
};

// Contacts between the two vehicles with the chaser at T_target_chaser.
std::vector<Contact> contacts(const VehicleModel& target, const VehicleModel& chaser,
                              const Eigen::Isometry3d& T_target_chaser) {
  BulletVehicleShape target_shape(target.collision), chaser_shape(chaser.collision);
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &configuration);
  btCollisionObject target_object, chaser_object;
  target_object.setCollisionShape(target_shape.compound());
  chaser_object.setCollisionShape(chaser_shape.compound());
  chaser_object.setWorldTransform(toBullet(T_target_chaser));
  world.addCollisionObject(&target_object);
  world.addCollisionObject(&chaser_object);

  struct Callback : btCollisionWorld::ContactResultCallback {
    const btCollisionObject* target_object;
    const std::vector<CollisionShape>* target_shapes;
    const std::vector<CollisionShape>* chaser_shapes;
    std::vector<Contact> found;
    btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper* a, int, int index_a,
                             const btCollisionObjectWrapper*, int, int index_b) override {
      if (point.getDistance() > 0) return 0;
      const bool a_is_target = a->getCollisionObject() == target_object;
      const int target_index = a_is_target ? index_a : index_b,
                chaser_index = a_is_target ? index_b : index_a;
      const CollisionShape &target = target_shapes->at(target_index),
                           &chaser = chaser_shapes->at(chaser_index);
      found.push_back({target.docking_port, chaser.docking_port, target.part, chaser.part});
      return 0;
    }
  } callback;
  callback.target_object = &target_object;
  callback.target_shapes = &target_shape.shapes();
  callback.chaser_shapes = &chaser_shape.shapes();
  world.contactPairTest(&target_object, &chaser_object, callback);
  return callback.found;
}

// The chaser docked at the target's port, then moved along the target port's x by `gap_m` and sideways by
// `lateral_m`.
Eigen::Isometry3d chaserPose(TargetKind kind, double gap_m, double lateral_m) {
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() = Eigen::Vector3d(gap_m, lateral_m, 0);
  return T_target_port(kind) * offset * T_port_port_docked() * T_chaser_port().inverse();
}

}  // namespace

TEST(Collision, ShapesAreWellFormedAndInsideTheMesh) {
  for (const VehicleModel& model : {buildIssModel(), buildHubbleModel(), buildChaserModel()}) {
    ASSERT_FALSE(model.collision.empty());
    Eigen::AlignedBox3d mesh_box = bounds(model.mesh).cast<double>();
    mesh_box.extend(mesh_box.min() - Eigen::Vector3d::Constant(0.01));
    mesh_box.extend(mesh_box.max() + Eigen::Vector3d::Constant(0.01));
    int port_shapes = 0;
    for (const CollisionShape& shape : model.collision) {
      ASSERT_LT(shape.part, model.mesh.parts.size());
      if (shape.kind == CollisionShape::Kind::kConvexHull) {
        ASSERT_GE(shape.hull_points.size(), 4u);
      } else {
        ASSERT_TRUE((shape.half_extents.array() > 0.0).all());
      }
      for (const auto& p : extremePoints(shape)) ASSERT_TRUE(mesh_box.contains(p)) << p.transpose();
      port_shapes += shape.docking_port ? 1 : 0;
    }
    EXPECT_GT(port_shapes, 3);  // the ring's boxes and the three petals
  }
}

TEST(Collision, DockedVehiclesTouchOnlyAtTheirPorts) {
  const VehicleModel chaser = buildChaserModel();
  for (TargetKind kind : {TargetKind::kIss, TargetKind::kHubble}) {
    SCOPED_TRACE(targetKindName(kind));
    const VehicleModel target = buildTargetModel(kind);
    for (const Contact& c : contacts(target, chaser, chaserPose(kind, 0.01, 0.0))) {
      ADD_FAILURE() << "contact 1 cm before docking: target " << target.mesh.parts[c.target_part].name
                    << ", chaser " << chaser.mesh.parts[c.chaser_part].name;
    }
    const auto docked = contacts(target, chaser, chaserPose(kind, -0.01, 0.0));
    ASSERT_FALSE(docked.empty()) << "no contact with the rings pressed 1 cm together";
    for (const Contact& c : docked) {
      EXPECT_TRUE(c.target_port && c.chaser_port)
          << "docked contact outside the ports: target " << target.mesh.parts[c.target_part].name
          << ", chaser " << chaser.mesh.parts[c.chaser_part].name;
    }
  }
}

TEST(Collision, AnOffsetApproachHitsStructureOutsideThePort) {
  // 1 m to the side of the port axis and 0.2 m past the docking plane, the chaser's port meets the ISS's
  // structure around the docking adapter: a collision, not a docking.
  const auto hits = contacts(buildIssModel(), buildChaserModel(), chaserPose(TargetKind::kIss, -0.2, 1.0));
  ASSERT_FALSE(hits.empty());
  bool outside_port = false;
  for (const Contact& c : hits) outside_port |= !(c.target_port && c.chaser_port);
  EXPECT_TRUE(outside_port);
}
