// The kind table (kinds.hpp) and the per-kind traits (kind_traits.hpp): names round-trip, numbers
// and arities agree with the functions the solver projects, and the traits' finite differences agree
// with their gradients for every kind that has a function.
#include "embra/core/panels.hpp"
#include "model/kind_traits.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
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
  const char* const names[] = {"distance", "edge_angle", "dihedral",     "tet_volume",   "weld",
                               "tether",   "planarity",  "plane_offset", "equal_length", "conical"};
  ASSERT_EQ(kKindCount, 10);
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

/// A conical vertex needs five different particles, no edge of zero length and no two neighbours
/// in line with the vertex (the angle between them has no gradient there).
TEST(Kinds, ConicalRefusesDegenerateVertices) {
  World w(test::settings(1, 1));
  std::vector<Vec3> grid;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) grid.emplace_back(0.25 * i, 0.25 * j, 1.0);
  test::add_particles(w, grid, std::vector<double>(9, 1.0));
  const auto add = [&](std::vector<int32_t> ids) {
    ConstraintDesc d;
    d.kind = Kind::conical;
    d.particles = ids;
    return w.add_constraints(d);
  };
  EXPECT_THROW(add({4, 5, 7, 3, 5}), Error);  // a neighbour twice
  EXPECT_THROW(add({4, 3, 5, 7, 1}), Error);  // 3 and 5 in line with 4
  EXPECT_EQ(w.constraint_count(), 0);
  EXPECT_EQ(add({4, 5, 7, 3, 1}), 1);  // counter-clockwise round it: four right angles
  EXPECT_EQ(w.constraint(Id{}, Kind::conical, 0).rest, 0.0);
}

/// A quad mesh form-found conical: a 7 x 7 vertex grid on a paraboloid, its inner vertices jittered
/// off it, its corners held, every face planar and every inner vertex conical (hard; damped so that
/// each frame is a projection, not a motion). It must reach
/// a conical defect below 1e-8 rad (measured here from the angles, and by the panel metrics), and a
/// panel mesh built from it must read thickness, planarity and miter below 1e-8 of its edge at
/// frame 0: a planar quad mesh conical at its inner vertices has exact face offsets (the four face
/// planes round a vertex, moved by one distance, meet in a point), which is what the builder puts
/// each bottom corner on; on the boundary, where two faces or one leave a corner free, the builder
/// moves it so that the boundary joints are planar too.
TEST(Kinds, ConicalFormFindingGivesExactPanelOffsets) {
  constexpr int n = 7;
  constexpr double edge = 0.25;
  test::Rng rng(11);
  std::vector<Vec3> x;
  std::vector<double> masses;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double u = (i - 3) * edge, v = (j - 3) * edge;
      Vec3 p(u, v, 0.4 * u * u + 0.25 * v * v);
      const bool inner = i > 0 && j > 0 && i < n - 1 && j < n - 1;
      if (inner) p += 0.005 * rng.vec(-1.0, 1.0);
      x.push_back(p);
      const bool corner = (i == 0 || i == n - 1) && (j == 0 || j == n - 1);
      masses.push_back(corner ? 0.0 : 1.0);
    }
  World w(test::settings(1, 50, Vec3::Zero(), 1000.0));
  const int32_t first = test::add_particles(w, x, masses);
  auto at = [&](int i, int j) { return first + j * n + i; };
  std::vector<int32_t> quads, faces, vertices;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) quads.insert(quads.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  for (int j = 1; j + 1 < n; ++j)
    for (int i = 1; i + 1 < n; ++i)  // the vertex, then its neighbours counter-clockwise
      vertices.insert(vertices.end(), {at(i, j), at(i + 1, j), at(i, j + 1), at(i - 1, j), at(i, j - 1)});
  const std::vector<double> planar(quads.size() / 4, 0.0), conical(vertices.size() / 5, 0.0);
  ConstraintDesc d;
  d.kind = Kind::planarity;
  d.particles = quads;
  d.rest = planar;
  ASSERT_EQ(w.add_constraints(d), 36);
  d.kind = Kind::conical;
  d.particles = vertices;
  d.rest = conical;
  ASSERT_EQ(w.add_constraints(d), 25);
  auto defect = [&]() {
    double worst = 0.0;
    for (size_t k = 0; k < vertices.size(); k += 5) {
      const auto& p = w.positions();
      worst = std::max(worst, std::abs(eval_conical(p[vertices[k]], p[vertices[k + 1]], p[vertices[k + 2]],
                                                    p[vertices[k + 3]], p[vertices[k + 4]])
                                           .value));
    }
    return worst;
  };
  const double before = defect();
  EXPECT_GT(before, 1e-3);  // the jitter made it far from conical
  int frames = 0;
  while (frames < 2000 && !(defect() < 1e-9 && w.report().residual_max < 1e-12)) {
    w.step();
    ++frames;
  }
  RecordProperty("frames", frames);
  const auto text = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return std::string(b);
  };
  RecordProperty("conical_defect_before", text(before));
  EXPECT_LT(defect(), 1e-8) << "after " << frames << " frames";
  // The mesh stayed near where it started (no collapse onto a degenerate solution).
  double moved = 0.0;
  for (int k = 0; k < n * n; ++k) moved = std::max(moved, (w.positions()[first + k] - x[k]).norm());
  EXPECT_LT(moved, 0.1 * edge);

  // The panel mesh of the form-found mesh, at frame 0.
  std::vector<double> top;
  for (int k = 0; k < n * n; ++k) {
    const Vec3& p = w.positions()[first + k];
    top.insert(top.end(), {p.x(), p.y(), p.z()});
  }
  std::vector<int32_t> local(quads);
  for (int32_t& v : local) v -= first;
  World panels(test::settings(1, 1));
  PanelMeshDesc pd;
  pd.positions = top;
  pd.quads = local;
  pd.thickness = 0.02;
  const Id body = build_panel_mesh(panels, pd);
  const PanelLayout& layout = *panels.panel_layout(body);
  const PanelErrors errors = measure_panels(layout, panels.positions());
  const PanelReport r = report_panels(errors, Tolerances{});
  ASSERT_EQ(r.conical.count, 25);
  EXPECT_LT(r.conical.max, 1e-8);
  EXPECT_NEAR(r.conical.max, defect(), 1e-12);  // the panel metric measures the same angles
  EXPECT_LT(r.thickness.max, 1e-8 * edge);
  EXPECT_LT(r.corner_distance_top.max, 1e-8 * edge);
  EXPECT_LT(r.corner_distance_bottom.max, 1e-8 * edge);
  EXPECT_LT(r.miter.max, 1e-8 * edge);
  RecordProperty("thickness_error", text(r.thickness.max));
  RecordProperty("miter", text(r.miter.max));
}

}  // namespace
}  // namespace embra
