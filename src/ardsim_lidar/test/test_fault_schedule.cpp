#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "ardsim_lidar/fault_schedule.h"

namespace ardsim_lidar {
namespace {

LidarFrame frameWithReturns(int width, int height) {
  LidarFrame frame;
  frame.width = width;
  frame.height = height;
  frame.range_m.assign(static_cast<std::size_t>(width * height), 12.5f);
  frame.intensity.assign(static_cast<std::size_t>(width * height), 0.3f);
  return frame;
}

TEST(FaultSchedule, IntervalsAreClosedAndDroppedWinsOverBlinded) {
  FaultOptions options;
  options.drop_intervals_s = {10.0, 12.0, 30.0, 30.0};
  options.blind_intervals_s = {11.0, 20.0};
  validate(options);
  EXPECT_EQ(faultAt(options, 9.9), SensorFault::kNone);
  EXPECT_EQ(faultAt(options, 10.0), SensorFault::kDropped);
  EXPECT_EQ(faultAt(options, 11.5), SensorFault::kDropped);
  EXPECT_EQ(faultAt(options, 12.1), SensorFault::kBlinded);
  EXPECT_EQ(faultAt(options, 20.0), SensorFault::kBlinded);
  EXPECT_EQ(faultAt(options, 20.1), SensorFault::kNone);
  EXPECT_EQ(faultAt(options, 30.0), SensorFault::kDropped);
  EXPECT_EQ(faultAt(FaultOptions{}, 10.0), SensorFault::kNone);
}

TEST(FaultSchedule, BadIntervalListsNameTheParameter) {
  FaultOptions odd;
  odd.drop_intervals_s = {1.0, 2.0, 3.0};
  try {
    validate(odd);
    FAIL() << "an odd list was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("faults/drop_intervals_s = [1 2 3]"), std::string::npos) << e.what();
  }
  FaultOptions reversed;
  reversed.blind_intervals_s = {5.0, 4.0};
  EXPECT_THROW(validate(reversed), std::invalid_argument);
  FaultOptions not_finite;
  not_finite.blind_intervals_s = {std::numeric_limits<double>::quiet_NaN(), 4.0};
  EXPECT_THROW(validate(not_finite), std::invalid_argument);
}

TEST(FaultSchedule, DroppedFrameHasNoReturnsAndBlindedFrameIsSaturatedWithoutRange) {
  LidarFrame dropped = frameWithReturns(4, 3);
  applyFault(SensorFault::kDropped, &dropped);
  EXPECT_EQ(dropped.width, 4);
  EXPECT_EQ(dropped.height, 3);
  ASSERT_EQ(dropped.range_m.size(), 12u);
  EXPECT_EQ(dropped.returnCount(), 0u);
  for (float i : dropped.intensity) EXPECT_TRUE(std::isnan(i));

  LidarFrame blinded = frameWithReturns(4, 3);
  applyFault(SensorFault::kBlinded, &blinded);
  EXPECT_EQ(blinded.returnCount(), 0u);
  for (float i : blinded.intensity) EXPECT_EQ(i, 1.0f);

  LidarFrame untouched = frameWithReturns(4, 3);
  applyFault(SensorFault::kNone, &untouched);
  EXPECT_EQ(untouched.returnCount(), 12u);
}

}  // namespace
}  // namespace ardsim_lidar
