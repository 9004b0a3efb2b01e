// The hanging-cloth case of the acceptance benchmark, defined once: a square cloth of n x n
// particles, flat and horizontal in the z = 0 plane, pinned with hard pins at the two corners of
// one side, 1 kg in all, under gravity (0, 0, -9.81), stepped at dt = 1/60 s.
//
// The cloth is a regular grid; each quad is split into two triangles along the same diagonal, and
// embra::World::create_body generates the constraints: a distance (stretch) constraint on every
// triangle edge and a dihedral (bend) constraint on every interior edge, with embra's default
// material (inextensible stretch, bend compliance 1 rad/(N m)) but for the 1 kg mass. The measures
// below are what the benchmark reports: the largest edge strain |len / rest - 1| over all triangle
// edges, and the largest over the edges near the pins.
#pragma once

#include "embra/core/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace embra::bench {

struct ClothCase {
  int n = 128;                                          // particles per side
  double size = 1.0;                                    // m, side length
  double mass = 1.0;                                    // kg, whole cloth
  double stretch_compliance = 0.0;                      // m/N: inextensible
  double bend_compliance = Material{}.bend_compliance;  // rad/(N m): embra's default
  bool bend = true;                                     // generate dihedral bend constraints
  Settings settings{};                                  // solver settings: embra's defaults unless a variant says
  int32_t stretch_weight = 0;                           // > 0: stretch in its own group of this weight
  int32_t bend_weight = 0;                              // > 0: bend in its own group of this weight
  double near_pin = 0.05;  // m: "near the pins" = an edge end within this rest distance of a pin
};

struct ClothScene {
  Id body;
  int n = 0;
  std::vector<int32_t> edges;  // 2 per unique triangle edge, world particle indices
  std::vector<double> rest;    // rest length per edge
  std::vector<uint8_t> near;   // 1 if the edge is near a pin
  int32_t pins[2] = {0, 0};    // the pinned particles
};

/// Particle index of grid vertex (i along x, j along y), body-local.
inline int32_t cloth_index(int n, int i, int j) {
  return j * n + i;
}

/// Builds the cloth case into `world` (an empty world made with c.settings).
inline ClothScene build_cloth(World& world, const ClothCase& c) {
  const int n = c.n;
  const double step = c.size / (n - 1);
  std::vector<double> xyz;
  xyz.reserve(3 * static_cast<size_t>(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      xyz.push_back(-0.5 * c.size + i * step);
      xyz.push_back(-0.5 * c.size + j * step);
      xyz.push_back(0.0);
    }
  std::vector<int32_t> tris;
  tris.reserve(6 * static_cast<size_t>(n - 1) * (n - 1));
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int32_t a = cloth_index(n, i, j), b = cloth_index(n, i + 1, j), d = cloth_index(n, i + 1, j + 1),
                    e = cloth_index(n, i, j + 1);
      tris.insert(tris.end(), {a, b, d, a, d, e});
    }
  BodyDesc desc;
  desc.positions = xyz;
  desc.triangles = tris;
  desc.material.mass = c.mass;
  desc.material.stretch_compliance = c.stretch_compliance;
  desc.material.bend_compliance = c.bend_compliance;
  desc.generate = generate_stretch | (c.bend ? generate_bend : 0u);
  if (c.stretch_weight > 0) {
    GroupDesc g;
    g.name = "stretch";
    g.weight = c.stretch_weight;
    desc.stretch_group = world.create_group(g);
  }
  if (c.bend_weight > 0) {
    GroupDesc g;
    g.name = "bend";
    g.weight = c.bend_weight;
    desc.bend_group = world.create_group(g);
  }
  ClothScene s;
  s.n = n;
  s.body = world.create_body(desc);
  const int32_t first = world.body(s.body).first_particle;
  s.pins[0] = first + cloth_index(n, 0, 0);
  s.pins[1] = first + cloth_index(n, n - 1, 0);
  for (int32_t p : s.pins) {
    PinDesc pin;
    pin.particle = p;
    pin.target = world.positions()[p];
    world.create_pin(pin);
  }

  // The unique triangle edges, for the strain measure.
  std::vector<std::pair<int32_t, int32_t>> edges;
  for (size_t t = 0; t < tris.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const int32_t a = tris[t + k], b = tris[t + (k + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const auto& x = world.positions();
  auto near_pin = [&](int32_t v) {
    for (int32_t p : s.pins)
      if ((x[first + v] - x[p]).norm() <= c.near_pin + 1e-12) return true;
    return false;
  };
  for (auto [a, b] : edges) {
    s.edges.push_back(first + a);
    s.edges.push_back(first + b);
    s.rest.push_back((x[first + a] - x[first + b]).norm());
    s.near.push_back(near_pin(a) || near_pin(b) ? 1 : 0);
  }
  return s;
}

struct Strain {
  double max = 0.0;       // max over all edges of |len / rest - 1|
  double stretch = 0.0;   // max over all edges of len / rest - 1 (0 if none is longer than its rest)
  double squeeze = 0.0;   // max over all edges of 1 - len / rest (0 if none is shorter)
  double near_pin = 0.0;  // the same over the edges near the pins
  double rms = 0.0;       // root mean square over all edges
};

/// Edge strain of the cloth now; infinite if any position is not finite.
inline Strain measure_strain(const World& world, const ClothScene& s) {
  Strain r;
  const auto& x = world.positions();
  double sq = 0.0;
  for (size_t e = 0; e < s.rest.size(); ++e) {
    const double signed_strain = (x[s.edges[2 * e]] - x[s.edges[2 * e + 1]]).norm() / s.rest[e] - 1.0;
    const double strain = std::abs(signed_strain);
    r.max = std::max(r.max, strain);
    r.stretch = std::max(r.stretch, signed_strain);
    r.squeeze = std::max(r.squeeze, -signed_strain);
    if (s.near[e]) r.near_pin = std::max(r.near_pin, strain);
    sq += strain * strain;
  }
  r.rms = std::sqrt(sq / static_cast<double>(s.rest.size()));
  if (!std::isfinite(sq)) r.max = r.stretch = r.squeeze = r.near_pin = r.rms = std::numeric_limits<double>::infinity();
  return r;
}

}  // namespace embra::bench
