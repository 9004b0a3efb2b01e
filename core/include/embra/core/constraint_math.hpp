// Constraint functions C(x) and their gradients, one small function per kind.
//
// Every function here is pure: it reads particle positions and writes the constraint value and the
// gradient with respect to each operand. The solver (solver.cpp) projects with them; the tests
// check each gradient against finite differences. Units: lengths in model units (metres by
// convention), angles in radians, volumes in cubed length units.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <numbers>

namespace embra {

using Vec3 = Eigen::Vector3d;

/// Value and gradient of a constraint with N operands. `valid` is false where the gradient is not
/// defined (coincident points, a collapsed triangle); the solver skips such a constraint for that
/// iteration rather than dividing by zero.
template <int N>
struct ConstraintEval {
  double value = 0.0;
  std::array<Vec3, N> grad{};
  bool valid = false;
};

/// Wraps an angle difference to (-pi, pi].
inline double wrap_angle(double a) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  a = std::fmod(a + std::numbers::pi, two_pi);
  if (a <= 0.0) a += two_pi;
  return a - std::numbers::pi;
}

/// Distance |x0 - x1|: the stretch constraint's function (C = distance - rest).
inline ConstraintEval<2> eval_distance(const Vec3& x0, const Vec3& x1) {
  ConstraintEval<2> e;
  const Vec3 d = x0 - x1;
  const double len = d.norm();
  e.value = len;
  if (len <= 1e-300) return e;
  const Vec3 n = d / len;
  e.grad = {n, -n};
  e.valid = true;
  return e;
}

/// Angle at vertex c between edges c->a and c->b, in [0, pi] (shear).
inline ConstraintEval<3> eval_edge_angle(const Vec3& c, const Vec3& a, const Vec3& b) {
  ConstraintEval<3> e;
  const Vec3 u = a - c;
  const Vec3 v = b - c;
  const double lu = u.norm();
  const double lv = v.norm();
  if (lu <= 1e-300 || lv <= 1e-300) return e;
  const Vec3 uh = u / lu;
  const Vec3 vh = v / lv;
  const double cos_t = uh.dot(vh);
  const double sin_t = uh.cross(vh).norm();
  e.value = std::atan2(sin_t, cos_t);
  // The gradient of the angle is singular when the edges are parallel.
  if (sin_t < 1e-9) return e;
  const Vec3 ga = (cos_t * uh - vh) / (lu * sin_t);
  const Vec3 gb = (cos_t * vh - uh) / (lv * sin_t);
  e.grad = {-(ga + gb), ga, gb};
  e.valid = true;
  return e;
}

/// Signed dihedral angle across the edge x0-x1 between triangle (x0, x1, x2) and triangle
/// (x1, x0, x3), in (-pi, pi]. Zero when the two triangles are coplanar and unfolded; negative when
/// x3 lies on the side the first triangle's right-hand normal points to, positive on the other side.
inline ConstraintEval<4> eval_dihedral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const Vec3 edge = x1 - x0;
  const double le = edge.norm();
  const Vec3 n1 = edge.cross(x2 - x0);
  const Vec3 n2 = (x3 - x0).cross(edge);
  const double n1sq = n1.squaredNorm();
  const double n2sq = n2.squaredNorm();
  if (le <= 1e-300 || n1sq <= 1e-300 || n2sq <= 1e-300) return e;
  const Vec3 eh = edge / le;
  const double inv1 = 1.0 / std::sqrt(n1sq);
  const double inv2 = 1.0 / std::sqrt(n2sq);
  const double cos_t = n1.dot(n2) * inv1 * inv2;
  const double sin_t = n1.cross(n2).dot(eh) * inv1 * inv2;
  e.value = std::atan2(sin_t, cos_t);
  const Vec3 g2 = -le / n1sq * n1;
  const Vec3 g3 = -le / n2sq * n2;
  const double s1 = (x2 - x0).dot(eh);
  const double s2 = (x3 - x0).dot(eh);
  // Translation invariance: the four gradients sum to zero.
  const Vec3 g1 = -(s1 / le) * g2 - (s2 / le) * g3;
  const Vec3 g0 = -(g1 + g2 + g3);
  e.grad = {g0, g1, g2, g3};
  e.valid = true;
  return e;
}

/// Signed volume of the tetrahedron (x0, x1, x2, x3): positive when x3 lies on the side of the
/// triangle (x0, x1, x2) its right-hand normal points to.
inline ConstraintEval<4> eval_tet_volume(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const Vec3 a = x1 - x0;
  const Vec3 b = x2 - x0;
  const Vec3 c = x3 - x0;
  e.value = a.cross(b).dot(c) / 6.0;
  const Vec3 g1 = b.cross(c) / 6.0;
  const Vec3 g2 = c.cross(a) / 6.0;
  const Vec3 g3 = a.cross(b) / 6.0;
  e.grad = {-(g1 + g2 + g3), g1, g2, g3};
  e.valid = g1.squaredNorm() + g2.squaredNorm() + g3.squaredNorm() > 1e-300;
  return e;
}

}  // namespace embra
