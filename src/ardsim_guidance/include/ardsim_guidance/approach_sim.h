// Offline closed-loop study of guidance, ROS-free: the truth dynamics of ardsim_dynamics (Simulation) with
// the target on a circular orbit holding its attitude in LVLH, under point-mass gravity without drag or
// gravity-gradient torque (so that only guidance and the estimate noise shape the result), the commanded
// force and torque applied exactly (no actuator limits beyond guidance's own), and pose estimates made from
// the truth by TruthPoseGenerator (noise, dropouts). Used by the tests and the approach_sim tool to measure
// contact conditions, delta-v and how estimate noise reaches the thrust, without ROS. Contact = the port
// reaching the port plane.
#pragma once

#include <string>

#include <Eigen/Geometry>

#include "ardsim_guidance/guidance.h"
#include "ardsim_guidance/truth_pose.h"

namespace ardsim_guidance {

struct ApproachSimOptions {
  GuidanceOptions guidance;
  TruthPoseOptions truth_pose;
  double orbit_radius_m = 6378136.3 + 415e3;  // ISS-like circular orbit
  Eigen::Vector3d start_port_position_m{100.0, 0.0,
                                        0.0};  // chaser port in target_port at t = 0, at rest in LVLH
  Eigen::Vector3d start_attitude_error_rad{0.0, 0.0, 0.0};  // roll, pitch, yaw added to the docking attitude
  double max_time_s = 3000.0;
  int substeps = 10;  // integration steps per control period
};

struct ApproachSimResult {
  bool contact = false;            // the vehicles touched
  bool captured = false;           // ... at the ports, inside the capture envelope
  std::string contact_reason;      // why a contact is a collision
  double time_s = 0.0;             // time of contact or end of the run
  double closing_speed_mps = 0.0;  // at contact, truth
  double lateral_misalignment_m = 0.0;
  double lateral_rate_mps = 0.0;
  double angular_misalignment_rad = 0.0;
  double angular_rate_rad_s = 0.0;
  double delta_v_mps = 0.0;           // commanded, as guidance counts it
  double rms_force_last_10m_n = 0.0;  // RMS of |commanded force| while the true range is below 10 m
  double max_corridor_ratio = 0.0;    // max over the near field of lateral offset / corridor radius (truth)
  Phase final_phase = Phase::kWait;
  std::string final_reason;
};

ApproachSimResult runApproachSim(const ApproachSimOptions& options);

}  // namespace ardsim_guidance
