// Area loads (Pa on triangles) and line loads (N/m on edges): World::set_area_loads,
// World::set_line_loads, checked against geometry worked out here, independently of the solver.
//
//   - normal pressure p on a closed surface pushes each vertex by p times the gradient of the
//     enclosed volume (central differences, exact to rounding: the volume is linear in each vertex);
//   - the totals: a normal load's force is p times the surface's vector area, which over a surface
//     spanning a plane boundary is the boundary's plan area times its normal, whatever the shape;
//     true_area gives p times the area; projected_area gives p times the area projected on the plane
//     normal to the direction (a curved roof under snow: p times its plan area); a line load q times
//     the edge's length;
//   - a membrane pinned round its square edge, settled under gravity, an area load, a line load and
//     point loads: its reactions sum to minus the total applied load (to 1e-9 of it), in each mode;
//   - determinism: the same scene run twice, and on two threads, gives the same bits.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace embra {
namespace {

constexpr double kG = 9.81;

/// A closed octahedron, slightly irregular, wound counter-clockwise seen from outside.
void octahedron(std::vector<Vec3>& x, std::vector<int32_t>& tri) {
  x = {Vec3(1.1, 0.05, -0.02),   Vec3(-0.9, 0.1, 0.03),  Vec3(0.02, 1.2, 0.1),
       Vec3(-0.05, -0.95, 0.04), Vec3(0.1, -0.03, 1.05), Vec3(0.04, 0.08, -1.15)};
  // Top (4 = +z): (+x, +y), (+y, -x), (-x, -y), (-y, +x); bottom (5) the other way round.
  tri = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
}

/// The enclosed volume, sum of x0 . (x1 x x2) / 6.
double volume(const std::vector<Vec3>& x, const std::vector<int32_t>& tri) {
  double v = 0.0;
  for (size_t t = 0; t < tri.size(); t += 3) v += x[tri[t]].dot(x[tri[t + 1]].cross(x[tri[t + 2]])) / 6.0;
  return v;
}

std::vector<AreaLoad> area_loads(const std::vector<int32_t>& tri, int32_t first, AreaLoadMode mode, double p,
                                 const Vec3& direction = Vec3(0.0, 0.0, -1.0)) {
  std::vector<AreaLoad> out;
  for (size_t t = 0; t < tri.size(); t += 3) {
    AreaLoad l;
    l.particles = {first + tri[t], first + tri[t + 1], first + tri[t + 2]};
    l.mode = mode;
    l.pressure = p;
    l.direction = direction;
    out.push_back(l);
  }
  return out;
}

TEST(Loads, NormalPressureIsPressureTimesTheVolumeGradient) {
  std::vector<Vec3> x;
  std::vector<int32_t> tri;
  octahedron(x, tri);
  World w;
  const int32_t first = test::add_particles(w, x, std::vector<double>(x.size(), 1.0));
  constexpr double p = 2500.0;  // Pa
  w.set_area_loads(area_loads(tri, first, AreaLoadMode::normal, p));
  const std::vector<Vec3> f = w.applied_loads();
  double worst = 0.0, scale = 0.0;
  for (size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      constexpr double e = 1e-3;  // the volume is linear in one vertex: central differences are exact
      std::vector<Vec3> a = x, b = x;
      a[i][k] += e;
      b[i][k] -= e;
      const double grad = (volume(a, tri) - volume(b, tri)) / (2.0 * e);
      worst = std::max(worst, std::abs(f[first + i][k] - p * grad));
      scale = std::max(scale, std::abs(p * grad));
    }
  RecordProperty("relative_error", test::sci(worst / scale));
  EXPECT_LT(worst, 1e-12 * scale);
  // A closed surface under uniform pressure feels no net force.
  Vec3 total = Vec3::Zero();
  for (const Vec3& v : f) total += v;
  EXPECT_LT(total.norm(), 1e-12 * p);
}

/// A curved roof over [0, L]^2: z = c (x (L - x) + 0.5 y (L - y)) on an n x n grid.
test::Grid roof(int n, double L, double c) {
  test::Grid g = test::make_grid(n, n, L / (n - 1), Vec3::Zero());
  for (size_t i = 0; i < g.positions.size(); i += 3) {
    const double x = g.positions[i], y = g.positions[i + 1];
    g.positions[i + 2] = c * (x * (L - x) + 0.5 * y * (L - y));
  }
  return g;
}

std::vector<Vec3> points(const std::vector<double>& xyz) {
  std::vector<Vec3> out;
  for (size_t i = 0; i < xyz.size(); i += 3) out.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  return out;
}

Vec3 sum(const std::vector<Vec3>& f) {
  Vec3 s = Vec3::Zero();
  for (const Vec3& v : f) s += v;
  return s;
}

TEST(Loads, TotalsArePressureTimesTheAreaOfEachMode) {
  constexpr double L = 4.0;
  const test::Grid g = roof(9, L, 0.15);
  const std::vector<Vec3> x = points(g.positions);
  World w;
  const int32_t first = test::add_particles(w, x, std::vector<double>(x.size(), 1.0));
  double area = 0.0;  // the true area, by Heron's formula on each triangle
  for (size_t t = 0; t < g.triangles.size(); t += 3) {
    const double a = (x[g.triangles[t + 1]] - x[g.triangles[t]]).norm();
    const double b = (x[g.triangles[t + 2]] - x[g.triangles[t + 1]]).norm();
    const double c = (x[g.triangles[t]] - x[g.triangles[t + 2]]).norm();
    const double s = 0.5 * (a + b + c);
    area += std::sqrt(s * (s - a) * (s - b) * (s - c));
  }
  ASSERT_GT(area, 1.05 * L * L) << "curved enough to tell true from plan area";
  constexpr double p = 800.0;
  // Normal: the vector area of a surface spanning the plane square boundary is L^2 z.
  w.set_area_loads(area_loads(g.triangles, first, AreaLoadMode::normal, p));
  EXPECT_LT((sum(w.applied_loads()) - p * L * L * Vec3::UnitZ()).norm(), 1e-12 * p * L * L);
  // True area along a slanted direction of any length.
  const Vec3 d(0.3, -0.4, -1.2);
  w.set_area_loads(area_loads(g.triangles, first, AreaLoadMode::true_area, p, d));
  const Vec3 u = d.normalized();
  EXPECT_LT((sum(w.applied_loads()) - p * area * u).norm(), 1e-12 * p * area);
  // Snow: per plan area, straight down.
  w.set_area_loads(area_loads(g.triangles, first, AreaLoadMode::projected_area, p, Vec3(0.0, 0.0, -2.0)));
  EXPECT_LT((sum(w.applied_loads()) + p * L * L * Vec3::UnitZ()).norm(), 1e-12 * p * L * L);
  // Projected on the plane normal to a slanted direction: the square's shadow, L^2 |u_z|, when no
  // triangle turns its back to u (true on this gentle roof for a steep u).
  w.set_area_loads(area_loads(g.triangles, first, AreaLoadMode::projected_area, p, d));
  EXPECT_LT((sum(w.applied_loads()) - p * L * L * std::abs(u.z()) * u).norm(), 1e-12 * p * L * L);
  // Line loads: q times the length of each edge, half to each end.
  const Vec3 q(0.0, 150.0, -300.0);
  std::vector<LineLoad> lines;
  double length = 0.0;
  for (int i = 0; i + 1 < g.nx; ++i) {
    const int32_t a = first + g.index(i, 4), b = first + g.index(i + 1, 4);
    lines.push_back(LineLoad{{a, b}, q});
    length += (x[b] - x[a]).norm();
  }
  w.set_area_loads({});
  w.set_line_loads(lines);
  const std::vector<Vec3> f = w.applied_loads();
  EXPECT_LT((sum(f) - q * length).norm(), 1e-12 * q.norm() * length);
  const double half = 0.5 * (x[first + g.index(1, 4)] - x[first + g.index(0, 4)]).norm();
  EXPECT_LT((f[first + g.index(0, 4)] - half * q).norm(), 1e-12 * q.norm()) << "half an edge's load on its end";
}

/// A square membrane L x L of n x n particles, stretch only (compliant), its edge hard-pinned.
struct Membrane {
  test::Grid g;
  int32_t first = 0;
  std::vector<int32_t> boundary;
};

constexpr double kSide = 2.0;
constexpr int kNodes = 7;

Membrane membrane(World& w) {
  Membrane m;
  m.g = test::make_grid(kNodes, kNodes, kSide / (kNodes - 1), Vec3::Zero());
  BodyDesc d;
  d.positions = m.g.positions;
  d.triangles = m.g.triangles;
  d.material.mass = 10.0;  // kg
  d.material.stretch_compliance = 1e-3;
  d.generate = generate_stretch;
  const Id body = w.create_body(d);
  m.first = w.body(body).first_particle;
  for (int j = 0; j < kNodes; ++j)
    for (int i = 0; i < kNodes; ++i)
      if (i == 0 || j == 0 || i == kNodes - 1 || j == kNodes - 1) {
        const int32_t p = m.first + m.g.index(i, j);
        m.boundary.push_back(p);
        test::hard_pin(w, p, w.positions()[p]);
      }
  return m;
}

Settings membrane_settings() {
  Settings s = test::settings(4, 50, Vec3(0.0, 0.0, -kG), 4.0);
  s.realign_passes = 6;
  s.tethers = 0;
  return s;
}

/// The total load applied, from the geometry: weights, point loads, every area load by its own
/// formula at the settled positions, every line load q |edge|.
Vec3 total_load(const World& w, const Membrane& m, AreaLoadMode mode, double p, const Vec3& d) {
  Vec3 total = Vec3::Zero();
  for (int32_t i = 0; i < w.particle_count(); ++i) {
    if (w.inverse_masses()[i] > 0.0) total += w.settings().gravity / w.inverse_masses()[i];
    total += w.loads()[i];
  }
  const std::vector<Vec3>& x = w.positions();
  const Vec3 u = d.normalized();
  switch (mode) {
    case AreaLoadMode::normal:  // a surface spanning the pinned square: vector area L^2 z
      total += p * kSide * kSide * Vec3::UnitZ();
      break;
    case AreaLoadMode::true_area:
      for (size_t t = 0; t < m.g.triangles.size(); t += 3) {
        const Vec3 a = x[m.first + m.g.triangles[t]], b = x[m.first + m.g.triangles[t + 1]],
                   c = x[m.first + m.g.triangles[t + 2]];
        total += p * 0.5 * (b - a).cross(c - a).norm() * u;
      }
      break;
    case AreaLoadMode::projected_area:  // d vertical: the plan area of the pinned square
      total += p * kSide * kSide * u;
      break;
  }
  for (const LineLoad& l : w.line_loads()) total += (x[l.particles[1]] - x[l.particles[0]]).norm() * l.load;
  return total;
}

TEST(Loads, PinnedMembraneReactionsSumToTheTotalAppliedLoad) {
  for (const AreaLoadMode mode : {AreaLoadMode::normal, AreaLoadMode::true_area, AreaLoadMode::projected_area}) {
    World w(membrane_settings());
    const Membrane m = membrane(w);
    // Normal: 40 Pa of wind pressure from above (the winding's normal is +z: push down with -40);
    // the fixed modes: 40 Pa along -z.
    const double p = mode == AreaLoadMode::normal ? -40.0 : 40.0;
    const Vec3 d(0.0, 0.0, -1.0);
    w.set_area_loads(area_loads(m.g.triangles, m.first, mode, p, d));
    std::vector<LineLoad> lines;  // a ridge line load across the middle row
    for (int i = 0; i + 1 < kNodes; ++i)
      lines.push_back(LineLoad{{m.first + m.g.index(i, 3), m.first + m.g.index(i + 1, 3)}, Vec3(5.0, 0.0, -30.0)});
    w.set_line_loads(lines);
    const double point[3] = {4.0, -3.0, -25.0};
    w.set_loads(m.first + m.g.index(2, 4), point);
    for (int f = 0; f < 600; ++f) w.step();
    Vec3 reactions = Vec3::Zero();
    for (const Reaction& r : w.reactions()) reactions += r.force;
    const Vec3 total = total_load(w, m, mode, p, d);
    const double imbalance = (reactions + total).norm() / total.norm();
    const char* name[] = {"normal", "true_area", "projected_area"};
    RecordProperty(std::string("imbalance_") + name[static_cast<int>(mode)], test::sci(imbalance));
    RecordProperty(std::string("max_speed_") + name[static_cast<int>(mode)], test::sci(w.report().max_speed));
    EXPECT_LT(imbalance, 1e-9) << name[static_cast<int>(mode)];
    EXPECT_LT(w.positions()[m.first + m.g.index(3, 3)].z(), -1e-3) << "the membrane sags under its loads";
  }
}

TEST(Loads, SameBitsRunAfterRunAndOnTwoThreads) {
  std::vector<std::vector<Vec3>> runs;
  for (const int threads : {1, 1, 2}) {
    Settings s = membrane_settings();
    s.threads = threads;
    s.realign_passes = 0;
    World w(s);
    const Membrane m = membrane(w);
    w.set_area_loads(area_loads(m.g.triangles, m.first, AreaLoadMode::normal, -60.0));
    w.set_line_loads(
        std::vector<LineLoad>{LineLoad{{m.first + m.g.index(2, 2), m.first + m.g.index(3, 3)}, Vec3(1, 2, 3)}});
    for (int f = 0; f < 30; ++f) w.step();
    runs.push_back(w.positions());
  }
  for (size_t r = 1; r < runs.size(); ++r)
    EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[r].data(), runs[0].size() * sizeof(Vec3))) << "run " << r;
}

TEST(Loads, RefusedArgumentsChangeNothing) {
  World w;
  test::add_particles(w, {Vec3::Zero(), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {1.0, 1.0, 1.0});
  AreaLoad good;
  good.particles = {0, 1, 2};
  good.pressure = 10.0;
  w.set_area_loads(std::vector<AreaLoad>{good});
  w.set_line_loads(std::vector<LineLoad>{LineLoad{{0, 1}, Vec3(0, 0, -1)}});
  auto bad = [&](auto edit) {
    AreaLoad l = good;
    edit(l);
    return std::vector<AreaLoad>{good, l};
  };
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.particles[2] = 3; })), Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.particles[0] = -1; })), Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.particles[2] = 1; })), Error) << "repeated corner";
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.mode = static_cast<AreaLoadMode>(3); })), Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.pressure = std::nan(""); })), Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.pressure = 2e300; })), Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) { l.direction[1] = INFINITY; })), Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) {
    l.mode = AreaLoadMode::true_area;
    l.direction = Vec3::Zero();
  })),
               Error);
  EXPECT_THROW(w.set_area_loads(bad([](AreaLoad& l) {
    l.mode = AreaLoadMode::projected_area;
    l.direction = Vec3(1e-320, 0.0, 0.0);  // too short to normalise
  })),
               Error);
  EXPECT_THROW(w.set_line_loads(std::vector<LineLoad>{LineLoad{{1, 1}, Vec3(0, 0, 1)}}), Error) << "degenerate";
  EXPECT_THROW(w.set_line_loads(std::vector<LineLoad>{LineLoad{{0, 7}, Vec3(0, 0, 1)}}), Error);
  EXPECT_THROW(w.set_line_loads(std::vector<LineLoad>{LineLoad{{0, 1}, Vec3(0, std::nan(""), 1)}}), Error);
  ASSERT_EQ(w.area_loads().size(), 1u);
  EXPECT_EQ(w.area_loads()[0].pressure, 10.0);
  EXPECT_EQ(w.area_loads()[0].mode, AreaLoadMode::normal);
  ASSERT_EQ(w.line_loads().size(), 1u);
  EXPECT_EQ(w.line_loads()[0].load, Vec3(0, 0, -1));
  // A normal load needs no direction: a zero one is accepted and unused.
  AreaLoad n = good;
  n.direction = Vec3::Zero();
  w.set_area_loads(std::vector<AreaLoad>{n});
  EXPECT_LT((sum(w.applied_loads()) - w.line_loads()[0].load - Vec3(0, 0, 5.0)).norm(), 1e-15);
}

}  // namespace
}  // namespace embra
