// A scenario: the target's orbit, both vehicles' properties and initial states, the environment, steps and
// seeds. Loaded from a commented YAML file (see scenarios/); every value is validated with the key, value and
// allowed range in the error. ROS-free.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>

#include <cmath>

#include <Eigen/Core>

#include "ardsim_description/frames.h"
#include "ardsim_dynamics/actuator.h"
#include "ardsim_dynamics/contact.h"
#include "ardsim_dynamics/orbit.h"
#include "ardsim_dynamics/vehicle_dynamics.h"

namespace ardsim_dynamics {

class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class RelativeFrame {
  kTargetLvlh,  // chaser centre of mass in the target's LVLH
  kTargetPort,  // chaser port in the target port frame (x out of the port), velocity relative to the target
                // body
};

struct ChaserInitialState {
  RelativeFrame frame = RelativeFrame::kTargetPort;
  Eigen::Vector3d position_m = Eigen::Vector3d(100.0, 0.0, 0.0);
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  // Roll, pitch, yaw (about x, y, z of the chaser body, applied in that order) added to the docking attitude:
  // the chaser port axis anti-parallel to the target port axis.
  Eigen::Vector3d attitude_offset_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rate_offset_radps =
      Eigen::Vector3d::Zero();  // added to co-rotation with the target
};

struct Scenario {
  std::string name;
  std::string source_path;
  ardsim_description::TargetKind target_kind = ardsim_description::TargetKind::kIss;
  // 415 km, 51.64 deg [shared reference iss_environment_and_mass.md].
  KeplerianElements target_orbit{6793137.0, 0.0005, 51.64 * M_PI / 180.0, 0.0, 0.0, 0.0};
  // Target attitude: body axes on the LVLH axes (ISS +XVV torque-equilibrium-like) turned by this
  // roll/pitch/yaw, and rotating with the LVLH frame.
  Eigen::Vector3d target_attitude_offset_rad = Eigen::Vector3d::Zero();
  // ISS: mass [NASA Facts and Figures 2014], inertia [NASA JEOD set_mass_iss()], drag [JSC TOPO header
  // 2023-02-15].
  VehicleProperties target{
      419455.0,
      (Eigen::Matrix3d() << 1.02e8, -6.96e6, -5.48e6, -6.96e6, 0.91e8, 5.90e5, -5.48e6, 5.90e5, 1.64e8)
          .finished(),
      1504.78, 3.25};
  // Crew-Dragon-sized: mass [Demo-2 at undock], solid-cylinder inertia and end-on drag area [derived
  // estimates].
  VehicleProperties chaser{12519.0, Eigen::Vector3d(2.5e4, 8.1e4, 8.1e4).asDiagonal(), 12.57, 2.2};
  ChaserInitialState chaser_initial;
  ActuatorOptions chaser_actuator;
  EnvironmentOptions environment;
  ContactOptions contact;           // contact detection and the capture envelope
  std::string gravity_model_file;   // empty: the shipped EGM96 table
  double control_step_s = 0.1;      // one LIDAR frame, one guidance command
  double integration_step_s = 0.1;  // RK4 step; the control step must be a whole multiple of it
  double duration_s = 600.0;
  std::map<std::string, std::uint64_t> seeds;  // named seeds, e.g. actuator, lidar, pose, guidance

  std::uint64_t seed(const std::string& name) const;  // 0 where the scenario names none
};

Scenario loadScenario(const std::string& path);
Scenario parseScenario(const std::string& yaml_text, const std::string& source_name);

// Rotation from roll, pitch, yaw (rad): R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d rotationFromRollPitchYaw(const Eigen::Vector3d& rpy_rad);

}  // namespace ardsim_dynamics
