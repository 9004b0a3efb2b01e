// The kind table (kinds.hpp) and the per-kind traits (kind_traits.hpp): names round-trip, numbers
// and arities agree with the functions the solver projects, and the traits' finite differences agree
// with their gradients for every kind that has a function.
#include "embra/core/panels.hpp"
#include "model/kind_traits.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <numbers>
#include <set>
#include <string>
#include <utility>

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
  const char* const names[] = {"distance",  "edge_angle",   "dihedral",     "tet_volume", "weld",       "tether",
                               "planarity", "plane_offset", "equal_length", "conical",    "length_min", "angle_min",
                               "angle_max", "colinear",     "direction",    "cocircular", "cospherical"};
  ASSERT_EQ(kKindCount, 17);
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

/// Adds one constraint of `kind` on `ids` with `rest` (hard unless `compliance`); returns its count.
int64_t add_goal(World& w, Kind kind, std::vector<int32_t> ids, double rest, double compliance = 0.0) {
  ConstraintDesc d;
  d.kind = kind;
  d.particles = ids;
  const std::vector<double> r{rest};
  d.rest = r;
  d.uniform_compliance = compliance;
  return w.add_constraints(d);
}

/// A length range 0.5 <= |x - anchor| <= 1 (a length_min and a tether): under gravity down the
/// particle hangs on the upper bound, exactly 1 below the anchor; under gravity up, pushed toward
/// the anchor, it sits on the lower bound, 0.5 below it. Started 0.2 below the anchor (inside the
/// lower bound), the length_min pushes it out at once: after the first frame it is at least 0.5.
TEST(Kinds, LengthRangeHoldsAParticleBetweenItsBounds) {
  for (const double g : {-9.81, 9.81}) {
    World w(test::settings(4, 4, Vec3(0, 0, g), 5.0));
    const int32_t a = test::add_particles(w, {{0, 0, 0}, {0, 0, -0.2}}, {0.0, 1.0});
    ASSERT_EQ(add_goal(w, Kind::length_min, {a, a + 1}, 0.5), 1);
    ASSERT_EQ(add_goal(w, Kind::tether, {a, a + 1}, 1.0), 1);
    w.step();
    EXPECT_GE(w.positions()[a + 1].norm(), 0.5 - 1e-12) << "gravity " << g;
    for (int f = 0; f < 300; ++f) w.step();
    const Vec3 x = w.positions()[a + 1];
    EXPECT_NEAR(x.z(), g < 0 ? -1.0 : -0.5, 1e-9) << "gravity " << g;
    EXPECT_EQ(x.x(), 0.0);
    EXPECT_EQ(x.y(), 0.0);
    EXPECT_LT(w.report().residual_max, 1e-9);
  }
}

/// An angle range 60 <= angle <= 120 degrees at a hinge: x0 and x1 immovable, x2 on a hard unit
/// distance from x0, swung by gravity in the plane. Pulled away from x1 the corner opens to exactly
/// 120 degrees and stops there; pulled toward x1 it closes to exactly 60.
TEST(Kinds, AngleRangeStopsAHingeAtItsBounds) {
  const double pi = std::numbers::pi;
  for (const Vec3& g : {Vec3(-6.0, -7.0, 0), Vec3(9.81, 0.5, 0)}) {
    World w(test::settings(4, 8, g, 5.0));
    const int32_t a = test::add_particles(w, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0.0, 0.0, 1.0});
    ASSERT_EQ(add_goal(w, Kind::distance, {a, a + 2}, 1.0), 1);
    ASSERT_EQ(add_goal(w, Kind::angle_min, {a, a + 1, a + 2}, pi / 3), 1);
    ASSERT_EQ(add_goal(w, Kind::angle_max, {a, a + 1, a + 2}, 2 * pi / 3), 1);
    for (int f = 0; f < 400; ++f) w.step();
    const Vec3 x = w.positions()[a + 2];
    const double angle = eval_edge_angle(Vec3::Zero(), Vec3(1, 0, 0), x).value;
    EXPECT_NEAR(angle, g.x() < 0 ? 2 * pi / 3 : pi / 3, 1e-9) << "gravity " << g.transpose();
    EXPECT_NEAR(x.norm(), 1.0, 1e-9);
    EXPECT_EQ(x.z(), 0.0);
    EXPECT_LT(w.report().residual_max, 1e-9);
  }
}

/// Points pulled onto one line: the two ends immovable, three points between them off the line,
/// each held co-linear with the ends (hard, no gravity). Every point ends on the line to 1e-12 of
/// the span, and the points moved only across it: their position along the line is kept (the
/// gradient of the distance from the line has no part along it).
TEST(Kinds, ColinearPullsPointsOntoTheLineThroughTheEnds) {
  World w(test::settings(4, 10));
  const Vec3 e0(0.2, -0.1, 0.3), e1(1.4, 0.5, -0.1);
  const std::vector<Vec3> x{e0, e1, {0.5, 0.3, 0.1}, {0.8, -0.2, 0.4}, {1.1, 0.6, 0.3}};
  const int32_t a = test::add_particles(w, x, {0.0, 0.0, 1.0, 0.5, 2.0});
  const Vec3 t = (e1 - e0).normalized();
  for (int k = 2; k < 5; ++k) ASSERT_EQ(add_goal(w, Kind::colinear, {a, a + k, a + 1}, 0.0), 1);
  for (int f = 0; f < 20; ++f) w.step();
  for (int k = 2; k < 5; ++k) {
    const Vec3 p = w.positions()[a + k];
    const auto line = Eigen::ParametrizedLine<double, 3>::Through(e0, e1);
    EXPECT_LT(line.distance(p), 1e-12 * (e1 - e0).norm()) << "point " << k;
    EXPECT_NEAR((p - e0).dot(t), (x[k] - e0).dot(t), 1e-12) << "point " << k;
  }
  EXPECT_LT(w.report().residual_max, 1e-12);
}

/// An edge turned to a fixed direction: the reference edge's particles immovable along
/// (1, 2, 2) / 3; the free edge (two equal masses) ends along it to 1e-9 rad, its midpoint where it
/// was (the gradients of an angle between the edges sum to zero over the free edge: momentum is
/// kept). Rest pi: against it.
TEST(Kinds, DirectionTurnsAnEdgeAlongAFixedVector) {
  const double pi = std::numbers::pi;
  for (const double rest : {0.0, pi}) {
    World w(test::settings(4, 10));
    const Vec3 u = Vec3(1, 2, 2) / 3.0;
    const std::vector<Vec3> x{{0.3, 0.1, -0.2}, {0.9, -0.4, 0.3}, {5, 5, 5}, Vec3(5, 5, 5) + 0.1 * u};
    const int32_t a = test::add_particles(w, x, {1.0, 1.0, 0.0, 0.0});
    ASSERT_EQ(add_goal(w, Kind::direction, {a, a + 1, a + 2, a + 3}, rest), 1);
    for (int f = 0; f < 20; ++f) w.step();
    const Vec3 e = w.positions()[a + 1] - w.positions()[a];
    const double angle = std::acos(std::clamp(e.normalized().dot(u), -1.0, 1.0));
    EXPECT_LT(std::abs(angle - rest), 1e-7) << "rest " << rest;  // acos near 1: sqrt of rounding
    EXPECT_LT(e.normalized().cross(u).norm(), 1e-9) << "rest " << rest;
    EXPECT_LT((0.5 * (w.positions()[a] + w.positions()[a + 1]) - 0.5 * (x[0] + x[1])).norm(), 1e-12);  // rounding
    EXPECT_EQ(w.positions()[a + 2], x[2]);
    EXPECT_EQ(w.positions()[a + 3], x[3]);
  }
}

/// The centre and radius of the circle through three points (in their plane).
std::pair<Vec3, double> circumcircle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
  const Vec3 centre = a + (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / (2 * n.squaredNorm());
  return {centre, (a - centre).norm()};
}

/// A quad made cyclic: a skew, non-planar, non-cyclic quad (one corner immovable) held planar
/// (EMBRA_CONSTRAINT_PLANARITY) and co-circular, hard. Its fourth corner ends on the circle through
/// the other three (centre and radius computed here) to 1e-9 of the radius, and in their plane.
TEST(Kinds, CocircularAndPlanarityPutAQuadOnOneCircle) {
  test::Rng rng(21);
  for (int c = 0; c < 10; ++c) {
    World w(test::settings(4, 10));
    std::vector<Vec3> x{{0, 0, 0}, {1, 0, 0}, {1.1, 0.9, 0}, {-0.1, 1.2, 0}};
    for (Vec3& p : x) p += rng.vec(-0.1, 0.1);
    const int32_t a = test::add_particles(w, x, {0.0, 1.0, 1.5, 0.7});
    ASSERT_GT(std::abs(eval_cocircular(x[0], x[1], x[2], x[3]).value), 0.02);
    ASSERT_EQ(add_goal(w, Kind::planarity, {a, a + 1, a + 2, a + 3}, 0.0), 1);
    ASSERT_EQ(add_goal(w, Kind::cocircular, {a, a + 1, a + 2, a + 3}, 0.0), 1);
    for (int f = 0; f < 30; ++f) w.step();
    const auto& p = w.positions();
    const auto [centre, r] = circumcircle(p[a], p[a + 1], p[a + 2]);
    const Vec3 n = (p[a + 1] - p[a]).cross(p[a + 2] - p[a]).normalized();
    EXPECT_LT(std::abs((p[a + 3] - centre).norm() - r), 1e-9 * r) << "case " << c;
    EXPECT_LT(std::abs((p[a + 3] - p[a]).dot(n)), 1e-9 * r) << "case " << c;
  }
}

/// Points pulled onto one sphere: four immovable corners of a tetrahedron on the unit sphere about
/// c, and six more points off it, each held co-spherical with the four (hard). Every point ends at
/// 1 from c to 1e-12.
TEST(Kinds, CosphericalPullsPointsOntoTheSphereThroughFour) {
  test::Rng rng(22);
  World w(test::settings(4, 10));
  const Vec3 c(0.3, -0.2, 0.5);
  std::vector<Vec3> x{c + Vec3(1, 1, 1).normalized(), c + Vec3(1, -1, -1).normalized(),
                      c + Vec3(-1, 1, -1).normalized(), c + Vec3(-1, -1, 1).normalized()};
  std::vector<double> m{0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < 6; ++k) {
    x.push_back(c + rng.uniform(0.7, 1.4) * rng.vec(-1, 1).normalized());
    m.push_back(rng.uniform(0.5, 2.0));
  }
  const int32_t a = test::add_particles(w, x, m);
  for (int k = 4; k < 10; ++k) ASSERT_EQ(add_goal(w, Kind::cospherical, {a, a + 1, a + 2, a + 3, a + k}, 0.0), 1);
  for (int f = 0; f < 20; ++f) w.step();
  for (int k = 4; k < 10; ++k) EXPECT_NEAR((w.positions()[a + k] - c).norm(), 1.0, 1e-12) << "point " << k;
  EXPECT_LT(w.report().residual_max, 1e-12);
}

/// The goals refuse what has no gradient to act along: coincident ends, a line of no length, an
/// edge of no length, a straight corner, a flat tetrahedron; and rest values out of their range.
TEST(Kinds, GoalsRefuseDegenerateElementsAndRestsOutOfRange) {
  World w(test::settings(1, 1));
  // 0 and 1 coincide; 0, 2, 3 on one line; 0, 2, 4, 5 in one plane.
  test::add_particles(w, {{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}},
                      std::vector<double>(7, 1.0));
  const auto add = [&](Kind kind, std::vector<int32_t> ids) {
    ConstraintDesc d;
    d.kind = kind;
    d.particles = ids;
    return w.add_constraints(d);
  };
  EXPECT_THROW(add(Kind::length_min, {0, 1}), Error);
  EXPECT_THROW(add(Kind::angle_min, {0, 1, 2}), Error);
  EXPECT_THROW(add(Kind::angle_max, {0, 2, 1}), Error);
  EXPECT_THROW(add(Kind::colinear, {0, 2, 1}), Error);
  EXPECT_THROW(add(Kind::direction, {2, 4, 0, 1}), Error);
  EXPECT_THROW(add(Kind::cocircular, {0, 2, 3, 4}), Error);
  EXPECT_THROW(add(Kind::cospherical, {0, 2, 4, 5, 6}), Error);
  EXPECT_THROW(add(Kind::cospherical, {0, 2, 4, 6, 2}), Error);
  EXPECT_EQ(w.constraint_count(), 0);
  // On the line already: a rest of 0 measured, and accepted.
  EXPECT_EQ(add(Kind::colinear, {0, 3, 2}), 1);
  EXPECT_EQ(w.constraint(Id{}, Kind::colinear, 0).rest, 0.0);
  const auto rest = [&](Kind kind, std::vector<int32_t> ids, double r) {
    ConstraintDesc d;
    d.kind = kind;
    d.particles = ids;
    const std::vector<double> v{r};
    d.rest = v;
    return w.add_constraints(d);
  };
  const double pi = std::numbers::pi;
  EXPECT_THROW(rest(Kind::length_min, {0, 2}, -0.1), Error);
  EXPECT_THROW(rest(Kind::angle_min, {0, 2, 4}, pi + 0.01), Error);
  EXPECT_THROW(rest(Kind::angle_max, {0, 2, 4}, -0.01), Error);
  EXPECT_THROW(rest(Kind::colinear, {0, 2, 4}, -0.01), Error);
  EXPECT_THROW(rest(Kind::direction, {0, 2, 4, 5}, 3.2), Error);
  EXPECT_THROW(rest(Kind::cocircular, {0, 2, 5, 4}, 6.3), Error);
  EXPECT_THROW(rest(Kind::cospherical, {0, 2, 4, 6, 5}, std::numeric_limits<double>::infinity()), Error);
  EXPECT_EQ(w.constraint_count(), 1);
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
