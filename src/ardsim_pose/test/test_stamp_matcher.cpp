// StampMatcher (the evaluator's pairing of estimates with truth by stamp), time going back in particular.
#include <string>

#include <gtest/gtest.h>

#include "ardsim_pose/stamp_matcher.h"

namespace ardsim_pose {
namespace {

// Stream 0 stands for the estimates, 1 and 2 for the two truth states; a message is its stream's letter and
// stamp.
using Matcher = StampMatcher<std::string, std::string, std::string>;
constexpr Matcher::Stamp kSecond = 1000000000;
constexpr Matcher::Stamp kFrame = kSecond / 10;

// The truths of a frame, then its estimate (the order of a simulation or a replay): the estimate's match, if
// any.
std::optional<Matcher::Match> frame(Matcher* matcher, int k) {
  const Matcher::Stamp stamp = k * kFrame;
  EXPECT_FALSE(matcher->add<1>(stamp, "t" + std::to_string(k)).match);
  EXPECT_FALSE(matcher->add<2>(stamp, "c" + std::to_string(k)).match);
  return matcher->add<0>(stamp, "e" + std::to_string(k)).match;
}

TEST(StampMatcher, MatchesByStampWhicheverArrivesFirst) {
  Matcher matcher(100, kSecond);
  EXPECT_FALSE(matcher.add<0>(kFrame, "e1").match);
  EXPECT_FALSE(matcher.add<2>(kFrame, "c1").match);
  EXPECT_FALSE(matcher.add<1>(2 * kFrame, "t2").match);
  const auto match = matcher.add<1>(kFrame, "t1").match;
  ASSERT_TRUE(match);
  EXPECT_EQ(*match, Matcher::Match("e1", "t1", "c1"));
  EXPECT_EQ(matcher.waiting(), 1u);  // t2
  ASSERT_TRUE(frame(&matcher, 3));
  EXPECT_EQ(matcher.waiting(), 0u);  // t2 is older than the match at 3: it will not be completed
}

TEST(StampMatcher, AFullBufferDropsItsOldest) {
  Matcher matcher(2, kSecond);
  for (int k = 1; k <= 3; ++k) matcher.add<0>(k * kFrame, "e" + std::to_string(k));
  matcher.add<1>(kFrame, "t1");
  EXPECT_FALSE(matcher.add<2>(kFrame, "c1").match);  // e1 was dropped
  matcher.add<1>(2 * kFrame, "t2");
  EXPECT_TRUE(matcher.add<2>(2 * kFrame, "c2").match);
}

// A bag played again: estimates of the first pass that never got their truth, as many as the buffer holds,
// are newer than the second pass's; with one time line they pushed its estimates out and left them unmatched.
TEST(StampMatcher, TimeGoingBackKeepsTheOldTimeLineApart) {
  Matcher matcher(3, kSecond);
  for (int k = 1; k <= 70; ++k) ASSERT_TRUE(frame(&matcher, k));
  for (int k = 80; k <= 82; ++k) matcher.add<0>(k * kFrame, "e" + std::to_string(k));
  const Matcher::Added back = matcher.add<1>(kFrame, "t1");
  ASSERT_TRUE(back.went_back_from);
  EXPECT_EQ(*back.went_back_from, 70 * kFrame);
  EXPECT_FALSE(matcher.add<2>(kFrame, "c1").went_back_from);
  const auto match = matcher.add<0>(kFrame, "e1").match;
  ASSERT_TRUE(match);
  EXPECT_EQ(*match, Matcher::Match("e1", "t1", "c1"));
  for (int k = 2; k <= 5; ++k) EXPECT_TRUE(frame(&matcher, k)) << k;
}

// The truths of the next pass come before the last estimates of the pass before (they waited in the pose
// node's queue): those are matched with their own truths, and the new pass's waiting messages stay.
TEST(StampMatcher, LateMessagesOfTheTimeLineBeforeAreMatchedWithIt) {
  Matcher matcher(100, kSecond);
  for (int k = 1; k <= 548; ++k) ASSERT_TRUE(frame(&matcher, k));
  for (int k = 549; k <= 550; ++k) {
    matcher.add<1>(k * kFrame, "t" + std::to_string(k));
    matcher.add<2>(k * kFrame, "c" + std::to_string(k));
  }
  EXPECT_TRUE(matcher.add<1>(0, "t0").went_back_from);  // the old line's last match was 548
  matcher.add<2>(0, "c0");
  matcher.add<1>(kFrame, "t1");
  matcher.add<2>(kFrame, "c1");
  for (int k = 549; k <= 550; ++k) {
    const Matcher::Added late = matcher.add<0>(k * kFrame, "e" + std::to_string(k));
    EXPECT_FALSE(late.went_back_from);
    ASSERT_TRUE(late.match) << k;
    EXPECT_EQ(std::get<1>(*late.match), "t" + std::to_string(k));
  }
  EXPECT_TRUE(matcher.add<0>(0, "e0").match);
  EXPECT_TRUE(matcher.add<0>(kFrame, "e1").match);
}

TEST(StampMatcher, AFrameOutOfOrderIsNotTimeGoingBack) {
  Matcher matcher(100, kSecond);
  for (int k = 1; k <= 20; ++k) ASSERT_TRUE(frame(&matcher, k));
  const Matcher::Added early = matcher.add<0>(18 * kFrame, "e18 again");
  EXPECT_FALSE(early.went_back_from);
  EXPECT_FALSE(early.match);  // its truths are gone
  EXPECT_TRUE(frame(&matcher, 21));
}

// Once the new time line reaches the old one's stamps the two cannot be told apart: the old one is dropped
// and a message of such a stamp belongs to the new line.
TEST(StampMatcher, TheOldTimeLineIsDroppedWhereTheNewOneReachesIt) {
  Matcher matcher(100, kSecond);
  for (int k = 1; k <= 30; ++k) ASSERT_TRUE(frame(&matcher, k));
  matcher.add<1>(31 * kFrame, "t31 old");
  matcher.add<2>(31 * kFrame, "c31 old");
  for (int k = 1; k <= 25; ++k) ASSERT_TRUE(frame(&matcher, k)) << k;
  EXPECT_EQ(matcher.waiting(), 0u);  // at 2.5 s, within 1 s of the old line's 3.1 s
  EXPECT_FALSE(matcher.add<0>(31 * kFrame, "e31").match);
}

}  // namespace
}  // namespace ardsim_pose
