// The point of a triangle closest to a point: which feature it lies on and where, written once for
// the mesh colliders (collider_shapes.cpp) and the self-collision narrow phase (self_collision.cpp).
#pragma once

#include <Eigen/Core>

namespace embra {

/// Where the point of triangle (a, b, c) closest to p lies: Ericson, Real-Time Collision Detection
/// 5.1.5, by Voronoi region, the regions tried in the order vertex a, vertex b, edge ab, vertex c,
/// edge ac, edge bc, face.
struct TriangleRegion {
  enum Feature : int { vertex_a = 0, vertex_b = 1, vertex_c = 2, edge_ab = 3, edge_bc = 4, edge_ac = 5, face = 6 };
  int feature = vertex_a;
  double t = 0.0;           // an edge: the closest point is a + t (b - a), b + t (c - b) or a + t (c - a)
  double sum = 0.0;         // the face: the sum of the unnormalised weights (not > 0: a degenerate triangle)
  double v = 0.0, w = 0.0;  // the face: the closest point is a + v (b - a) + w (c - a)
};

inline TriangleRegion triangle_region(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c) {
  using R = TriangleRegion;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {R::vertex_a};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {R::vertex_b};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {R::edge_ab, d1 / (d1 - d3)};
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {R::vertex_c};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {R::edge_ac, d2 / (d2 - d6)};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return {R::edge_bc, (d4 - d3) / ((d4 - d3) + (d5 - d6))};
  const double sum = va + vb + vc;
  const double denom = 1.0 / sum;
  return {R::face, 0.0, sum, vb * denom, vc * denom};
}

}  // namespace embra
