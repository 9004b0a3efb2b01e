// Distributed loads: area loads on triangles (Pa) and line loads on edges (N/m), turned into forces
// on their corners. The world applies them every substep beside gravity and the point loads, from
// the positions at the substep's start (World::set_area_loads, World::set_line_loads), and counts
// them in the reactions (World::reactions).
#pragma once

#include "embra/core/constraint_math.hpp"

#include <array>
#include <cmath>
#include <cstdint>

namespace embra {

/// Which way an area load pushes and over which area (the numbering is part of the C ABI:
/// EMBRA_AREA_LOAD_*).
///   normal          pressure along the triangle's normal (x1 - x0) x (x2 - x0): it follows the
///                   surface (wind pressure, inflation); negative is suction
///   true_area       along the fixed `direction`, per m^2 of the triangle (self-weight of a cover)
///   projected_area  along the fixed `direction`, per m^2 of the triangle projected on the plane
///                   normal to `direction` (snow on its plan area when `direction` is vertical)
enum class AreaLoadMode : int32_t { normal = 0, true_area = 1, projected_area = 2 };
constexpr int kAreaLoadModeCount = 3;

/// An area load on the triangle of three distinct world particles.
struct AreaLoad {
  std::array<int32_t, 3> particles{0, 1, 2};
  AreaLoadMode mode = AreaLoadMode::normal;
  double pressure = 0.0;              // Pa (N/m^2)
  Vec3 direction = Vec3(0, 0, -1.0);  // true_area, projected_area: any nonzero length (used as a unit
                                      // vector; kept as given, so a saved scene reads back the same)
};

/// A line load on the edge between two distinct world particles.
struct LineLoad {
  std::array<int32_t, 2> particles{0, 1};
  Vec3 load = Vec3::Zero();  // N per m of the edge's current length
};

/// The total force (N) of an area load on its triangle (x0, x1, x2): a third of it goes to each
/// corner. With the vector area a = (x1 - x0) x (x2 - x0) / 2 and u = direction / |direction|:
/// normal p a; true_area p |a| u; projected_area p |a . u| u. Continuous in the corners, and 0 on a
/// triangle of zero area.
inline Vec3 area_load_force(const AreaLoad& l, const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  const Vec3 a = 0.5 * (x1 - x0).cross(x2 - x0);
  switch (l.mode) {
    case AreaLoadMode::normal:
      return l.pressure * a;
    case AreaLoadMode::true_area: {
      const Vec3 u = l.direction / l.direction.norm();
      return (l.pressure * a.norm()) * u;
    }
    case AreaLoadMode::projected_area: {
      const Vec3 u = l.direction / l.direction.norm();
      return (l.pressure * std::abs(a.dot(u))) * u;
    }
  }
  return Vec3::Zero();
}

/// The total force (N) of a line load on its edge (x0, x1): load |x1 - x0|, half to each end.
inline Vec3 line_load_force(const LineLoad& l, const Vec3& x0, const Vec3& x1) {
  return (x1 - x0).norm() * l.load;
}

}  // namespace embra
