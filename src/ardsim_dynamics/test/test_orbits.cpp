// Relative motion: LVLH conversions and the truth dynamics against the Clohessy-Wiltshire closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "ardsim_dynamics/simulation.h"

using namespace ardsim_dynamics;

namespace {

Scenario cwScenario(const Eigen::Vector3d& rho0, const Eigen::Vector3d& rho_dot0) {
  Scenario s;
  s.target_orbit.semi_major_axis_m = 6793137.0;
  s.target_orbit.eccentricity = 0.0;
  s.target_orbit.inclination_rad = 51.64 * M_PI / 180.0;
  s.environment.gravity_degree = 0;  // spherical Earth
  s.environment.atmosphere_density_kgm3 = 0.0;
  s.chaser_initial.frame = RelativeFrame::kTargetLvlh;
  s.chaser_initial.position_m = rho0;
  s.chaser_initial.velocity_mps = rho_dot0;
  s.control_step_s = 0.1;
  s.integration_step_s = 0.1;
  return s;
}

}  // namespace

TEST(Lvlh, RoundTripAndAxes) {
  KeplerianElements e;
  e.semi_major_axis_m = 6.8e6;
  e.eccentricity = 0.001;
  e.inclination_rad = 0.9;
  e.true_anomaly_rad = 1.0;
  const CartesianState target = keplerianToCartesian(e);
  const Eigen::Matrix3d R = R_eci_lvlh(target);
  EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  EXPECT_GT(R.col(0).dot(target.velocity_mps), 0.0);  // x along the velocity
  EXPECT_LT(R.col(2).dot(target.position_m), 0.0);    // z towards the Earth
  const CartesianState rel{Eigen::Vector3d(-100.0, 5.0, 20.0), Eigen::Vector3d(0.1, -0.02, 0.03)};
  const CartesianState back = relativeStateInLvlh(target, inertialFromLvlh(target, rel));
  EXPECT_NEAR((back.position_m - rel.position_m).norm(), 0.0, 1e-7);
  EXPECT_NEAR((back.velocity_mps - rel.velocity_mps).norm(), 0.0, 1e-10);
}

TEST(Cw, TransitionMatrixIsTheFlowOfTheCwEquations) {
  // d/dt Phi(t) = A Phi(t) with the CW system matrix, checked by central differences.
  const double n = 1.12762e-3, t = 700.0, h = 1e-3;
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  A.block<3, 3>(0, 3).setIdentity();
  A(3, 5) = 2 * n;
  A(4, 1) = -n * n;
  A(5, 2) = 3 * n * n;
  A(5, 3) = -2 * n;
  const Eigen::Matrix<double, 6, 6> dPhi = (cwTransition(n, t + h) - cwTransition(n, t - h)) / (2 * h);
  EXPECT_LT((dPhi - A * cwTransition(n, t)).norm(), 1e-9);
  EXPECT_LT((cwTransition(n, 0.0) - Eigen::Matrix<double, 6, 6>::Identity()).norm(), 1e-15);
}

// A chaser on a closed-form CW trajectory ~100 m from the target stays within 0.1 % of the range of the CW
// prediction over 600 s under the full (nonlinear, spherical-Earth) truth dynamics.
class CwAgreement : public ::testing::TestWithParam<std::pair<Eigen::Vector3d, Eigen::Vector3d>> {};

TEST_P(CwAgreement, TruthFollowsCwWithin0p1PercentOfRangeOver600s) {
  const Scenario s = cwScenario(GetParam().first, GetParam().second);
  Simulation sim(s);
  const CartesianState rel0 = sim.chaserInTargetLvlh();
  const double n = std::sqrt(sim.environment().field().gm() / std::pow(s.target_orbit.semi_major_axis_m, 3));
  double worst = 0.0;
  while (sim.time() < 600.0 - 1e-9) {
    sim.step(BodyWrench{});
    const CartesianState cw = cwPropagate(rel0, n, sim.time());
    const double error = (sim.chaserInTargetLvlh().position_m - cw.position_m).norm();
    worst = std::max(worst, error / cw.position_m.norm());
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
  EXPECT_LT(worst, 1e-3);
}

INSTANTIATE_TEST_SUITE_P(
    Trajectories, CwAgreement,
    ::testing::Values(
        // V-bar station keeping 100 m behind: an equilibrium of the CW equations.
        std::make_pair(Eigen::Vector3d(-100.0, 0.0, 0.0), Eigen::Vector3d(0.0, 0.0, 0.0)),
        // Closed "football" orbit (vx0 = 2 n z0 removes the drift) with an out-of-plane oscillation.
        std::make_pair(Eigen::Vector3d(-90.0, 20.0, 40.0),
                       Eigen::Vector3d(2 * 1.1276e-3 * 40.0, 0.01, 0.02))));

TEST(Cw, InitialStateRelativeToThePortIsWhatTheScenarioSays) {
  Scenario s;
  s.chaser_initial.frame = RelativeFrame::kTargetPort;
  s.chaser_initial.position_m = Eigen::Vector3d(30.0, 1.5, -2.0);
  s.chaser_initial.velocity_mps = Eigen::Vector3d(-0.1, 0.01, 0.0);
  s.chaser_initial.attitude_offset_rad = Eigen::Vector3d(0.02, -0.05, 0.08);
  const Simulation sim(s);
  const RelativeState rel = sim.chaserPortInTargetPort();
  EXPECT_NEAR((rel.pose.translation() - s.chaser_initial.position_m).norm(), 0.0, 1e-8);
  EXPECT_NEAR((rel.velocity_mps - s.chaser_initial.velocity_mps).norm(), 0.0, 1e-10);
  EXPECT_NEAR(rel.angular_velocity_radps.norm(), 0.0, 1e-12);
  // Docking attitude plus the offset: the chaser port x axis points back along the target port x axis.
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                   rotationFromRollPitchYaw(s.chaser_initial.attitude_offset_rad);
  EXPECT_NEAR((rel.pose.linear() - expected).norm(), 0.0, 1e-9);
}
