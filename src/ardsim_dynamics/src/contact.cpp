#include "ardsim_dynamics/contact.h"

#include <cstdio>
#include <vector>

#include <btBulletCollisionCommon.h>

#include "ardsim_description/bullet_shapes.h"
#include "ardsim_description/models.h"
#include "ardsim_dynamics/simulation.h"

namespace ardsim_dynamics {
namespace {

constexpr double kDeg = M_PI / 180.0;

std::string format(const char* fmt, double a, double b) {
  char text[128];
  std::snprintf(text, sizeof(text), fmt, a, b);
  return text;
}

struct Vehicle {
  explicit Vehicle(const ardsim_description::VehicleModel& model) : shape(model.collision) {
    for (const auto& part : model.mesh.parts) part_names.push_back(part.name);
    btVector3 centre;
    btScalar radius = 0;
    shape.compound()->getBoundingSphere(centre, radius);
    sphere_centre = Eigen::Vector3d(centre.x(), centre.y(), centre.z());
    sphere_radius = radius;
    object.setCollisionShape(shape.compound());
  }
  const std::string& partName(int child) const { return part_names.at(shape.shapes().at(child).part); }
  bool isPort(int child) const { return shape.shapes().at(child).docking_port; }

  ardsim_description::BulletVehicleShape shape;
  std::vector<std::string> part_names;
  Eigen::Vector3d sphere_centre;
  double sphere_radius = 0.0;
  btCollisionObject object;
};

// Collects the touching pairs of one contactPairTest.
struct TouchCallback : btCollisionWorld::ContactResultCallback {
  TouchCallback(const Vehicle& target, const Vehicle& chaser) : target_(target), chaser_(chaser) {}

  btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper* a, int, int index_a,
                           const btCollisionObjectWrapper*, int, int index_b) override {
    // Bullet also reports pairs closer than its contact threshold: only penetration is contact.
    if (point.getDistance() > 0) return 0;
    const bool a_is_target = a->getCollisionObject() == &target_.object;
    const int target_child = a_is_target ? index_a : index_b;
    const int chaser_child = a_is_target ? index_b : index_a;
    const bool ports = target_.isPort(target_child) && chaser_.isPort(chaser_child);
    const double depth = -point.getDistance();
    // Report a pair outside the ports before any port pair: it decides the verdict.
    const bool better = !touch.touching || (!ports && touch.ports_only) ||
                        (ports == touch.ports_only && depth > touch.depth_m);
    touch.touching = true;
    if (better) {
      const btVector3 p = a_is_target ? point.getPositionWorldOnA() : point.getPositionWorldOnB();
      touch.target_part = target_.partName(target_child);
      touch.chaser_part = chaser_.partName(chaser_child);
      touch.point_in_target_m = Eigen::Vector3d(p.x(), p.y(), p.z());
      touch.depth_m = depth;
    }
    touch.ports_only = touch.ports_only && ports;
    return 0;
  }

  const Vehicle& target_;
  const Vehicle& chaser_;
  Touch touch;
};

}  // namespace

struct ContactDetector::Impl {
  explicit Impl(ardsim_description::TargetKind kind)
      : target(ardsim_description::buildTargetModel(kind)),
        chaser(ardsim_description::buildChaserModel()),
        dispatcher(&configuration),
        world(&dispatcher, &broadphase, &configuration) {
    // The target stays at the origin of the world: poses are relative, so Bullet's single precision works
    // with metres, not with the 7e6 m of eci.
    world.addCollisionObject(&target.object);
    world.addCollisionObject(&chaser.object);
  }

  Vehicle target;
  Vehicle chaser;
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher;
  btDbvtBroadphase broadphase;
  btCollisionWorld world;
};

ContactDetector::ContactDetector(ardsim_description::TargetKind target_kind)
    : impl_(std::make_unique<Impl>(target_kind)) {}

ContactDetector::~ContactDetector() = default;

double ContactDetector::targetRadius() const {
  return impl_->target.sphere_radius;
}

double ContactDetector::chaserRadius() const {
  return impl_->chaser.sphere_radius;
}

Touch ContactDetector::test(const Eigen::Isometry3d& T_target_chaser) {
  Impl& d = *impl_;
  const double separation_m = (T_target_chaser * d.chaser.sphere_centre - d.target.sphere_centre).norm();
  if (separation_m > d.target.sphere_radius + d.chaser.sphere_radius) return Touch{};
  d.chaser.object.setWorldTransform(ardsim_description::toBullet(T_target_chaser));
  TouchCallback callback(d.target, d.chaser);
  d.world.contactPairTest(&d.target.object, &d.chaser.object, callback);
  return callback.touch;
}

ContactConditions contactConditions(const RelativeState& s) {
  ContactConditions c;
  const Eigen::Vector3d& p = s.pose.translation();
  const Eigen::Vector3d& v = s.velocity_mps;
  c.closing_speed_mps = -v.x();
  c.lateral_misalignment_m = std::hypot(p.y(), p.z());
  c.lateral_rate_mps = std::hypot(v.y(), v.z());
  const Eigen::Matrix3d R_docked_actual =
      ardsim_description::T_port_port_docked().linear().transpose() * s.pose.linear();
  c.angular_misalignment_rad = Eigen::AngleAxisd(R_docked_actual).angle();
  c.angular_rate_radps = s.angular_velocity_radps.norm();
  return c;
}

std::string envelopeViolations(const ContactConditions& c, const CaptureEnvelope& e) {
  std::string out;
  const auto add = [&out](const std::string& clause) { out += (out.empty() ? "" : "; ") + clause; };
  if (c.closing_speed_mps > e.max_closing_speed_mps)
    add(format("closing speed %.3f m/s > %.3f m/s", c.closing_speed_mps, e.max_closing_speed_mps));
  if (c.closing_speed_mps < e.min_closing_speed_mps)
    add(format("closing speed %.3f m/s < %.3f m/s", c.closing_speed_mps, e.min_closing_speed_mps));
  if (c.lateral_misalignment_m > e.max_lateral_misalignment_m)
    add(format("lateral misalignment %.3f m > %.3f m", c.lateral_misalignment_m,
               e.max_lateral_misalignment_m));
  if (c.angular_misalignment_rad > e.max_angular_misalignment_rad)
    add(format("angular misalignment %.2f deg > %.2f deg", c.angular_misalignment_rad / kDeg,
               e.max_angular_misalignment_rad / kDeg));
  if (c.lateral_rate_mps > e.max_lateral_rate_mps)
    add(format("lateral rate %.4f m/s > %.4f m/s", c.lateral_rate_mps, e.max_lateral_rate_mps));
  if (c.angular_rate_radps > e.max_angular_rate_radps)
    add(format("angular rate %.3f deg/s > %.3f deg/s", c.angular_rate_radps / kDeg,
               e.max_angular_rate_radps / kDeg));
  return out;
}

const char* verdictName(ContactVerdict verdict) {
  return verdict == ContactVerdict::kCapture ? "CAPTURE" : "COLLISION";
}

ContactEvent judgeContact(double time_s, const Touch& touch, const RelativeState& port_state,
                          const Eigen::Isometry3d& T_target_port, const CaptureEnvelope& envelope) {
  ContactEvent event;
  event.time_s = time_s;
  event.target_part = touch.target_part;
  event.chaser_part = touch.chaser_part;
  event.contact_point_m = T_target_port.inverse() * touch.point_in_target_m;
  event.conditions = contactConditions(port_state);
  const std::string violations = envelopeViolations(event.conditions, envelope);
  event.within_envelope = violations.empty();
  if (touch.ports_only && event.within_envelope) {
    event.verdict = ContactVerdict::kCapture;
    event.reason = "the ports met inside the capture envelope";
    return event;
  }
  event.verdict = ContactVerdict::kCollision;
  if (!touch.ports_only) {
    event.reason = "chaser '" + touch.chaser_part + "' touched target '" + touch.target_part +
                   "' outside the docking ports";
    if (!violations.empty()) event.reason += "; " + violations;
  } else {
    event.reason = "the ports met outside the capture envelope: " + violations;
  }
  return event;
}

}  // namespace ardsim_dynamics
