// Truth-dynamics throughput: the 13x13 field alone, one RK4 step of one vehicle with the full environment,
// and one control step of the whole simulation (two vehicles), without and with the contact test (chaser far
// from the ISS: bounding spheres only; near its port: Bullet's shape test every step). Goal (issue 2): at
// least 1e5 integration steps/s on one core.
#include <benchmark/benchmark.h>

#include <memory>

#include "ardsim_dynamics/simulation.h"

using namespace ardsim_dynamics;

namespace {

VehicleState orbitState() {
  KeplerianElements e;
  e.semi_major_axis_m = 6793137.0;
  e.eccentricity = 0.0005;
  e.inclination_rad = 0.9013;
  const CartesianState c = keplerianToCartesian(e);
  VehicleState s;
  s.position_m = c.position_m;
  s.velocity_mps = c.velocity_mps;
  s.angular_velocity_radps = Eigen::Vector3d(0.0, -1.1e-3, 0.0);
  return s;
}

void BM_GravityAcceleration_Ardsim(benchmark::State& state) {
  const GravityField field = GravityField::egm96();
  const int degree = static_cast<int>(state.range(0));
  Eigen::Vector3d r(1.2e6, -5.1e6, 4.3e6);
  for (auto _ : state) {
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(field.acceleration(r, degree));
  }
  state.counters["evals_per_s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GravityAcceleration_Ardsim)->Arg(2)->Arg(13);

void BM_Rk4Step13x13_Ardsim(benchmark::State& state) {
  EnvironmentOptions options;  // 13x13, drag, Earth rotation, gravity-gradient torque
  const Environment env(GravityField::egm96(), options);
  VehicleProperties vehicle;
  vehicle.mass_kg = 12519.0;
  vehicle.inertia_kgm2 = Eigen::Vector3d(2.5e4, 8.1e4, 8.1e4).asDiagonal();
  vehicle.drag_area_m2 = 12.57;
  VehicleState s = orbitState();
  double t = 0.0;
  for (auto _ : state) {
    s = rk4Step(env, vehicle, s, BodyWrench{}, t, 0.1);
    t += 0.1;
    benchmark::DoNotOptimize(s);
  }
  state.counters["steps_per_s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Rk4Step13x13_Ardsim);

void BM_SimulationControlStep_Ardsim(benchmark::State& state) {
  Scenario scenario;                 // defaults: ISS orbit, 13x13, one RK4 step per 0.1 s control step
  scenario.contact.enabled = false;  // the dynamics alone
  Simulation sim(scenario);
  BodyWrench command;
  command.force_n = Eigen::Vector3d(1.0, 0.0, 0.0);
  for (auto _ : state) benchmark::DoNotOptimize(sim.step(command));
  state.counters["control_steps_per_s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
  state.counters["real_time_factor"] =
      benchmark::Counter(state.iterations() * scenario.control_step_s, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulationControlStep_Ardsim);

// Arg 0: the chaser port 100 m out on the ISS docking axis (outside the bounding spheres); arg 1: 0.5 m from
// the port, at rest relative to the ISS (inside them: the full shape test, no contact).
void BM_SimulationControlStepContact_Ardsim(benchmark::State& state) {
  Scenario scenario;
  scenario.chaser_initial.frame = RelativeFrame::kTargetPort;
  scenario.chaser_initial.position_m = Eigen::Vector3d(state.range(0) == 0 ? 100.0 : 0.5, 0.0, 0.0);
  auto sim = std::make_unique<Simulation>(scenario);
  for (auto _ : state) {
    benchmark::DoNotOptimize(sim->step(BodyWrench{}));
    if (sim->stepIndex() == 100) {
      // Restart every 10 s of simulation so that the near chaser stays near (it drifts on its CW path).
      state.PauseTiming();
      sim = std::make_unique<Simulation>(scenario);
      state.ResumeTiming();
    }
  }
  if (sim->contact()) state.SkipWithError("unexpected contact");
  state.counters["control_steps_per_s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulationControlStepContact_Ardsim)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
