#include "ardsim_dynamics/vehicle_dynamics.h"

#include <cmath>
#include <utility>

#include "ardsim_dynamics/orbit.h"

namespace ardsim_dynamics {

Environment::Environment(GravityField field, EnvironmentOptions options)
    : field_(std::move(field)), options_(options) {
  if (options_.gravity_degree < 0 || options_.gravity_degree > field_.maxDegree())
    throw GravityModelError("gravity degree " + std::to_string(options_.gravity_degree) + " outside 0.." +
                            std::to_string(field_.maxDegree()) + " of the coefficient table");
}

double Environment::greenwichAngle(double t_s) const {
  return options_.greenwich_angle_at_epoch_rad + (options_.earth_rotation ? kEarthRotationRate * t_s : 0.0);
}

Eigen::Vector3d Environment::gravityEci(const Eigen::Vector3d& r_eci, double t_s) const {
  const Eigen::Matrix3d R = R_ecef_eci(greenwichAngle(t_s));
  return R.transpose() * field_.acceleration(R * r_eci, options_.gravity_degree);
}

Eigen::Vector3d Environment::dragAccelerationEci(const VehicleProperties& vehicle,
                                                 const Eigen::Vector3d& r_eci,
                                                 const Eigen::Vector3d& v_eci) const {
  if (options_.atmosphere_density_kgm3 <= 0.0 || vehicle.drag_area_m2 <= 0.0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d earth_rate(0.0, 0.0, options_.earth_rotation ? kEarthRotationRate : 0.0);
  const Eigen::Vector3d v_air = v_eci - earth_rate.cross(r_eci);  // relative to the co-rotating atmosphere
  return -0.5 * options_.atmosphere_density_kgm3 * vehicle.drag_coefficient * vehicle.drag_area_m2 /
         vehicle.mass_kg * v_air.norm() * v_air;
}

Eigen::Vector3d Environment::gravityGradientTorqueBody(const VehicleProperties& vehicle,
                                                       const VehicleState& state) const {
  if (!options_.gravity_gradient_torque) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d r_body = state.attitude.conjugate() * state.position_m;
  const double r = r_body.norm();
  return 3.0 * field_.gm() / std::pow(r, 5) * r_body.cross(vehicle.inertia_kgm2 * r_body);
}

StateDerivative derivative(const Environment& env, const VehicleProperties& vehicle, const VehicleState& s,
                           const BodyWrench& applied, double t_s) {
  StateDerivative d;
  d.velocity_mps = s.velocity_mps;
  d.acceleration_mps2 = env.gravityEci(s.position_m, t_s) +
                        env.dragAccelerationEci(vehicle, s.position_m, s.velocity_mps) +
                        s.attitude * applied.force_n / vehicle.mass_kg;
  // q_dot = 0.5 q (x) (0, w)
  const Eigen::Quaterniond omega(0.0, s.angular_velocity_radps.x(), s.angular_velocity_radps.y(),
                                 s.angular_velocity_radps.z());
  const Eigen::Quaterniond q_dot = s.attitude * omega;
  d.attitude_rate = 0.5 * Eigen::Vector4d(q_dot.w(), q_dot.x(), q_dot.y(), q_dot.z());
  // Euler's equations.
  const Eigen::Vector3d& w = s.angular_velocity_radps;
  const Eigen::Vector3d torque = applied.torque_nm + env.gravityGradientTorqueBody(vehicle, s);
  d.angular_acceleration_radps2 =
      vehicle.inertia_kgm2.ldlt().solve(torque - w.cross(vehicle.inertia_kgm2 * w));
  return d;
}

namespace {

VehicleState advance(const VehicleState& s, const StateDerivative& d, double h) {
  VehicleState out;
  out.position_m = s.position_m + h * d.velocity_mps;
  out.velocity_mps = s.velocity_mps + h * d.acceleration_mps2;
  const Eigen::Vector4d q =
      Eigen::Vector4d(s.attitude.w(), s.attitude.x(), s.attitude.y(), s.attitude.z()) + h * d.attitude_rate;
  out.attitude = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);  // not normalized inside the step
  out.angular_velocity_radps = s.angular_velocity_radps + h * d.angular_acceleration_radps2;
  return out;
}

}  // namespace

VehicleState rk4Step(const Environment& env, const VehicleProperties& vehicle, const VehicleState& s,
                     const BodyWrench& applied, double t, double h) {
  const StateDerivative k1 = derivative(env, vehicle, s, applied, t);
  const StateDerivative k2 = derivative(env, vehicle, advance(s, k1, 0.5 * h), applied, t + 0.5 * h);
  const StateDerivative k3 = derivative(env, vehicle, advance(s, k2, 0.5 * h), applied, t + 0.5 * h);
  const StateDerivative k4 = derivative(env, vehicle, advance(s, k3, h), applied, t + h);
  StateDerivative sum;
  sum.velocity_mps =
      (k1.velocity_mps + 2.0 * k2.velocity_mps + 2.0 * k3.velocity_mps + k4.velocity_mps) / 6.0;
  sum.acceleration_mps2 = (k1.acceleration_mps2 + 2.0 * k2.acceleration_mps2 + 2.0 * k3.acceleration_mps2 +
                           k4.acceleration_mps2) /
                          6.0;
  sum.attitude_rate =
      (k1.attitude_rate + 2.0 * k2.attitude_rate + 2.0 * k3.attitude_rate + k4.attitude_rate) / 6.0;
  sum.angular_acceleration_radps2 = (k1.angular_acceleration_radps2 + 2.0 * k2.angular_acceleration_radps2 +
                                     2.0 * k3.angular_acceleration_radps2 + k4.angular_acceleration_radps2) /
                                    6.0;
  VehicleState out = advance(s, sum, h);
  out.attitude.normalize();
  return out;
}

}  // namespace ardsim_dynamics
