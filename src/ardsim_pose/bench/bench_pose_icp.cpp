// Milliseconds per 256 x 256 frame of ICP tracking of the ISS at 100, 30 and 10 m (lidar to port), one core,
// and the same frames aligned by PCL's IterativeClosestPoint (point-to-point),
// IterativeClosestPointWithNormals (point-to-plane) and Open3D's point-to-plane ICP.
//
// Like for like: frames rendered once (LidarSimulator, noise on); per frame the same initial guess (truth
// turned 0.5 deg about a random axis through the port and moved 0.2 m across the line of sight, seeded by the
// frame), the same iteration limit (15, ours when tracking) and first correspondence distance (0.5 m). The
// peers get the scan points ours uses (its subsample of at most 1000 valid pixels, lidar frame) and the
// reference model cropped to what is visible from the guess (our visibility prediction, target frame, with
// the normals of the model's triangles). Timed for the peers: building their KD-tree over the cropped model
// (the crop changes every frame) and the alignment; for ours: the whole estimate() from the organized cloud
// (subsampling, visibility crop, ICP, quality checks, covariance). Counters: mean port position error (m) and
// attitude error (deg) against the truth over the frames; ours also the mean iterations and the fraction of
// frames it called DEGRADED (at 10 m some stop at the iteration limit while still sliding).
//
// PCL twice: as shipped, and with OpenMP regions of one thread run inline (`..InlineOmp`). Debian's FLANN,
// under PCL's KdTreeFLANN, opens a parallel region of one thread (SearchParams::cores) for every query, and
// libgomp ends each with a futex wake syscall although nothing waits; where a syscall is dear (a virtual
// machine) that is half to most of PCL's time (2026-11-23, this 2-core guest: 125 vs 18 ms a 10 m frame), and
// how dear depends on the host. The inline variant does the same arithmetic (identical transforms) without
// it: the ratio to it compares the work alone, on any host.
#include <benchmark/benchmark.h>
#include <dlfcn.h>
#include <omp.h>

#include <atomic>
#include <map>
#include <memory>
#include <vector>

#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include "ardsim_description/frames.h"
#include "ardsim_description/models.h"
#include "ardsim_lidar/lidar_simulator.h"
#include "ardsim_pose/dataset.h"
#include "ardsim_pose/estimator_factory.h"
#include "ardsim_pose/evaluation.h"
#include "open3d_peer.h"

namespace {
std::atomic<bool> g_inline_one_thread_regions{false};
}  // namespace

// Interposes libgomp's entry to a parallel region (the executable's definition wins, exported by the link
// option in CMakeLists.txt); everything but one-thread regions while g_inline_one_thread_regions goes to it.
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags) {
  using Entry = void (*)(void (*)(void*), void*, unsigned, unsigned);
  static const Entry libgomp_parallel = reinterpret_cast<Entry>(dlsym(RTLD_NEXT, "GOMP_parallel"));
  if (num_threads == 1 && g_inline_one_thread_regions.load(std::memory_order_relaxed)) {
    fn(data);  // outside a team, omp_get_num_threads() is 1 and worksharing loops give this thread all
    return;
  }
  libgomp_parallel(fn, data, num_threads, flags);
}

namespace ardsim_pose {
namespace {

using ardsim_description::TargetKind;

constexpr int kFrames = 8;
constexpr int kMaxIterations = 15;
constexpr double kMaxDistanceM = 0.5;

struct Frame {
  OrganizedCloud cloud;
  Eigen::Isometry3d truth;
  Eigen::Isometry3d guess;
  std::vector<Eigen::Vector3d> scan;  // ours' subsample, lidar frame
  std::vector<Eigen::Vector3d> model_points;
  std::vector<Eigen::Vector3d> model_normals;
  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_scan{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_model{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::PointCloud<pcl::PointNormal>::Ptr pcl_scan_normals{new pcl::PointCloud<pcl::PointNormal>};
  pcl::PointCloud<pcl::PointNormal>::Ptr pcl_model_normals{new pcl::PointCloud<pcl::PointNormal>};
};

struct Fixture {
  PoseConfig config;
  std::shared_ptr<const ReferenceModel> model = buildReferenceModel(TargetKind::kIss, config.model);
  std::map<int, std::vector<Frame>> frames;  // by range, m

  Fixture() {
    omp_set_num_threads(1);  // Open3D's correspondence search is OpenMP-parallel: one core like the others
    ardsim_lidar::LidarSimulator simulator(config.sensor, ardsim_lidar::NoiseOptions{}, 7);
    simulator.setTarget(ardsim_description::buildIss());
    const ardsim_lidar::Intrinsics intrinsics = ardsim_lidar::intrinsicsFor(config.sensor);
    IcpTracker tracker(model, intrinsics, config.icp, config.visibility);
    VisibilityPredictor visibility(intrinsics, config.visibility);
    ardsim_lidar::LidarFrame rendered;
    for (int range_m : {100, 30, 10}) {
      for (int k = 0; k < kFrames; ++k) {
        Frame f;
        // Lidar to port range_m (the chaser port is 1 m ahead of the lidar), closing 1 cm per frame.
        f.truth = dockingAxisPose(TargetKind::kIss, range_m - 1.0 - 0.01 * k);
        simulator.simulate(f.truth, k, &rendered);
        f.cloud = fromLidarFrame(rendered, simulator.rays(), 0.1 * k);
        f.guess = perturbPrior(f.truth, ardsim_description::T_target_port(TargetKind::kIss),
                               PriorPerturbation{0.5, 0.0, 0.2}, 100 + k);
        tracker.estimate(f.cloud, f.guess);  // for its scan subsample
        for (const Eigen::Vector3f& p : tracker.lastScanPoints()) {
          f.scan.push_back(p.cast<double>());
          f.pcl_scan->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
          pcl::PointNormal pn;
          pn.getVector3fMap() = p;
          pn.getNormalVector3fMap().setZero();
          f.pcl_scan_normals->push_back(pn);
        }
        visibility.predict(*model, f.guess);
        const std::vector<std::uint8_t>& visible = visibility.visible();
        for (std::size_t i = 0; i < model->size(); ++i) {
          if (!visible[i]) continue;
          const Eigen::Vector3f& p = model->points()[i];
          const Eigen::Vector3f& n = model->normals()[i];
          f.model_points.push_back(p.cast<double>());
          f.model_normals.push_back(n.cast<double>());
          f.pcl_model->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
          pcl::PointNormal pn;
          pn.getVector3fMap() = p;
          pn.getNormalVector3fMap() = n;
          f.pcl_model_normals->push_back(pn);
        }
        frames[range_m].push_back(std::move(f));
      }
    }
  }
};

Fixture& fixture() {
  static Fixture instance;
  return instance;
}

// Mean errors over the frames aligned, as counters.
struct ErrorCounters {
  double position_m = 0.0;
  double attitude_deg = 0.0;
  int count = 0;
  void add(const Eigen::Isometry3d& T_lidar_target, const Frame& f) {
    const PoseErrorValue e =
        poseError(T_lidar_target, f.truth, ardsim_description::T_target_port(TargetKind::kIss));
    position_m += e.port_position_error_m.norm();
    attitude_deg += e.attitude_error_angle_rad * 180.0 / M_PI;
    ++count;
  }
  void report(benchmark::State& state, const std::vector<Frame>& frames) const {
    state.counters["pos_err_m"] = position_m / std::max(1, count);
    state.counters["att_err_deg"] = attitude_deg / std::max(1, count);
    state.counters["scan_points"] = static_cast<double>(frames[0].scan.size());
    state.counters["model_points"] = static_cast<double>(frames[0].model_points.size());
  }
};

void BM_IcpTrack_Ardsim(benchmark::State& state) {
  Fixture& fx = fixture();
  const std::vector<Frame>& frames = fx.frames.at(static_cast<int>(state.range(0)));
  PoseConfig config = fx.config;
  config.icp.max_iterations_tracking = kMaxIterations;
  config.icp.gate_tracking_m = kMaxDistanceM;
  IcpTracker tracker(fx.model, ardsim_lidar::intrinsicsFor(config.sensor), config.icp, config.visibility);
  // Into tracking: an acquisition from the truth (the benchmark times tracking frames).
  auto prime = [&] {
    tracker.reset();
    tracker.estimate(frames[0].cloud, frames[0].truth);
  };
  prime();
  ErrorCounters errors;
  int lost = 0;
  int degraded = 0;
  double iterations = 0.0;
  std::size_t k = 0;
  for (auto _ : state) {
    const Frame& f = frames[k++ % frames.size()];
    const PoseResult result = tracker.estimate(f.cloud, f.guess);
    benchmark::DoNotOptimize(result);
    errors.add(result.T_lidar_target, f);
    iterations += result.iterations;
    if (result.status == EstimateStatus::kDegraded) ++degraded;
    if (tracker.acquiring()) {  // LOST: back to tracking, untimed
      ++lost;
      state.PauseTiming();
      prime();
      state.ResumeTiming();
    }
  }
  errors.report(state, frames);
  state.counters["lost"] = lost;
  state.counters["degraded"] = degraded / std::max<double>(1.0, static_cast<double>(k));  // fraction
  state.counters["iterations"] = iterations / std::max<double>(1.0, static_cast<double>(k));
}

// Sets g_inline_one_thread_regions for one benchmark's lifetime.
class InlineOneThreadRegions {
 public:
  explicit InlineOneThreadRegions(bool on) { g_inline_one_thread_regions = on; }
  ~InlineOneThreadRegions() { g_inline_one_thread_regions = false; }
  InlineOneThreadRegions(const InlineOneThreadRegions&) = delete;
  InlineOneThreadRegions& operator=(const InlineOneThreadRegions&) = delete;
};

void pclIcp(benchmark::State& state, bool inline_one_thread_regions) {
  const InlineOneThreadRegions regions(inline_one_thread_regions);
  const std::vector<Frame>& frames = fixture().frames.at(static_cast<int>(state.range(0)));
  ErrorCounters errors;
  pcl::PointCloud<pcl::PointXYZ> aligned;
  std::size_t k = 0;
  for (auto _ : state) {
    const Frame& f = frames[k++ % frames.size()];
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    icp.setMaximumIterations(kMaxIterations);
    icp.setMaxCorrespondenceDistance(kMaxDistanceM);
    icp.setTransformationEpsilon(1e-10);
    icp.setInputSource(f.pcl_scan);
    icp.setInputTarget(f.pcl_model);
    icp.align(aligned, f.guess.inverse().matrix().cast<float>());
    errors.add(Eigen::Isometry3d(icp.getFinalTransformation().cast<double>()).inverse(), f);
  }
  errors.report(state, frames);
}

void pclIcpNormals(benchmark::State& state, bool inline_one_thread_regions) {
  const InlineOneThreadRegions regions(inline_one_thread_regions);
  const std::vector<Frame>& frames = fixture().frames.at(static_cast<int>(state.range(0)));
  ErrorCounters errors;
  pcl::PointCloud<pcl::PointNormal> aligned;
  std::size_t k = 0;
  for (auto _ : state) {
    const Frame& f = frames[k++ % frames.size()];
    pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
    icp.setMaximumIterations(kMaxIterations);
    icp.setMaxCorrespondenceDistance(kMaxDistanceM);
    icp.setTransformationEpsilon(1e-10);
    icp.setInputSource(f.pcl_scan_normals);
    icp.setInputTarget(f.pcl_model_normals);
    icp.align(aligned, f.guess.inverse().matrix().cast<float>());
    errors.add(Eigen::Isometry3d(icp.getFinalTransformation().cast<double>()).inverse(), f);
  }
  errors.report(state, frames);
}

void BM_IcpTrack_PclIcp(benchmark::State& state) {
  pclIcp(state, false);
}
void BM_IcpTrack_PclIcpInlineOmp(benchmark::State& state) {
  pclIcp(state, true);
}
void BM_IcpTrack_PclIcpNormals(benchmark::State& state) {
  pclIcpNormals(state, false);
}
void BM_IcpTrack_PclIcpNormalsInlineOmp(benchmark::State& state) {
  pclIcpNormals(state, true);
}

void BM_IcpTrack_Open3d(benchmark::State& state) {
  const std::vector<Frame>& frames = fixture().frames.at(static_cast<int>(state.range(0)));
  ErrorCounters errors;
  Open3dPointToPlane open3d;
  std::size_t k = 0;
  for (auto _ : state) {
    const Frame& f = frames[k++ % frames.size()];
    state.PauseTiming();
    open3d.setFrame(f.scan, f.model_points, f.model_normals);
    state.ResumeTiming();
    const Eigen::Isometry3d T_target_lidar = open3d.align(f.guess.inverse(), kMaxDistanceM, kMaxIterations);
    errors.add(T_target_lidar.inverse(), f);
  }
  errors.report(state, frames);
}

BENCHMARK(BM_IcpTrack_Ardsim)->Arg(100)->Arg(30)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IcpTrack_PclIcp)->Arg(100)->Arg(30)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IcpTrack_PclIcpInlineOmp)->Arg(100)->Arg(30)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IcpTrack_PclIcpNormals)->Arg(100)->Arg(30)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IcpTrack_PclIcpNormalsInlineOmp)->Arg(100)->Arg(30)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IcpTrack_Open3d)->Arg(100)->Arg(30)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ardsim_pose

BENCHMARK_MAIN();
