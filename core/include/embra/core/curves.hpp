// The closest point of a polyline, for the supports that hold a particle on a curve
// (PinSupport::polyline).
#pragma once

#include "embra/core/constraint_math.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>

namespace embra {

/// The closest point of a polyline to q, and where it lies.
struct CurvePoint {
  Vec3 point = Vec3::Zero();
  Vec3 tangent = Vec3::Zero();  // the unit direction of its segment, when inside one (else zero)
  bool inside_segment = false;  // strictly between a segment's ends (else at a vertex)
  int64_t segment = -1;
};

/// The point of the polyline through `points` (closed: the last joined back to the first) closest to
/// q. Segments are searched in order and the first of equally close ones kept, so the answer is the
/// same bits run after run. Every segment must have a nonzero length (World::create_pin checks it).
inline CurvePoint closest_point_on_polyline(std::span<const Vec3> points, bool closed, const Vec3& q) {
  CurvePoint best;
  double best_d2 = std::numeric_limits<double>::infinity();
  const size_t n = points.size();
  const size_t segments = closed ? n : (n > 0 ? n - 1 : 0);
  for (size_t s = 0; s < segments; ++s) {
    const Vec3& a = points[s];
    const Vec3& b = points[(s + 1) % n];
    const Vec3 e = b - a;
    const double t = std::clamp((q - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    const Vec3 c = t == 1.0 ? b : Vec3(a + t * e);
    const double d2 = (q - c).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.point = c;
      best.inside_segment = t > 0.0 && t < 1.0;
      best.tangent = best.inside_segment ? Vec3(e.normalized()) : Vec3(Vec3::Zero());
      best.segment = static_cast<int64_t>(s);
    }
  }
  return best;
}

}  // namespace embra
