// The acceptance benchmark: a 1 m square cloth of n x n particles (stretch + dihedral bend), pinned
// at the two corners of one side, 1 kg, gravity, dt = 1/60 s, single thread. Each benchmark
// iteration builds the scene (not timed) and steps 200 frames (timed). Counters:
//
//   ms_per_frame     wall time of one step, averaged over the 200 frames
//   max_edge_strain  max over all triangle edges of |len / rest - 1| after frame 200
//   pin_strain       the same over the edges within 5 cm (material distance) of a pin
//   rms_strain       root mean square of the edge strain after frame 200
//
// A fast frame that leaves the cloth stretched is not a frame: read ms_per_frame together with
// max_edge_strain. Run: ./build/bench/embra_bench --benchmark_filter=Cloth
#include "cloth_scenario.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <limits>
#include <memory>

namespace {

using embra::bench::ClothCase;

constexpr int kFrames = 200;

void run_cloth(benchmark::State& state, const ClothCase& c) {
  embra::bench::Strain strain;
  double seconds = 0.0;
  int64_t runs = 0;
  int64_t constraints = 0;
  for (auto _ : state) {
    auto world = std::make_unique<embra::World>(c.settings);
    const auto scene = embra::bench::build_cloth(*world, c);
    constraints = world->constraint_count();
    const auto t0 = std::chrono::steady_clock::now();
    try {
      for (int f = 0; f < kFrames; ++f) world->step();
    } catch (const embra::Error& e) {
      state.SkipWithError(e.what());
      break;
    }
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(dt);
    seconds += dt;
    ++runs;
    strain = embra::bench::measure_strain(*world, scene);
  }
  if (runs == 0) return;
  const auto& s = c.settings;
  state.counters["ms_per_frame"] = 1e3 * seconds / static_cast<double>(runs * kFrames);
  state.counters["max_edge_strain"] = strain.max;
  state.counters["pin_strain"] = strain.near_pin;
  state.counters["rms_strain"] = strain.rms;
  state.counters["particles"] = static_cast<double>(c.n * c.n);
  state.counters["constraints"] = static_cast<double>(constraints);
  state.counters["substeps"] = s.substeps;
  state.counters["iterations"] = s.iterations;
}

/// The acceptance case with embra's default settings, at n = 128 (and 64, 32).
void BM_Cloth(benchmark::State& state) {
  ClothCase c;
  c.n = static_cast<int>(state.range(0));
  run_cloth(state, c);
}
BENCHMARK(BM_Cloth)->Arg(128)->Arg(64)->Arg(32)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1);

/// A configuration sweep: {n, substeps, iterations, explicit tethers, stretch weight, bend weight}
/// (weight 0 = stretch or bend stays in the default group).
void BM_ClothConfig(benchmark::State& state) {
  ClothCase c;
  c.n = static_cast<int>(state.range(0));
  c.settings.substeps = static_cast<int32_t>(state.range(1));
  c.settings.iterations = static_cast<int32_t>(state.range(2));
  c.tethers = state.range(3) != 0;
  c.stretch_weight = static_cast<int32_t>(state.range(4));
  c.bend_weight = static_cast<int32_t>(state.range(5));
  state.counters["tethers"] = c.tethers;
  state.counters["stretch_weight"] = c.stretch_weight;
  state.counters["bend_weight"] = c.bend_weight;
  run_cloth(state, c);
}
BENCHMARK(BM_ClothConfig)
    ->ArgNames({"n", "substeps", "iters", "tethers", "sw", "bw"})
    ->Args({128, 8, 1, 0, 0, 0})
    ->Args({128, 8, 1, 1, 0, 0})
    ->Args({128, 16, 1, 1, 0, 0})
    ->Args({128, 32, 1, 1, 0, 0})
    ->Args({128, 8, 1, 1, 2, 1})
    ->Args({128, 16, 1, 1, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
