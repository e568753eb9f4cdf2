#include "model_builder.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ardsim_description {

namespace {

constexpr int kCollisionSegments = 24;  // a ring of boxes or a hull this fine is enough for contact

std::vector<Eigen::Vector2d> circle(int segments) {
  std::vector<Eigen::Vector2d> polygon;
  for (int k = 0; k < segments; ++k) {
    const double angle = 2.0 * M_PI * k / segments;
    polygon.emplace_back(std::cos(angle), std::sin(angle));
  }
  return polygon;
}

}  // namespace

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

Eigen::Isometry3d rotX(double deg) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitX()));
}
Eigen::Isometry3d rotY(double deg) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitY()));
}
Eigen::Isometry3d rotZ(double deg) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
}
Eigen::Isometry3d alongY() {
  return rotZ(90.0);
}
Eigen::Isometry3d alongZ() {
  return rotY(-90.0);
}

std::uint16_t ModelBuilder::material(const std::string& name, float reflectivity, bool retro_reflector) {
  for (std::size_t i = 0; i < mesh_.materials.size(); ++i) {
    if (mesh_.materials[i].name == name) return static_cast<std::uint16_t>(i);
  }
  mesh_.materials.push_back(Material{name, reflectivity, retro_reflector});
  return static_cast<std::uint16_t>(mesh_.materials.size() - 1);
}

std::uint16_t ModelBuilder::part(const std::string& name, bool articulated) {
  for (std::size_t i = 0; i < mesh_.parts.size(); ++i) {
    if (mesh_.parts[i].name == name) return static_cast<std::uint16_t>(i);
  }
  mesh_.parts.push_back(Part{name, articulated});
  return static_cast<std::uint16_t>(mesh_.parts.size() - 1);
}

int ModelBuilder::addVertex(const Eigen::Isometry3d& T, const Eigen::Vector3d& p_local) {
  mesh_.vertices.push_back((T * p_local).cast<float>());
  return static_cast<int>(mesh_.vertices.size() - 1);
}

void ModelBuilder::addTriangle(int a, int b, int c, Surface surface) {
  mesh_.triangles.emplace_back(a, b, c);
  mesh_.triangle_material.push_back(surface.material);
  mesh_.triangle_part.push_back(surface.part);
}

void ModelBuilder::loft(const Eigen::Isometry3d& T, const std::vector<Eigen::Vector2d>& polygon,
                        double x_start, double x_end, double scale_start, double scale_end, Surface surface) {
  if (!(x_end > x_start) || polygon.size() < 3) throw std::logic_error("loft: empty extent or polygon");
  const int n = static_cast<int>(polygon.size());
  const int first = static_cast<int>(mesh_.vertices.size());
  for (const auto& p : polygon)
    addVertex(T, Eigen::Vector3d(x_start, scale_start * p.x(), scale_start * p.y()));
  for (const auto& p : polygon) addVertex(T, Eigen::Vector3d(x_end, scale_end * p.x(), scale_end * p.y()));
  auto bottom = [&](int i) { return first + (i % n); };
  auto top = [&](int i) { return first + n + (i % n); };
  // With the polygon counter-clockwise seen from +x and x_end > x_start, (b_i, b_i+1, t_i+1) faces outwards.
  for (int i = 0; i < n; ++i) {
    addTriangle(bottom(i), bottom(i + 1), top(i + 1), surface);
    addTriangle(bottom(i), top(i + 1), top(i), surface);
  }
  for (int i = 1; i + 1 < n; ++i) {
    addTriangle(top(0), top(i), top(i + 1), surface);           // faces +x
    addTriangle(bottom(0), bottom(i + 1), bottom(i), surface);  // faces -x
  }
}

void ModelBuilder::addHull(const Eigen::Isometry3d& T, std::vector<Eigen::Vector3d> points, Surface surface,
                           Collide collide) {
  CollisionShape shape;
  shape.kind = CollisionShape::Kind::kConvexHull;
  shape.T_body_shape = T;
  shape.hull_points = std::move(points);
  shape.part = surface.part;
  shape.docking_port = collide == Collide::kDockingPort;
  collision_.push_back(std::move(shape));
}

void ModelBuilder::box(const Eigen::Isometry3d& T_body_local, const Eigen::Vector3d& size, Surface surface,
                       Collide collide) {
  const double hy = size.y() / 2, hz = size.z() / 2;
  loft(T_body_local, {{-hy, -hz}, {hy, -hz}, {hy, hz}, {-hy, hz}}, -size.x() / 2, size.x() / 2, 1.0, 1.0,
       surface);
  if (collide == Collide::kNo) return;
  CollisionShape shape;
  shape.kind = CollisionShape::Kind::kBox;
  shape.T_body_shape = T_body_local;
  shape.half_extents = size / 2;
  shape.part = surface.part;
  shape.docking_port = collide == Collide::kDockingPort;
  collision_.push_back(shape);
}

void ModelBuilder::frustum(const Eigen::Isometry3d& T_body_local, double radius_start, double radius_end,
                           double x_start, double x_end, int segments, Surface surface, Collide collide) {
  loft(T_body_local, circle(segments), x_start, x_end, radius_start, radius_end, surface);
  if (collide == Collide::kNo) return;
  if (radius_start == radius_end) {
    CollisionShape shape;
    shape.kind = CollisionShape::Kind::kCylinder;
    shape.T_body_shape = T_body_local * at((x_start + x_end) / 2, 0, 0);
    shape.half_extents = Eigen::Vector3d((x_end - x_start) / 2, radius_start, radius_start);
    shape.part = surface.part;
    shape.docking_port = collide == Collide::kDockingPort;
    collision_.push_back(shape);
    return;
  }
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : circle(kCollisionSegments)) {
    points.emplace_back(x_start, radius_start * p.x(), radius_start * p.y());
    points.emplace_back(x_end, radius_end * p.x(), radius_end * p.y());
  }
  addHull(T_body_local, std::move(points), surface, collide);
}

void ModelBuilder::tube(const Eigen::Isometry3d& T_body_local, double inner_radius, double outer_radius,
                        double x_start, double x_end, int segments, Surface surface, Collide collide) {
  if (!(x_end > x_start) || !(outer_radius > inner_radius) || segments < 3) {
    throw std::logic_error("tube: empty extent or wall");
  }
  const int n = segments;
  const int first = static_cast<int>(mesh_.vertices.size());
  const auto unit = circle(n);
  for (double x : {x_start, x_end}) {
    for (double r : {outer_radius, inner_radius}) {
      for (const auto& p : unit) addVertex(T_body_local, Eigen::Vector3d(x, r * p.x(), r * p.y()));
    }
  }
  auto o0 = [&](int k) { return first + (k % n); };
  auto i0 = [&](int k) { return first + n + (k % n); };
  auto o1 = [&](int k) { return first + 2 * n + (k % n); };
  auto i1 = [&](int k) { return first + 3 * n + (k % n); };
  for (int k = 0; k < n; ++k) {
    addTriangle(o0(k), o0(k + 1), o1(k + 1), surface);  // outer wall, faces away from the axis
    addTriangle(o0(k), o1(k + 1), o1(k), surface);
    addTriangle(i0(k), i1(k + 1), i0(k + 1), surface);  // inner wall, faces the axis
    addTriangle(i0(k), i1(k), i1(k + 1), surface);
    addTriangle(o1(k), o1(k + 1), i1(k + 1), surface);  // end face at x_end, faces +x
    addTriangle(o1(k), i1(k + 1), i1(k), surface);
    addTriangle(o0(k), i0(k), i0(k + 1), surface);  // end face at x_start, faces -x
    addTriangle(o0(k), i0(k + 1), o0(k + 1), surface);
  }
  if (collide == Collide::kNo) return;
  // A ring of boxes keeps the passage open, which a convex shape could not.
  for (int k = 0; k < kCollisionSegments; ++k) {
    const double angle_deg = 360.0 * k / kCollisionSegments;
    CollisionShape shape;
    shape.kind = CollisionShape::Kind::kBox;
    shape.T_body_shape =
        T_body_local * rotX(angle_deg) * at((x_start + x_end) / 2, (inner_radius + outer_radius) / 2, 0);
    shape.half_extents = Eigen::Vector3d((x_end - x_start) / 2, (outer_radius - inner_radius) / 2,
                                         outer_radius * std::tan(M_PI / kCollisionSegments));
    shape.part = surface.part;
    shape.docking_port = collide == Collide::kDockingPort;
    collision_.push_back(shape);
  }
}

void ModelBuilder::prism(const Eigen::Isometry3d& T_body_local, const std::vector<Eigen::Vector2d>& polygon,
                         double x_start, double x_end, Surface surface, Collide collide) {
  loft(T_body_local, polygon, x_start, x_end, 1.0, 1.0, surface);
  if (collide == Collide::kNo) return;
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : polygon) {
    points.emplace_back(x_start, p.x(), p.y());
    points.emplace_back(x_end, p.x(), p.y());
  }
  addHull(T_body_local, std::move(points), surface, collide);
}

VehicleModel ModelBuilder::finish(const MassProperties& mass) {
  VehicleModel model;
  model.mesh = std::move(mesh_);
  model.collision = std::move(collision_);
  model.mass = mass;
  mesh_ = TriangleMesh();
  collision_.clear();
  return model;
}

void addIdssInterface(ModelBuilder& builder, const Eigen::Isometry3d& T_body_port,
                      const IdssInterface& config) {
  using namespace idss;
  const Surface mechanism{builder.material("docking_mechanism", 0.5f),
                          builder.part("soft_capture_ring", false)};
  const Surface petals{mechanism.material, builder.part("guide_petals", false)};
  const Surface adapter{mechanism.material, builder.part("docking_adapter", false)};
  const int n = config.segments;

  // Ring, front face on the docking plane.
  builder.tube(T_body_port, kRingInnerRadius, kRingOuterRadius, -kRingDepth, 0.0, n, mechanism,
               Collide::kDockingPort);
  // Tunnel behind it, the clear passage continuing to the hatch (or the vehicle's bulkhead).
  const double tunnel_depth = std::max(config.hatch_depth_m + 0.2, 0.3);
  builder.tube(T_body_port, kRingInnerRadius, config.tunnel_outer_radius_m, -tunnel_depth, -kRingDepth, n,
               adapter, Collide::kYes);
  if (config.hatch_depth_m > 0.0) {
    const Surface hatch{builder.material("hatch", 0.6f), builder.part("docking_hatch", false)};
    builder.frustum(T_body_port, kRingInnerRadius - 0.005, kRingInnerRadius - 0.005,
                    -config.hatch_depth_m - 0.03, -config.hatch_depth_m, n / 2, hatch, Collide::kYes);
  }

  // Three guide petals at 120 deg [src: IDSS], first on the port's +y. Flat plates rooted inside the ring and
  // leaning inwards; where they cross the docking plane their corners stay inside the passage (0.38 m from
  // the axis, 0.16 m half-width: 0.41 m < 0.42 m), so two mated interfaces (frames.h T_port_port_docked) put
  // each side's petals into the other's passage, 60 deg apart. Base 0.32 m, tip 0.10 m, 0.30 m tall, 20 mm
  // thick [estimates].
  const double lean = std::atan2(0.11, kPetalHeight);  // tip 0.11 m closer to the axis than the base
  const double length = std::hypot(0.11, kPetalHeight);
  for (int i = 0; i < 3; ++i) {
    // Petal frame: x = plate normal (outwards), y = tangential, z = up the petal; origin at its foot on the
    // plane.
    Eigen::Isometry3d T_foot_petal = Eigen::Isometry3d::Identity();
    T_foot_petal.linear().col(0) = Eigen::Vector3d::UnitY();  // outwards for the petal on the port's +y
    T_foot_petal.linear().col(1) = Eigen::Vector3d::UnitZ();
    T_foot_petal.linear().col(2) = Eigen::Vector3d::UnitX();
    const Eigen::Isometry3d T_port_petal =
        rotX(120.0 * i) * at(0, kRingInnerRadius - 0.04, 0) * T_foot_petal * rotY(-lean * 180.0 / M_PI);
    builder.prism(T_body_port * T_port_petal,
                  {{-0.16, -0.08}, {0.16, -0.08}, {0.05, length}, {-0.05, length}}, -0.02, 0.0, petals,
                  Collide::kDockingPort);
  }

  if (config.reflectors) {
    // Three peripheral reflector targets between the petals, on brackets; their outer edge on the 2.4 m
    // diameter.
    const Surface bracket{mechanism.material, builder.part("docking_reflectors", false)};
    const Surface reflector{builder.material("retro_reflector", 1.0f, true), bracket.part};
    const double reflector_radius_m = 0.075;  // [estimate]
    for (int i = 0; i < 3; ++i) {
      const Eigen::Isometry3d T_port_arm = rotX(60.0 + 120.0 * i);
      const double arm_start = config.tunnel_outer_radius_m - 0.05;
      const double arm_length = kReflectorRadius - arm_start + reflector_radius_m;
      builder.box(T_body_port * T_port_arm * at(-0.33, arm_start + arm_length / 2, 0),
                  Eigen::Vector3d(0.06, arm_length, 0.08), bracket, Collide::kNo);
      builder.frustum(T_body_port * T_port_arm * at(0, kReflectorRadius, 0), reflector_radius_m,
                      reflector_radius_m, -0.30, -0.27, 16, reflector, Collide::kNo);
    }
  }

  if (config.centreline_docking_target && config.hatch_depth_m > 0.0) {
    // Standoff cross on the hatch, seen through the passage like iron sights [src: IDSS IDD 3.5 by summary];
    // its dimensions are not in the sources: black back plate 0.4 m, white cross 0.3 m on a 0.3 m post
    // [estimates].
    const Surface plate{builder.material("target_black", 0.05f),
                        builder.part("centreline_docking_target", false)};
    const Surface white{builder.material("target_white", 0.85f), plate.part};
    const double x_hatch = -config.hatch_depth_m;
    builder.frustum(T_body_port, 0.2, 0.2, x_hatch, x_hatch + 0.01, 48, plate, Collide::kNo);
    builder.box(T_body_port * at(x_hatch + 0.16, 0, 0), Eigen::Vector3d(0.30, 0.04, 0.04), white,
                Collide::kNo);
    builder.box(T_body_port * at(x_hatch + 0.32, 0, 0), Eigen::Vector3d(0.02, 0.30, 0.04), white,
                Collide::kNo);
    builder.box(T_body_port * at(x_hatch + 0.32, 0, 0), Eigen::Vector3d(0.02, 0.04, 0.30), white,
                Collide::kNo);
  }
}

}  // namespace ardsim_description
