#include <gtest/gtest.h>

#include <cmath>

#include "ardsim_dynamics/orbit.h"
#include "ardsim_dynamics/vehicle_dynamics.h"
#include "ardsim_guidance/cw.h"
#include "ardsim_guidance/geometry.h"

using namespace ardsim_guidance;

namespace {

constexpr double kMu = 3.986004415e14;
constexpr double kRadius = 6378136.3 + 415e3;
const double kN = std::sqrt(kMu / (kRadius * kRadius * kRadius));

// RK4 of the linear CW ODE.
Vector6d propagateLinear(Vector6d x, double duration, double h) {
  auto f = [](const Vector6d& s) {
    Vector6d d;
    d << s.tail<3>(), cwAcceleration(kN, s.head<3>(), s.tail<3>());
    return d;
  };
  for (double t = 0.0; t < duration - 1e-9; t += h) {
    const Vector6d k1 = f(x), k2 = f(x + 0.5 * h * k1), k3 = f(x + 0.5 * h * k2), k4 = f(x + h * k3);
    x += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return x;
}

}  // namespace

TEST(Cw, StateTransitionMatchesIntegratedOde) {
  Vector6d x0;
  x0 << -200.0, 15.0, 30.0, 0.1, -0.02, 0.05;
  for (double t : {60.0, 600.0, 2786.0}) {
    const Vector6d closed = ardsim_dynamics::cwTransition(kN, t) * x0;
    EXPECT_LT((closed - propagateLinear(x0, t, 0.5)).cwiseAbs().maxCoeff(), 1e-6) << "t = " << t;
  }
}

TEST(Cw, RadialHopMatchesReferenceExample) {
  // cw_and_approach.md: -V-bar station-keeping x = -2000 m to x = -250 m in half an orbit, n = 1.12762e-3:
  // dv1 = dv2 = +0.4933 m/s along +z.
  const double n = 1.12762e-3;
  const TwoImpulseTransfer hop = cwTwoImpulse(n, {-2000, 0, 0}, {0, 0, 0}, {-250, 0, 0}, {0, 0, 0}, M_PI / n);
  ASSERT_TRUE(hop.valid);
  EXPECT_NEAR(hop.dv1_mps.z(), 0.4933, 5e-4);
  EXPECT_NEAR(hop.dv2_mps.z(), 0.4933, 5e-4);
  EXPECT_NEAR(hop.dv1_mps.x(), 0.0, 1e-9);
}

TEST(Cw, TwoImpulseReachesAimWithinOneMillimetreUnderLinearModel) {
  const Eigen::Vector3d r0(400.0, 25.0, -40.0), v0(-0.05, 0.01, 0.02), rf(25.0, 0.0, 0.0), vf(-0.1, 0.0, 0.0);
  const double T = 600.0;
  const TwoImpulseTransfer plan = cwTwoImpulse(kN, r0, v0, rf, vf, T);
  ASSERT_TRUE(plan.valid);
  Vector6d x0;
  x0 << r0, v0 + plan.dv1_mps;
  const Vector6d closed = ardsim_dynamics::cwTransition(kN, T) * x0;
  EXPECT_LT((closed.head<3>() - rf).norm(), 1e-3);
  // Independent check by integrating the ODE, and the arrival velocity after the second impulse.
  const Vector6d integrated = propagateLinear(x0, T, 0.1);
  EXPECT_LT((integrated.head<3>() - rf).norm(), 1e-3);
  EXPECT_LT((integrated.tail<3>() + plan.dv2_mps - vf).norm(), 1e-6);
}

TEST(Cw, TwoImpulseReachesAimWithinOnePercentUnderTwoBodyDynamics) {
  // Target on a circular orbit; chaser placed at r0 in LVLH; first impulse from CW; both propagated with the
  // truth dynamics' RK4 under nonlinear point-mass gravity for 10 minutes.
  using ardsim_dynamics::CartesianState;
  ardsim_dynamics::EnvironmentOptions point_mass;
  point_mass.gravity_degree = 0;
  point_mass.atmosphere_density_kgm3 = 0.0;
  point_mass.earth_rotation = false;
  point_mass.gravity_gradient_torque = false;
  const ardsim_dynamics::Environment env(ardsim_dynamics::GravityField(kMu, 6378136.3, 0), point_mass);
  const CartesianState target0{{kRadius, 0.0, 0.0}, {0.0, kN * kRadius, 0.0}};
  const Eigen::Vector3d r0(-800.0, 30.0, 60.0), v0(0.0, 0.0, 0.0), rf(-100.0, 0.0, 0.0);
  const double T = 600.0;
  const TwoImpulseTransfer plan = cwTwoImpulse(kN, r0, v0, rf, Eigen::Vector3d::Zero(), T);
  ASSERT_TRUE(plan.valid);
  const CartesianState chaser0 = ardsim_dynamics::inertialFromLvlh(target0, {r0, v0 + plan.dv1_mps});
  ardsim_dynamics::VehicleState target, chaser;
  target.position_m = target0.position_m;
  target.velocity_mps = target0.velocity_mps;
  chaser.position_m = chaser0.position_m;
  chaser.velocity_mps = chaser0.velocity_mps;
  const ardsim_dynamics::VehicleProperties body;
  const double h = 0.05;
  for (int k = 0; k * h < T - 1e-9; ++k) {
    target = ardsim_dynamics::rk4Step(env, body, target, {}, k * h, h);
    chaser = ardsim_dynamics::rk4Step(env, body, chaser, {}, k * h, h);
  }
  const Eigen::Vector3d r_final =
      ardsim_dynamics::relativeStateInLvlh({target.position_m, target.velocity_mps},
                                           {chaser.position_m, chaser.velocity_mps})
          .position_m;
  const double miss = (r_final - rf).norm();
  EXPECT_LT(miss, 0.01 * r0.norm()) << "miss " << miss << " m";
  // And the linear model is not trivially exact here: the nonlinearity is visible but small.
  EXPECT_GT(miss, 1e-3);
}

TEST(Cw, SingularTransferTimeIsRejected) {
  const TwoImpulseTransfer plan =
      cwTwoImpulse(kN, {100, 0, 0}, {0, 0, 0}, {20, 0, 0}, {0, 0, 0}, 2.0 * M_PI / kN);
  EXPECT_FALSE(plan.valid);
}
