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
  const char* const names[] = {"distance", "edge_angle", "dihedral",  "tet_volume",
                               "weld",     "tether",     "planarity", "plane_offset"};
  ASSERT_EQ(kKindCount, 8);
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

}  // namespace
}  // namespace embra
