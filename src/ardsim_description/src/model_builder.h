// Private: builds a vehicle's mesh and collision shapes from the same primitive calls, so that what the LIDAR
// sees and what the contact model touches cannot drift apart.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ardsim_description/models.h"

namespace ardsim_description {

// Whether a primitive becomes collision shapes too; small detail (reflectors, the docking target) does not.
enum class Collide { kNo, kYes, kDockingPort };

struct Surface {
  std::uint16_t material = 0;
  std::uint16_t part = 0;
};

class ModelBuilder {
 public:
  std::uint16_t material(const std::string& name, float reflectivity, bool retro_reflector = false);
  std::uint16_t part(const std::string& name, bool articulated);

  // Box of `size` centred on the origin of its local frame.
  void box(const Eigen::Isometry3d& T_body_local, const Eigen::Vector3d& size, Surface surface,
           Collide collide);

  // Closed frustum (a cylinder when radius_start == radius_end) about the local x axis from x_start to x_end,
  // approximated by `segments` flat sides.
  void frustum(const Eigen::Isometry3d& T_body_local, double radius_start, double radius_end, double x_start,
               double x_end, int segments, Surface surface, Collide collide);

  // Closed hollow cylinder about the local x axis: inner and outer walls and two annular faces.
  void tube(const Eigen::Isometry3d& T_body_local, double inner_radius, double outer_radius, double x_start,
            double x_end, int segments, Surface surface, Collide collide);

  // Convex polygon (counter-clockwise in the local y-z plane) extruded along local x from x_start to x_end.
  void prism(const Eigen::Isometry3d& T_body_local, const std::vector<Eigen::Vector2d>& polygon,
             double x_start, double x_end, Surface surface, Collide collide);

  VehicleModel finish(const MassProperties& mass);

 private:
  // Polygon scaled by scale_start at x_start and scale_end at x_end, sides and both caps.
  void loft(const Eigen::Isometry3d& T, const std::vector<Eigen::Vector2d>& polygon, double x_start,
            double x_end, double scale_start, double scale_end, Surface surface);
  int addVertex(const Eigen::Isometry3d& T, const Eigen::Vector3d& p_local);
  void addTriangle(int a, int b, int c, Surface surface);
  void addHull(const Eigen::Isometry3d& T, std::vector<Eigen::Vector3d> points, Surface surface,
               Collide collide);

  TriangleMesh mesh_;
  std::vector<CollisionShape> collision_;
};

// Poses for primitives: translation, then rotations about body axes (degrees as the sources give them).
Eigen::Isometry3d at(double x, double y, double z);
Eigen::Isometry3d rotX(double deg);
Eigen::Isometry3d rotY(double deg);
Eigen::Isometry3d rotZ(double deg);

// Local x of a primitive along body y, or along body z.
Eigen::Isometry3d alongY();
Eigen::Isometry3d alongZ();

// The IDSS (NASA Docking System) soft-capture interface shared by the targets and the chaser, built in the
// port frame (x out of the port, origin at the centre of the docking plane) and placed by T_body_port.
struct IdssInterface {
  double tunnel_outer_radius_m = 0.8;  // structure around the passage behind the ring
  double hatch_depth_m = 0.9;  // hatch behind the docking plane; 0 = no hatch (a bulkhead closes the tunnel)
  bool reflectors = true;      // three peripheral retro-reflector targets
  bool centreline_docking_target = false;
  int segments = 128;  // the sensor looks closely here: finer than the rest of the vehicle
};
void addIdssInterface(ModelBuilder& builder, const Eigen::Isometry3d& T_body_port,
                      const IdssInterface& config);

// Dimensions of the IDSS ring shared by the builders and the tests.
namespace idss {
constexpr double kRingOuterRadius = 0.60;  // outer ring diameter ~1200 mm [src: IDD summary, secondary]
constexpr double kRingInnerRadius = 0.42;  // clear passage 800 mm [src: IDD summary, secondary] plus 20 mm
constexpr double kRingDepth = 0.12;        // axial thickness of the ring [estimate]
constexpr double kPetalHeight = 0.28;  // how far the guide petals stand out of the docking plane [estimate]
constexpr double kReflectorRadius = 1.125;  // 2.4 m outer diameter including the reflector targets [src: IDA]
}  // namespace idss

}  // namespace ardsim_description
