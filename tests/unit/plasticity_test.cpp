// Plasticity and rupture (World::set_constraint_plasticity), checked against statics worked out
// here:
//
//   - a bar of compliance alpha (m/N) holding a weight W past its yield strain e_y: at rest its
//     rest length has followed it so that the strain is e_y, (L - r) / r = e_y, while L - r is the
//     elastic part alpha W; unloaded it keeps its new rest: the length it returns to is the loaded
//     length minus the elastic part, alpha W / e_y, and never shortens again;
//   - a hanging chain of compliant links under a slowly growing weight breaks at its top link (the
//     one carrying every weight below, whose strain first passes the rupture strain): one event
//     names it (group, kind, index, particles, frame), nothing else breaks, and the rest of the chain
//     falls and steps on with its links at their lengths;
//   - refusals: kinds other than distance and dihedral, negative or non-finite values, an index
//     out of range, a distance of rest 0 (and a plastic distance's rest set to 0).
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace embra {
namespace {

constexpr double kG = 9.81;

Settings quiet(double damping) {
  Settings s = test::settings(10, 20, Vec3(0.0, 0.0, -kG), damping);
  s.tethers = 0;
  s.realign_passes = 4;
  return s;
}

TEST(Plasticity, BarLoadedPastYieldKeepsLoadedLengthLessElasticPart) {
  // Elastic strain under W = m g would be alpha W / L = 0.012, past the yield 0.01: by hand the rest
  // grows to alpha W / yield = 1.2 m. While it flows the bar is as stiff as yield / alpha = 16 N/m
  // (2.9 rad/s for 2 kg): 8/s of damping is past critical for that, so it never overshoots and flows
  // no further than the static load makes it.
  constexpr double m = 2.0, alpha = 0.012 / (m * kG), yield = 0.01;
  World w(quiet(8.0));
  const int32_t first = test::add_particles(w, {Vec3(0, 0, 0), Vec3(0, 0, -1.0)}, {0.0, m});
  ConstraintDesc d;
  d.kind = Kind::distance;
  const std::vector<int32_t> ids = {first, first + 1};
  d.particles = ids;
  d.uniform_compliance = alpha;
  ASSERT_EQ(w.add_constraints(d), 1);
  w.set_constraint_plasticity(Id{}, Kind::distance, 0, yield, 0.0);
  const double W = m * kG;
  // The weight grows over 2 s (quasi-static), then is held for a minute: the rest is set once a
  // frame at the frame's length, which has settled on the last rest plus alpha W, so it approaches
  // alpha W / yield by a factor 1 / (1 + yield) a frame.
  for (int f = 0; f < 3600; ++f) {
    w.set_gravity(Vec3(0.0, 0.0, -kG * std::min(1.0, (f + 1) / 120.0)));
    w.step();
  }
  const double loaded = (w.positions()[first + 1] - w.positions()[first]).norm();
  const double rest = w.constraint(Id{}, Kind::distance, 0).rest;
  RecordProperty("loaded_length", test::sci(loaded));
  EXPECT_LT(w.report().max_speed, 1e-9);
  EXPECT_NEAR((loaded - rest) / rest, yield, 1e-12) << "at rest the strain is the yield strain";
  EXPECT_NEAR(loaded - rest, alpha * W, 1e-9 * alpha * W) << "the elastic part carries the weight";
  EXPECT_NEAR(rest, alpha * W / yield, 1e-6 * rest) << "quasi-static: the permanent set by hand";
  // Unloaded: gravity off, the bar springs back by its elastic part and keeps its set.
  w.set_gravity(Vec3::Zero());
  for (int f = 0; f < 1200; ++f) w.step();
  const double unloaded = (w.positions()[first + 1] - w.positions()[first]).norm();
  RecordProperty("unloaded_length", test::sci(unloaded));
  EXPECT_NEAR(unloaded, loaded - alpha * W, 1e-9 * loaded);
  EXPECT_EQ(w.constraint(Id{}, Kind::distance, 0).rest, rest) << "within yield: the rest no longer moves";
  EXPECT_TRUE(w.take_broken().empty());
}

TEST(Plasticity, ChainBreaksAtItsTopLinkAndStepsOn) {
  constexpr int links = 5;
  constexpr double m = 1.0, alpha = 1e-3, L = 0.2;
  // The top link carries 5 m g, the next 4 m g: strain alpha T / L = 0.245 and 0.196 at full weight.
  constexpr double rupture = 0.22;
  // The weight grows over 20 s: the chain's slowest mode (omega about 9 rad/s) lags a slow ramp by
  // damping / omega^2 = 0.05 s, a quarter of a percent of the ramp.
  constexpr int ramp = 1200;
  World w(quiet(4.0));
  std::vector<Vec3> x;
  std::vector<double> masses;
  for (int k = 0; k <= links; ++k) {
    x.emplace_back(0.0, 0.0, -L * k);
    masses.push_back(k == 0 ? 0.0 : m);
  }
  const int32_t first = test::add_particles(w, x, masses);
  std::vector<int32_t> ids;
  for (int k = 0; k < links; ++k) ids.insert(ids.end(), {first + k, first + k + 1});
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = ids;
  d.uniform_compliance = alpha;
  ASSERT_EQ(w.add_constraints(d), links);
  for (int k = 0; k < links; ++k) w.set_constraint_plasticity(Id{}, Kind::distance, k, 0.0, rupture);
  std::vector<BrokenConstraint> events;
  int broke_at = -1;
  const auto strain = [&](int k) { return ((w.positions()[first + k + 1] - w.positions()[first + k]).norm() - L) / L; };
  for (int f = 0; f < ramp + 120; ++f) {
    w.set_gravity(Vec3(0.0, 0.0, -kG * std::min(1.0, (f + 1.0) / ramp)));
    w.step();
    const std::vector<BrokenConstraint> now = w.take_broken();
    if (!now.empty() && broke_at < 0) {
      broke_at = f + 1;
      // The others were within the rupture strain when the top link passed it.
      for (int k = 1; k < links; ++k) EXPECT_LT(strain(k), rupture) << "link " << k;
    }
    events.insert(events.end(), now.begin(), now.end());
  }
  ASSERT_EQ(events.size(), 1u) << "one link breaks";
  const BrokenConstraint& b = events[0];
  EXPECT_EQ(b.kind, Kind::distance);
  EXPECT_EQ(b.index, 0);
  EXPECT_EQ(b.particles[0], first);
  EXPECT_EQ(b.particles[1], first + 1);
  EXPECT_EQ(b.frame, broke_at);
  EXPECT_GT(b.strain, rupture);
  RecordProperty("broke_at_frame", broke_at);
  // The weight by hand when the top link's static strain reaches the rupture strain: g_break =
  // rupture L / (alpha 5 m) = 8.8 m/s^2; the gravity it broke under is that to the ramp's lag.
  const double g_break = rupture * L / (alpha * links * m);
  const double g_at = kG * broke_at / ramp;
  RecordProperty("gravity_at_break", test::sci(g_at));
  EXPECT_NEAR(g_at, g_break, 0.005 * g_break);
  EXPECT_EQ(w.constraint_count(Id{}, Kind::distance).first, links - 1);
  // The rest fell freely and kept its links.
  EXPECT_LT(w.positions()[first + 1].z(), -2.0);  // 2 s of free fall
  for (int k = 1; k < links; ++k) {
    const double len = (w.positions()[first + k + 1] - w.positions()[first + k]).norm();
    EXPECT_NEAR(len, L, 1e-4) << "link " << k;  // its recoil from 0.04 m at the break died down
  }
  EXPECT_EQ(w.positions()[first], Vec3::Zero());
}

TEST(Plasticity, RefusalsChangeNothing) {
  World w;
  const int32_t first =
      test::add_particles(w, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, {1.0, 1.0, 1.0, 1.0});
  const std::vector<int32_t> edge = {first, first + 1}, same = {first + 2, first + 3};
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = edge;
  w.add_constraints(d);
  const std::vector<double> zero = {0.0};
  d.particles = same;
  d.rest = zero;
  w.add_constraints(d);
  d.kind = Kind::tether;
  d.particles = edge;
  d.rest = {};
  w.add_constraints(d);
  w.set_constraint_plasticity(Id{}, Kind::distance, 0, 0.1, 0.5);
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, Kind::distance, 0, -0.1, 0.5), Error);
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, Kind::distance, 0, 0.1, std::nan("")), Error);
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, Kind::distance, 0, INFINITY, 0.5), Error);
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, Kind::distance, 2, 0.1, 0.5), Error) << "index";
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, Kind::distance, 1, 0.1, 0.0), Error) << "rest 0";
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, Kind::tether, 0, 0.1, 0.0), Error) << "kind";
  EXPECT_THROW(w.set_constraint_plasticity(Id{}, static_cast<Kind>(99), 0, 0.1, 0.0), Error);
  // A plastic distance keeps a strain to measure: its rest cannot be set to 0 (a saved world
  // always loads back).
  EXPECT_THROW(w.set_constraint_rest(Id{}, Kind::distance, 0, 0.0), Error);
  const ConstraintInfo c = w.constraint(Id{}, Kind::distance, 0);
  EXPECT_EQ(c.yield, 0.1);
  EXPECT_EQ(c.rupture, 0.5);
  EXPECT_EQ(c.rest, 1.0);
  EXPECT_EQ(w.constraint(Id{}, Kind::distance, 1).yield, 0.0);
}

}  // namespace
}  // namespace embra
