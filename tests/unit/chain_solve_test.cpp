// Settings::chain_solve: distance constraints lying end to end in straight runs are projected a run
// at a time, each run's linearised XPBD system solved exactly (tridiagonal).
//
// Two properties anyone can check from positions alone:
// * Along a straight line the constraints are linear in the displacements along it, so one exact
//   solve of the chain satisfies every link at once, from any stretch pattern, where one
//   Gauss-Seidel sweep leaves most of it (a correction travels one link per pass).
// * Off a straight line the solve is one Newton step for the whole chain: the residual after it is
//   quadratic in the residual before (ten times smaller a perturbation, a hundred times smaller a
//   residual), and far below what one sweep leaves.
// And the chains a regular grid gets are exactly its rows, columns and diagonals.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>
#include <set>

namespace embra {
namespace {

constexpr double kLink = 0.05;  // m

/// A chain of links through `shape` (its rest shape; the first particle immovable), moved to `start`
/// and stepped once with no gravity, no velocity and one iteration: the step is one projection pass.
/// Returns the largest |length / rest - 1| over the links afterwards.
double one_pass(const std::vector<Vec3>& shape, const std::vector<Vec3>& start, int32_t chain_solve,
                int32_t* chains = nullptr) {
  Settings s = test::settings(1, 1);
  s.tethers = 0;
  s.chain_solve = chain_solve;
  World w(s);
  const std::vector<double> xyz = test::flatten(shape);
  std::vector<double> masses(shape.size(), 0.1);
  masses[0] = 0.0;
  std::vector<int32_t> edges;
  for (int32_t k = 0; k + 1 < static_cast<int32_t>(shape.size()); ++k) edges.insert(edges.end(), {k, k + 1});
  BodyDesc d;
  d.positions = xyz;
  d.masses = masses;
  d.edges = edges;
  d.generate = generate_stretch;
  w.create_body(d);
  w.set_positions(0, test::flatten(start));
  w.step();
  if (chains) {
    const SolverArray& a = w.group(w.default_group()).solve[static_cast<int>(Kind::distance)];
    *chains = a.chain_start.empty() ? 0 : static_cast<int32_t>(a.chain_start.size() - 1);
  }
  double worst = 0.0;
  const auto& x = w.positions();
  for (size_t k = 0; k + 1 < x.size(); ++k)
    worst = std::max(worst, std::abs((x[k + 1] - x[k]).norm() / (shape[k + 1] - shape[k]).norm() - 1.0));
  return worst;
}

/// A 40-link vertical line whose links are stretched or squeezed by up to 5 %, each at random.
TEST(ChainSolve, OnePassSatisfiesEveryLinkOfAStraightLine) {
  test::Rng rng(7);
  std::vector<Vec3> shape, start;
  double z = 0.0;
  for (int k = 0; k <= 40; ++k) {
    shape.emplace_back(0.0, 0.0, -kLink * k);
    start.emplace_back(0.0, 0.0, z);
    z -= kLink * (1.0 + rng.uniform(-0.05, 0.05));
  }
  int32_t chains = 0;
  const double chained = one_pass(shape, start, 1, &chains);
  const double swept = one_pass(shape, start, 0);
  RecordProperty("residual_chain", test::sci(chained));
  RecordProperty("residual_gauss_seidel", test::sci(swept));
  EXPECT_EQ(chains, 1);
  EXPECT_LT(chained, 1e-13);  // exact to rounding
  EXPECT_GT(swept, 1e-3);     // what one sweep leaves of the same start
}

/// A 30-link quarter circle (3 degrees a joint) moved by random 3D offsets of size eps and 10 eps.
TEST(ChainSolve, OnePassIsANewtonStepForACurvedChain) {
  std::vector<Vec3> shape;
  const int links = 30;
  const double radius = links * kLink / (std::numbers::pi / 2);
  for (int k = 0; k <= links; ++k) {
    const double t = (std::numbers::pi / 2) * k / links;
    shape.emplace_back(radius * std::sin(t), 0.0, -radius * (1.0 - std::cos(t)));
  }
  auto residual_after = [&](double eps, int32_t chain_solve, double* before) {
    test::Rng rng(11);
    std::vector<Vec3> start = shape;
    for (size_t k = 1; k < start.size(); ++k) start[k] += eps * kLink * rng.vec(-1.0, 1.0);
    if (before) {
      *before = 0.0;
      for (size_t k = 0; k + 1 < start.size(); ++k)
        *before = std::max(*before, std::abs((start[k + 1] - start[k]).norm() / kLink - 1.0));
    }
    return one_pass(shape, start, chain_solve);
  };
  double before_large = 0.0, before_small = 0.0;
  const double large = residual_after(1e-3, 1, &before_large);
  const double small = residual_after(1e-4, 1, &before_small);
  const double swept = residual_after(1e-3, 0, nullptr);
  RecordProperty("before_1e-3", test::sci(before_large));
  RecordProperty("after_1e-3", test::sci(large));
  RecordProperty("before_1e-4", test::sci(before_small));
  RecordProperty("after_1e-4", test::sci(small));
  RecordProperty("after_1e-3_gauss_seidel", test::sci(swept));
  // Quadratic: a residual of order before^2 (times the chain's curvature), not before.
  EXPECT_LT(large, 0.01 * before_large * before_large);
  EXPECT_LT(small, 0.01 * before_small * before_small);
  EXPECT_GT(large / small, 50.0);
  EXPECT_LT(large, swept / 100.0);
}

/// An n x n grid split along one diagonal: its chains are its n rows, n columns and 2n - 3
/// diagonals, each constraint in exactly one, each chain a path of distinct particles. At the two
/// corners the diagonals miss only a row's and a column's edges meet, and a diagonal joins their far
/// ends: a triangle's corner, where the row does not turn into the column (a chain goes on through
/// a particle of two constraints at any angle only where no third joins their far ends: a cable's).
TEST(ChainSolve, AGridsChainsAreItsRowsColumnsAndDiagonals) {
  const int n = 9;
  std::vector<double> xyz;
  std::vector<int32_t> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) xyz.insert(xyz.end(), {kLink * i, kLink * j, 0.0});
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int32_t a = j * n + i, b = a + 1, c = a + n + 1, e = a + n;
      tris.insert(tris.end(), {a, b, c, a, c, e});
    }
  World w(test::settings(1, 1, Vec3(0, 0, -9.81)));
  BodyDesc d;
  d.positions = xyz;
  d.triangles = tris;
  d.generate = generate_stretch;
  w.create_body(d);
  w.step();
  const SolverArray& a = w.group(w.default_group()).solve[static_cast<int>(Kind::distance)];
  ASSERT_EQ(a.chain_start.size(), static_cast<size_t>(4 * n - 3 + 1));
  std::vector<int> seen(a.size(), 0);
  std::multiset<int> lengths;
  for (size_t c = 0; c + 1 < a.chain_start.size(); ++c) {
    const int32_t first = a.chain_start[c], m = a.chain_start[c + 1] - first;
    const int32_t* parts = &a.chain_part[first + c];
    std::set<int32_t> distinct(parts, parts + m + 1);
    EXPECT_EQ(distinct.size(), static_cast<size_t>(m + 1));
    for (int32_t k = 0; k < m; ++k) {
      const int32_t e = a.chain_edge[first + k];
      ++seen[e];
      const std::set<int32_t> ends{a.ids[2 * e], a.ids[2 * e + 1]};
      EXPECT_EQ(ends, (std::set<int32_t>{parts[k], parts[k + 1]}));
    }
    lengths.insert(m);
  }
  for (int count : seen) EXPECT_EQ(count, 1);
  // Rows and columns have n - 1 links; the diagonals 1 .. n - 1 links, two of each but the longest.
  EXPECT_EQ(lengths.count(n - 1), static_cast<size_t>(2 * n + 1));
  EXPECT_EQ(lengths.count(2 * (n - 1)), 0u);
  for (int m = 1; m < n - 1; ++m) EXPECT_EQ(lengths.count(m), 2u) << m;
}

/// A 64-link rope (links 0.01 kg) whose first particle is immovable, with or without its last, in
/// the default schedule (20 substeps x 1 iteration) with damping 20/s for 600 frames; the rest
/// lengths add up to `length` over a span of 1 m. Returns the peak and final speeds and the final
/// largest |length - rest| of a link.
struct RopeRun {
  double peak = 0.0, speed = 0.0, residual = 0.0;
};
RopeRun rope(int32_t chain_solve, double length, bool both_ends, bool sagged_start, int32_t substeps = 20,
             int32_t weight = 1) {
  const int n = 64;
  Settings s = test::settings(substeps, 1, Vec3(0, 0, -9.81), 20.0);
  s.tethers = 0;
  s.chain_solve = chain_solve;
  World w(s);
  std::vector<Vec3> x;
  for (int k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) / n;
    x.emplace_back(t, 0.0, sagged_start ? -0.3 * std::sin(std::numbers::pi * t) : 0.0);
  }
  std::vector<double> masses(n + 1, 0.01);
  masses[0] = 0.0;
  if (both_ends) masses[n] = 0.0;
  const int32_t first = test::add_particles(w, x, masses);
  std::vector<int32_t> ids;
  for (int k = 0; k < n; ++k) ids.insert(ids.end(), {first + k, first + k + 1});
  const std::vector<double> rest(n, length / n);
  GroupDesc g;
  g.weight = weight;
  ConstraintDesc d;
  d.group = w.create_group(g);
  d.particles = ids;
  d.rest = rest;
  w.add_constraints(d);
  RopeRun r;
  for (int f = 0; f < 600; ++f) {
    w.step();
    r.peak = std::max(r.peak, w.report().max_speed);
  }
  r.speed = w.report().max_speed;
  for (int k = 0; k < n; ++k)
    r.residual =
        std::max(r.residual, std::abs((w.positions()[first + k + 1] - w.positions()[first + k]).norm() - length / n));
  return r;
}

/// A straight rope held at one end whose links are 2 % or 20 % too short for where they start
/// (rest lengths adding up to 1.02 or 1.2 m over 1 m): nearly straight chains squeezed along their
/// length have near-zero pivots, and an unguarded Newton step carried particles many links and blew
/// the rope up (to 1e37 m/s in review). It falls and hangs like the one-at-a-time solve, its links
/// exact.
TEST(ChainSolve, AStraightRopeSqueezedAlongItsLengthFallsAndHangsCalmly) {
  for (double length : {1.02, 1.2}) {
    const RopeRun chain = rope(1, length, false, false), swept = rope(0, length, false, false);
    std::printf("rope of %.2f m on one pin: peak speed %.2f m/s (one at a time %.2f), link residual %.1e (%.1e)\n",
                length, chain.peak, swept.peak, chain.residual, swept.residual);
    EXPECT_LT(chain.peak, 5.0) << length;  // a 1 m rope falling from level: about 3.5 m/s at most
    EXPECT_LT(chain.peak, 1.5 * std::max(swept.peak, 2.0)) << length;
    EXPECT_LT(chain.residual, 1e-9) << length;
  }
}

/// A rope between two pins started off its lengths (a sagged sine, rest 1.2 m over a 1 m span) comes
/// to rest, its links exact; and with the rope's group at weight 10 (two substeps of one iteration)
/// the chain step is taken once a substep, not ten times, so it rests there too (repeated Newton steps
/// within a substep had left it sliding at 3 cm/s).
TEST(ChainSolve, ARopeBetweenTwoPinsComesToRestAtAnyGroupWeight) {
  const RopeRun settled = rope(1, 1.2, true, true);
  EXPECT_LT(settled.speed, 1e-6);
  EXPECT_LT(settled.residual, 1e-8);
  const RopeRun weighted = rope(1, 1.2, true, true, 2, 10);
  RecordProperty("speed_weight_10", test::sci(weighted.speed));
  EXPECT_LT(weighted.speed, 1e-6);
}

}  // namespace
}  // namespace embra
