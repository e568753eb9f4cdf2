#include "lidar_driver.h"
#include <ardsim_msgs/log_throttle.h>
#include <ardsim_msgs/param_read.h>
#include <ardsim_msgs/subscriber_wait.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <diagnostic_msgs/DiagnosticArray.h>

#include "ardsim_description/frames.h"
#include "conversions.h"

namespace ardsim_lidar {

namespace {

constexpr std::uint32_t kRecorderQueue = 100;  // frames queued per subscriber connection

template <typename T>
void read(const ros::NodeHandle& nh, const std::string& name, T* value) {
  ardsim_msgs::readParam(nh, name, value, "config/lidar.yaml");
}

void readFloat(const ros::NodeHandle& nh, const std::string& name, double* value) {
  read(nh, name, value);
}

std::string describe(const std::vector<double>& values) {
  std::ostringstream text;
  for (double v : values) text << (text.tellp() > 0 ? " " : "") << v;
  return "[" + text.str() + "]";
}

}  // namespace

LidarNodeOptions loadOptions(const ros::NodeHandle& nh) {
  LidarNodeOptions o;
  std::string target = ardsim_description::targetKindName(o.target);
  read(nh, "target", &target);
  ardsim_msgs::validateParameters([&] { o.target = ardsim_description::parseTargetKind(target); },
                                  "target: ");
  read(nh, "width", &o.sensor.width);
  read(nh, "height", &o.sensor.height);
  readFloat(nh, "fov_deg", &o.sensor.fov_deg);
  readFloat(nh, "min_range_m", &o.sensor.min_range_m);
  readFloat(nh, "max_range_m", &o.sensor.max_range_m);
  readFloat(nh, "near_plane_m", &o.sensor.near_plane_m);
  ardsim_msgs::validateParameters([&] { validate(o.sensor); });

  int seed = static_cast<int>(o.seed);
  read(nh, "seed", &seed);
  if (seed < 0)
    throw std::invalid_argument("parameter seed = " + std::to_string(seed) + " is out of range: >= 0");
  o.seed = static_cast<std::uint64_t>(seed);
  readFloat(nh, "frame_rate_hz", &o.frame_rate_hz);
  if (!std::isfinite(o.frame_rate_hz) || o.frame_rate_hz < 0.0)
    throw std::invalid_argument("parameter frame_rate_hz = " + std::to_string(o.frame_rate_hz) +
                                " is out of range: >= 0 (0 = every truth step)");
  read(nh, "faults/drop_intervals_s", &o.faults.drop_intervals_s);
  read(nh, "faults/blind_intervals_s", &o.faults.blind_intervals_s);
  ardsim_msgs::validateParameters([&] { validate(o.faults); });
  read(nh, "frame_id", &o.frame_id);
  std::string platform = "auto";
  read(nh, "egl_platform", &platform);
  o.renderer.platform = parseEglPlatform(platform);
  read(nh, "triangles_per_chunk", &o.renderer.triangles_per_chunk);
  if (o.renderer.triangles_per_chunk < 1)
    throw std::invalid_argument("parameter triangles_per_chunk = " +
                                std::to_string(o.renderer.triangles_per_chunk) + " is out of range: >= 1");

  NoiseOptions& n = o.noise;
  read(nh, "noise/enabled", &n.enabled);
  readFloat(nh, "noise/detection_range_m", &n.detection_range_m);
  readFloat(nh, "noise/saturation_range_m", &n.saturation_range_m);
  read(nh, "noise/range_noise", &n.range_noise);
  readFloat(nh, "noise/range_sigma_floor_m", &n.range_sigma_floor_m);
  readFloat(nh, "noise/range_sigma_weak_m", &n.range_sigma_weak_m);
  read(nh, "noise/incidence_cutoff", &n.incidence_cutoff);
  readFloat(nh, "noise/max_incidence_deg", &n.max_incidence_deg);
  read(nh, "noise/return_probability", &n.return_probability);
  read(nh, "noise/dead_pixels", &n.dead_pixels);
  readFloat(nh, "noise/dead_pixel_fraction", &n.dead_pixel_fraction);
  read(nh, "noise/hot_pixels", &n.hot_pixels);
  readFloat(nh, "noise/hot_pixel_fraction", &n.hot_pixel_fraction);
  read(nh, "noise/background_returns", &n.background_returns);
  readFloat(nh, "noise/background_probability", &n.background_probability);
  readFloat(nh, "noise/background_intensity", &n.background_intensity);
  read(nh, "noise/mixed_pixels", &n.mixed_pixels);
  readFloat(nh, "noise/mixed_pixel_min_jump_m", &n.mixed_pixel_min_jump_m);
  readFloat(nh, "noise/mixed_pixel_probability", &n.mixed_pixel_probability);
  read(nh, "noise/retro_reflectors", &n.retro_reflectors);
  readFloat(nh, "noise/retro_gain", &n.retro_gain);
  readFloat(nh, "noise/retro_acceptance_deg", &n.retro_acceptance_deg);
  read(nh, "noise/blooming", &n.blooming);
  read(nh, "noise/bloom_radius_px", &n.bloom_radius_px);
  readFloat(nh, "noise/bloom_probability", &n.bloom_probability);
  read(nh, "noise/saturation", &n.saturation);
  readFloat(nh, "noise/saturation_range_bias_m", &n.saturation_range_bias_m);
  ardsim_msgs::validateParameters([&] { validate(n); });

  readFloat(nh, "iss/sarj_port_deg", &o.iss.sarj_port_deg);
  readFloat(nh, "iss/sarj_starboard_deg", &o.iss.sarj_starboard_deg);
  std::vector<double> beta_deg(o.iss.beta_deg.begin(), o.iss.beta_deg.end());
  read(nh, "iss/beta_deg", &beta_deg);
  if (beta_deg.size() != o.iss.beta_deg.size())
    throw std::invalid_argument("parameter iss/beta_deg = " + describe(beta_deg) +
                                " is out of range: allowed a list of 8 angles (deg)");
  std::copy(beta_deg.begin(), beta_deg.end(), o.iss.beta_deg.begin());
  read(nh, "iss/centreline_docking_target", &o.iss.centreline_docking_target);
  readFloat(nh, "hubble/solar_array_deg", &o.hubble.solar_array_deg);
  for (double angle : {o.iss.sarj_port_deg, o.iss.sarj_starboard_deg, o.hubble.solar_array_deg})
    if (!std::isfinite(angle)) throw std::invalid_argument("solar-array angle parameters must be finite");
  for (double angle : o.iss.beta_deg)
    if (!std::isfinite(angle)) throw std::invalid_argument("parameter iss/beta_deg must hold finite angles");
  return o;
}

LidarDriver::LidarDriver(ros::NodeHandle nh, const ros::NodeHandle& private_nh)
    : options_(loadOptions(private_nh)),
      simulator_(options_.sensor, options_.noise, options_.seed, options_.renderer),
      T_chaser_lidar_(ardsim_description::T_chaser_lidar()),
      synchronizer_(target_subscriber_, chaser_subscriber_, 10) {
  simulator_.setTarget(ardsim_description::buildTarget(options_.target, options_.iss, options_.hubble));
  empty_frame_.width = options_.sensor.width;
  empty_frame_.height = options_.sensor.height;
  const std::size_t pixels = static_cast<std::size_t>(options_.sensor.width) * options_.sensor.height;
  empty_frame_.range_m.assign(pixels, std::numeric_limits<float>::quiet_NaN());
  empty_frame_.intensity = empty_frame_.range_m;
  fault_frame_ = empty_frame_;
  // Latched, like every lockstep output: a subscriber that connects late (the pose estimator still loading
  // its model at start-up, or respawned) still gets the current step's frame, and the lockstep does not
  // stall. Each subscriber's connection queues up to 100 frames (130 MB of 256 x 256 clouds, held only while
  // a subscriber lags): the recorder may lag the lockstep by up to its recorder_lag_steps (20 by default;
  // with 2 queued it lost 1-2 % of a run's messages).
  points_publisher_ = nh.advertise<sensor_msgs::PointCloud2>("lidar/points", kRecorderQueue, true);
  range_publisher_ = nh.advertise<sensor_msgs::Image>("lidar/range", kRecorderQueue, true);
  camera_info_publisher_ = nh.advertise<sensor_msgs::CameraInfo>("lidar/camera_info", kRecorderQueue, true);
  // The aggregator's conventional, global topic.
  diagnostics_publisher_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", kRecorderQueue);
  synchronizer_.registerCallback(&LidarDriver::onTruth, this);
  // Listen to the truth (which lets the dynamics start) only once the frames' subscribers are connected.
  for (const ros::Publisher* frames : {&points_publisher_, &range_publisher_})
    ardsim_msgs::waitForRegisteredSubscribers(*frames, ros::WallTime::now() + ros::WallDuration(10.0),
                                              "lidar");
  target_subscriber_.subscribe(nh, "truth/target/odom", 10);
  chaser_subscriber_.subscribe(nh, "truth/chaser/odom", 10);
  ROS_INFO("lidar: %s, %dx%d, %.1f deg, range %.2f..%.0f m, noise %s, seed %llu; EGL %s, GL_RENDERER %s",
           ardsim_description::targetKindName(options_.target).c_str(), options_.sensor.width,
           options_.sensor.height, options_.sensor.fov_deg, options_.sensor.min_range_m,
           options_.sensor.max_range_m, options_.noise.enabled ? "on" : "off",
           static_cast<unsigned long long>(options_.seed), simulator_.renderer().eglPlatform().c_str(),
           simulator_.renderer().glRenderer().c_str());
}

void LidarDriver::onTruth(const nav_msgs::OdometryConstPtr& target,
                          const nav_msgs::OdometryConstPtr& chaser) {
  const ros::Time stamp = target->header.stamp;
  Eigen::Isometry3d T_eci_target = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_eci_chaser = Eigen::Isometry3d::Identity();
  std::string error;
  if (!bodyPoseFromOdometry(*target, &T_eci_target, &error) ||
      !bodyPoseFromOdometry(*chaser, &T_eci_chaser, &error)) {
    ARDSIM_ERROR_THROTTLE(5.0, "lidar: bad truth at t = %.6f: %s; answering with an empty frame",
                          stamp.toSec(), error.c_str());
    publish(empty_frame_, stamp, "bad truth: " + error, false);
    return;
  }
  const SensorFault fault = faultAt(options_.faults, stamp.toSec());
  if (fault != SensorFault::kNone) {
    // A scripted fault (scenario): the step is still answered, with what the faulty sensor delivers.
    applyFault(fault, &fault_frame_);
    publish(fault_frame_, stamp, std::string("fault: ") + faultName(fault) + " frame", false);
    return;
  }
  const bool stale = options_.frame_rate_hz > 0.0 && have_frame_ &&
                     (stamp - last_frame_time_).toSec() < 1.0 / options_.frame_rate_hz - 1e-9;
  if (!stale) {
    const Eigen::Isometry3d T_lidar_target =
        ardsim_description::lidarFromTarget(T_eci_target, T_eci_chaser, T_chaser_lidar_);
    // The stamp in nanoseconds selects the frame's noise: a frame is reproducible whatever ran before it.
    simulator_.simulate(T_lidar_target, stamp.toNSec(), &frame_);
    last_frame_time_ = stamp;
    have_frame_ = true;
  }
  publish(frame_, stamp, stale ? "repeated last frame (frame_rate_hz)" : "new frame", true);
}

void LidarDriver::publish(const LidarFrame& frame, const ros::Time& stamp, const std::string& status,
                          bool ok) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = options_.frame_id;
  points_publisher_.publish(toPointCloud2(frame, simulator_.rays(), header));
  range_publisher_.publish(toRangeImage(frame, header));
  camera_info_publisher_.publish(toCameraInfo(simulator_.rays().intrinsics(), header));

  diagnostic_msgs::DiagnosticArrayPtr diagnostics(new diagnostic_msgs::DiagnosticArray);
  diagnostics->header.stamp = stamp;
  diagnostic_msgs::DiagnosticStatus state;
  state.name = ros::this_node::getName() + ": flash lidar";
  state.hardware_id = simulator_.renderer().glRenderer();
  state.level = ok ? diagnostic_msgs::DiagnosticStatus::OK : diagnostic_msgs::DiagnosticStatus::ERROR;
  state.message = status;
  auto add = [&state](const std::string& key, const std::string& value) {
    diagnostic_msgs::KeyValue entry;
    entry.key = key;
    entry.value = value;
    state.values.push_back(entry);
  };
  const FrameTiming& timing = simulator_.lastTiming();
  add("render_ms", std::to_string(timing.render_ms));
  add("noise_ms", std::to_string(timing.noise_ms));
  add("returns", std::to_string(frame.returnCount()));
  add("triangles_drawn", std::to_string(simulator_.renderer().trianglesDrawnLastFrame()));
  add("egl_platform", simulator_.renderer().eglPlatform());
  add("gl_renderer", simulator_.renderer().glRenderer());
  diagnostics->status.push_back(state);
  diagnostics_publisher_.publish(diagnostics);
}

}  // namespace ardsim_lidar
