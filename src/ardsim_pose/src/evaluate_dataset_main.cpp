// evaluate_dataset: runs the pose estimator over a render_dataset directory in frame order as one tracking
// sequence, writes DIR/estimates.csv (or --out CSV), prints a table by range band and one summary line. See
// README.md. Errors: one line on stderr, exit status 2.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ardsim_pose/dataset.h"
#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"

namespace {

constexpr const char* kUsage =
    "usage: evaluate_dataset --dataset DIR [--method icp|auto|ring|pyramid] [--init truth|perturbed]\n"
    "                        [--seed N] [--target iss|hubble] [--frame-period-s S] [--median-filter on|off]\n"
    "                        [--out CSV]\n"
    "Runs the estimator over DIR/frame_*.pcd in the order of DIR/truth.csv; writes DIR/estimates.csv, or "
    "CSV\n"
    "(runs of several configurations over one dataset at once then keep their own).\n"
    "--init truth: the first frame starts from its truth; perturbed (default): from the coarse prior\n"
    "(truth turned 10 deg about the port, port range 10 % off, 2 m lateral; directions seeded by --seed).\n"
    "Prints per range band (lidar to port) the position error of the port and the attitude error: the whole\n"
    "rotation (att), its part across the boresight (tilt) and about it (bore), and how the estimate's\n"
    "covariance fits its errors: the RMS of each error over its sigma (z_lat: the port across the\n"
    "boresight, z_rng: along it, z_att: the attitude; 1 = the covariance is right, < 1 pessimistic,\n"
    "> 1 optimistic). LOST frames are left out.";

struct Arguments {
  std::string dataset;
  std::string out;  // the estimates' CSV; empty: DIR/estimates.csv
  std::string init = "perturbed";
  std::uint64_t seed = 1;
  double frame_period_s = 0.1;
  ardsim_pose::PoseConfig config;
};

std::string onOff(const std::string& flag, const std::string& value) {
  if (value != "on" && value != "off")
    throw std::invalid_argument(flag + " '" + value + "' is not on or off");
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
    char* end = nullptr;
    if (flag == "--dataset") {
      a.dataset = value;
    } else if (flag == "--method") {
      a.config.method = value;
    } else if (flag == "--init") {
      if (value != "truth" && value != "perturbed")
        throw std::invalid_argument("--init '" + value + "' is not truth or perturbed");
      a.init = value;
    } else if (flag == "--seed") {
      const long long seed = std::strtoll(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0' || seed < 0)
        throw std::invalid_argument("--seed '" + value + "' is not an integer >= 0");
      a.seed = static_cast<std::uint64_t>(seed);
    } else if (flag == "--target") {
      a.config.target = ardsim_description::parseTargetKind(value);
    } else if (flag == "--frame-period-s") {
      a.frame_period_s = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0' || !(a.frame_period_s > 0.0))
        throw std::invalid_argument("--frame-period-s '" + value + "' is not a number > 0");
    } else if (flag == "--median-filter") {
      a.config.estimator.median_filter = onOff(flag, value) == "on";
    } else if (flag == "--out") {
      a.out = value;
    } else {
      throw std::invalid_argument("unknown option " + flag);
    }
  }
  if (a.dataset.empty()) throw std::invalid_argument("--dataset is required");
  if (a.out.empty()) a.out = a.dataset + "/estimates.csv";
  ardsim_pose::applyTargetDefaults(&a.config);
  return a;
}

struct Band {
  double min_m = 0.0, max_m = 0.0;
  std::vector<double> pos, att, tilt, boresight, ms;  // tilt: across the boresight; boresight: about it
  // Errors over the estimate's own sigmas (normalizedError): the port across the boresight (x and y), along
  // it, the attitude about all three axes.
  std::vector<double> z_lateral, z_range, z_attitude;
  int frames = 0, lost = 0;
};

double rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / v.size());
}
double maxOf(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}
double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

const char* statusName(ardsim_pose::EstimateStatus s) {
  switch (s) {
    case ardsim_pose::EstimateStatus::kTracking:
      return "TRACKING";
    case ardsim_pose::EstimateStatus::kDegraded:
      return "DEGRADED";
    default:
      return "LOST";
  }
}

int run(int argc, char** argv) {
  const Arguments args = parseArguments(argc, argv);
  const std::vector<ardsim_pose::TruthRow> truth = ardsim_pose::readTruth(args.dataset + "/truth.csv");
  if (truth.empty()) throw std::runtime_error(args.dataset + "/truth.csv has no frames");
  // The sensor's size is the dataset's (render_dataset --width/--height), the field of view the default.
  ardsim_pose::PoseConfig config = args.config;
  const ardsim_pose::OrganizedCloud first_cloud =
      ardsim_pose::loadFrame(ardsim_pose::framePath(args.dataset, truth.front().frame), 0.0);
  config.sensor.width = first_cloud.width;
  config.sensor.height = first_cloud.height;
  std::unique_ptr<ardsim_pose::PoseEstimator> estimator = ardsim_pose::makeEstimator(config);
  const Eigen::Isometry3d T_target_port = ardsim_description::T_target_port(config.target);
  const Eigen::Isometry3d& first = truth.front().T_lidar_target;
  estimator->setPrior(args.init == "truth" ? first
                                           : ardsim_pose::perturbPrior(first, T_target_port, {}, args.seed));

  std::ofstream csv(args.out);
  if (!csv) throw std::runtime_error("cannot write " + args.out);
  csv << "frame,stamp_s,status,x,y,z,qx,qy,qz,qw,range_m,pos_err_m,att_err_deg,fit_rms_m,inlier_fraction,"
         "points_used,iterations,ms,reason,port_sigma_x_m,port_sigma_y_m,port_sigma_z_m,att_sigma_x_deg,"
         "att_sigma_y_deg,att_sigma_z_deg\n";
  csv.precision(10);
  std::vector<Band> bands;
  for (const auto& [min_m, max_m] :
       {std::pair{0.0, 10.0}, {10.0, 20.0}, {20.0, 30.0}, {30.0, 50.0}, {50.0, 75.0}, {75.0, 1e9}}) {
    bands.emplace_back();
    bands.back().min_m = min_m;
    bands.back().max_m = max_m;
  }
  Band all;
  all.min_m = 0.0;
  all.max_m = 1e9;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const double stamp_s = static_cast<double>(k) * args.frame_period_s;
    const ardsim_pose::OrganizedCloud cloud =
        ardsim_pose::loadFrame(ardsim_pose::framePath(args.dataset, truth[k].frame), stamp_s);
    const ardsim_pose::EstimatorOutput out = estimator->process(cloud);
    const ardsim_pose::PoseErrorValue e =
        ardsim_pose::poseError(out.result.T_lidar_target, truth[k].T_lidar_target, T_target_port);
    const bool lost = out.result.status == ardsim_pose::EstimateStatus::kLost;
    const ardsim_pose::NormalizedError z =
        ardsim_pose::normalizedError(e, out.result.covariance, out.result.T_lidar_target, T_target_port);
    const double pos = e.port_position_error_m.norm();
    const double att_deg = e.attitude_error_angle_rad * 180.0 / M_PI;
    for (Band* band : {&all, &*std::find_if(bands.begin(), bands.end(), [&](const Band& b) {
                         return e.range_m >= b.min_m && e.range_m < b.max_m;
                       })}) {
      ++band->frames;
      band->ms.push_back(out.compute_ms);
      if (lost) {
        ++band->lost;
      } else {
        band->pos.push_back(pos);
        band->att.push_back(att_deg);
        band->tilt.push_back(e.attitude_error_rad.head<2>().norm() * 180.0 / M_PI);
        band->boresight.push_back(std::abs(e.attitude_error_rad.z()) * 180.0 / M_PI);
        if (z.port_sigma_m.minCoeff() > 0.0 && z.attitude_sigma_rad.minCoeff() > 0.0) {
          band->z_lateral.insert(band->z_lateral.end(), {z.port_position.x(), z.port_position.y()});
          band->z_range.push_back(z.port_position.z());
          band->z_attitude.insert(band->z_attitude.end(), z.attitude.data(), z.attitude.data() + 3);
        }
      }
    }
    const Eigen::Quaterniond q(out.result.T_lidar_target.linear());
    const Eigen::Vector3d& t = out.result.T_lidar_target.translation();
    csv << truth[k].frame << ',' << stamp_s << ',' << statusName(out.result.status) << ',' << t.x() << ','
        << t.y() << ',' << t.z() << ',' << q.x() << ',' << q.y() << ',' << q.z() << ',' << q.w() << ','
        << e.range_m << ',' << pos << ',' << att_deg << ',' << out.result.fit_rms_m << ','
        << out.result.inlier_fraction << ',' << out.result.points_used << ',' << out.result.iterations << ','
        << out.compute_ms << ",\"" << out.result.reason << "\"";
    const Eigen::Vector3d att_sigma_deg = z.attitude_sigma_rad * (180.0 / M_PI);
    for (double sigma : {z.port_sigma_m.x(), z.port_sigma_m.y(), z.port_sigma_m.z(), att_sigma_deg.x(),
                         att_sigma_deg.y(), att_sigma_deg.z()})
      csv << ',' << sigma;
    csv << '\n';
  }
  std::printf("%-12s %6s %5s %10s %10s %11s %11s %12s %12s %8s %6s %6s %6s\n", "range_m", "frames", "lost",
              "pos_rms_m", "pos_max_m", "att_rms_deg", "att_max_deg", "tilt_rms_deg", "bore_rms_deg",
              "ms_med", "z_lat", "z_rng", "z_att");
  for (const Band& b : bands) {
    if (b.frames == 0) continue;
    char label[32];
    if (b.max_m > 1e8)
      std::snprintf(label, sizeof(label), ">= %.0f", b.min_m);
    else
      std::snprintf(label, sizeof(label), "%.0f-%.0f", b.min_m, b.max_m);
    std::printf("%-12s %6d %5d %10.4f %10.4f %11.4f %11.4f %12.4f %12.4f %8.2f %6.2f %6.2f %6.2f\n", label,
                b.frames, b.lost, rms(b.pos), maxOf(b.pos), rms(b.att), maxOf(b.att), rms(b.tilt),
                rms(b.boresight), medianOf(b.ms), rms(b.z_lateral), rms(b.z_range), rms(b.z_attitude));
  }
  std::printf(
      "summary frames=%d lost=%d pos_rms_m=%.4f pos_max_m=%.4f att_rms_deg=%.4f att_max_deg=%.4f "
      "ms_median=%.2f\n",
      all.frames, all.lost, rms(all.pos), maxOf(all.pos), rms(all.att), maxOf(all.att), medianOf(all.ms));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evaluate_dataset: %s (--help for usage)\n", e.what());
    return 2;
  }
}
