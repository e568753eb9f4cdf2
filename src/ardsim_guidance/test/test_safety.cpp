#include <gtest/gtest.h>

#include "ardsim_guidance/safety.h"

using namespace ardsim_guidance;

TEST(Safety, CorridorIsAConeWithABluntApex) {
  SafetyOptions o;
  EXPECT_TRUE(insideCorridor(o, {20.0, 3.0, 0.0}));  // 20 tan 10 deg = 3.53 m
  EXPECT_FALSE(insideCorridor(o, {20.0, 3.0, 2.0}));
  EXPECT_TRUE(insideCorridor(o, {0.5, 0.4, 0.0}));       // apex radius 0.5 m
  EXPECT_FALSE(corridorViolated(o, {40.0, 30.0, 0.0}));  // outside the keep-out sphere: not a violation
  EXPECT_TRUE(corridorViolated(o, {20.0, 10.0, 0.0}));
}

TEST(Safety, DegradedHolds) {
  SafetyMonitor m;
  EXPECT_EQ(m.check(0.0, true, EstimateStatus::kTracking, "", true, {20, 0, 0}).action,
            SafetyAction::kProceed);
  const SafetyDecision d = m.check(0.1, true, EstimateStatus::kDegraded, "few points", true, {20, 0, 0});
  EXPECT_EQ(d.action, SafetyAction::kHold);
  EXPECT_NE(d.reason.find("DEGRADED"), std::string::npos);
  EXPECT_EQ(m.check(0.2, true, EstimateStatus::kTracking, "", true, {20, 0, 0}).action,
            SafetyAction::kProceed);
}

TEST(Safety, LostHoldsThenRetreatsAfterTheLimit) {
  SafetyOptions o;
  o.lost_limit_s = 3.0;
  SafetyMonitor m(o);
  m.check(10.0, true, EstimateStatus::kTracking, "", true, {20, 0, 0});
  EXPECT_EQ(m.check(12.9, false, EstimateStatus::kLost, "no points", false, Eigen::Vector3d::Zero()).action,
            SafetyAction::kHold);
  const SafetyDecision d =
      m.check(13.1, false, EstimateStatus::kLost, "no points", false, Eigen::Vector3d::Zero());
  EXPECT_EQ(d.action, SafetyAction::kRetreat);
  EXPECT_NE(d.reason.find("LOST"), std::string::npos);
  // RETREAT is latched: a good estimate does not resume the approach.
  EXPECT_EQ(m.check(13.2, true, EstimateStatus::kTracking, "", true, {20, 0, 0}).action,
            SafetyAction::kRetreat);
}

TEST(Safety, LeavingTheCorridorRetreats) {
  SafetyMonitor m;
  EXPECT_EQ(m.check(0.0, true, EstimateStatus::kTracking, "", true, {10, 1.0, 0}).action,
            SafetyAction::kProceed);
  const SafetyDecision d = m.check(0.1, true, EstimateStatus::kTracking, "", true, {10, 2.5, 0});
  EXPECT_EQ(d.action, SafetyAction::kRetreat);
  EXPECT_NE(d.reason.find("corridor"), std::string::npos);
}

TEST(Safety, NothingUsableYetIsAHoldNotARetreat) {
  SafetyMonitor m;
  EXPECT_EQ(m.check(100.0, false, EstimateStatus::kLost, "", false, Eigen::Vector3d::Zero()).action,
            SafetyAction::kHold);
}
