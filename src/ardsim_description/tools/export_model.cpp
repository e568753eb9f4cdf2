// export_model --target iss|hubble|chaser --out FILE.{ply,stl} [--rigid-only] [--no-centreline-target]
//   [--sarj-deg A] [--hubble-array-deg A]
// Writes a vehicle's procedural mesh in its body frame (metres) for rviz and other tools. Errors are one line
// on stderr and exit status 2.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <stdexcept>
#include <string>

#include "ardsim_description/mesh_io.h"
#include "ardsim_description/mesh_tools.h"
#include "ardsim_description/models.h"

using namespace ardsim_description;

namespace {

const char* kUsage =
    "usage: export_model --target iss|hubble|chaser --out FILE.{ply,stl} [--rigid-only] "
    "[--no-centreline-target]\n"
    "                    [--sarj-deg A] [--hubble-array-deg A]";

double parseDegrees(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(value)) {
    throw std::invalid_argument(flag + " '" + text + "' is not a number of degrees");
  }
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string target, out;
    bool rigid_only = false;
    IssOptions iss;
    HubbleOptions hubble;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--target") {
        target = value();
      } else if (arg == "--out") {
        out = value();
      } else if (arg == "--rigid-only") {
        rigid_only = true;
      } else if (arg == "--no-centreline-target") {
        iss.centreline_docking_target = false;
      } else if (arg == "--sarj-deg") {
        iss.sarj_port_deg = iss.sarj_starboard_deg = parseDegrees(arg, value());
      } else if (arg == "--hubble-array-deg") {
        hubble.solar_array_deg = parseDegrees(arg, value());
      } else if (arg == "-h" || arg == "--help") {
        std::cout << kUsage << '\n';
        return 0;
      } else {
        throw std::invalid_argument("unknown argument '" + arg + "'");
      }
    }
    if (target.empty() || out.empty()) throw std::invalid_argument("--target and --out are required");
    if (target != "iss" && target != "hubble" && target != "chaser") {
      throw std::invalid_argument("--target '" + target + "' is not one of: iss, hubble, chaser");
    }
    TriangleMesh mesh;
    if (target == "chaser") {
      mesh = buildChaser();
    } else if (parseTargetKind(target) == TargetKind::kIss) {
      mesh = buildIss(iss);
    } else {
      mesh = buildHubble(hubble);
    }
    if (rigid_only) mesh = rigidStructure(mesh);
    writeMesh(mesh, out);
    std::cout << "export_model: wrote " << out << ": " << mesh.triangles.size() << " triangles, "
              << mesh.vertices.size() << " vertices, " << mesh.parts.size() << " parts\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "export_model: " << e.what() << " (see --help)\n";
    return 2;
  }
}
