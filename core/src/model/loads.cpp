// Area and line loads (loads.hpp): checked and stored by the world, turned into forces on their
// corners every substep (World::predict) and in the reactions (World::reactions).
#include "common/check.hpp"
#include "embra/core/world.hpp"

#include <string>

namespace embra {

namespace {

/// A direction a fixed-direction load is used along: finite, nonzero, normalisable.
bool normalisable(const Vec3& d) {
  const double n = d.norm();
  return n > 0.0 && std::isfinite(n) && (d / n).allFinite();
}

}  // namespace

void World::check_area_load(const AreaLoad& l, const std::string& what) const {
  for (int32_t p : l.particles) check_particle(p, (what + " particle").c_str());
  if (l.particles[0] == l.particles[1] || l.particles[1] == l.particles[2] || l.particles[0] == l.particles[2])
    invalid(what + " repeats a corner: a triangle of three distinct particles is needed");
  const int32_t mode = static_cast<int32_t>(l.mode);
  if (mode < 0 || mode >= kAreaLoadModeCount)
    invalid(what + " mode " + std::to_string(mode) + " is not normal (0), true_area (1) or projected_area (2)");
  check_finite(l.pressure, what + " pressure");
  for (int k = 0; k < 3; ++k) check_finite(l.direction[k], what + " direction");
  if (l.mode != AreaLoadMode::normal && !normalisable(l.direction))
    invalid(what + " direction is zero (or too short to normalise): a fixed-direction load needs one");
}

void World::check_line_load(const LineLoad& l, const std::string& what) const {
  for (int32_t p : l.particles) check_particle(p, (what + " particle").c_str());
  if (l.particles[0] == l.particles[1]) invalid(what + " joins a particle to itself: an edge of two is needed");
  for (int k = 0; k < 3; ++k) check_finite(l.load[k], what + " load");
}

void World::set_area_loads(std::span<const AreaLoad> loads) {
  for (size_t i = 0; i < loads.size(); ++i) check_area_load(loads[i], "area load " + std::to_string(i));
  area_loads_.assign(loads.begin(), loads.end());
}

void World::set_line_loads(std::span<const LineLoad> loads) {
  for (size_t i = 0; i < loads.size(); ++i) check_line_load(loads[i], "line load " + std::to_string(i));
  line_loads_.assign(loads.begin(), loads.end());
}

void World::add_distributed_loads(const std::vector<Vec3>& x, std::vector<Vec3>& f) const {
  for (const AreaLoad& l : area_loads_) {
    const auto& p = l.particles;
    const Vec3 share = area_load_force(l, x[p[0]], x[p[1]], x[p[2]]) / 3.0;
    for (int32_t i : p) f[i] += share;
  }
  for (const LineLoad& l : line_loads_) {
    const Vec3 share = 0.5 * line_load_force(l, x[l.particles[0]], x[l.particles[1]]);
    for (int32_t i : l.particles) f[i] += share;
  }
}

std::vector<Vec3> World::applied_loads() const {
  std::vector<Vec3> f = load_;
  add_distributed_loads(x_, f);
  return f;
}

}  // namespace embra
