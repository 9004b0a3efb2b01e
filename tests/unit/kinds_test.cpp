// The kind table (kinds.hpp) and the per-kind traits (kind_traits.hpp): names round-trip, numbers
// and arities agree with the functions the solver projects, and the traits' finite differences agree
// with their gradients for every kind that has a function.
#include "model/kind_traits.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace embra {
namespace {

TEST(Kinds, NamesRoundTrip) {
  std::set<std::string> names;
  for (const KindInfo& k : kKinds) {
    EXPECT_EQ(kind_name(k.kind), k.name);
    ASSERT_TRUE(kind_from_name(k.name).has_value()) << k.name;
    EXPECT_EQ(*kind_from_name(k.name), k.kind);
    names.insert(std::string(k.name));
  }
  EXPECT_EQ(names.size(), kKinds.size());
  EXPECT_FALSE(kind_from_name("").has_value());
  EXPECT_FALSE(kind_from_name("Distance").has_value());
  EXPECT_FALSE(kind_from_name("distance ").has_value());
  EXPECT_STREQ(kind_name(static_cast<Kind>(kKindCount)), "unknown");
  EXPECT_EQ(arity(static_cast<Kind>(-1)), 0);
}

TEST(Kinds, SceneFormatNamesAndNumbers) {
  // The scene format's names and the C ABI's numbers (embra_constraint_kind).
  const char* const names[] = {"distance", "edge_angle", "dihedral",     "tet_volume",  "weld",
                               "tether",   "planarity",  "plane_offset", "equal_length"};
  ASSERT_EQ(kKindCount, 9);
  for (int k = 0; k < kKindCount; ++k) EXPECT_EQ(kind_from_name(names[k]), static_cast<Kind>(k)) << names[k];
}

/// Each kind's arity is the operand count of its function; its gradient matches central differences.
TEST(Kinds, TraitsAgreeWithTheTable) {
  test::Rng rng(7);
  for (const KindInfo& info : kKinds) {
    visit_kind(info.kind, [&](auto k) {
      using Traits = KindTraits<k>;
      if constexpr (requires { Traits::evaluate(nullptr, std::vector<Vec3>{}); }) {
        std::vector<Vec3> x(static_cast<size_t>(info.arity));
        std::vector<int32_t> ids(static_cast<size_t>(info.arity));
        for (int j = 0; j < info.arity; ++j) {
          ids[j] = j;
          x[j] = rng.vec(-1.0, 1.0);
        }
        const auto e = Traits::evaluate(ids.data(), x);
        ASSERT_EQ(static_cast<int>(e.grad.size()), info.arity) << info.name;
        ASSERT_TRUE(e.valid) << info.name;
        constexpr double step = 1e-6;
        for (int j = 0; j < info.arity; ++j)
          for (int d = 0; d < 3; ++d) {
            std::vector<Vec3> plus = x, minus = x;
            plus[j][d] += step;
            minus[j][d] -= step;
            const double fd = Traits::deviation(Traits::evaluate(ids.data(), plus).value, e.value) -
                              Traits::deviation(Traits::evaluate(ids.data(), minus).value, e.value);
            EXPECT_NEAR(fd / (2 * step), e.grad[j][d], 1e-6) << info.name << " particle " << j << " axis " << d;
          }
      } else {
        EXPECT_EQ(info.kind, Kind::weld);  // the weld alone is linear, three multipliers
        EXPECT_EQ(info.multipliers, 3);
      }
    });
  }
}

/// Four links on a line between two fixed ends, held equal pairwise (neighbouring links share a
/// particle): they must end a quarter of the span each, on the line. Shared operands move once, along
/// the sum of their slots' gradients; counted twice, the projection would overshoot and oscillate.
TEST(Kinds, EqualLengthSplitsAPinnedLineEvenly) {
  Settings s = test::settings(4, 4, Vec3::Zero(), 20.0);
  s.tethers = 0;
  World w(s);
  const std::vector<Vec3> x{{0, 0, 0}, {0.1, 0, 0}, {0.5, 0, 0}, {0.6, 0, 0}, {1.0, 0, 0}};
  test::add_particles(w, x, {0.0, 1.0, 2.0, 0.5, 0.0});
  const std::vector<int32_t> pairs{0, 1, 1, 2, 1, 2, 2, 3, 2, 3, 3, 4};
  const std::vector<double> rest(3, 0.0);
  ConstraintDesc d;
  d.kind = Kind::equal_length;
  d.particles = pairs;
  d.rest = rest;
  ASSERT_EQ(w.add_constraints(d), 3);
  for (int frame = 0; frame < 200; ++frame) w.step();
  const auto& p = w.positions();
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR((p[k + 1] - p[k]).norm(), 0.25, 1e-9) << "link " << k;
    EXPECT_NEAR(p[k].y(), 0.0, 1e-15);
    EXPECT_NEAR(p[k].z(), 0.0, 1e-15);
  }
  EXPECT_LT(w.report().residual_max, 1e-9);
}

/// One edge may not join a particle to itself; two edges may share one.
TEST(Kinds, EqualLengthRefusesAnEdgeOnOneParticle) {
  World w(test::settings(1, 1));
  test::add_particles(w, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {1.0, 1.0, 1.0, 1.0});
  const auto add = [&](std::vector<int32_t> ids) {
    ConstraintDesc d;
    d.kind = Kind::equal_length;
    d.particles = ids;
    return w.add_constraints(d);
  };
  EXPECT_THROW(add({0, 0, 1, 2}), Error);
  EXPECT_THROW(add({0, 1, 2, 2}), Error);
  EXPECT_EQ(add({0, 1, 1, 2}), 1);
  EXPECT_EQ(add({0, 1, 2, 0}), 1);
  EXPECT_EQ(w.constraint_count(), 2);
}

}  // namespace
}  // namespace embra
