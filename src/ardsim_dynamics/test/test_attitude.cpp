// Rigid-body attitude (torque-free conservation, intermediate-axis instability) and the actuator model.
#include <gtest/gtest.h>

#include <cmath>

#include "ardsim_dynamics/actuator.h"
#include "ardsim_dynamics/orbit.h"
#include "ardsim_dynamics/vehicle_dynamics.h"

using namespace ardsim_dynamics;

namespace {

Environment torqueFree() {
  EnvironmentOptions o;
  o.gravity_degree = 0;
  o.atmosphere_density_kgm3 = 0.0;
  o.earth_rotation = false;
  o.gravity_gradient_torque = false;
  return Environment(GravityField::egm96(), o);
}

VehicleState spinning(const Eigen::Vector3d& omega) {
  VehicleState s;
  s.position_m = Eigen::Vector3d(6.8e6, 0.0, 0.0);
  s.velocity_mps = Eigen::Vector3d(0.0, 7656.0, 0.0);
  s.angular_velocity_radps = omega;
  return s;
}

// Largest excursion of the angular velocity away from the given body axis while spinning about it for
// `duration`.
double maxTransverseRate(const Eigen::Vector3d& inertia_diag, int axis, double duration) {
  const Environment env = torqueFree();
  VehicleProperties body;
  body.inertia_kgm2 = inertia_diag.asDiagonal();
  Eigen::Vector3d omega = Eigen::Vector3d::Constant(1e-6);
  omega[axis] = 0.5;
  VehicleState s = spinning(omega);
  double worst = 0.0;
  const double dt = 0.01;
  for (int k = 0; k * dt < duration; ++k) {
    s = rk4Step(env, body, s, BodyWrench{}, k * dt, dt);
    Eigen::Vector3d transverse = s.angular_velocity_radps;
    transverse[axis] = 0.0;
    worst = std::max(worst, transverse.norm());
  }
  return worst;
}

}  // namespace

TEST(Attitude, TorqueFreeBodyConservesEnergyAndAngularMomentum) {
  const Environment env = torqueFree();
  VehicleProperties body;
  body.inertia_kgm2 << 2.5e4, 120.0, -300.0, 120.0, 8.1e4, 50.0, -300.0, 50.0, 7.9e4;
  VehicleState s = spinning(Eigen::Vector3d(0.05, -0.02, 0.03));
  auto energy = [&](const VehicleState& v) {
    return 0.5 * v.angular_velocity_radps.dot(body.inertia_kgm2 * v.angular_velocity_radps);
  };
  auto momentum = [&](const VehicleState& v) {  // in eci: conserved as a vector
    return Eigen::Vector3d(v.attitude * (body.inertia_kgm2 * v.angular_velocity_radps));
  };
  const double e0 = energy(s);
  const Eigen::Vector3d l0 = momentum(s);
  const double dt = 0.01;
  double worst_energy = 0.0, worst_momentum = 0.0;
  for (int k = 0; k < 100000; ++k) {  // 1000 s
    s = rk4Step(env, body, s, BodyWrench{}, k * dt, dt);
    worst_energy = std::max(worst_energy, std::abs(energy(s) - e0) / e0);
    worst_momentum = std::max(worst_momentum, (momentum(s) - l0).norm() / l0.norm());
  }
  EXPECT_LT(worst_energy, 1e-9);
  EXPECT_LT(worst_momentum, 1e-9);
}

TEST(Attitude, IntermediateAxisSpinIsUnstableTheOthersAreNot) {
  const Eigen::Vector3d inertia(100.0, 200.0, 300.0);
  EXPECT_GT(maxTransverseRate(inertia, 1, 120.0), 0.1);   // tumbles (Dzhanibekov effect)
  EXPECT_LT(maxTransverseRate(inertia, 0, 120.0), 1e-5);  // minor axis: stable
  EXPECT_LT(maxTransverseRate(inertia, 2, 120.0), 1e-5);  // major axis: stable
}

TEST(Actuator, SaturatesPerAxis) {
  ActuatorOptions o;
  o.max_force_n = Eigen::Vector3d(10.0, 20.0, 30.0);
  ActuatorModel model(o, 1);
  BodyWrench cmd;
  cmd.force_n = Eigen::Vector3d(100.0, -5.0, -100.0);
  const BodyWrench applied = model.apply(cmd, 0.1);
  EXPECT_EQ(applied.force_n, Eigen::Vector3d(10.0, -5.0, -30.0));
}

TEST(Actuator, MinimumImpulseBitSuppressesSmallCommands) {
  ActuatorOptions o;
  o.min_impulse_bit_ns = 1.0;  // 10 N over 0.1 s
  ActuatorModel model(o, 1);
  BodyWrench cmd;
  cmd.force_n = Eigen::Vector3d(9.0, 11.0, -9.99);
  const BodyWrench applied = model.apply(cmd, 0.1);
  EXPECT_EQ(applied.force_n, Eigen::Vector3d(0.0, 11.0, 0.0));
}

TEST(Actuator, NoiseIsSeededAndHasTheConfiguredSpread) {
  ActuatorOptions o;
  o.force_noise_fraction = 0.05;
  ActuatorModel a(o, 42), b(o, 42), c(o, 43);
  BodyWrench cmd;
  cmd.force_n = Eigen::Vector3d(100.0, 100.0, 100.0);
  double sum_sq = 0.0;
  bool differs = false;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const BodyWrench fa = a.apply(cmd, 0.1), fb = b.apply(cmd, 0.1), fc = c.apply(cmd, 0.1);
    EXPECT_EQ(fa.force_n, fb.force_n);
    differs |= fa.force_n != fc.force_n;
    sum_sq += (fa.force_n.x() - 100.0) * (fa.force_n.x() - 100.0);
  }
  EXPECT_TRUE(differs);
  EXPECT_NEAR(std::sqrt(sum_sq / n), 5.0, 0.15);
}

TEST(Actuator, NonFiniteCommandsApplyNothing) {
  ActuatorModel model(ActuatorOptions{}, 1);
  BodyWrench cmd;
  cmd.force_n = Eigen::Vector3d(std::nan(""), 5.0, INFINITY);
  cmd.torque_nm = Eigen::Vector3d(-INFINITY, 0.0, 1.0);
  const BodyWrench applied = model.apply(cmd, 0.1);
  EXPECT_EQ(applied.force_n, Eigen::Vector3d(0.0, 5.0, 0.0));
  EXPECT_EQ(applied.torque_nm, Eigen::Vector3d(0.0, 0.0, 1.0));
}
