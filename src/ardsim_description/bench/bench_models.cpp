// Time to build each vehicle model. A renderer that follows turning solar arrays rebuilds the target when the
// angles change, so this bounds what articulation costs per frame.
#include <benchmark/benchmark.h>

#include "ardsim_description/models.h"

using namespace ardsim_description;

static void BM_BuildIss_Ardsim(benchmark::State& state) {
  IssOptions options;
  for (auto _ : state) {
    options.sarj_starboard_deg += 0.1;
    benchmark::DoNotOptimize(buildIss(options));
  }
  state.counters["triangles"] = static_cast<double>(buildIss().triangles.size());
}
BENCHMARK(BM_BuildIss_Ardsim)->Unit(benchmark::kMicrosecond);

static void BM_BuildHubble_Ardsim(benchmark::State& state) {
  HubbleOptions options;
  for (auto _ : state) {
    options.solar_array_deg += 0.1;
    benchmark::DoNotOptimize(buildHubble(options));
  }
  state.counters["triangles"] = static_cast<double>(buildHubble().triangles.size());
}
BENCHMARK(BM_BuildHubble_Ardsim)->Unit(benchmark::kMicrosecond);

static void BM_BuildChaser_Ardsim(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(buildChaser());
  state.counters["triangles"] = static_cast<double>(buildChaser().triangles.size());
}
BENCHMARK(BM_BuildChaser_Ardsim)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
