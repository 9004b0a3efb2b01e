// The acceptance benchmark: a 1 m square cloth of n x n particles (stretch + dihedral bend), pinned
// at the two corners of one side, 1 kg, gravity, dt = 1/60 s, one thread (cloth_scenario.hpp).
// Each benchmark iteration builds the scene (not timed) and steps 200 frames (timed). Counters:
//
//   ms_per_frame     wall time of one World::step, averaged over the 200 frames
//   max_edge_strain  max over all triangle edges of |len / rest - 1| after frame 200
//   stretch, squeeze the largest len / rest - 1 and 1 - len / rest after frame 200 (its two sides)
//   worst_strain     max_edge_strain's largest value after any of the 200 frames (whip cracks)
//   frames_over_1pct how many of the 200 frames ended with max_edge_strain above 1 %
//   pin_strain       the same over the edges within 5 cm (rest distance) of a pin
//   rms_strain       root mean square edge strain after frame 200
//   substeps, iterations, tethers (automatic long-range attachments per particle), constraints
//
// A fast frame that leaves the cloth stretched is not a frame: read ms_per_frame together with
// max_edge_strain. The label names the configuration and the kernel set (avx2 / vec2 / scalar,
// all bit-identical).
//
//   ./build/bench/embra_bench --benchmark_filter='BM_Cloth/'          embra's defaults, n = 128, 64, 32
//   ./build/bench/embra_bench --benchmark_filter='BM_ClothThreads'    the defaults on 1 and 2 threads
//   ./build/bench/embra_bench --benchmark_filter='BM_ClothConfig'     the configurations compared
//   ./build/bench/embra_bench --benchmark_filter='BM_Kernels'         cost per constraint and substep
//   ./build/bench/embra_bench --benchmark_filter='BM_ClothDamped'     not the acceptance case: damped
//   ./build/bench/embra_bench --benchmark_filter='BM_ClothToRest'     time until the hanging cloth is at rest
#include "cloth_scenario.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <string>

namespace {

using embra::bench::ClothCase;

constexpr int kFrames = 200;

std::string describe(const ClothCase& c) {
  const auto& s = c.settings;
  std::string d = "n=" + std::to_string(c.n) + " substeps=" + std::to_string(s.substeps) +
                  " iterations=" + std::to_string(s.iterations) + " tethers=" + std::to_string(s.tethers) +
                  " chains=" + std::to_string(s.chain_solve);
  if (c.stretch_weight > 0) d += " stretch_weight=" + std::to_string(c.stretch_weight);
  if (c.bend_weight > 0) d += " bend_weight=" + std::to_string(c.bend_weight);
  return d + " kernels=" + embra::solver_kernels();
}

void run_cloth(benchmark::State& state, const ClothCase& c) {
  embra::bench::Strain strain;
  double seconds = 0.0, worst = 0.0;
  int64_t over = 0;  // frames after which max_edge_strain exceeds 1 %
  int64_t runs = 0, constraints = 0;
  for (auto _ : state) {
    auto world = std::make_unique<embra::World>(c.settings);
    const auto scene = embra::bench::build_cloth(*world, c);
    constraints = world->constraint_count();
    double dt = 0.0;  // the steps only: the strain is measured between them
    try {
      for (int f = 0; f < kFrames; ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        world->step();
        dt += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double now = embra::bench::measure_strain(*world, scene).max;
        worst = std::max(worst, now);
        over += now > 0.01 ? 1 : 0;
      }
    } catch (const embra::Error& e) {
      state.SkipWithError(e.what());
      break;
    }
    state.SetIterationTime(dt);
    seconds += dt;
    ++runs;
    strain = embra::bench::measure_strain(*world, scene);
  }
  if (runs == 0) return;
  const auto& s = c.settings;
  state.counters["ms_per_frame"] = 1e3 * seconds / static_cast<double>(runs * kFrames);
  state.counters["max_edge_strain"] = strain.max;
  state.counters["stretch"] = strain.stretch;
  state.counters["squeeze"] = strain.squeeze;
  state.counters["worst_strain"] = worst;
  state.counters["frames_over_1pct"] = static_cast<double>(over) / static_cast<double>(runs);
  state.counters["pin_strain"] = strain.near_pin;
  state.counters["rms_strain"] = strain.rms;
  state.counters["substeps"] = s.substeps;
  state.counters["iterations"] = s.iterations;
  state.counters["tethers"] = s.tethers;
  state.counters["chain_solve"] = s.chain_solve;
  state.counters["constraints"] = static_cast<double>(constraints);
  state.SetLabel(describe(c));
}

/// The acceptance case with embra's default settings, at n = 128 (and 64, 32).
void BM_Cloth(benchmark::State& state) {
  ClothCase c;
  c.n = static_cast<int>(state.range(0));
  run_cloth(state, c);
}
BENCHMARK(BM_Cloth)->Arg(128)->Arg(64)->Arg(32)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1);

/// The defaults on Settings::threads threads: {n, threads}. The same bits at any count
/// (Threads.ClothIsBitIdenticalAtAnyThreadCount); only the time differs.
void BM_ClothThreads(benchmark::State& state) {
  ClothCase c;
  c.n = static_cast<int>(state.range(0));
  c.settings.threads = static_cast<int32_t>(state.range(1));
  run_cloth(state, c);
}
BENCHMARK(BM_ClothThreads)
    ->Args({128, 1})
    ->Args({128, 2})
    ->Args({256, 1})
    ->Args({256, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

/// Configurations compared: {n, substeps, iterations, tethers per particle, stretch weight, bend
/// weight, Chebyshev rho in thousandths, chain solve} (a weight of 0 leaves stretch or bend in the
/// default group).
void BM_ClothConfig(benchmark::State& state) {
  ClothCase c;
  c.n = static_cast<int>(state.range(0));
  c.settings.substeps = static_cast<int32_t>(state.range(1));
  c.settings.iterations = static_cast<int32_t>(state.range(2));
  c.settings.tethers = static_cast<int32_t>(state.range(3));
  c.stretch_weight = static_cast<int32_t>(state.range(4));
  c.bend_weight = static_cast<int32_t>(state.range(5));
  c.settings.chebyshev_rho_milli = static_cast<int32_t>(state.range(6));
  c.settings.chain_solve = static_cast<int32_t>(state.range(7));
  run_cloth(state, c);
}
BENCHMARK(BM_ClothConfig)
    ->ArgNames({"n", "substeps", "iters", "tethers", "sw", "bw", "cheb", "chain"})
    ->Args({128, 1, 10, 0, 0, 0, 0, 0})  // the reference set-up: one step of 10 iterations, no tethers
    ->Args({128, 8, 1, 0, 0, 0, 0, 0})   // embra's old defaults
    ->Args({128, 16, 1, 2, 0, 0, 0, 0})  // one constraint at a time (chain_solve 0)
    ->Args({128, 20, 1, 2, 0, 0, 0, 0})
    ->Args({128, 32, 1, 2, 0, 0, 0, 0})
    ->Args({128, 5, 4, 2, 0, 0, 900, 0})  // Chebyshev acceleration (rho 0.9) of 4 iterations a substep
    ->Args({128, 12, 1, 2, 0, 0, 0, 1})   // chain solve
    ->Args({128, 16, 1, 2, 0, 0, 0, 1})
    ->Args({128, 20, 1, 2, 0, 0, 0, 1})
    ->Args({128, 30, 1, 2, 0, 0, 0, 1})
    ->Args({128, 40, 1, 2, 0, 0, 0, 1})
    ->Args({128, 12, 1, 2, 2, 1, 0, 1})  // chains and tethers twice a substep, bend once
    ->Args({128, 16, 1, 2, 2, 1, 0, 1})
    ->Args({128, 20, 1, 2, 2, 1, 0, 1})
    ->Args({128, 10, 1, 2, 4, 1, 0, 1})
    // Substeps in proportion to n: the falling cloth's fold crosses as many rows per substep
    // (docs/decisions.md, 2026-11-26: the 256 x 256 cloth needs substeps that grow with n).
    ->Args({64, 8, 1, 2, 0, 0, 0, 1})
    ->Args({128, 8, 1, 2, 0, 0, 0, 1})
    ->Args({256, 24, 1, 2, 0, 0, 0, 1})
    ->Args({256, 32, 1, 2, 0, 0, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

/// Not the acceptance case: the same cloth with air-like velocity damping (Settings::damping, 1/s),
/// to show the strain left once the swinging has died down. Args: {substeps, damping in 1/s}.
void BM_ClothDamped(benchmark::State& state) {
  ClothCase c;
  c.settings.substeps = static_cast<int32_t>(state.range(0));
  c.settings.damping = static_cast<double>(state.range(1));
  state.counters["damping"] = c.settings.damping;
  run_cloth(state, c);
}
BENCHMARK(BM_ClothDamped)
    ->ArgNames({"substeps", "damping"})
    ->Args({8, 3})
    ->Args({16, 3})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

/// Time to an answer: the 128 x 128 cloth hanging from its two corners with velocity damping
/// 6/s, stepped until it is at rest (max speed under 1 mm/s and max edge strain under 1 %, both
/// held 30 frames in a row); the time is the steps' wall time until the first of those 30 frames
/// (the strain is measured between steps, untimed). Args: {settings: 0 the defaults, 1 the
/// form-finding preset (form_finding_settings: dt 1/15 s, 1 substep x 1 iteration); threads}. At
/// most 3,000 frames: a case that never comes to rest reports frames_to_rest = -1.
void BM_ClothToRest(benchmark::State& state) {
  ClothCase c;
  if (state.range(0) == 1) c.settings = embra::form_finding_settings();
  c.settings.threads = static_cast<int32_t>(state.range(1));
  c.settings.damping = 6.0;
  constexpr int kMaxFrames = 3000, kHeld = 30;
  int rest_frame = -1;
  double strain = 0.0;
  for (auto _ : state) {
    embra::World world(c.settings);
    const auto scene = embra::bench::build_cloth(world, c);
    double elapsed = 0.0, at_rest_since = 0.0;
    int held = 0;
    rest_frame = -1;
    for (int f = 1; f <= kMaxFrames; ++f) {
      const auto t0 = std::chrono::steady_clock::now();
      world.step();
      elapsed += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      strain = embra::bench::measure_strain(world, scene).max;
      if (world.report().max_speed < 1e-3 && strain < 0.01) {
        if (held++ == 0) at_rest_since = elapsed;
        if (held == kHeld) {
          rest_frame = f - kHeld + 1;
          break;
        }
      } else {
        held = 0;
      }
    }
    state.SetIterationTime(rest_frame > 0 ? at_rest_since : elapsed);
  }
  state.counters["frames_to_rest"] = rest_frame;
  state.counters["seconds_simulated"] = rest_frame * c.settings.dt;
  state.counters["max_edge_strain"] = strain;
  state.counters["threads"] = c.settings.threads;
  state.SetLabel(describe(c) + (state.range(0) == 1 ? " form-finding preset" : " defaults") + " damping=6");
}
BENCHMARK(BM_ClothToRest)
    ->ArgNames({"preset", "threads"})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

/// Cost of one substep's pass per constraint kind on the 128 x 128 cloth, from runs that generate
/// only some kinds: arg 0 = no constraints, 1 = stretch, 2 = stretch + bend, 3 = stretch + tethers.
void BM_Kernels(benchmark::State& state) {
  const int what = static_cast<int>(state.range(0));
  ClothCase c;
  c.settings.substeps = 16;
  c.settings.tethers = what == 3 ? 2 : 0;
  c.bend = what == 2;
  const int frames = 20;
  double seconds = 0.0;
  int64_t constraints = 0;
  for (auto _ : state) {
    embra::World world(c.settings);
    auto scene = embra::bench::build_cloth(world, c);
    if (what == 0) {  // the same particles and pins without constraints: the stages around projection
      embra::World empty(c.settings);
      embra::BodyDesc d;
      std::vector<double> xyz;
      for (const auto& p : world.positions()) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
      std::vector<double> masses(world.particle_count(), 1.0 / world.particle_count());
      d.positions = xyz;
      d.masses = masses;
      d.generate = 0;
      empty.create_body(d);
      world.step();
      const auto t0 = std::chrono::steady_clock::now();
      for (int f = 0; f < frames; ++f) empty.step();
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      state.SetIterationTime(seconds);
      continue;
    }
    constraints = world.constraint_count();
    world.step();  // builds the solver arrays (and the tethers) outside the timing
    const auto t0 = std::chrono::steady_clock::now();
    for (int f = 0; f < frames; ++f) world.step();
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    seconds += dt;
    state.SetIterationTime(dt);
    (void)scene;
  }
  state.counters["ms_per_substep"] = 1e3 * seconds / (frames * c.settings.substeps);
  state.counters["constraints"] = static_cast<double>(constraints);
  state.SetLabel(std::string(what == 0   ? "no constraints"
                             : what == 1 ? "stretch"
                             : what == 2 ? "stretch + bend"
                                         : "stretch + 2 tethers per particle") +
                 " kernels=" + embra::solver_kernels());
}
BENCHMARK(BM_Kernels)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
