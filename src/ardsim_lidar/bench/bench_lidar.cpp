// Frames per second of the flash LIDAR on the ISS from the docking axis (256 x 256, 20 deg, noise on):
// BM_RenderIss_Ardsim renders with EGL (llvmpipe without a GPU) and BM_RenderIss_Embree casts the same pixel
// rays through the same mesh with Embree 3 (rtcIntersect16, TBB); both then apply the same noise model.
// One frame at a time, as in the closed loop (the next pose depends on this frame). The *Sequence* pair
// makes kSequenceFrames frames of poses known ahead (render_dataset): EGL pipelined
// (LidarSimulator::simulateSequence), Embree with frames in parallel over the cores.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <utility>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "ardsim_description/models.h"
#include "ardsim_lidar/docking_views.h"
#include "ardsim_lidar/embree_ray_caster.h"
#include "ardsim_lidar/lidar_simulator.h"

namespace ardsim_lidar {

struct Fixture {
  ardsim_description::TriangleMesh mesh = ardsim_description::buildIss();
  SensorOptions sensor;
  NoiseOptions noise;
  LidarSimulator simulator{sensor, noise, 1};
  EmbreeRayCaster caster{sensor, mesh};
  NoiseModel noise_model{sensor, noise, 1};

  Fixture() {
    simulator.setTarget(mesh);
    benchmark::AddCustomContext("gl_renderer", simulator.renderer().glRenderer());
    benchmark::AddCustomContext("egl_platform", simulator.renderer().eglPlatform());
    benchmark::AddCustomContext("iss_triangles", std::to_string(mesh.triangles.size()));
  }
};

Fixture& fixture() {
  static Fixture instance;
  return instance;
}

namespace {

// CPU time of the whole process (every thread: llvmpipe's, Embree's and TBB's workers), ms.
double processCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return 1e3 * (usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-3 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

void BM_RenderIss_Ardsim(benchmark::State& state) {
  Fixture& f = fixture();
  const Eigen::Isometry3d T = lidarOnDockingAxis(ardsim_description::TargetKind::kIss, state.range(0));
  LidarFrame frame;
  std::uint64_t index = 0;
  double render_ms = 0.0;
  double noise_ms = 0.0;
  const double cpu_start_ms = processCpuMs();
  for (auto _ : state) {
    f.simulator.simulate(T, index++, &frame);
    render_ms += f.simulator.lastTiming().render_ms;
    noise_ms += f.simulator.lastTiming().noise_ms;
    benchmark::DoNotOptimize(frame.range_m.data());
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  // With the wall time per frame, how well the frame's work spreads over the cores.
  state.counters["process_cpu_ms"] = (processCpuMs() - cpu_start_ms) / state.iterations();
  state.counters["render_ms"] = render_ms / state.iterations();
  state.counters["noise_ms"] = noise_ms / state.iterations();
  state.counters["triangles_drawn"] = static_cast<double>(f.simulator.renderer().trianglesDrawnLastFrame());
  state.counters["returns"] = static_cast<double>(frame.returnCount());
}

void BM_RenderIss_Embree(benchmark::State& state) {
  Fixture& f = fixture();
  const Eigen::Isometry3d T = lidarOnDockingAxis(ardsim_description::TargetKind::kIss, state.range(0));
  RenderedFrame rendered;
  LidarFrame frame;
  std::uint64_t index = 0;
  const double cpu_start_ms = processCpuMs();
  for (auto _ : state) {
    f.caster.cast(T, &rendered);
    f.noise_model.apply(rendered, f.mesh.materials, index++, &frame);
    benchmark::DoNotOptimize(frame.range_m.data());
  }
  state.counters["process_cpu_ms"] = (processCpuMs() - cpu_start_ms) / state.iterations();
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["returns"] = static_cast<double>(frame.returnCount());
}

constexpr std::size_t kSequenceFrames = 64;

// The same view in every frame, each with its own noise.
std::vector<Eigen::Isometry3d> sequenceAt(double range_m) {
  return std::vector<Eigen::Isometry3d>(kSequenceFrames,
                                        lidarOnDockingAxis(ardsim_description::TargetKind::kIss, range_m));
}

void BM_RenderIssSequence_Ardsim(benchmark::State& state) {
  Fixture& f = fixture();
  const std::vector<Eigen::Isometry3d> poses = sequenceAt(state.range(0));
  std::uint64_t index = 0;
  std::atomic<std::size_t> returns{0};
  for (auto _ : state) {
    f.simulator.simulateSequence(poses, index, [&](std::size_t, const LidarFrame& frame) {
      returns.store(frame.returnCount(), std::memory_order_relaxed);
    });
    index += poses.size();
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations() * poses.size()), benchmark::Counter::kIsRate);
  state.counters["returns"] = static_cast<double>(returns.load());
  // The rendering thread's time per frame (last sequence): what bounds the pipeline when the cores keep up.
  const SequenceTiming& timing = f.simulator.renderer().lastSequenceTiming();
  const double frames = static_cast<double>(std::max<std::size_t>(1, timing.frames));
  state.counters["submit_ms"] = timing.submit_ms / frames;
  state.counters["wait_ms"] = timing.wait_ms / frames;
  state.counters["copy_ms"] = timing.copy_ms / frames;
  state.counters["handoff_ms"] = timing.consume_ms / frames;
}

void BM_RenderIssSequence_Embree(benchmark::State& state) {
  Fixture& f = fixture();
  const std::vector<Eigen::Isometry3d> poses = sequenceAt(state.range(0));
  std::uint64_t index = 0;
  std::atomic<std::size_t> returns{0};
  // Frames reused per thread, as the EGL path reuses its slots.
  tbb::enumerable_thread_specific<std::pair<RenderedFrame, LidarFrame>> buffers;
  for (auto _ : state) {
    tbb::parallel_for(std::size_t{0}, poses.size(), [&](std::size_t k) {
      auto& [rendered, frame] = buffers.local();
      f.caster.cast(poses[k], &rendered);
      f.noise_model.apply(rendered, f.mesh.materials, index + k, &frame);
      returns.store(frame.returnCount(), std::memory_order_relaxed);
    });
    index += poses.size();
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations() * poses.size()), benchmark::Counter::kIsRate);
  state.counters["returns"] = static_cast<double>(returns.load());
}

// The docking-axis ranges. Wall time: llvmpipe and Embree both work on threads other than the benchmark's.
void atRanges(benchmark::internal::Benchmark* b) {
  b->Arg(100)->Arg(30)->Arg(10)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(BM_RenderIss_Ardsim)->Apply(atRanges);
BENCHMARK(BM_RenderIss_Embree)->Apply(atRanges);
BENCHMARK(BM_RenderIssSequence_Ardsim)->Apply(atRanges);
BENCHMARK(BM_RenderIssSequence_Embree)->Apply(atRanges);

}  // namespace
}  // namespace ardsim_lidar

// The fixture is built before the run so that its context (GL_RENDERER, mesh size) heads the report.
int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  ardsim_lidar::fixture();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
