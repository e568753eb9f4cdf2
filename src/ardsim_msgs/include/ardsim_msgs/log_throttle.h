// Wall-clock throttled logging for every ardsim node. rosconsole's *_THROTTLE macros compare against
// ros::Time::now(), which under sim time starts at 0 with the last hit at 0: every message in the first
// `period` seconds of simulation is silently dropped. Throttle on wall time instead (it only decides what is
// logged, never a result).
#pragma once

#include <ros/console.h>
#include <ros/time.h>

#define ARDSIM_LOG_THROTTLE(level_macro, period_s, ...)                                        \
  do {                                                                                         \
    static ros::WallTime ardsim_last_hit_;                                                     \
    const ros::WallTime ardsim_now_ = ros::WallTime::now();                                    \
    if (ardsim_last_hit_.isZero() || (ardsim_now_ - ardsim_last_hit_).toSec() >= (period_s)) { \
      ardsim_last_hit_ = ardsim_now_;                                                          \
      level_macro(__VA_ARGS__);                                                                \
    }                                                                                          \
  } while (0)
#define ARDSIM_WARN_THROTTLE(period_s, ...) ARDSIM_LOG_THROTTLE(ROS_WARN, period_s, __VA_ARGS__)
#define ARDSIM_ERROR_THROTTLE(period_s, ...) ARDSIM_LOG_THROTTLE(ROS_ERROR, period_s, __VA_ARGS__)
