// render_dataset: renders the target at every pose of a list and writes, per pose, an organized binary PCD
// and a 16-bit range PNG, plus truth.csv. See README.md. Errors: one line on stderr, exit status 2.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <pcl/io/pcd_io.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "ardsim_description/models.h"
#include "ardsim_lidar/lidar_simulator.h"
#include "ardsim_lidar/pose_file.h"

namespace {

constexpr const char* kUsage =
    "usage: render_dataset --target iss|hubble --poses POSES.csv --out DIR [--noise on|off] [--seed N]\n"
    "                      [--width W] [--height H] [--fov-deg F] [--arrays-deg A]\n"
    "POSES.csv rows: x y z qx qy qz qw, the pose of `target` in `lidar_optical` (m, Hamilton quaternion).\n"
    "--arrays-deg: the solar arrays turned by A degrees (ISS: both solar alpha rotary joints; Hubble: both\n"
    "arrays about their masts), to test estimators whose model has them at 0.";

struct Arguments {
  std::string target;
  std::string poses;
  std::string out;
  bool noise = true;
  std::uint64_t seed = 1;
  double arrays_deg = 0.0;
  ardsim_lidar::SensorOptions sensor;
};

long parseInteger(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0') throw std::invalid_argument(flag + " '" + text + "' is not an integer");
  return value;
}

double parseNumber(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') throw std::invalid_argument(flag + " '" + text + "' is not a number");
  return value;
}

Arguments parseArguments(int argc, char** argv) {
  Arguments a;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "-h" || flag == "--help") {
      std::puts(kUsage);
      std::exit(0);
    }
    if (i + 1 >= argc) throw std::invalid_argument(flag + " needs a value (or is not an option)");
    const std::string value = argv[++i];
    if (flag == "--target") {
      a.target = value;
    } else if (flag == "--poses") {
      a.poses = value;
    } else if (flag == "--out") {
      a.out = value;
    } else if (flag == "--noise") {
      if (value != "on" && value != "off")
        throw std::invalid_argument("--noise '" + value + "' is not on or off");
      a.noise = value == "on";
    } else if (flag == "--seed") {
      const long seed = parseInteger(flag, value);
      if (seed < 0) throw std::invalid_argument("--seed " + value + " must be >= 0");
      a.seed = static_cast<std::uint64_t>(seed);
    } else if (flag == "--width") {
      a.sensor.width = static_cast<int>(parseInteger(flag, value));
    } else if (flag == "--height") {
      a.sensor.height = static_cast<int>(parseInteger(flag, value));
    } else if (flag == "--fov-deg") {
      a.sensor.fov_deg = parseNumber(flag, value);
    } else if (flag == "--arrays-deg") {
      a.arrays_deg = parseNumber(flag, value);
      if (!(std::abs(a.arrays_deg) <= 360.0))
        throw std::invalid_argument("--arrays-deg " + value + " is out of range: -360 .. 360");
    } else {
      throw std::invalid_argument("unknown option " + flag);
    }
  }
  if (a.target.empty() || a.poses.empty() || a.out.empty())
    throw std::invalid_argument("--target, --poses and --out are required");
  return a;
}

std::string frameName(std::size_t index, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06zu.%s", index, extension);
  return name;
}

int run(int argc, char** argv) {
  const Arguments args = parseArguments(argc, argv);
  const ardsim_description::TargetKind kind = ardsim_description::parseTargetKind(args.target);
  std::ifstream poses_file(args.poses);
  if (!poses_file) throw std::runtime_error("cannot read " + args.poses);
  std::vector<ardsim_lidar::PoseRow> poses;
  std::vector<ardsim_lidar::PoseRowError> errors;
  ardsim_lidar::parsePoses(poses_file, &poses, &errors);
  for (const auto& error : errors)
    std::fprintf(stderr, "%s:%d: %s (row skipped)\n", args.poses.c_str(), error.line_number,
                 error.message.c_str());

  ardsim_lidar::NoiseOptions noise;
  noise.enabled = args.noise;
  ardsim_lidar::LidarSimulator simulator(args.sensor, noise, args.seed);
  ardsim_description::IssOptions iss;
  iss.sarj_port_deg = iss.sarj_starboard_deg = args.arrays_deg;
  ardsim_description::HubbleOptions hubble;
  hubble.solar_array_deg = args.arrays_deg;
  simulator.setTarget(ardsim_description::buildTarget(kind, iss, hubble));
  std::filesystem::create_directories(args.out);
  const std::filesystem::path out(args.out);
  std::ofstream truth(out / "truth.csv");
  if (!truth) throw std::runtime_error("cannot write " + (out / "truth.csv").string());
  truth << "# frame x y z qx qy qz qw: T_lidar_target (pose of target in lidar_optical), m\n";
  truth.precision(17);

  // Frames are made pipelined (the GPU renders ahead while earlier frames get their noise and are written,
  // several at once); each is seeded by its row index, so the files are those of one-at-a-time rendering.
  std::vector<Eigen::Isometry3d> T_lidar_target;
  for (const auto& row : poses) T_lidar_target.push_back(row.T_lidar_target);
  std::atomic<std::size_t> clipped{0};
  simulator.simulateSequence(
      T_lidar_target, 0, [&](std::size_t index, const ardsim_lidar::LidarFrame& frame) {
        pcl::PointCloud<pcl::PointXYZI> cloud;
        ardsim_lidar::toPointCloud(frame, simulator.rays(), &cloud);
        const std::string pcd_path = (out / frameName(index, "pcd")).string();
        if (pcl::io::savePCDFileBinary(pcd_path, cloud) != 0)
          throw std::runtime_error("cannot write " + pcd_path);
        cv::Mat range_mm(frame.height, frame.width, CV_16UC1);
        for (int v = 0; v < frame.height; ++v) {
          for (int u = 0; u < frame.width; ++u) {
            const float range = frame.range_m[static_cast<std::size_t>(v) * frame.width + u];
            double millimetres = std::isnan(range) ? 0.0 : std::round(1000.0 * range);  // 0 = no return
            if (millimetres > 65535.0) {
              millimetres = 65535.0;  // 16-bit millimetres end at 65.535 m
              clipped.fetch_add(1, std::memory_order_relaxed);
            }
            range_mm.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(millimetres);
          }
        }
        const std::string png_path = (out / frameName(index, "png")).string();
        if (!cv::imwrite(png_path, range_mm)) throw std::runtime_error("cannot write " + png_path);
      });
  for (std::size_t index = 0; index < poses.size(); ++index) {
    const Eigen::Isometry3d& T = poses[index].T_lidar_target;
    const Eigen::Quaterniond q(T.linear());
    truth << index << ' ' << T.translation().x() << ' ' << T.translation().y() << ' ' << T.translation().z()
          << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  }
  std::printf("render_dataset: %zu frames in %s (%zu bad rows skipped; GL_RENDERER %s)\n", poses.size(),
              args.out.c_str(), errors.size(), simulator.renderer().glRenderer().c_str());
  if (clipped.load() > 0)
    std::printf(
        "render_dataset: %zu returns beyond 65.535 m saturate the 16-bit PNG at 65535 mm (the PCD keeps "
        "them)\n",
        clipped.load());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_dataset: %s (--help for usage)\n", e.what());
    return 2;
  }
}
