// Translational and rotational dynamics of a rigid vehicle in orbit, and the fixed-step integrator. ROS-free.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ardsim_dynamics/gravity_field.h"

namespace ardsim_dynamics {

struct VehicleProperties {
  double mass_kg = 1.0;
  Eigen::Matrix3d inertia_kgm2 = Eigen::Matrix3d::Identity();  // about the centre of mass, body axes
  double drag_area_m2 = 0.0;
  double drag_coefficient = 2.2;
};

struct VehicleState {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();          // centre of mass in eci
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();        // in eci
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();  // q_eci_body: body coords -> eci coords
  Eigen::Vector3d angular_velocity_radps =
      Eigen::Vector3d::Zero();  // body rate relative to eci, in body axes
};

// Force and torque applied by the vehicle's actuators, in its body frame.
struct BodyWrench {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_nm = Eigen::Vector3d::Zero();
};

struct EnvironmentOptions {
  int gravity_degree = 13;                   // 0 = point mass
  double atmosphere_density_kgm3 = 2.9e-12;  // constant; 0 = no drag
  bool earth_rotation = true;                // the field turns with the Earth; the atmosphere co-rotates
  double greenwich_angle_at_epoch_rad = 0.0;
  bool gravity_gradient_torque = true;
};

// Forces and torques of the environment at a time and state.
class Environment {
 public:
  Environment(GravityField field, EnvironmentOptions options);

  Eigen::Vector3d gravityEci(const Eigen::Vector3d& r_eci_m, double t_s) const;
  Eigen::Vector3d dragAccelerationEci(const VehicleProperties& vehicle, const Eigen::Vector3d& r_eci_m,
                                      const Eigen::Vector3d& v_eci_mps) const;
  // 3 GM / r^5 (r_b x I r_b), r_b the position in body axes (point-mass gradient, enough for torques).
  Eigen::Vector3d gravityGradientTorqueBody(const VehicleProperties& vehicle,
                                            const VehicleState& state) const;
  double greenwichAngle(double t_s) const;

  const EnvironmentOptions& options() const { return options_; }
  const GravityField& field() const { return field_; }

 private:
  GravityField field_;
  EnvironmentOptions options_;
};

struct StateDerivative {
  Eigen::Vector3d velocity_mps;
  Eigen::Vector3d acceleration_mps2;
  Eigen::Vector4d attitude_rate;  // d/dt of (w, x, y, z)
  Eigen::Vector3d angular_acceleration_radps2;
};

StateDerivative derivative(const Environment& env, const VehicleProperties& vehicle,
                           const VehicleState& state, const BodyWrench& applied, double t_s);

// One step of the classical 4th-order Runge-Kutta method (fixed step h): the applied wrench is held constant
// over the step; the quaternion is integrated as a 4-vector and renormalized at the end of the step (the
// drift it removes is O(h^5)). RK4 rather than an adaptive method keeps every run bit-identical and the cost
// per control step fixed.
VehicleState rk4Step(const Environment& env, const VehicleProperties& vehicle, const VehicleState& state,
                     const BodyWrench& applied, double t_s, double h_s);

}  // namespace ardsim_dynamics
