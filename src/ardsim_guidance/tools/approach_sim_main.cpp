// approach_sim: runs guidance against the offline plant of approach_sim.h and prints the contact conditions,
// delta-v and the RMS commanded force over the last 10 m. Arguments are key=value:
//   velocity=kalman|differencing  position_sigma_m=0.02  attitude_sigma_deg=0.1  seed=1
//   start_x=100 start_y=0 start_z=0  attitude_offset_deg=0  max_time_s=3000  lost_t0=-1 lost_t1=-1
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "ardsim_guidance/approach_sim.h"

using namespace ardsim_guidance;

int main(int argc, char** argv) {
  std::map<std::string, std::string> args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "argument '%s' is not key=value\n", a.c_str());
      return 2;
    }
    args[a.substr(0, eq)] = a.substr(eq + 1);
  }
  auto num = [&](const std::string& key, double fallback) {
    return args.count(key) ? std::atof(args[key].c_str()) : fallback;
  };
  ApproachSimOptions o;
  try {
    o.guidance.navigator.velocity_source =
        parseVelocitySource(args.count("velocity") ? args["velocity"] : "kalman");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  o.truth_pose.position_sigma_m = num("position_sigma_m", 0.0);
  o.truth_pose.attitude_sigma_rad = num("attitude_sigma_deg", 0.0) * M_PI / 180.0;
  o.truth_pose.seed = static_cast<int>(num("seed", 1));
  o.guidance.navigator.measurement_sigma_m = std::max(0.01, o.truth_pose.position_sigma_m);
  if (num("lost_t1", -1.0) >= 0.0)
    o.truth_pose.lost_intervals_s.push_back({num("lost_t0", 0.0), num("lost_t1", 0.0)});
  o.start_port_position_m = {num("start_x", 100.0), num("start_y", 0.0), num("start_z", 0.0)};
  const double offset = num("attitude_offset_deg", 0.0) * M_PI / 180.0;
  o.start_attitude_error_rad = Eigen::Vector3d(offset, offset, offset) / std::sqrt(3.0);
  o.max_time_s = num("max_time_s", 3000.0);
  try {
    const ApproachSimResult r = runApproachSim(o);
    std::printf("%s at t = %.1f s, final phase %s (%s)\n",
                !r.contact   ? "no contact"
                : r.captured ? "CAPTURE"
                             : ("COLLISION: " + r.contact_reason).c_str(),
                r.time_s, phaseName(r.final_phase), r.final_reason.c_str());
    std::printf(
        "closing speed %.4f m/s, lateral %.4f m, lateral rate %.4f m/s, angular misalignment %.3f deg, "
        "angular rate %.4f deg/s\n",
        r.closing_speed_mps, r.lateral_misalignment_m, r.lateral_rate_mps,
        r.angular_misalignment_rad * 180.0 / M_PI, r.angular_rate_rad_s * 180.0 / M_PI);
    std::printf(
        "delta-v commanded %.3f m/s, RMS |force| over the last 10 m %.2f N, max lateral/corridor %.3f\n",
        r.delta_v_mps, r.rms_force_last_10m_n, r.max_corridor_ratio);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}
