// Small helpers shared by the unit tests: a portable random source, scene builders and residuals
// computed straight from positions (independently of the solver's own bookkeeping).
#pragma once

#include "embra/core/constraint_math.hpp"
#include "embra/core/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
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
