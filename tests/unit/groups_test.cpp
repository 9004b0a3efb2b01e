// Constraint groups (projection order and weight) and rest-length scaling.
#include "test_support.hpp"

#include <gtest/gtest.h>

namespace embra {
namespace {

using test::Rng;

// Two hard distance constraints that cannot both hold, on one particle p and an immovable anchor a:
//   group A: |p - a| = 1        group B: |p - a| = 2
// Every substep projects the groups in increasing order; a hard projection against an immovable
// anchor lands exactly on its rest length, so the group projected last wins exactly. Swapping the
// orders swaps the winner; equal orders fall back to creation order.
TEST(Groups, TheGroupProjectedLastWinsExactly) {
  Rng rng(21);
  for (int c = 0; c < 5; ++c) {
    World w(test::settings(4, 3));
    const int32_t first = test::add_particles(w, {Vec3::Zero(), 1.5 * rng.unit()}, {0.0, 1.0});
    GroupDesc ga, gb;
    ga.order = 0;
    gb.order = 1;
    const Id a = w.create_group(ga), b = w.create_group(gb);
    const std::vector<int32_t> ids{first, first + 1};
    for (const auto& [group, rest] : {std::pair{a, 1.0}, std::pair{b, 2.0}}) {
      const std::vector<double> r{rest};
      ConstraintDesc d;
      d.group = group;
      d.particles = ids;
      d.rest = r;
      w.add_constraints(d);
    }
    auto length = [&] { return (w.positions()[first + 1] - w.positions()[first]).norm(); };
    for (int f = 0; f < 10; ++f) {
      w.step();
      EXPECT_NEAR(length(), 2.0, 1e-14) << "B last, frame " << f;
    }
    w.set_group_order(a, 2);
    for (int f = 0; f < 10; ++f) {
      w.step();
      EXPECT_NEAR(length(), 1.0, 1e-14) << "A last, frame " << f;
    }
    w.set_group_order(a, 1);  // tie with B: creation order, so B (created after A) is last again
    for (int f = 0; f < 10; ++f) {
      w.step();
      EXPECT_NEAR(length(), 2.0, 1e-14) << "tie, frame " << f;
    }
  }
}

// A soft conflict: springs in series between an immovable anchor and a soft pin's target.
//
//   anchor o~~~~~o~~~~~o ~ ~ ~ x target          group B: the two links (rest 1, compliance alpha)
//          0     1     2       3                 group A: soft pin of particle 2 to x = 3 (alpha)
//
// The physical equilibrium stretches each of the three springs by the same force F:
// 1 = F (alpha + 2 alpha), each spring taking 1/3 of the total extension of 1 m. With converged
// iterations the solver lands there whatever the groups' order and weight. With one iteration per
// substep the solve is truncated and the compromise depends on the schedule: projecting B more often
// (weight 2, 4) moves it towards B (the links stretch less, the pin gives more), and the group
// projected last is the better satisfied one.
struct Series {
  double link_stretch;  // mean over the two links
  double pin_gap;       // distance of particle 2 from the pin target
};

Series series(int iterations, int order_a, int weight_b) {
  const double alpha = 2e-5;  // alpha / h^2 = 1.15 with h = 1/240 s: comparable to 1/m = 1
  // One constraint at a time (Settings::chain_solve = 0): the truncated solve is the Gauss-Seidel one
  // that weights and order bias. A chain solve would satisfy B's two collinear links exactly in one
  // projection, whatever B's weight.
  Settings s = test::settings(4, iterations, Vec3::Zero(), 40.0);
  s.chain_solve = 0;
  World w(s);
  const int32_t first = test::add_particles(w, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}, {0.0, 1.0, 1.0});
  GroupDesc ga, gb;
  ga.order = order_a;
  gb.order = 1;
  gb.weight = weight_b;
  const Id a = w.create_group(ga), b = w.create_group(gb);
  const std::vector<int32_t> ids{first, first + 1, first + 1, first + 2};
  const std::vector<double> rest{1.0, 1.0};
  ConstraintDesc d;
  d.group = b;
  d.particles = ids;
  d.rest = rest;
  d.uniform_compliance = alpha;
  w.add_constraints(d);
  PinDesc p;
  p.particle = first + 2;
  p.target = Vec3(3, 0, 0);
  p.compliance = alpha;
  p.group = a;
  w.create_pin(p);
  for (int f = 0; f < 300; ++f) w.step();
  const auto& x = w.positions();
  return Series{0.5 * ((x[first + 1] - x[first]).norm() + (x[first + 2] - x[first + 1]).norm()) - 1.0,
                (x[first + 2] - Vec3(3, 0, 0)).norm()};
}

TEST(Groups, ConvergedSolveIsThePhysicalEquilibriumWhateverTheSchedule) {
  for (int order_a : {0, 2})
    for (int weight_b : {1, 4}) {
      const Series s = series(200, order_a, weight_b);
      EXPECT_NEAR(s.link_stretch, 1.0 / 3.0, 1e-9) << "order_a " << order_a << " weight_b " << weight_b;
      EXPECT_NEAR(s.pin_gap, 1.0 / 3.0, 1e-9) << "order_a " << order_a << " weight_b " << weight_b;
    }
}

TEST(Groups, WeightAndOrderBiasATruncatedSolve) {
  // Heavier B: B's links closer to their rest length, A's pin further from its target.
  const Series w1 = series(1, 0, 1), w2 = series(1, 0, 2), w4 = series(1, 0, 4);
  EXPECT_LT(w2.link_stretch, w1.link_stretch);
  EXPECT_LT(w4.link_stretch, w2.link_stretch);
  EXPECT_GT(w2.pin_gap, w1.pin_gap);
  EXPECT_GT(w4.pin_gap, w2.pin_gap);
  // Order: A last (order 2 > 1) satisfies A better than A first.
  const Series a_first = series(1, 0, 1), a_last = series(1, 2, 1);
  EXPECT_LT(a_last.pin_gap, a_first.pin_gap);
  EXPECT_GT(a_last.link_stretch, a_first.link_stretch);
  RecordProperty("pin_gap_weight1", test::sci(w1.pin_gap));
  RecordProperty("pin_gap_weight4", test::sci(w4.pin_gap));
}

// Rest-length scale: a hard chain (a body of edges, zig-zag so it is not a straight line) with
// set_rest_scale(body, 0.8, 1, 1) settles with every link at 0.8 of its original length.
TEST(RestScale, UniformScaleShrinksAHardChain) {
  World w(test::settings(8, 20, Vec3::Zero(), 10.0));
  std::vector<double> x;
  std::vector<int32_t> edges;
  for (int k = 0; k < 8; ++k) {
    x.insert(x.end(), {0.2 * k, (k % 2) * 0.07, 0.0});
    if (k > 0) edges.insert(edges.end(), {k - 1, k});
  }
  BodyDesc d;
  d.positions = x;
  d.edges = edges;
  d.generate = generate_stretch;
  const Id body = w.create_body(d);
  std::vector<double> original;
  for (int k = 1; k < 8; ++k) original.push_back((w.positions()[k] - w.positions()[k - 1]).norm());
  w.set_rest_scale(body, 0.8, 1.0, 1.0);
  EXPECT_EQ(w.body(body).rest_scale, 0.8);
  for (int f = 0; f < 240; ++f) w.step();
  for (int k = 1; k < 8; ++k)
    EXPECT_NEAR((w.positions()[k] - w.positions()[k - 1]).norm(), 0.8 * original[k - 1], 1e-9 * original[k - 1])
        << "link " << k;
}

// Per-direction scale on a body with uvs: a flat 4 x 3 cloth in the xy plane with uv = grid index
// (u along x, v along y), hard stretch. set_rest_scale(body, 1, 0.7, 1) scales the u part of every
// rest length: edges along u shrink to 0.7, edges along v keep their length, and a diagonal with
// grid steps (du, dv) becomes spacing * sqrt((0.7 du)^2 + dv^2). The affinely squashed grid
// (x -> 0.7 x) meets all of these at once, so the hard cloth can settle onto it exactly.
TEST(RestScale, UScaleChangesOnlyTheUEdges) {
  const double spacing = 0.1, su = 0.7;
  World w(test::settings(8, 50, Vec3::Zero(), 10.0));
  const test::Grid g = test::make_grid(4, 3, spacing, Vec3::Zero());
  BodyDesc d;
  d.positions = g.positions;
  d.uvs = g.uvs;
  d.triangles = g.triangles;
  d.material.bend_compliance = 1e-3;
  d.generate = generate_stretch | generate_bend;
  const Id body = w.create_body(d);
  w.set_rest_scale(body, 1.0, su, 1.0);
  for (int f = 0; f < 240; ++f) w.step();
  const ConstraintArray& links = w.group(w.default_group()).arrays[static_cast<int>(Kind::distance)];
  int u_edges = 0, v_edges = 0, diagonals = 0;
  for (size_t i = 0; i < links.size(); ++i) {
    const int32_t a = links.ids[2 * i], b = links.ids[2 * i + 1];
    const double du = std::abs(g.uvs[2 * a] - g.uvs[2 * b]), dv = std::abs(g.uvs[2 * a + 1] - g.uvs[2 * b + 1]);
    const double expected = spacing * std::hypot(su * du, dv);
    const double length = (w.positions()[a] - w.positions()[b]).norm();
    EXPECT_NEAR(length, expected, 1e-9 * expected) << "edge " << a << "-" << b << " du " << du << " dv " << dv;
    if (dv == 0.0) ++u_edges;
    if (du == 0.0) {
      ++v_edges;
      EXPECT_NEAR(length, spacing * dv, 1e-9 * spacing) << "a v edge changed length";
    }
    if (du != 0.0 && dv != 0.0) ++diagonals;
  }
  EXPECT_EQ(u_edges, 3 * 3);
  EXPECT_EQ(v_edges, 4 * 2);
  EXPECT_EQ(diagonals, 3 * 2);
}

}  // namespace
}  // namespace embra
