// approach_poses: writes the pose list of an approach along the docking axis for render_dataset: the chaser
// in docking attitude, its port from --from to --to metres out of the target port in --frames steps, the
// lidar on its port axis (the target port on the boresight). Errors: one line on stderr, exit status 2.
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "ardsim_pose/evaluation.h"

namespace {

constexpr const char* kUsage =
    "usage: approach_poses --target iss|hubble --from M --to M --frames N > POSES.csv\n"
    "Rows: x y z qx qy qz qw, T_lidar_target (render_dataset's pose list). --from/--to: chaser port "
    "distance\n"
    "from the target port, m (the lidar is 1 m behind the chaser port).";

double number(const std::string& flag, const std::string& value) {
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0') throw std::invalid_argument(flag + " '" + value + "' is not a number");
  return v;
}

int run(int argc, char** argv) {
  std::string target;
  double from_m = -1.0, to_m = -1.0;
  int frames = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "-h" || flag == "--help") {
      std::puts(kUsage);
      return 0;
    }
    if (i + 1 >= argc) throw std::invalid_argument(flag + " needs a value");
    const std::string value = argv[++i];
    if (flag == "--target")
      target = value;
    else if (flag == "--from")
      from_m = number(flag, value);
    else if (flag == "--to")
      to_m = number(flag, value);
    else if (flag == "--frames")
      frames = static_cast<int>(number(flag, value));
    else
      throw std::invalid_argument("unknown option " + flag);
  }
  if (target.empty() || !(from_m > 0.0) || !(to_m > 0.0) || frames < 1)
    throw std::invalid_argument("--target, --from > 0, --to > 0 and --frames >= 1 are required");
  const ardsim_description::TargetKind kind = ardsim_description::parseTargetKind(target);
  std::printf("# x y z qx qy qz qw: T_lidar_target, %s docking axis, chaser port %g m -> %g m\n",
              target.c_str(), from_m, to_m);
  for (int k = 0; k < frames; ++k) {
    const double d = frames == 1 ? from_m : from_m + (to_m - from_m) * k / (frames - 1);
    const Eigen::Isometry3d T = ardsim_pose::dockingAxisPose(kind, d);
    const Eigen::Quaterniond q(T.linear());
    std::printf("%.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", T.translation().x(), T.translation().y(),
                T.translation().z(), q.x(), q.y(), q.z(), q.w());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "approach_poses: %s (--help for usage)\n", e.what());
    return 2;
  }
}
