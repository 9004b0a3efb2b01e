// The solver's threads (Settings::threads, common/pool.hpp): the same scene gives the same bits at
// any thread count, and the pool covers every item of a range exactly once, in aligned parts.
// Labelled "threads": the ThreadSanitizer stage of the test command runs these too.
#include "common/pool.hpp"
#include "embra/core/limits.hpp"
#include "embra/core/panels.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace embra {
namespace {

/// Every item of [begin, end) is visited exactly once; parts are contiguous, start on `align` from
/// `begin` and number at most the pool's threads.
TEST(Threads, PoolCoversEveryItemOnceInAlignedParts) {
  for (int threads : {1, 2, 3, 8}) {
    ThreadPool pool(threads);
    ASSERT_EQ(pool.size(), threads);
    for (size_t n : {0u, 1u, 7u, 100u, 1023u, 5000u, 65537u}) {
      std::vector<std::atomic<int>> seen(n + 3);
      std::atomic<int> parts{0};
      std::vector<std::atomic<int>> part_used(static_cast<size_t>(threads));
      pool.run(3, n + 3, 4, 64, [&](size_t b, size_t e, int part) {
        EXPECT_EQ((b - 3) % 4, 0u);
        EXPECT_LT(b, e);
        ASSERT_GE(part, 0);
        ASSERT_LT(part, threads);
        part_used[static_cast<size_t>(part)].fetch_add(1);
        parts.fetch_add(1);
        for (size_t i = b; i < e; ++i) seen[i].fetch_add(1);
      });
      for (size_t i = 0; i < 3; ++i) EXPECT_EQ(seen[i].load(), 0);
      for (size_t i = 3; i < n + 3; ++i) ASSERT_EQ(seen[i].load(), 1) << "item " << i << " of " << n;
      EXPECT_LE(parts.load(), threads);
      for (auto& u : part_used) EXPECT_LE(u.load(), 1);  // one part per thread's scratch
      if (n < 128) {
        EXPECT_LE(parts.load(), 1);  // under two grains: the caller alone
      }
    }
  }
}

/// run_parts calls each part of [0, parts) exactly once, part 0 on the caller and each other part on
/// its own worker or on the caller (which takes the parts no worker has started once its own is
/// done), never more parts than the pool's threads, and throws what a part threw once all are done.
TEST(Threads, RunPartsCallsEachPartOnceOnItsOwnThread) {
  for (int threads : {1, 2, 3, 8}) {
    ThreadPool pool(threads);
    for (int parts : {0, 1, 2, 3, 8, 20}) {
      std::vector<std::atomic<int>> called(static_cast<size_t>(std::max(parts, 1)));
      std::vector<std::thread::id> on(called.size());
      pool.run_parts(parts, [&](int part) {
        ASSERT_GE(part, 0);
        ASSERT_LT(part, std::min(std::max(parts, 1), threads));
        called[static_cast<size_t>(part)].fetch_add(1);
        on[static_cast<size_t>(part)] = std::this_thread::get_id();
      });
      const int expected = std::min(std::max(parts, 1), threads);
      for (int p = 0; p < static_cast<int>(called.size()); ++p)
        EXPECT_EQ(called[static_cast<size_t>(p)].load(), p < expected ? 1 : 0) << p << " of " << parts;
      EXPECT_EQ(on[0], std::this_thread::get_id());  // part 0 on the caller
      for (int a = 1; a < expected; ++a)
        for (int b = a + 1; b < expected; ++b)
          if (on[static_cast<size_t>(a)] != on[0]) {
            EXPECT_NE(on[static_cast<size_t>(a)], on[static_cast<size_t>(b)]);
          }
    }
    if (threads > 1) {
      const auto throw_last = [&](int part) {
        if (part == threads - 1) throw std::runtime_error("last part");
      };
      EXPECT_THROW(pool.run_parts(threads, throw_last), std::runtime_error);
    }
  }
}

/// A part that throws, on a worker or on the caller, never unwinds a worker: every part still
/// runs, and the caller gets the exception once all are done. The pool works on afterwards.
TEST(Threads, AThrowingPartReachesTheCaller) {
  ThreadPool pool(3);
  for (int thrower : {0, 1, 2}) {
    std::atomic<int> ran{0};
    try {
      pool.run(0, 3000, 1, 100, [&](size_t, size_t, int part) {
        ran.fetch_add(1);
        if (part == thrower) throw Error(ErrorCode::internal, "part " + std::to_string(part));
      });
      ADD_FAILURE() << "no exception from part " << thrower;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "part " + std::to_string(thrower));
    }
    EXPECT_EQ(ran.load(), 3);
  }
  std::atomic<int> items{0};
  pool.run(0, 3000, 1, 100, [&](size_t b, size_t e, int) { items.fetch_add(static_cast<int>(e - b)); });
  EXPECT_EQ(items.load(), 3000);
}

/// run_lines runs every step of every line once, each line's steps in order, each step only once
/// `ready` let it (here the islands' rule: an even step k > 0 of a line after step k - 2 of every
/// other line has ended), and ends whatever the threads: with more threads than this machine has
/// cores (a worker the system has not run yet), the others take its line.
TEST(Threads, RunLinesKeepsEachLinesOrderAndWhatReadyAsks) {
  for (int threads : {2, 3, 8}) {
    ThreadPool pool(threads);
    constexpr int kSteps = 40;
    const int lines = threads;
    std::atomic<int> clock{0};
    std::vector<int> begun(static_cast<size_t>(lines * kSteps), -1), ended(begun.size(), -1);
    std::vector<std::atomic<int>> runs(begun.size());
    const auto at = [&](int line, int step) { return static_cast<size_t>(line * kSteps + step); };
    const auto ready = [&](int line, int step, const auto& done) {
      if (step % 2 != 0 || step == 0) return true;
      for (int q = 0; q < lines; ++q)
        if (q != line && done(q) < step - 1) return false;
      return true;
    };
    for (int repeat = 0; repeat < 50; ++repeat) {
      pool.run_lines(lines, kSteps, ready, [&](int line, int step) {
        begun[at(line, step)] = clock.fetch_add(1);
        runs[at(line, step)].fetch_add(1);
        ended[at(line, step)] = clock.fetch_add(1);
      });
      for (int s = 0; s < lines; ++s)
        for (int k = 0; k < kSteps; ++k) {
          ASSERT_EQ(runs[at(s, k)].exchange(0), 1) << "line " << s << " step " << k;
          if (k > 0) {
            EXPECT_LT(ended[at(s, k - 1)], begun[at(s, k)]) << "line " << s << " step " << k;
          }
          for (int q = 0; k % 2 == 0 && k > 0 && q < lines; ++q) {
            if (q != s) {
              EXPECT_LT(ended[at(q, k - 2)], begun[at(s, k)]) << "line " << s << " step " << k;
            }
          }
        }
    }
  }
}

/// A step that throws stops the lines: the caller gets the exception (no part waits for the line
/// that stopped), and the pool works on afterwards.
TEST(Threads, AThrowingStepOfRunLinesReachesTheCaller) {
  ThreadPool pool(3);
  const auto always = [](int, int, const auto&) { return true; };
  for (int thrower : {0, 1, 2}) {
    try {
      pool.run_lines(3, 10, always, [&](int line, int step) {
        if (line == thrower && step == 5) throw Error(ErrorCode::internal, "line " + std::to_string(line));
      });
      ADD_FAILURE() << "no exception from line " << thrower;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "line " + std::to_string(thrower));
    }
  }
  std::atomic<int> steps{0};
  pool.run_lines(3, 10, always, [&](int, int) { steps.fetch_add(1); });
  EXPECT_EQ(steps.load(), 30);
}

/// A 128 x 128 cloth pinned at two corners at the default settings (chain solve, automatic tethers
/// in lanes, bending) falling onto a sphere: big enough that every colour of every kind is split
/// over the threads.
std::unique_ptr<World> cloth(int threads, int n = 128, int32_t self_collision = 0) {
  Settings s;
  s.threads = threads;
  s.self_collision = self_collision;
  auto w = std::make_unique<World>(s);
  const test::Grid g = test::make_grid(n, n, 1.0 / (n - 1), Vec3(-0.5, -0.5, 1.0));
  BodyDesc d;
  d.positions = g.positions;
  d.triangles = g.triangles;
  d.material.thickness = 0.002;
  d.generate = generate_stretch | generate_bend;
  w->create_body(d);
  test::hard_pin(*w, g.index(0, n - 1), Vec3(-0.5, 0.5, 1.0));
  test::hard_pin(*w, g.index(n - 1, n - 1), Vec3(0.5, 0.5, 1.0));
  ColliderDesc sphere;
  sphere.shape = ColliderShape::sphere;
  sphere.position = Vec3(0.1, -0.2, 0.8);
  sphere.radius = 0.15;
  w->create_collider(sphere);
  return w;
}

/// Positions, velocities and the residual, as raw doubles.
std::vector<double> state(const World& w) {
  std::vector<double> out = test::flatten(w.positions());
  const std::vector<double> v = test::flatten(w.velocities());
  out.insert(out.end(), v.begin(), v.end());
  out.push_back(w.report().residual_max);
  out.push_back(w.report().residual_rms);
  return out;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(Threads, ClothIsBitIdenticalAtAnyThreadCount) {
  constexpr int kFrames = 10;
  auto w1 = cloth(1);
  for (int f = 0; f < kFrames; ++f) w1->step();
  const std::vector<double> one = state(*w1);
  for (int threads : {2, 3, 8}) {
    auto w = cloth(threads);
    for (int f = 0; f < kFrames; ++f) w->step();
    EXPECT_TRUE(same_bits(state(*w), one)) << threads << " threads";
  }
  // The thread count changed between frames changes nothing either.
  auto w = cloth(1);
  for (int f = 0; f < kFrames; ++f) {
    Settings s = w->settings();
    s.threads = 1 + f % 4;
    w->set_settings(s);
    w->step();
  }
  EXPECT_TRUE(same_bits(state(*w), one)) << "thread count changed every frame";
}

/// A 65 x 65 cloth sliding at 1 m/s along the crease of a V of two planes (each tilted 20 degrees,
/// each with its own friction): over 4,096 contacts, so collider friction is split over the
/// threads, and the column of particles on the crease pushed by both planes, their two contacts
/// listed collider by collider, far apart (friction takes a particle's contacts in their order on
/// one thread). The same bits at 1, 2 and 3 threads.
TEST(Threads, CollidersFrictionIsBitIdenticalAtAnyThreadCount) {
  constexpr int kFrames = 10, n = 65;
  const double tilt = 20.0 * std::numbers::pi / 180.0;
  test::Grid g = test::make_grid(n, n, 1.0 / (n - 1), Vec3(-0.5, -0.5, 0.0));
  for (size_t i = 0; i < g.positions.size(); i += 3)  // resting on the planes: a half thickness off them
    g.positions[i + 2] = std::abs(g.positions[i]) * std::tan(tilt) + 0.001 / std::cos(tilt);
  std::vector<double> one;
  for (int threads : {1, 2, 3}) {
    Settings s;
    s.threads = threads;
    World w(s);
    BodyDesc d;
    d.positions = g.positions;
    d.triangles = g.triangles;
    d.material.thickness = 0.002;
    const int32_t first = w.body(w.create_body(d)).first_particle;
    std::vector<double> v;
    for (int i = 0; i < n * n; ++i) v.insert(v.end(), {0.0, 1.0, 0.0});
    w.set_velocities(first, v);
    for (double side : {1.0, -1.0}) {
      ColliderDesc plane;
      plane.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(side * tilt, Vec3::UnitY()));
      plane.friction_static = side > 0.0 ? 0.5 : 0.8;
      plane.friction_dynamic = side > 0.0 ? 0.3 : 0.6;
      w.create_collider(plane);
    }
    for (int f = 0; f < kFrames; ++f) w.step();
    EXPECT_GE(w.report().contact_count, n * n) << threads << " threads";  // split over the threads
    if (threads == 1) {
      one = state(w);
      EXPECT_LT(test::flatten(w.velocities())[1], 0.9);  // friction slowed the cloth
    } else {
      EXPECT_TRUE(same_bits(state(w), one)) << threads << " threads";
    }
  }
}

/// The geometry goal kinds (length and angle ranges, co-linear, direction, co-circular,
/// co-spherical) on a falling 32 x 32 cloth, soft: the same bits at 1, 2 and 3 threads.
TEST(Threads, GeometryGoalsAreBitIdenticalAtAnyThreadCount) {
  constexpr int kFrames = 10, n = 32;
  const test::Grid g = test::make_grid(n, n, 1.0 / (n - 1), Vec3(-0.5, -0.5, 1.0));
  const auto add = [&](World& w, Kind kind, std::vector<int32_t> ids) {
    ConstraintDesc d;
    d.kind = kind;
    d.particles = ids;
    d.uniform_compliance = 1e-6;
    w.add_constraints(d);
  };
  std::vector<double> one;
  for (int threads : {1, 2, 3}) {
    auto w = cloth(threads, n);
    for (int j = 1; j + 2 < n; j += 3) {
      const int32_t a = g.index(0, j), b = g.index(n / 2, j + 1), c = g.index(n - 1, j);
      add(*w, Kind::length_min, {g.index(3, j), g.index(5, j + 1)});
      add(*w, Kind::angle_min, {g.index(4, j), g.index(5, j), g.index(4, j + 1)});
      add(*w, Kind::angle_max, {g.index(7, j), g.index(8, j), g.index(7, j + 1)});
      add(*w, Kind::colinear, {a, b, c});
      add(*w, Kind::direction, {g.index(10, j), g.index(11, j + 1), g.index(12, j), g.index(13, j)});
      add(*w, Kind::cocircular, {g.index(15, j), g.index(16, j), g.index(17, j + 2), g.index(15, j + 1)});
    }
    // Five points off the cloth (its points are flat: no sphere through four of them).
    const int32_t p = test::add_particles(*w, {{2, 0, 1}, {2.3, 0, 1}, {2, 0.3, 1}, {2, 0, 1.3}, {2.4, 0.4, 1.3}},
                                          {1.0, 1.0, 1.0, 1.0, 1.0});
    add(*w, Kind::cospherical, {p, p + 1, p + 2, p + 3, p + 4});
    for (int f = 0; f < kFrames; ++f) w->step();
    if (threads == 1)
      one = state(*w);
    else
      EXPECT_TRUE(same_bits(state(*w), one)) << threads << " threads";
  }
}

/// The self-collision detection (broad phase pairs, narrow phase contacts) split over the threads:
/// a 64 x 64 cloth folding over a sphere onto itself, the same bits at 1, 2 and 3 threads.
TEST(Threads, SelfCollidingClothIsBitIdenticalAtAnyThreadCount) {
  constexpr int kFrames = 24;
  std::vector<double> one;
  int64_t contacts = 0;
  for (int threads : {1, 2, 3}) {
    auto w = cloth(threads, 64, 1);
    for (int f = 0; f < kFrames; ++f) {
      w->step();
      if (threads == 1) contacts += w->report().contact_count;
    }
    if (threads == 1)
      one = state(*w);
    else
      EXPECT_TRUE(same_bits(state(*w), one)) << threads << " threads";
  }
  EXPECT_GT(contacts, 0);  // contacts were found (the sphere, and the cloth on itself)
}

/// A panel mesh with shared corners projects its panels colour by colour, each colour cut over the
/// threads at the same places of the mesh (IslandPlan::cut). The per-particle passes (prediction,
/// Chebyshev steps, velocities) give each thread the particles its own panels hold, so a particle
/// crosses between the cores' caches only along the border between their stretches: with equal
/// ranges of particle indices, one thread would take the whole top layer and the other the bottom.
TEST(Threads, ParticlePassesTakeTheParticlesOfTheirThreadsPanels) {
  Settings s;
  s.threads = 2;
  World w(s);
  test::add_panel_grid(w, 16, 16, 0.2, 0.01, PanelCorners::shared);
  w.step();
  const IslandPlan& plan = w.group(w.default_group()).islands;
  ASSERT_GT(plan.colour_start.size(), 2u) << "the panels go as islands in colours";
  // The cut: from 0 to 1, in order, one stretch per thread.
  ASSERT_EQ(plan.cut.size(), (plan.colour_start.size() - 1) * 3);
  for (size_t c = 0; c + 1 < plan.colour_start.size(); ++c) {
    EXPECT_EQ(plan.cut[3 * c], 0.0);
    EXPECT_LE(plan.cut[3 * c], plan.cut[3 * c + 1]);
    EXPECT_LE(plan.cut[3 * c + 1], plan.cut[3 * c + 2]);
    EXPECT_EQ(plan.cut[3 * c + 2], 1.0);
  }
  // The runs cover every particle once, in order, each in one of the two parts.
  const auto& runs = w.particle_runs();
  ASSERT_FALSE(runs.empty());
  const size_t n = w.positions().size();
  std::vector<int> part(n, -1);
  int32_t next = 0;
  for (const auto& r : runs) {
    EXPECT_EQ(r[0], next);
    EXPECT_LT(r[0], r[1]);
    EXPECT_TRUE(r[2] == 0 || r[2] == 1);
    for (int32_t i = r[0]; i < r[1]; ++i) part[static_cast<size_t>(i)] = r[2];
    next = r[1];
  }
  EXPECT_EQ(static_cast<size_t>(next), n);
  // Each panel's particles in the part of the thread that projects it at the mesh's middle cut
  // (items placed before 1/2 go to the first thread), but for the particles on the border.
  size_t held = 0, elsewhere = 0;
  for (const IslandPlan::Item& item : plan.items) {
    const IslandPlan::Shape& shape = plan.shapes[static_cast<size_t>(item.shape)];
    const int thread = item.place < 0.5 ? 0 : 1;
    for (int32_t is = item.first; is < item.first + item.count; ++is)
      for (int32_t k = 0; k < shape.slots; ++k)
        (part[static_cast<size_t>(shape.particle[static_cast<size_t>(is * shape.slots + k)])] == thread ? held
                                                                                                        : elsewhere)++;
  }
  EXPECT_LT(static_cast<double>(elsewhere), 0.15 * static_cast<double>(held + elsewhere)) << held << " " << elsewhere;
}

TEST(Threads, CountIsValidated) {
  Settings s;
  s.threads = 0;  // every core
  World w(s);
  EXPECT_EQ(w.settings().threads, 0);
  s.threads = limits::kMaxThreads + 1;
  EXPECT_THROW(w.set_settings(s), Error);
  s.threads = -1;
  EXPECT_THROW(w.set_settings(s), Error);
  EXPECT_EQ(w.settings().threads, 0);
}

}  // namespace
}  // namespace embra
