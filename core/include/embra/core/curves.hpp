// The closest point of a polyline or of a triangle mesh, for the supports that hold a particle on a
// curve (PinSupport::polyline) or on a surface (PinSupport::mesh).
#pragma once

#include "embra/core/constraint_math.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <span>

namespace embra {

/// A closest point counts as inside its segment (weights 1 - t and t) or triangle (barycentric
/// weights) when each weight exceeds this: a particle held at a vertex or on an edge sits there only
/// to rounding (weights of 1e-16), and must still read as held there (its whole multiplier kept), not
/// as inside a segment or a face, whose multiplier keeps only its part across it.
inline constexpr double kInsideWeight = 1e-9;

/// The closest point of a polyline to q, and where it lies.
struct CurvePoint {
  Vec3 point = Vec3::Zero();
  Vec3 tangent = Vec3::Zero();  // the unit direction of its segment, when inside one (else zero)
  bool inside_segment = false;  // between a segment's ends, t and 1 - t above kInsideWeight (else at a vertex)
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
      best.inside_segment = t > kInsideWeight && 1.0 - t > kInsideWeight;
      best.tangent = best.inside_segment ? Vec3(e.normalized()) : Vec3(Vec3::Zero());
      best.segment = static_cast<int64_t>(s);
    }
  }
  return best;
}

/// The closest point of a triangle mesh to q, and where it lies.
struct SurfacePoint {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // the unit normal of its triangle, when inside one (else zero)
  bool inside_face = false;    // inside a triangle, every weight above kInsideWeight (else on an edge or at a vertex)
  int64_t triangle = -1;
};

/// The point of triangle (a, b, c) closest to q, with its barycentric weights (Ericson, Real-Time
/// Collision Detection 5.1.5: the Voronoi regions of the vertices, then of the edges, then the face).
/// The triangle must have a nonzero area.
inline Vec3 closest_point_on_triangle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& weights) {
  const Vec3 ab = b - a, ac = c - a, ap = q - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    weights = Vec3(1.0, 0.0, 0.0);
    return a;
  }
  const Vec3 bp = q - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    weights = Vec3(0.0, 1.0, 0.0);
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    weights = Vec3(1.0 - v, v, 0.0);
    return a + v * ab;
  }
  const Vec3 cp = q - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    weights = Vec3(0.0, 0.0, 1.0);
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    weights = Vec3(1.0 - w, 0.0, w);
    return a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    weights = Vec3(0.0, 1.0 - w, w);
    return b + w * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  weights = Vec3(1.0 - v - w, v, w);
  return a + ab * v + ac * w;
}

/// The point of the triangle mesh (`vertices`, `triangles` of three vertex indices each) closest to
/// q. Triangles are searched in order and the first of equally close ones kept, so the answer is the
/// same bits run after run. Every triangle must have a nonzero area (World::create_pin checks it).
inline SurfacePoint closest_point_on_mesh(std::span<const Vec3> vertices,
                                          std::span<const std::array<int32_t, 3>> triangles, const Vec3& q) {
  SurfacePoint best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Vec3& a = vertices[static_cast<size_t>(triangles[t][0])];
    const Vec3& b = vertices[static_cast<size_t>(triangles[t][1])];
    const Vec3& c = vertices[static_cast<size_t>(triangles[t][2])];
    Vec3 weights;
    const Vec3 p = closest_point_on_triangle(q, a, b, c, weights);
    const double d2 = (q - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.point = p;
      best.inside_face = weights.minCoeff() > kInsideWeight;
      best.normal = best.inside_face ? Vec3((b - a).cross(c - a).normalized()) : Vec3(Vec3::Zero());
      best.triangle = static_cast<int64_t>(t);
    }
  }
  return best;
}

}  // namespace embra
