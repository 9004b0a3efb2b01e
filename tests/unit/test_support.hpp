// Small helpers shared by the unit tests: a portable random source, scene builders and residuals
// computed straight from positions (independently of the solver's own bookkeeping).
#pragma once

#include "embra/core/constraint_math.hpp"
#include "embra/core/panels.hpp"
#include "embra/core/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace embra::test {

/// A random source whose sequence is the same on every platform: std::mt19937_64 is fully specified
/// by the standard, and the doubles are made from its bits here (std::uniform_real_distribution is
/// not specified bit for bit).
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * (static_cast<double>(engine_() >> 11) * 0x1.0p-53); }
  Vec3 vec(double lo, double hi) { return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)); }
  Vec3 unit() {
    for (;;) {
      const Vec3 v = vec(-1.0, 1.0);
      const double n = v.norm();
      if (n > 0.1 && n <= 1.0) return v / n;
    }
  }

 private:
  std::mt19937_64 engine_;
};

/// A number in scientific notation with 4 significant digits, for RecordProperty.
inline std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

/// Records a panel report's worst planarity, corner distance (both layers), thickness, miter and
/// conical defect as test properties, each name after `prefix` (as "frame0_").
inline void record_panel_report(const std::string& prefix, const PanelReport& r) {
  ::testing::Test::RecordProperty(prefix + "planarity_top", sci(r.planarity_top.max));
  ::testing::Test::RecordProperty(prefix + "planarity_bottom", sci(r.planarity_bottom.max));
  ::testing::Test::RecordProperty(prefix + "corner_distance_top", sci(r.corner_distance_top.max));
  ::testing::Test::RecordProperty(prefix + "corner_distance_bottom", sci(r.corner_distance_bottom.max));
  ::testing::Test::RecordProperty(prefix + "thickness", sci(r.thickness.max));
  ::testing::Test::RecordProperty(prefix + "miter", sci(r.miter.max));
  ::testing::Test::RecordProperty(prefix + "conical_defect_rad", sci(r.conical.max));
}

inline std::vector<double> flatten(const std::vector<Vec3>& xs) {
  std::vector<double> out;
  out.reserve(3 * xs.size());
  for (const Vec3& x : xs) out.insert(out.end(), {x.x(), x.y(), x.z()});
  return out;
}

inline Settings settings(int32_t substeps, int32_t iterations, const Vec3& gravity = Vec3::Zero(), double damping = 0.0,
                         double dt = 1.0 / 60.0) {
  Settings s;
  s.dt = dt;
  s.substeps = substeps;
  s.iterations = iterations;
  s.gravity = gravity;
  s.damping = damping;
  return s;
}

/// Adds loose particles (a body with no generated constraints); returns the first particle's index.
/// A mass of 0 makes a particle immovable.
inline int32_t add_particles(World& world, const std::vector<Vec3>& x, const std::vector<double>& masses) {
  const std::vector<double> xyz = flatten(x);
  BodyDesc d;
  d.positions = xyz;
  d.masses = masses;
  d.generate = 0;
  const Id id = world.create_body(d);
  return world.body(id).first_particle;
}

inline Id hard_pin(World& world, int32_t particle, const Vec3& target) {
  PinDesc p;
  p.particle = particle;
  p.target = target;
  return world.create_pin(p);
}

/// A net of n x n particles `dx` apart in the plane z = z0 (row j, column i: the returned first
/// particle + j n + i), of mass `mass` each, joined along its rows and columns by distance
/// constraints of compliance `compliance` (m/N) in the default group, each particle's row link
/// before its column link. `x` receives the particles' positions.
inline int32_t add_net(World& w, int n, double dx, double z0, double mass, double compliance, std::vector<Vec3>& x) {
  x.clear();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.emplace_back(i * dx, j * dx, z0);
  const int32_t first = add_particles(w, x, std::vector<double>(x.size(), mass));
  std::vector<int32_t> ids;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int32_t p = first + j * n + i;
      if (i + 1 < n) ids.insert(ids.end(), {p, p + 1});
      if (j + 1 < n) ids.insert(ids.end(), {p, p + n});
    }
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = ids;
  d.uniform_compliance = compliance;
  w.add_constraints(d);
  return first;
}

/// An n x m grid of square panels of side `size` in the plane z = 1 (panel_grid), `thickness` thick,
/// hard-pinned at the top corners of the mesh's corners, the panels' corners welded or shared;
/// returns the body.
inline Id add_panel_grid(World& w, int32_t n, int32_t m, double size, double thickness = 0.01,
                         PanelCorners corners = PanelCorners::welded) {
  std::vector<double> positions;
  std::vector<int32_t> quads;
  panel_grid(n, m, size, Vec3(0.0, 0.0, 1.0), positions, quads);
  PanelMeshDesc d;
  d.positions = positions;
  d.quads = quads;
  d.thickness = thickness;
  d.pins = PanelPins::top_corners;
  d.corners = corners;
  return build_panel_mesh(w, d);
}

/// Sum of the applied loads (N): the weight m g of every movable particle and every point load,
/// worked out from the masses, gravity and loads as set (not the solver's own sum).
inline Vec3 applied_load(const World& w) {
  Vec3 total = Vec3::Zero();
  for (int32_t i = 0; i < w.particle_count(); ++i) {
    if (w.inverse_masses()[i] > 0.0) total += w.settings().gravity / w.inverse_masses()[i];
    total += w.loads()[i];
  }
  return total;
}

/// The largest difference over the three axes between `grad` and the central difference, step
/// `e`, of the scalar function f at q: (f(q + e u_k) - f(q - e u_k)) / 2e.
template <class F>
double gradient_error(const F& f, const Vec3& q, const Vec3& grad, double e = 1e-6) {
  double worst = 0.0;
  for (int k = 0; k < 3; ++k) {
    Vec3 a = q, b = q;
    a[k] += e;
    b[k] -= e;
    const double fd = (f(a) - f(b)) / (2 * e);
    worst = std::max(worst, std::abs(fd - grad[k]));
  }
  return worst;
}

/// A pin holding `particle` on a support whose geometry is given as offsets from `target` (moving
/// the target moves it): a polyline (PinSupport::polyline: `points` in order, the last joined back
/// to the first when `closed`) or a triangle mesh (PinSupport::mesh: `points` its vertices,
/// `triangles` its triangles). Hard when `compliance` is 0, else compliant (m/N).
inline Id shape_support(World& w, PinSupport support, int32_t particle, const Vec3& target,
                        const std::vector<Vec3>& points, bool closed,
                        const std::vector<std::array<int32_t, 3>>& triangles, double compliance) {
  PinDesc d;
  d.particle = particle;
  d.target = target;
  d.support = support;
  d.curve = points;
  d.closed = closed;
  d.triangles = triangles;
  d.compliance = compliance;
  return w.create_pin(d);
}

/// A bead: one particle of mass `mass` released at `start` and held by a hard polyline or mesh
/// support round `target` (shape_support), pulled by gravity (0, 0, -g) and the point load `load`;
/// 8 substeps of 2 iterations a frame with 2 realignment passes (so that at rest its reaction is the
/// exact static one), no automatic tethers. The supports' tests slide it over their curve or surface
/// and let it come to rest.
struct Bead {
  World world;
  int32_t particle = -1;
  Id pin;
  Vec3 target;
  double mass = 0.0;
  Vec3 load;

  Bead(PinSupport support, const Vec3& at, const std::vector<Vec3>& points, bool closed,
       const std::vector<std::array<int32_t, 3>>& triangles, const Vec3& start, double m, const Vec3& f, double g)
      : world(bead_settings(g)), target(at), mass(m) {
    particle = add_particles(world, {start}, {m});
    pin = shape_support(world, support, particle, at, points, closed, triangles, 0.0);
    set_load(f);
  }
  /// Where the bead is, from the support's target (m): in the support's own coordinates.
  Vec3 offset() const { return world.positions()[particle] - target; }
  /// Weight plus point load (N): what the support's reaction balances at rest.
  Vec3 pull() const { return mass * world.settings().gravity + load; }
  void set_load(const Vec3& f) {
    load = f;
    world.set_loads(particle, std::span<const double>(f.data(), 3));
  }
  /// Damps the motion at `rate` (1/s) and steps `frames` frames.
  void settle(double rate, int frames) {
    Settings damped = world.settings();
    damped.damping = rate;
    world.set_settings(damped);
    for (int f = 0; f < frames; ++f) world.step();
  }

 private:
  static Settings bead_settings(double g) {
    Settings s = settings(8, 2, Vec3(0.0, 0.0, -g));
    s.tethers = 0;
    s.realign_passes = 2;
    return s;
  }
};

/// Where a particle of mass 1 released at (0.7, 0, 0.1) under gravity (0, 0, -g) and held by a
/// compliant (1e-5 m/N) shape support round the origin (shape_support) is after 100 frames of 4
/// substeps of 3 iterations, run twice in fresh worlds: the supports' same-bits check.
inline std::array<Vec3, 2> support_run_twice(PinSupport support, const std::vector<Vec3>& points, bool closed,
                                             const std::vector<std::array<int32_t, 3>>& triangles, double g) {
  std::array<Vec3, 2> runs;
  for (Vec3& end : runs) {
    Settings s = settings(4, 3, Vec3(0.0, 0.0, -g));
    s.tethers = 0;
    World w(s);
    const int32_t p = add_particles(w, {Vec3(0.7, 0.0, 0.1)}, {1.0});
    shape_support(w, support, p, Vec3::Zero(), points, closed, triangles, 1e-5);
    for (int f = 0; f < 100; ++f) w.step();
    end = w.positions()[p];
  }
  return runs;
}

/// A flat grid cloth of nx by ny vertices in the plane z = z0, spacing `dx`, two triangles per cell;
/// uvs are the grid coordinates (u along x, v along y).
struct Grid {
  std::vector<double> positions, uvs;
  std::vector<int32_t> triangles;
  int nx = 0, ny = 0;
  int32_t index(int i, int j) const { return static_cast<int32_t>(j * nx + i); }
};

inline Grid make_grid(int nx, int ny, double dx, const Vec3& origin) {
  Grid g;
  g.nx = nx;
  g.ny = ny;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      g.positions.insert(g.positions.end(), {origin.x() + i * dx, origin.y() + j * dx, origin.z()});
      g.uvs.insert(g.uvs.end(), {static_cast<double>(i), static_cast<double>(j)});
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int32_t a = g.index(i, j), b = g.index(i + 1, j), c = g.index(i + 1, j + 1), d = g.index(i, j + 1);
      // Alternate the diagonal so the cloth has no preferred shear direction.
      if ((i + j) % 2 == 0)
        g.triangles.insert(g.triangles.end(), {a, b, c, a, c, d});
      else
        g.triangles.insert(g.triangles.end(), {a, b, d, b, c, d});
    }
  return g;
}

/// |C(x) - rest| of one constraint of `kind` at positions `x` (angles wrapped for hinges), computed
/// from constraint_math.hpp directly.
inline double deviation(Kind kind, const std::vector<Vec3>& x, const int32_t* p, double rest) {
  switch (kind) {
    case Kind::distance:
      return eval_distance(x[p[0]], x[p[1]]).value - rest;
    case Kind::tether:
      return std::max(eval_distance(x[p[0]], x[p[1]]).value - rest, 0.0);
    case Kind::edge_angle:
      return eval_edge_angle(x[p[0]], x[p[1]], x[p[2]]).value - rest;
    case Kind::dihedral:
      return wrap_angle(eval_dihedral(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest);
    case Kind::tet_volume:
      return eval_tet_volume(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest;
    case Kind::weld:
      return (x[p[0]] - x[p[1]]).norm();
    case Kind::planarity:
      return eval_quad_planarity(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest;
    case Kind::plane_offset:
      return eval_plane_offset(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest;
    case Kind::equal_length:
      return eval_equal_length(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest;
    case Kind::conical:
      return eval_conical(x[p[0]], x[p[1]], x[p[2]], x[p[3]], x[p[4]]).value - rest;
    case Kind::length_min:  // one-sided: only a shortfall counts
      return std::min(eval_distance(x[p[0]], x[p[1]]).value - rest, 0.0);
    case Kind::angle_min:
      return std::min(eval_edge_angle(x[p[0]], x[p[1]], x[p[2]]).value - rest, 0.0);
    case Kind::angle_max:
      return std::max(eval_edge_angle(x[p[0]], x[p[1]], x[p[2]]).value - rest, 0.0);
    case Kind::colinear:
      return eval_colinear(x[p[0]], x[p[1]], x[p[2]]).value - rest;
    case Kind::direction:
      return eval_direction(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest;
    case Kind::cocircular:
      return eval_cocircular(x[p[0]], x[p[1]], x[p[2]], x[p[3]]).value - rest;
    case Kind::cospherical:
      return eval_cospherical(x[p[0]], x[p[1]], x[p[2]], x[p[3]], x[p[4]]).value - rest;
  }
  return 0.0;
}

inline Vec3 total_momentum(const World& w) {
  Vec3 p = Vec3::Zero();
  for (int32_t i = 0; i < w.particle_count(); ++i)
    if (w.inverse_masses()[i] > 0.0) p += w.velocities()[i] / w.inverse_masses()[i];
  return p;
}

}  // namespace embra::test
