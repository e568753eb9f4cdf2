// Sensor faults injected by scenario: time intervals in which the LIDAR delivers nothing usable. ROS-free.
//   dropped: the frame is lost (the node still answers the step, with an all-NaN frame: no return, no
//   intensity); blinded: the detector is saturated (sun or stray light in the field of view): no range
//   anywhere, intensity 1.
#pragma once

#include <vector>

#include "ardsim_lidar/noise_model.h"

namespace ardsim_lidar {

enum class SensorFault { kNone, kDropped, kBlinded };

struct FaultOptions {
  // Flat lists [t0, t1, t0, t1, ...] of closed intervals in simulation time, s (t0 <= t1).
  std::vector<double> drop_intervals_s;
  std::vector<double> blind_intervals_s;
};

// Throws std::invalid_argument naming the parameter (faults/drop_intervals_s or faults/blind_intervals_s)
// when a list has an odd length, a non-finite time or an interval that ends before it starts.
void validate(const FaultOptions& options);

// The fault active at time t_s; a dropped frame wins over a blinded one where intervals overlap.
SensorFault faultAt(const FaultOptions& options, double t_s);

// Overwrites the frame (width and height kept) with what the sensor delivers under the fault; kNone leaves
// it.
void applyFault(SensorFault fault, LidarFrame* frame);

const char* faultName(SensorFault fault);

}  // namespace ardsim_lidar
