// propagate SCENARIO.yaml [--duration S] [--every S] [--out FILE.csv]
// Runs a scenario's truth dynamics without ROS or thrust and writes a CSV of both vehicles' eci states and
// the chaser's state in the target's LVLH (and its port relative to the target port), for fast orbit
// analysis. A first contact between the vehicles ends the run: its last row is the contact state, and the
// verdict goes to stderr.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "ardsim_dynamics/simulation.h"

namespace {

constexpr const char* kUsage = "usage: propagate SCENARIO.yaml [--duration S] [--every S] [--out FILE.csv]";

[[noreturn]] void die(const std::string& message) {
  std::cerr << "propagate: " << message << "\n";
  std::exit(2);
}

double positiveNumber(const std::string& text, const std::string& option) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(value > 0.0) || !std::isfinite(value))
    die(option + " '" + text + "' is not a positive number (" + kUsage + ")");
  return value;
}

void writeVehicle(std::ostream& out, const ardsim_dynamics::VehicleState& s) {
  out << ',' << s.position_m.x() << ',' << s.position_m.y() << ',' << s.position_m.z() << ','
      << s.velocity_mps.x() << ',' << s.velocity_mps.y() << ',' << s.velocity_mps.z() << ',' << s.attitude.x()
      << ',' << s.attitude.y() << ',' << s.attitude.z() << ',' << s.attitude.w() << ','
      << s.angular_velocity_radps.x() << ',' << s.angular_velocity_radps.y() << ','
      << s.angular_velocity_radps.z();
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario_path, out_path;
  double duration = -1.0, every = -1.0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--duration" || arg == "--every" || arg == "--out") {
      if (i + 1 >= argc) die(arg + " needs a value (" + std::string(kUsage) + ")");
      const std::string value = argv[++i];
      if (arg == "--duration") duration = positiveNumber(value, arg);
      if (arg == "--every") every = positiveNumber(value, arg);
      if (arg == "--out") out_path = value;
    } else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage << "\n";
      return 0;
    } else if (scenario_path.empty()) {
      scenario_path = arg;
    } else {
      die("unexpected argument '" + arg + "' (" + kUsage + ")");
    }
  }
  if (scenario_path.empty()) die(std::string("a scenario file is required (") + kUsage + ")");
  try {
    const ardsim_dynamics::Scenario scenario = ardsim_dynamics::loadScenario(scenario_path);
    if (duration < 0.0) duration = scenario.duration_s;
    if (every < 0.0) every = scenario.control_step_s;
    const long stride = std::max(1L, std::lround(every / scenario.control_step_s));
    std::ofstream file;
    if (!out_path.empty()) {
      file.open(out_path);
      if (!file) die("cannot write '" + out_path + "'");
    }
    std::ostream& out = out_path.empty() ? std::cout : file;
    out.precision(17);
    out << "t_s";
    for (const char* v : {"target", "chaser"})
      for (const char* c : {"x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps", "qx", "qy", "qz", "qw",
                            "wx_radps", "wy_radps", "wz_radps"})
        out << ',' << v << '_' << c;
    out << ",lvlh_x_m,lvlh_y_m,lvlh_z_m,lvlh_vx_mps,lvlh_vy_mps,lvlh_vz_mps,port_x_m,port_y_m,port_z_m\n";
    ardsim_dynamics::Simulation sim(scenario);
    const long steps = std::lround(duration / scenario.control_step_s);
    for (long k = 0; k <= steps; ++k) {
      const bool contact = sim.contact().has_value();
      if (k % stride == 0 || k == steps || contact) {
        out << sim.time();
        writeVehicle(out, sim.target());
        writeVehicle(out, sim.chaser());
        const ardsim_dynamics::CartesianState rel = sim.chaserInTargetLvlh();
        const Eigen::Vector3d port = sim.chaserPortInTargetPort().pose.translation();
        out << ',' << rel.position_m.x() << ',' << rel.position_m.y() << ',' << rel.position_m.z() << ','
            << rel.velocity_mps.x() << ',' << rel.velocity_mps.y() << ',' << rel.velocity_mps.z() << ','
            << port.x() << ',' << port.y() << ',' << port.z() << '\n';
      }
      if (contact) {
        std::cerr << "propagate: " << ardsim_dynamics::verdictName(sim.contact()->verdict)
                  << " at t = " << sim.time() << " s: " << sim.contact()->reason << "\n";
        break;
      }
      if (k < steps) sim.step(ardsim_dynamics::BodyWrench{});
    }
  } catch (const std::exception& e) {
    die(e.what());
  }
  return 0;
}
