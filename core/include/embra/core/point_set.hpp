// What a point set must be before a rigid frame or a plane can be fitted to it, written once for
// every adder that takes one (World::add_shape_match, embra_rigid_set_add,
// embra_polygon_planarity_add): its particles distinct, and its points off one line.
#pragma once

#include "embra/core/constraint_math.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace embra {

/// The smallest particle that appears more than once in `ids`; -1 when they are all different.
inline int32_t repeated_particle(std::span<const int32_t> ids) {
  std::vector<int32_t> sorted(ids.begin(), ids.end());
  std::sort(sorted.begin(), sorted.end());
  for (size_t i = 1; i < sorted.size(); ++i)
    if (sorted[i] == sorted[i - 1]) return sorted[i];
  return -1;
}

/// A base of a point set, chosen the same way on every machine (the first of equals each time):
/// point 0; `far`, the point farthest from it (at `reach`); `off`, the point farthest from the line
/// through those two (at `off_line`); `off_plane`, the point farthest from the plane through those
/// three (at `plane_distance`; 0 when the three are on one line).
struct PointSetBase {
  size_t far = 0, off = 0, off_plane = 0;
  double reach = 0.0, off_line = 0.0, plane_distance = 0.0;

  /// The points span a plane: the base's third point is more than kOffLine of the reach from the
  /// line of the first two (a rotation about that line can then be told apart).
  static constexpr double kOffLine = 1e-6;
  bool spans_plane() const { return off_line > kOffLine * reach; }
};

/// The base of the points point(0) .. point(n - 1) (n >= 1).
template <class Point>
PointSetBase point_set_base(size_t n, Point&& point) {
  PointSetBase b;
  const Vec3 first = point(0);
  const auto farthest = [&](auto&& distance, size_t& at, double& most) {
    most = -1.0;
    for (size_t i = 0; i < n; ++i)
      if (const double d = distance(point(i)); d > most) most = d, at = i;
  };
  farthest([&](const Vec3& p) { return (p - first).norm(); }, b.far, b.reach);
  if (!(b.reach > 0.0)) return b;
  const Vec3 u = (point(b.far) - first) / b.reach;
  farthest([&](const Vec3& p) { return (p - first).cross(u).norm(); }, b.off, b.off_line);
  if (!b.spans_plane()) return b;
  const Vec3 normal = u.cross(point(b.off) - first).normalized();
  farthest([&](const Vec3& p) { return std::abs((p - first).dot(normal)); }, b.off_plane, b.plane_distance);
  return b;
}

}  // namespace embra
