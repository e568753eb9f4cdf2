// Contact detection and the capture verdict: the docking approach inside the envelope captures; off the axis,
// tilted, too fast or into the structure it collides; the first contact time is located inside the step.
#include <gtest/gtest.h>

#include <stdexcept>

#include "ardsim_dynamics/simulation.h"

using namespace ardsim_dynamics;
using ardsim_description::TargetKind;

namespace {

constexpr double kDeg = M_PI / 180.0;

// Chaser port in the target port frame at `position_m`, moving at `velocity_mps` relative to the target body,
// in the docked attitude turned by `rpy_deg`.
Scenario approach(const Eigen::Vector3d& position_m, const Eigen::Vector3d& velocity_mps,
                  const Eigen::Vector3d& rpy_deg = Eigen::Vector3d::Zero(),
                  TargetKind kind = TargetKind::kIss) {
  Scenario s;
  s.target_kind = kind;
  s.chaser_initial.frame = RelativeFrame::kTargetPort;
  s.chaser_initial.position_m = position_m;
  s.chaser_initial.velocity_mps = velocity_mps;
  s.chaser_initial.attitude_offset_rad = rpy_deg * kDeg;
  return s;
}

// Steps with zero command until the first contact or `max_steps`.
std::optional<ContactEvent> runToContact(Simulation& sim, int max_steps = 200) {
  for (int k = 0; k < max_steps && !sim.contact(); ++k) sim.step(BodyWrench{});
  return sim.contact();
}

// The chaser body in the target body frame with its port `gap_m` in front of the target port along the axis,
// `lateral_m` to the side.
Eigen::Isometry3d chaserAtPort(TargetKind kind, double gap_m, double lateral_m = 0.0) {
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() = Eigen::Vector3d(gap_m, lateral_m, 0.0);
  return ardsim_description::T_target_port(kind) * offset * ardsim_description::T_port_port_docked() *
         ardsim_description::T_chaser_port().inverse();
}

}  // namespace

TEST(Contact, DockedAtCaptureSpeedIsACapture) {
  for (TargetKind kind : {TargetKind::kIss, TargetKind::kHubble}) {
    SCOPED_TRACE(ardsim_description::targetKindName(kind));
    const double gap_m = 0.02, speed_mps = 0.075;
    Simulation sim(
        approach(Eigen::Vector3d(gap_m, 0, 0), Eigen::Vector3d(-speed_mps, 0, 0), {0, 0, 0}, kind));
    const auto event = runToContact(sim);
    ASSERT_TRUE(event);
    EXPECT_EQ(event->verdict, ContactVerdict::kCapture) << event->reason;
    EXPECT_TRUE(event->within_envelope);
    EXPECT_NEAR(event->conditions.closing_speed_mps, speed_mps, 1e-4);
    EXPECT_LT(event->conditions.lateral_misalignment_m, 1e-3);
    EXPECT_LT(event->conditions.angular_misalignment_rad, 1e-4);
    // The rings' faces lie on the docking planes: first contact when the gap has closed, located inside the
    // 0.1 s step to the 1 ms tolerance (plus the 2 mm Bullet margin of the hull-shaped parts).
    EXPECT_NEAR(event->time_s, gap_m / speed_mps, 0.001 + 0.002 / speed_mps);
    EXPECT_NEAR(event->contact_point_m.x(), 0.0, 0.005);
    // Halted at the contact: the time and states are those of the contact.
    EXPECT_DOUBLE_EQ(sim.time(), event->time_s);
    EXPECT_EQ(sim.stepIndex(), 2);
    EXPECT_NEAR(sim.chaserPortInTargetPort().pose.translation().x(), 0.0, 0.005);
    EXPECT_THROW(sim.step(BodyWrench{}), std::logic_error);
  }
}

TEST(Contact, OffTheAxisIsACollision) {
  Simulation sim(approach(Eigen::Vector3d(0.3, 1.0, 0.0), Eigen::Vector3d(-0.075, 0, 0)));
  const auto event = runToContact(sim);
  ASSERT_TRUE(event);
  EXPECT_EQ(event->verdict, ContactVerdict::kCollision);
  EXPECT_FALSE(event->within_envelope);
  EXPECT_NEAR(event->conditions.lateral_misalignment_m, 1.0, 1e-3);
  EXPECT_NE(event->reason.find("lateral misalignment 1.000 m > 0.100 m"), std::string::npos) << event->reason;
}

TEST(Contact, TenDegreesMisalignedIsACollision) {
  Simulation sim(approach(Eigen::Vector3d(0.3, 0.0, 0.0), Eigen::Vector3d(-0.075, 0, 0), {0.0, 10.0, 0.0}));
  const auto event = runToContact(sim);
  ASSERT_TRUE(event);
  EXPECT_EQ(event->verdict, ContactVerdict::kCollision);
  EXPECT_NEAR(event->conditions.angular_misalignment_rad, 10.0 * kDeg, 1e-3);
  EXPECT_NE(event->reason.find("angular misalignment 10.00 deg > 4.00 deg"), std::string::npos)
      << event->reason;
  // The tilted ring touches before the port centres meet.
  EXPECT_GT(sim.chaserPortInTargetPort().pose.translation().x(), 0.01);
}

TEST(Contact, TooFastAtThePortsIsACollisionNamingTheClosingSpeed) {
  Simulation sim(approach(Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d(-0.3, 0, 0)));
  const auto event = runToContact(sim);
  ASSERT_TRUE(event);
  EXPECT_EQ(event->verdict, ContactVerdict::kCollision);
  EXPECT_FALSE(event->within_envelope);
  EXPECT_NE(event->reason.find("closing speed 0.300 m/s > 0.100 m/s"), std::string::npos) << event->reason;
  EXPECT_NE(event->reason.find("the ports met outside the capture envelope"), std::string::npos);
  // 3 cm per step: the bisection still finds the ports at the docking plane, not 3 cm into each other.
  EXPECT_NEAR(sim.chaserPortInTargetPort().pose.translation().x(), 0.0, 0.005);
}

TEST(Contact, TooSlowIsNotACapture) {
  Simulation sim(approach(Eigen::Vector3d(0.005, 0, 0), Eigen::Vector3d(-0.02, 0, 0)));
  const auto event = runToContact(sim);
  ASSERT_TRUE(event);
  EXPECT_EQ(event->verdict, ContactVerdict::kCollision);
  EXPECT_NE(event->reason.find("closing speed 0.020 m/s < 0.050 m/s"), std::string::npos) << event->reason;
}

TEST(Contact, HittingTheStructureBesideThePortNamesTheParts) {
  // 3 m beside the docking axis the chaser's nose meets the ISS's pressurized structure, not its port.
  Simulation sim(approach(Eigen::Vector3d(0.3, 3.0, 0.0), Eigen::Vector3d(-0.075, 0, 0)));
  const auto event = runToContact(sim, 1000);
  ASSERT_TRUE(event);
  EXPECT_EQ(event->verdict, ContactVerdict::kCollision);
  EXPECT_NE(event->reason.find("outside the docking ports"), std::string::npos) << event->reason;
  EXPECT_FALSE(event->target_part.empty());
  EXPECT_FALSE(event->chaser_part.empty());
}

TEST(Contact, NoContactAtACentimetreGap) {
  for (TargetKind kind : {TargetKind::kIss, TargetKind::kHubble}) {
    SCOPED_TRACE(ardsim_description::targetKindName(kind));
    ContactDetector detector(kind);
    EXPECT_FALSE(detector.test(chaserAtPort(kind, 0.01)).touching);
    const Touch pressed = detector.test(chaserAtPort(kind, -0.01));
    EXPECT_TRUE(pressed.touching);
    EXPECT_TRUE(pressed.ports_only);
    EXPECT_GT(pressed.depth_m, 0.0);
  }
  // And the simulation at rest 1 cm from the port sees none over 10 s.
  Simulation sim(approach(Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d::Zero()));
  EXPECT_FALSE(runToContact(sim, 100));
  EXPECT_EQ(sim.stepIndex(), 100);
}

TEST(Contact, FarChaserIsRejectedByTheBoundingSpheres) {
  ContactDetector detector(TargetKind::kIss);
  EXPECT_GT(detector.targetRadius(), 40.0);  // the truss
  EXPECT_LT(detector.chaserRadius(), 6.0);
  EXPECT_FALSE(detector.test(chaserAtPort(TargetKind::kIss, 100.0)).touching);
}

TEST(Contact, StartingInContactIsReportedAtTimeZero) {
  Simulation sim(approach(Eigen::Vector3d(-0.01, 0, 0), Eigen::Vector3d(-0.075, 0, 0)));
  ASSERT_TRUE(sim.contact());
  EXPECT_EQ(sim.contact()->time_s, 0.0);
  EXPECT_EQ(sim.time(), 0.0);
}

TEST(Contact, DisabledLetsTheVehiclesPassThrough) {
  Scenario s = approach(Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d(-0.3, 0, 0));
  s.contact.enabled = false;
  Simulation sim(s);
  EXPECT_FALSE(runToContact(sim, 10));
  EXPECT_LT(sim.chaserPortInTargetPort().pose.translation().x(), -0.2);
}

TEST(Contact, ConditionsAreThoseOfTheChaserPortInTheTargetPort) {
  RelativeState s;
  s.pose = ardsim_description::T_port_port_docked();
  s.pose.translation() = Eigen::Vector3d(0.5, 0.03, -0.04);
  s.pose.linear() =
      s.pose.linear() * Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  s.velocity_mps = Eigen::Vector3d(-0.08, 0.006, 0.008);
  s.angular_velocity_radps = Eigen::Vector3d(0.0, 0.001, 0.0);
  const ContactConditions c = contactConditions(s);
  EXPECT_NEAR(c.closing_speed_mps, 0.08, 1e-12);
  EXPECT_NEAR(c.lateral_misalignment_m, 0.05, 1e-12);
  EXPECT_NEAR(c.lateral_rate_mps, 0.01, 1e-12);
  EXPECT_NEAR(c.angular_misalignment_rad, 3.0 * kDeg, 1e-9);
  EXPECT_NEAR(c.angular_rate_radps, 0.001, 1e-12);
  EXPECT_EQ(envelopeViolations(c, CaptureEnvelope{}), "");
  CaptureEnvelope tight;
  tight.max_angular_rate_radps = 0.01 * kDeg;
  tight.max_lateral_rate_mps = 0.005;
  EXPECT_EQ(envelopeViolations(c, tight),
            "lateral rate 0.0100 m/s > 0.0050 m/s; angular rate 0.057 deg/s > 0.010 deg/s");
}

TEST(Contact, ScenarioSectionIsReadAndValidated) {
  const Scenario s = parseScenario(
      "contact:\n  enabled: false\n  min_closing_speed_mps: 0.04\n  max_closing_speed_mps: 0.12\n"
      "  max_lateral_misalignment_m: 0.2\n  max_angular_misalignment_deg: 5\n  max_lateral_rate_mps: 0.05\n"
      "  max_angular_rate_dps: 0.3\n  time_tolerance_s: 0.0005\n",
      "test.yaml");
  EXPECT_FALSE(s.contact.enabled);
  EXPECT_DOUBLE_EQ(s.contact.envelope.min_closing_speed_mps, 0.04);
  EXPECT_DOUBLE_EQ(s.contact.envelope.max_closing_speed_mps, 0.12);
  EXPECT_DOUBLE_EQ(s.contact.envelope.max_lateral_misalignment_m, 0.2);
  EXPECT_NEAR(s.contact.envelope.max_angular_misalignment_rad, 5.0 * kDeg, 1e-15);
  EXPECT_DOUBLE_EQ(s.contact.envelope.max_lateral_rate_mps, 0.05);
  EXPECT_NEAR(s.contact.envelope.max_angular_rate_radps, 0.3 * kDeg, 1e-15);
  EXPECT_DOUBLE_EQ(s.contact.time_tolerance_s, 0.0005);

  const auto error = [](const std::string& yaml) -> std::string {
    try {
      parseScenario(yaml, "test.yaml");
    } catch (const ScenarioError& e) {
      return e.what();
    }
    return "";
  };
  const std::string e1 = error("contact:\n  max_lateral_rate_mps: -1\n");
  EXPECT_NE(e1.find("contact.max_lateral_rate_mps"), std::string::npos) << e1;
  EXPECT_NE(e1.find("[0, 10]"), std::string::npos) << e1;
  const std::string e2 = error("contact:\n  min_closing_speed_mps: 0.2\n");
  EXPECT_NE(e2.find("contact.min_closing_speed_mps"), std::string::npos) << e2;
  EXPECT_NE(e2.find("max_closing_speed_mps"), std::string::npos) << e2;
  const std::string e3 = error("contact:\n  enabled: maybe\n");
  EXPECT_NE(e3.find("contact.enabled"), std::string::npos) << e3;
  const std::string e4 = error("contact:\n  max_closing_speed: 0.1\n");
  EXPECT_NE(e4.find("contact.max_closing_speed"), std::string::npos) << e4;
}
