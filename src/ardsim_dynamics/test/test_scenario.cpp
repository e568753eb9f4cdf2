// Scenario files: the shipped ones load, bad values are rejected naming key, value and range; runs are
// deterministic.
#include <gtest/gtest.h>

#include <cstring>

#include "ardsim_dynamics/simulation.h"

using namespace ardsim_dynamics;

namespace {

std::string errorOf(const std::string& yaml) {
  try {
    parseScenario(yaml, "test.yaml");
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Scenario, ShippedFreeDriftLoads) {
  const Scenario s = loadScenario(std::string(SCENARIO_DIR) + "/free_drift.yaml");
  EXPECT_EQ(s.name, "free_drift");
  EXPECT_EQ(s.chaser_initial.frame, RelativeFrame::kTargetLvlh);
  EXPECT_DOUBLE_EQ(s.chaser.mass_kg, 12519.0);
  EXPECT_EQ(s.seed("actuator"), 1u);
  EXPECT_EQ(s.environment.gravity_degree, 13);
}

TEST(Scenario, BadValuesNameKeyValueAndRange) {
  const std::string e1 = errorOf("chaser:\n  mass_kg: -5\n");
  EXPECT_NE(e1.find("chaser.mass_kg"), std::string::npos) << e1;
  EXPECT_NE(e1.find("-5"), std::string::npos) << e1;
  EXPECT_NE(e1.find("(0, 1e+07]"), std::string::npos) << e1;

  const std::string e2 = errorOf("environment:\n  gravity_degree: 20\n");
  EXPECT_NE(e2.find("environment.gravity_degree"), std::string::npos) << e2;
  EXPECT_NE(e2.find("[0, 13]"), std::string::npos) << e2;

  const std::string e3 = errorOf("target:\n  kind: mir\n");
  EXPECT_NE(e3.find("target.kind"), std::string::npos) << e3;
  EXPECT_NE(e3.find("iss or hubble"), std::string::npos) << e3;

  const std::string e4 = errorOf("simulation:\n  control_step_s: 0.1\n  integration_step_s: 0.03\n");
  EXPECT_NE(e4.find("integration_step_s"), std::string::npos) << e4;

  const std::string e5 = errorOf("chaser:\n  initial_state:\n    position_m: [1, 2]\n");
  EXPECT_NE(e5.find("chaser.initial_state.position_m"), std::string::npos) << e5;

  const std::string e6 = errorOf("target:\n  inertia_kgm2: [[1, 0, 0], [0, -1, 0], [0, 0, 1]]\n");
  EXPECT_NE(e6.find("positive-definite"), std::string::npos) << e6;

  const std::string e7 = errorOf("simulation: [1, 2]\n");
  EXPECT_NE(e7.find("simulation"), std::string::npos) << e7;

  const std::string e8 = errorOf("target: {orbit: {eccentricity: nan}}\n");
  EXPECT_NE(e8.find("target.orbit.eccentricity"), std::string::npos) << e8;
}

TEST(Scenario, MisspeltKeysAreRejected) {
  const std::string e = errorOf("chaser:\n  mas_kg: 100\n");
  EXPECT_NE(e.find("chaser.mas_kg"), std::string::npos) << e;
  EXPECT_NE(e.find("mass_kg"), std::string::npos) << e;  // lists the known keys
}

TEST(Scenario, MissingFileIsAClearError) {
  EXPECT_THROW(loadScenario("/nonexistent/scenario.yaml"), ScenarioError);
  EXPECT_FALSE(errorOf("target: [unclosed\n").empty());
}

TEST(Simulation, SameScenarioTwiceGivesBitIdenticalStates) {
  Scenario s = loadScenario(std::string(SCENARIO_DIR) + "/free_drift.yaml");
  s.chaser_actuator.force_noise_fraction = 0.1;  // the seeded noise must repeat too
  Simulation a(s), b(s);
  BodyWrench cmd;
  cmd.force_n = Eigen::Vector3d(3.0, -2.0, 1.0);
  cmd.torque_nm = Eigen::Vector3d(0.5, 0.0, -0.5);
  for (int k = 0; k < 500; ++k) {
    a.step(cmd);
    b.step(cmd);
  }
  EXPECT_EQ(std::memcmp(a.chaser().position_m.data(), b.chaser().position_m.data(), sizeof(double) * 3), 0);
  EXPECT_EQ(std::memcmp(a.chaser().velocity_mps.data(), b.chaser().velocity_mps.data(), sizeof(double) * 3),
            0);
  EXPECT_EQ(std::memcmp(a.chaser().attitude.coeffs().data(), b.chaser().attitude.coeffs().data(),
                        sizeof(double) * 4),
            0);
  EXPECT_EQ(std::memcmp(a.target().position_m.data(), b.target().position_m.data(), sizeof(double) * 3), 0);
  // And the thrust did something.
  Simulation c(s);
  for (int k = 0; k < 500; ++k) c.step(BodyWrench{});
  EXPECT_GT((a.chaser().position_m - c.chaser().position_m).norm(), 0.01);
}
