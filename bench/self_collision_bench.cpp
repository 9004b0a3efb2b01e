// Self-collision cost: an n x n cloth, 1 m square, 1 kg, folded along its diagonal over a half
// cylinder (radius 6 cm, upper layer turned over onto the lower one) and dropped from 5 cm onto a
// ground plane, so the layers land on each other; thickness half the grid spacing; embra's default
// solver settings (embra::Settings{}: 16 substeps x 1 iteration, tethers) with self-collision on (or
// off, for the reference). Times 30 frames of World::step from the release (the fall, the landing
// and the upper layer settling on the lower). BM_ClothSelfCollision keeps the cloth 1 m square, so its
// spacing and thickness shrink with n while a substep's motion does not; BM_ClothSelfCollisionSimilar
// keeps the spacing of n = 64 and widens the cloth, a self-similar scene whose linear cost means
// ms_per_frame x 4 from one n to 2n.
#include "embra/core/world.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

namespace {

using embra::Vec3;

/// An n x n cloth of side `size` (m) and 1 kg per square metre, folded and placed as above.
void build_folded_cloth(embra::World& w, int n, double size = 1.0) {
  const double step = size / (n - 1), radius = 0.06, z0 = 0.05;
  std::vector<double> flat, folded;
  const Vec3 u = Vec3(1, 1, 0).normalized(), v = Vec3(-1, 1, 0).normalized();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec3 p(-0.5 * size + i * step, -0.5 * size + j * step, 0.0);
      flat.insert(flat.end(), {p.x(), p.y(), p.z()});
      const double a = p.dot(u), d = p.dot(v) + 0.013;  // the crease a little off the grid's diagonal
      Vec3 q;
      if (d <= 0.0)
        q = a * u + d * v;
      else if (d < std::numbers::pi * radius)
        q = a * u + radius * std::sin(d / radius) * v + Vec3(0, 0, radius * (1.0 - std::cos(d / radius)));
      else
        q = a * u - (d - std::numbers::pi * radius) * v + Vec3(0, 0, 2.0 * radius);
      q += Vec3(0, 0, z0) - 0.013 * v;
      folded.insert(folded.end(), {q.x(), q.y(), q.z()});
    }
  std::vector<int32_t> tris;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int32_t a = j * n + i, b = a + 1, c = a + n + 1, e = a + n;
      tris.insert(tris.end(), {a, b, c, a, c, e});
    }
  embra::BodyDesc desc;
  desc.positions = flat;
  desc.triangles = tris;
  desc.material.mass = size * size;
  desc.material.thickness = 0.5 * step;
  const embra::Id body = w.create_body(desc);
  w.set_positions(w.body(body).first_particle, folded);
  w.create_collider(embra::ColliderDesc{});  // the ground plane z = 0
}

/// Times 30 frames of the folded cloth; `size` is the cloth's side for n (m).
void run_folded_cloth(benchmark::State& state, int n, double size) {
  constexpr int kFrames = 30;
  double seconds = 0.0;
  int64_t contacts = 0;
  for (auto _ : state) {
    embra::Settings s;
    s.self_collision = static_cast<int32_t>(state.range(1));
    s.threads = static_cast<int32_t>(state.range(2));
    embra::World w(s);
    build_folded_cloth(w, n, size);
    const auto t0 = std::chrono::steady_clock::now();
    for (int f = 0; f < kFrames; ++f) {
      w.step();
      contacts = std::max(contacts, w.report().contact_count);
    }
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    seconds += dt;
    state.SetIterationTime(dt);
  }
  state.counters["ms_per_frame"] = 1e3 * seconds / (static_cast<double>(state.iterations()) * kFrames);
  state.counters["particles"] = static_cast<double>(n) * n;
  state.counters["max_contacts"] = static_cast<double>(contacts);
  state.counters["threads"] = static_cast<double>(state.range(2));
  state.SetLabel(state.range(1) ? "self-collision on" : "self-collision off");
}

void BM_ClothSelfCollision(benchmark::State& state) {
  run_folded_cloth(state, static_cast<int>(state.range(0)), 1.0);
}

/// The self-similar scene: the grid spacing, thickness, fold and drop of the 64 x 64 cloth (1 m), the
/// cloth n / 64 times as wide, so a substep moves every particle as far, relative to the spacing and
/// the thickness, at every n: a linear cost means ms_per_frame x 4 from one n to 2n.
void BM_ClothSelfCollisionSimilar(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  run_folded_cloth(state, n, (n - 1) / 63.0);
}

/// Args: {n, self-collision, threads}.
BENCHMARK(BM_ClothSelfCollision)
    ->ArgNames({"n", "self", "threads"})
    ->Args({64, 1, 1})
    ->Args({64, 1, 2})
    ->Args({128, 1, 1})
    ->Args({128, 1, 2})
    ->Args({256, 1, 1})
    ->Args({256, 1, 2})
    ->Args({64, 0, 1})
    ->Args({128, 0, 1})
    ->Args({256, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

/// Args: {n, self-collision, threads}.
BENCHMARK(BM_ClothSelfCollisionSimilar)
    ->ArgNames({"n", "self", "threads"})
    ->Args({32, 1, 1})
    ->Args({32, 1, 2})
    ->Args({64, 1, 1})
    ->Args({64, 1, 2})
    ->Args({128, 1, 1})
    ->Args({128, 1, 2})
    ->Args({128, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

}  // namespace
