// Coming to rest on the right shape, and saying so only when it is: a cable built by hand is one
// chain for the chain solve whatever its turns; solve's "within tolerance" holds only when the
// constraints' residuals are within their targets (a stretched inextensible chain is not); with the
// chain solve before the realignment passes a 64-link chain settles on its exact static equilibrium
// (the discrete catenary, and pin reactions that carry the whole weight); a 32 x 32 net carries its
// weight at rest and solve says how far its links are off.
#include "discrete_catenary.hpp"
#include "embra/core/solve.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace embra {
namespace {

constexpr double kSpan = 1.0, kLength = 1.2, kMass = 0.1, kG = 9.81;
const Vec3 kLeft(-0.5, 0.0, 0.0);

/// A chain of n links built by hand (loose particles, distance constraints added one by one) on a
/// circular arc of length kLength through two hard pins kSpan apart: its rest shape curves by
/// 2 / n rad a joint. Every particle kMass. Returns the first particle.
int32_t hang_arc_chain(World& w, int n) {
  double lo = 1e-6, hi = std::numbers::pi - 1e-6;  // half angle t: sin(t) / t = span / length
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::sin(mid) / mid > kSpan / kLength ? lo : hi) = mid;
  }
  const double t = 0.5 * (lo + hi), radius = kLength / (2.0 * t);
  std::vector<Vec3> x;
  for (int k = 0; k <= n; ++k) {
    const double a = -t + 2.0 * t * k / n;
    x.emplace_back(radius * std::sin(a), 0.0, -radius * (std::cos(a) - std::cos(t)));
  }
  const int32_t first = test::add_particles(w, x, std::vector<double>(n + 1, kMass));
  test::hard_pin(w, first, x.front());
  test::hard_pin(w, first + n, x.back());
  std::vector<int32_t> ids;
  for (int k = 0; k < n; ++k) ids.insert(ids.end(), {first + k, first + k + 1});
  const std::vector<double> rest(n, kLength / n);
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = ids;
  d.rest = rest;
  w.add_constraints(d);
  return first;
}

double chain_length(const World& w, int32_t first, int n) {
  double s = 0.0;
  for (int k = 0; k < n; ++k) s += (w.positions()[first + k + 1] - w.positions()[first + k]).norm();
  return s;
}

Vec3 total_reaction(const World& w) {
  Vec3 f = Vec3::Zero();
  for (const Reaction& r : w.reactions()) f += r.force;
  return f;
}

/// Settings that settle on the exact equilibrium: the defaults (16 substeps of 1/60 s, 1 iteration,
/// chain solve) with 2 realignment passes and damping 6/s.
Settings exact_settings() {
  Settings s;
  s.realign_passes = 2;
  s.damping = 6.0;
  return s;
}

/// A polyline of 16 links turning 90 degrees at every joint (a staircase in the x-z plane), built by
/// hand: the chain solve takes it as one chain, every link in it once.
TEST(FormFinding, AHandBuiltCableIsOneChainWhateverItsTurns) {
  World w(test::settings(1, 1));
  std::vector<Vec3> x;
  for (int k = 0; k <= 16; ++k) x.emplace_back(0.05 * ((k + 1) / 2), 0.0, -0.05 * (k / 2));
  const int32_t first = test::add_particles(w, x, std::vector<double>(17, kMass));
  std::vector<int32_t> ids;
  for (int k = 0; k < 16; ++k) ids.insert(ids.end(), {first + k, first + k + 1});
  const std::vector<double> rest(16, 0.05);
  ConstraintDesc d;
  d.particles = ids;
  d.rest = rest;
  w.add_constraints(d);
  w.step();
  const SolverArray& a = w.group(w.default_group()).solve[static_cast<int>(Kind::distance)];
  ASSERT_EQ(a.chain_start.size(), 2u);
  EXPECT_EQ(a.chain_start[1], 16);
  std::vector<int> seen(16, 0);
  for (int32_t e : a.chain_edge) ++seen[e];
  for (int count : seen) EXPECT_EQ(count, 1);
}

/// The defect this file was written for: a 16-link chain built by hand, solved with the form-finding
/// preset's step (one substep of 1/15 s, one iteration) without its global solve, comes to rest
/// stretched: its links add up to far more than their 1.2 m. solve says so: settled but out of
/// tolerance, the distance residual named, in metres, above its target.
TEST(FormFinding, AStretchedChainAtRestIsOutOfTolerance) {
  Settings s = form_finding_settings();
  s.global_solve = 0;
  World w(s);
  const int n = 16;
  const int32_t first = hang_arc_chain(w, n);
  const SolveResult r = solve(w, SolveSettings{}, Tolerances{});
  const double stretched = chain_length(w, first, n);
  RecordProperty("chain_length", test::sci(stretched));
  RecordProperty("distance_residual", test::sci(r.worst.value));
  EXPECT_GT(stretched, 1.05 * kLength);  // the preset leaves it stretched (see embra.h)
  EXPECT_EQ(r.outcome, SolveOutcome::settled_out_of_tolerance);
  EXPECT_EQ(r.worst.metric, kWorstResidual);
  EXPECT_EQ(r.worst.element, static_cast<int32_t>(Kind::distance));
  EXPECT_EQ(r.worst.target, kResidualTargetLength);
  EXPECT_GT(r.worst.value, 100.0 * r.worst.target);
  EXPECT_EQ(r.worst.value, w.report().by_kind[static_cast<int>(Kind::distance)].max);
}

/// 64 links of 1.875 cm built by hand on a circular arc, at the defaults with 2 realignment passes:
/// solve finds it at rest within tolerance; stepped on, it is the exact discrete catenary to 1e-6 of
/// the span, and the pins carry the whole weight (the pinned particles' too) to 1e-6 (measured
/// 3e-7: the reactions are the last substep's multipliers, and the chain still creeps at 1e-8 m/s)
/// with the catenary's horizontal tension H = W / (W / H) pulling them together.
TEST(FormFinding, SixtyFourLinksSettleOnTheExactDiscreteCatenary) {
  const int n = 64;
  World w(exact_settings());
  const int32_t first = hang_arc_chain(w, n);
  const SolveResult r = solve(w, SolveSettings{}, Tolerances{});
  EXPECT_EQ(r.outcome, SolveOutcome::settled_within_tolerance);
  for (int f = 0; f < 300; ++f) w.step();
  const test::DiscreteCatenary exact = test::discrete_catenary(n, kSpan, kLength, kLeft);
  double error = 0.0;
  for (int k = 0; k <= n; ++k) error = std::max(error, (w.positions()[first + k] - exact.nodes[k]).norm());
  const Vec3 total = total_reaction(w);
  const double weight = (n + 1) * kMass * kG, h_exact = kMass * kG / exact.w_over_h;
  const std::vector<Reaction> pins = w.reactions();
  ASSERT_EQ(pins.size(), 2u);
  RecordProperty("solve_frames", r.frames);
  RecordProperty("catenary_error", test::sci(error));
  RecordProperty("reaction_z", test::sci(total.z()));
  RecordProperty("max_speed", test::sci(w.report().max_speed));
  EXPECT_LT(error, 1e-6 * kSpan);
  EXPECT_NEAR(total.z(), weight, 1e-6 * weight);
  EXPECT_NEAR(total.x(), 0.0, 1e-6 * weight);
  EXPECT_NEAR(std::abs(pins[0].force.x()), h_exact, 1e-6 * h_exact);
  EXPECT_NEAR(std::abs(pins[1].force.x()), h_exact, 1e-6 * h_exact);
}

/// A net of n x n inextensible links (1 m square, 0.25 kg, no diagonals) hung from its four corners
/// drawn in to 70 % of the span. Returns the first particle; `edges` gets the links' particles.
int32_t hang_net(World& w, int n, std::vector<int32_t>& edges) {
  const double link = 1.0 / (n - 1), mass = 0.25 / (n * n);
  std::vector<double> xyz;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      xyz.insert(xyz.end(), {-0.5 + i * link, -0.5 + j * link, 0.0});
      const int32_t a = j * n + i;
      if (i + 1 < n) edges.insert(edges.end(), {a, a + 1});
      if (j + 1 < n) edges.insert(edges.end(), {a, a + n});
    }
  const std::vector<double> masses(static_cast<size_t>(n) * n, mass);
  BodyDesc d;
  d.positions = xyz;
  d.masses = masses;
  d.edges = edges;
  d.generate = generate_stretch;
  const int32_t first = w.body(w.create_body(d)).first_particle;
  std::vector<double> start = xyz;
  for (size_t i = 0; i < start.size(); i += 3) start[i] *= 0.7, start[i + 1] *= 0.7;
  w.set_positions(first, start);
  for (int32_t p : {0, n - 1, n * (n - 1), n * n - 1}) test::hard_pin(w, first + p, w.positions()[first + p]);
  return first;
}

/// The largest distance of a net's link (particles first + edges[2 e], first + edges[2 e + 1]) from
/// its length `link`.
double worst_link_stretch(const World& w, int32_t first, const std::vector<int32_t>& edges, double link) {
  const auto& x = w.positions();
  double stretch = 0.0;
  for (size_t e = 0; e < edges.size(); e += 2)
    stretch = std::max(stretch, std::abs((x[first + edges[e]] - x[first + edges[e + 1]]).norm() - link));
  return stretch;
}

/// The 32 x 32 net at the same settings: it comes to rest with the corners carrying the whole
/// weight, a quarter each; but one pass a substep does not converge a net's long-wavelength modes,
/// and it rests with links stretched by 2 % (measured: 6.6e-4 m). solve must say so: settled out of
/// tolerance, naming the distance residual, which is the stretch a link is left with.
TEST(FormFinding, AThirtyTwoNetAtRestCarriesItsWeightAndSaysWhereItIsOff) {
  const int n = 32;
  const double link = 1.0 / (n - 1);
  World w(exact_settings());
  std::vector<int32_t> edges;
  const int32_t first = hang_net(w, n, edges);
  const SolveResult r = solve(w, SolveSettings{}, Tolerances{});
  const double stretch = worst_link_stretch(w, first, edges, link);
  const double weight = 0.25 * kG;
  RecordProperty("solve_frames", r.frames);
  RecordProperty("max_link_stretch_m", test::sci(stretch));
  EXPECT_TRUE(r.outcome == SolveOutcome::settled_within_tolerance ||
              r.outcome == SolveOutcome::settled_out_of_tolerance);
  EXPECT_NEAR(total_reaction(w).z(), weight, 1e-4 * weight);
  for (const Reaction& c : w.reactions()) EXPECT_NEAR(c.force.z(), weight / 4, 1e-4 * weight);
  // The verdict is the links': out of tolerance exactly when a link is off its length by more than
  // the target, and then the distance residual is what it names.
  const bool off = stretch > kResidualTargetLength;
  EXPECT_EQ(r.outcome == SolveOutcome::settled_out_of_tolerance, off);
  if (off) {
    EXPECT_EQ(r.worst.metric, kWorstResidual);
    EXPECT_EQ(r.worst.element, static_cast<int32_t>(Kind::distance));
    EXPECT_NEAR(r.worst.value, stretch, 0.01 * stretch);
  }
}

/// The largest force left unbalanced at a free node of a settled net of distance constraints: its
/// weight plus the tension of every link on it (the solver's forces, N), over the node's weight.
double worst_node_imbalance(const World& w, Id group, double node_weight) {
  const ConstraintArray& a = w.group(group).arrays[static_cast<int>(Kind::distance)];
  const std::vector<double> tension = w.constraint_forces(group, Kind::distance);
  const auto& x = w.positions();
  std::vector<Vec3> f(x.size(), Vec3(0.0, 0.0, -node_weight));
  for (size_t e = 0; e < a.size(); ++e) {
    const int32_t p = a.ids[2 * e], q = a.ids[2 * e + 1];
    const Vec3 u = (x[q] - x[p]).normalized();
    f[p] += tension[e] * u;
    f[q] -= tension[e] * u;
  }
  double worst = 0.0;
  for (size_t i = 0; i < x.size(); ++i)
    if (w.inverse_masses()[i] > 0.0 && w.pins()[0].particle != static_cast<int32_t>(i)) {
      bool pinned = false;
      for (const Pin& pin : w.pins()) pinned = pinned || (pin.alive && pin.particle == static_cast<int32_t>(i));
      if (!pinned) worst = std::max(worst, f[i].norm() / node_weight);
    }
  return worst;
}

/// The form-finding preset (one substep of 1/15 s, one iteration, damping 6/s, the global solve) with
/// no tuning: the hand-built 64-link chain comes to rest on the exact discrete catenary to 1e-6 of
/// the span, its links at their length, the pins carrying the whole weight to 1e-9 with the
/// catenary's horizontal tension.
TEST(FormFinding, ThePresetSettlesSixtyFourLinksOnTheExactCatenary) {
  const int n = 64;
  World w(form_finding_settings());
  const int32_t first = hang_arc_chain(w, n);
  const SolveResult r = solve(w, SolveSettings{}, Tolerances{});
  const test::DiscreteCatenary exact = test::discrete_catenary(n, kSpan, kLength, kLeft);
  double error = 0.0, stretch = 0.0;
  for (int k = 0; k <= n; ++k) error = std::max(error, (w.positions()[first + k] - exact.nodes[k]).norm());
  for (int k = 0; k < n; ++k)
    stretch =
        std::max(stretch, std::abs((w.positions()[first + k + 1] - w.positions()[first + k]).norm() - kLength / n));
  RecordProperty("solve_frames", r.frames);
  RecordProperty("catenary_error", test::sci(error));
  RecordProperty("link_stretch", test::sci(stretch));
  EXPECT_EQ(r.outcome, SolveOutcome::settled_within_tolerance);
  EXPECT_LT(error, 1e-6 * kSpan);
  EXPECT_LT(stretch, 1e-9 * kLength);
  // Stepped on to rest (solve stops below 1 mm/s), the pins carry the weight with the catenary's
  // horizontal tension.
  for (int f = 0; f < 60; ++f) w.step();
  const Vec3 total = total_reaction(w);
  const double weight = (n + 1) * kMass * kG, h_exact = kMass * kG / exact.w_over_h;
  RecordProperty("max_speed_after", test::sci(w.report().max_speed));
  RecordProperty("reaction_z", test::sci(total.z()));
  EXPECT_NEAR(total.z(), weight, 1e-9 * weight);
  EXPECT_NEAR(total.x(), 0.0, 1e-9 * weight);
  for (const Reaction& pin : w.reactions()) EXPECT_NEAR(std::abs(pin.force.x()), h_exact, 1e-6 * h_exact);
}

/// The 32 x 32 net at the preset: at rest within tolerance, every link at its length to 1e-9 of it,
/// every free node in equilibrium (its weight balanced by its links' tensions to 1e-6 of it), the
/// corners carrying a quarter of the weight each to 1e-9.
TEST(FormFinding, ThePresetSettlesTheThirtyTwoNetExactly) {
  const int n = 32;
  const double link = 1.0 / (n - 1), weight = 0.25 * kG;
  World w(form_finding_settings());
  std::vector<int32_t> edges;
  const int32_t first = hang_net(w, n, edges);
  const SolveResult r = solve(w, SolveSettings{}, Tolerances{});
  const double stretch = worst_link_stretch(w, first, edges, link);
  RecordProperty("solve_frames", r.frames);
  RecordProperty("max_link_stretch_m", test::sci(stretch));
  EXPECT_EQ(r.outcome, SolveOutcome::settled_within_tolerance);
  EXPECT_LT(stretch, 1e-9 * link);
  // Stepped on to rest (solve stops below 1 mm/s): every node in equilibrium.
  for (int f = 0; f < 60; ++f) w.step();
  const double imbalance = worst_node_imbalance(w, w.default_group(), weight / (n * n));
  RecordProperty("max_speed_after", test::sci(w.report().max_speed));
  RecordProperty("node_imbalance", test::sci(imbalance));
  EXPECT_LT(imbalance, 1e-6);
  EXPECT_NEAR(total_reaction(w).z(), weight, 1e-9 * weight);
  for (const Reaction& c : w.reactions()) EXPECT_NEAR(c.force.z(), weight / 4, 1e-9 * weight);
}

}  // namespace
}  // namespace embra
