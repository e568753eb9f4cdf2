// Contact between the target and the chaser: the Bullet collision shapes of both vehicles
// (ardsim_description), tested at every integration step, and the verdict on the first contact (CAPTURE or
// COLLISION). ROS-free; Bullet stays behind this header. See README.md "Contact".
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "ardsim_description/frames.h"

namespace ardsim_dynamics {

struct RelativeState;  // simulation.h

// Conditions of the chaser port relative to the target port under which a port-to-port contact is a capture.
// Defaults: IDSS initial contact conditions [shared reference iss_geometry.md, marked there unverified].
struct CaptureEnvelope {
  double min_closing_speed_mps = 0.05;
  double max_closing_speed_mps = 0.10;
  double max_lateral_misalignment_m = 0.10;
  double max_angular_misalignment_rad = 4.0 * M_PI / 180.0;
  double max_lateral_rate_mps = 0.04;
  double max_angular_rate_radps = 0.2 * M_PI / 180.0;  // the reference gives 0.15-0.2 deg/s
};

struct ContactOptions {
  bool enabled = true;  // false: no contact test, the vehicles pass through each other
  CaptureEnvelope envelope;
  // The first contact inside an integration step is located by bisection to within this.
  double time_tolerance_s = 1e-3;
};

// The chaser port relative to the target port (target_port coordinates).
struct ContactConditions {
  double closing_speed_mps = 0.0;         // along the docking axis, towards the target (-v_x)
  double lateral_misalignment_m = 0.0;    // chaser port centre from the docking axis
  double angular_misalignment_rad = 0.0;  // rotation away from the docked attitude (T_port_port_docked)
  double lateral_rate_mps = 0.0;          // speed across the docking axis
  double angular_rate_radps = 0.0;        // magnitude of the relative angular velocity
};

ContactConditions contactConditions(const RelativeState& chaser_port_in_target_port);

// Empty when every condition is inside the envelope; otherwise one clause per condition outside it, joined by
// "; ", e.g. "closing speed 0.300 m/s > 0.100 m/s".
std::string envelopeViolations(const ContactConditions& conditions, const CaptureEnvelope& envelope);

// One test of the two vehicles' shapes at one relative pose.
struct Touch {
  bool touching = false;
  bool ports_only = true;  // every touching pair of shapes is a docking-port shape on both vehicles
  // The pair reported: the deepest pair outside the ports if there is one, else the deepest pair.
  std::string target_part;
  std::string chaser_part;
  Eigen::Vector3d point_in_target_m = Eigen::Vector3d::Zero();  // on the target's surface, target body frame
  double depth_m = 0.0;                                         // penetration of that pair (>= 0)
};

// The collision shapes of the target (of one kind) and of the chaser, in a private Bullet collision world.
class ContactDetector {
 public:
  explicit ContactDetector(ardsim_description::TargetKind target_kind);
  ~ContactDetector();
  ContactDetector(const ContactDetector&) = delete;
  ContactDetector& operator=(const ContactDetector&) = delete;

  // T_target_chaser: the chaser body frame in the target body frame. A bounding-sphere test first, so that a
  // chaser far from the target costs a few multiplications.
  Touch test(const Eigen::Isometry3d& T_target_chaser);

  // Radii of the spheres about the body origins that hold every shape, m.
  double targetRadius() const;
  double chaserRadius() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

enum class ContactVerdict { kCapture, kCollision };
const char* verdictName(ContactVerdict verdict);  // "CAPTURE" or "COLLISION"

struct ContactEvent {
  double time_s = 0.0;  // simulation time of first contact
  ContactVerdict verdict = ContactVerdict::kCollision;
  std::string reason;
  std::string target_part;
  std::string chaser_part;
  Eigen::Vector3d contact_point_m = Eigen::Vector3d::Zero();  // in target_port
  ContactConditions conditions;
  bool within_envelope = false;  // the conditions alone (whatever the parts)
};

// CAPTURE when only docking-port shapes touch and the conditions are inside the envelope; COLLISION
// otherwise, with the reason naming the parts outside the ports and / or the conditions outside the envelope.
ContactEvent judgeContact(double time_s, const Touch& touch, const RelativeState& chaser_port_in_target_port,
                          const Eigen::Isometry3d& T_target_port, const CaptureEnvelope& envelope);

}  // namespace ardsim_dynamics
