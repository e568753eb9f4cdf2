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
    "                      [--width W] [--height H] [--fov-deg F] [--arrays-deg A] [--stamps FILE]\n"
    "POSES.csv rows: x y z qx qy qz qw, the pose of `target` in `lidar_optical` (m, Hamilton quaternion).\n"
    "--arrays-deg: the solar arrays turned by A degrees (ISS: both solar alpha rotary joints; Hubble: both\n"
    "arrays about their masts), to test estimators whose model has them at 0.\n"
    "--stamps FILE: one stamp (s, as scripts/run_poses --stamps writes them) per pose row; each frame's\n"
    "noise is then drawn as the lidar node draws that of a frame so stamped: with the run's lidar\n"
    "seed as --seed, a recorded run's frames come out as it saw them (else frame k is seeded with k).";

struct Arguments {
  std::string target;
  std::string poses;
  std::string out;
  bool noise = true;
  std::uint64_t seed = 1;
  double arrays_deg = 0.0;
  std::string stamps;
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
    } else if (flag == "--stamps") {
      a.stamps = value;
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

// A stamp in seconds as the nanoseconds the lidar node seeds its frame with (ros::Time::toNSec), read from
// the decimal text itself: through a double, 364.4 s would be 364399999999 ns.
std::uint64_t stampNanoseconds(const std::string& path, int line_number, const std::string& text) {
  const std::string where = path + ":" + std::to_string(line_number) + ": stamp '" + text + "' ";
  const std::size_t dot = text.find('.');
  const std::string whole = text.substr(0, dot);
  std::string fraction = dot == std::string::npos ? "" : text.substr(dot + 1);
  const auto digits = [](const std::string& t) {
    return t.find_first_not_of("0123456789") == std::string::npos;
  };
  if (whole.empty() || whole.size() > 10 || !digits(whole) || !digits(fraction) || fraction.size() > 9)
    throw std::invalid_argument(where + "is not a time of at most 9 decimals, >= 0 s");
  fraction.resize(9, '0');
  return std::stoull(whole) * 1000000000ull + std::stoull(fraction);
}

std::vector<std::uint64_t> readStamps(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot read " + path);
  std::vector<std::uint64_t> stamps_ns;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::size_t last = line.find_last_not_of(" \t\r");
    stamps_ns.push_back(stampNanoseconds(path, line_number, line.substr(first, last - first + 1)));
  }
  return stamps_ns;
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

  std::vector<std::uint64_t> stamps_ns;
  if (!args.stamps.empty()) {
    stamps_ns = readStamps(args.stamps);
    // A skipped row would pair every later pose with another frame's stamp.
    if (!errors.empty() || stamps_ns.size() != poses.size())
      throw std::invalid_argument("--stamps " + args.stamps + ": " + std::to_string(stamps_ns.size()) +
                                  " stamps for " + std::to_string(poses.size()) + " poses and " +
                                  std::to_string(errors.size()) + " bad rows: one stamp a pose row");
  }

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
  const auto write = [&](std::size_t index, const ardsim_lidar::LidarFrame& frame) {
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
  };
  if (stamps_ns.empty()) {
    simulator.simulateSequence(T_lidar_target, 0, write);
  } else {  // frame by frame: the sequence's seeds are consecutive
    ardsim_lidar::LidarFrame frame;
    for (std::size_t index = 0; index < poses.size(); ++index) {
      simulator.simulate(T_lidar_target[index], stamps_ns[index], &frame);
      write(index, frame);
    }
  }
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
