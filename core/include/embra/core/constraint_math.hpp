// Constraint functions C(x) and their gradients, one small function per kind.
//
// Every function here is pure: it reads particle positions and writes the constraint value and the
// gradient with respect to each operand. The solver (core/src/solver) projects with them; the tests
// check each gradient against finite differences. Units: lengths in model units (metres by
// convention), angles in radians, volumes in cubed length units.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>

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

/// atan(num / den) for 0 <= num, 0 < den, from +, -, *, / only: Cephes' rational approximation on
/// [0, tan(pi/8)] after its range reduction, with the reduction folded into the one division
/// (atan(a/b) = pi/2 + atan(-b/a) = pi/4 + atan((a - b)/(a + b))).
inline double atan_ratio(double num, double den) {
  constexpr double p0 = -8.750608600031904122785e-1, p1 = -1.615753718733365076637e1, p2 = -7.500855792314704667340e1,
                   p3 = -1.228866684490136173410e2, p4 = -6.485021904942025371773e1;
  constexpr double q0 = 2.485846490142306297962e1, q1 = 1.650270098316988542046e2, q2 = 4.328810604912902668951e2,
                   q3 = 4.853903996359136964868e2, q4 = 1.945506571482613964425e2;
  constexpr double tan_3pi_8 = 2.41421356237309504880, more_bits = 6.123233995736765886130e-17;
  double base = 0.0, extra = 0.0, r;
  if (num > tan_3pi_8 * den) {
    base = std::numbers::pi / 2;
    extra = more_bits;
    r = -den / num;
  } else if (num > 0.66 * den) {
    base = std::numbers::pi / 4;
    extra = 0.5 * more_bits;
    r = (num - den) / (num + den);
  } else {
    r = num / den;
  }
  const double z = r * r;
  const double p = (((p0 * z + p1) * z + p2) * z + p3) * z + p4;
  const double q = ((((z + q0) * z + q1) * z + q2) * z + q3) * z + q4;
  return base + ((r * (z * p / q) + r) + extra);
}

/// atan2(y, x) in [-pi, pi], within about one ulp of std::atan2 but built from +, -, *, / only, so
/// it gives the same bits on every IEEE-754 machine and C library (and is about 4 times faster).
inline double atan2_det(double y, double x) {
  if (x == 0.0) return y > 0.0 ? std::numbers::pi / 2 : y < 0.0 ? -std::numbers::pi / 2 : 0.0;
  const double u = atan_ratio(y < 0.0 ? -y : y, x < 0.0 ? -x : x);  // in [0, pi/2]
  if (x > 0.0) return y < 0.0 ? -u : u;
  return y >= 0.0 ? std::numbers::pi - u : u - std::numbers::pi;
}

/// Wraps an angle difference to (-pi, pi].
inline double wrap_angle(double a) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  if (a > -std::numbers::pi && a <= std::numbers::pi) return a;
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
  e.value = atan2_det(sin_t, cos_t);
  // The gradient of the angle is singular when the edges are parallel.
  if (sin_t < 1e-9) return e;
  const Vec3 ga = (cos_t * uh - vh) / (lu * sin_t);
  const Vec3 gb = (cos_t * vh - uh) / (lv * sin_t);
  e.grad = {-(ga + gb), ga, gb};
  e.valid = true;
  return e;
}

/// The signed angle from n1 to n2 about `edge` (length le), for normals n1, n2 perpendicular to it:
/// atan2((n1 x n2) . edge, (n1 . n2) le), the common factor |n1| |n2| le cancelled. Shared by
/// eval_dihedral and the solver so both measure the same angle to the bit.
inline double dihedral_angle(const Vec3& n1, const Vec3& n2, const Vec3& edge, double le) {
  return atan2_det(n1.cross(n2).dot(edge), n1.dot(n2) * le);
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
  e.value = dihedral_angle(n1, n2, edge, le);
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

/// Signed distance between the diagonals of the quad (x0, x1, x2, x3): the distance from the line
/// x0-x2 to the line x1-x3 along their common normal n = (x2 - x0) x (x3 - x1), i.e.
/// C = (x1 - x0) . n / |n|. Zero exactly when the four corners lie in one plane (planarity of a
/// quad; the field's usual measure of it, in length units). Not valid when the diagonals are
/// parallel (a collapsed quad).
inline ConstraintEval<4> eval_quad_planarity(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const Vec3 d1 = x2 - x0;
  const Vec3 d2 = x3 - x1;
  const Vec3 n = d1.cross(d2);
  const double m = n.norm();
  if (!(m > 1e-300)) return e;
  const Vec3 u = n / m;
  const Vec3 s = x1 - x0;
  e.value = s.dot(u);
  // dC = ds . u + (s_perp / m) . dn,  s_perp = s - (s . u) u,  dn = dd1 x d2 + d1 x dd2.
  const Vec3 q = (s - e.value * u) / m;
  const Vec3 g_d1 = d2.cross(q);
  const Vec3 g_d2 = q.cross(d1);
  e.grad = {-u - g_d1, u - g_d2, g_d1, g_d2};
  e.valid = true;
  return e;
}

/// Signed distance of x0 from the plane through (x1, x2, x3), positive on the side the triangle's
/// right-hand normal n = (x2 - x1) x (x3 - x1) points to: C = (x0 - x1) . n / |n|. The offset
/// constraint of a panel's bottom layer: x0 keeps its distance from the plane and may slide along
/// it. Not valid for a collapsed triangle.
inline ConstraintEval<4> eval_plane_offset(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const Vec3 a = x2 - x1;
  const Vec3 b = x3 - x1;
  const Vec3 n = a.cross(b);
  const double m = n.norm();
  if (!(m > 1e-300)) return e;
  const Vec3 u = n / m;
  const Vec3 s = x0 - x1;
  e.value = s.dot(u);
  const Vec3 q = (s - e.value * u) / m;
  const Vec3 g2 = b.cross(q);
  const Vec3 g3 = q.cross(a);
  e.grad = {u, -(u + g2 + g3), g2, g3};
  e.valid = true;
  return e;
}

/// Difference of two edge lengths: C = |x0 - x1| - |x2 - x3|. Zero when the edges are equal
/// (gridshells, Chebyshev nets: a set of edges held equal by pairing each with another). The
/// gradient is the unit direction of each edge, +/-; not valid when either edge has zero length.
/// The two edges may share a particle (x1 = x2 is a particle between two equal links).
inline ConstraintEval<4> eval_equal_length(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const Vec3 a = x0 - x1;
  const Vec3 b = x2 - x3;
  const double la = a.norm(), lb = b.norm();
  if (!(la > 1e-300) || !(lb > 1e-300)) return e;
  const Vec3 ua = a / la, ub = b / lb;
  e.value = la - lb;
  e.grad = {ua, -ua, -ub, ub};
  e.valid = true;
  return e;
}

/// The conical vertex condition (the angle criterion of Liu et al., "Geometric modeling with conical
/// meshes and developable surfaces", 2006): at a vertex x0 of valence four with neighbours x1, x2,
/// x3, x4 in order round it, C = a12 - a23 + a34 - a41, a_ij the angle at x0 between x_i - x0 and
/// x_j - x0 (each in [0, pi]). Zero when the four faces round a vertex of a planar quad mesh touch
/// one cone, so that their planes offset by one distance meet in a point: the mesh has exact face
/// offsets (a panel mesh of constant thickness with planar joints). The gradient is the sum of the
/// four angles' (eval_edge_angle); not valid when an edge has zero length or two neighbours lie on
/// one line through x0.
inline ConstraintEval<5> eval_conical(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, const Vec3& x4) {
  ConstraintEval<5> e;
  const Vec3* n[4] = {&x1, &x2, &x3, &x4};
  for (Vec3& g : e.grad) g.setZero();
  double value = 0.0;
  for (int k = 0; k < 4; ++k) {
    const auto a = eval_edge_angle(x0, *n[k], *n[(k + 1) % 4]);
    if (!a.valid) return ConstraintEval<5>{};
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    value += sign * a.value;
    e.grad[0] += sign * a.grad[0];
    e.grad[1 + k] += sign * a.grad[1];
    e.grad[1 + (k + 1) % 4] += sign * a.grad[2];
  }
  e.value = value;
  e.valid = true;
  return e;
}

/// Distance of x1 from the line through x0 and x2 (co-linear points: 0), |(x1 - x0) x (x2 - x0)| /
/// |x2 - x0|. With a = x1 - x0, b = x2 - x0, n = a x b and L = |b|: grad_1 = (b x n^) / L,
/// grad_2 = (n^ x a) / L - C b / L^2, grad_0 = -(grad_1 + grad_2). A length, so as well conditioned
/// as the distance; not valid when x0 and x2 coincide or x1 is on the line (where |n| has no
/// gradient: it holds there already).
inline ConstraintEval<3> eval_colinear(const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  ConstraintEval<3> e;
  const Vec3 a = x1 - x0, b = x2 - x0;
  const Vec3 n = a.cross(b);
  const double len = b.norm(), nn = n.norm();
  if (len <= 1e-300) return e;
  e.value = nn / len;
  if (nn <= 1e-300) return e;
  const Vec3 nh = n / nn;
  const Vec3 g1 = b.cross(nh) / len;
  const Vec3 g2 = nh.cross(a) / len - (e.value / (len * len)) * b;
  e.grad = {-(g1 + g2), g1, g2};
  e.valid = true;
  return e;
}

/// The angle between the edges x0 -> x1 and x2 -> x3, in [0, pi] (0: the same direction, pi:
/// opposite). With x2 and x3 immovable the reference edge is a fixed direction. The gradients are
/// eval_edge_angle's at a common origin: grad_1 = -grad_0 the first edge's, grad_3 = -grad_2 the
/// second's; not valid when an edge has zero length or the edges are parallel (sin < 1e-9: where it
/// holds, for a rest of 0 or pi).
inline ConstraintEval<4> eval_direction(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const auto a = eval_edge_angle(Vec3::Zero(), x1 - x0, x3 - x2);
  e.value = a.value;
  if (!a.valid) return e;
  e.grad = {-a.grad[1], a.grad[1], -a.grad[2], a.grad[2]};
  e.valid = true;
  return e;
}

/// The angle criterion of a cyclic quad x0 x1 x2 x3 (in order round it): C = a0 - a1 + a2 - a3, a_k
/// the angle at corner x_k between its two neighbours (eval_edge_angle). A planar convex quad has
/// a0 + a1 + a2 + a3 = 2 pi, and its corners lie on one circle exactly when opposite angles sum to pi,
/// that is when C = 0. Planarity is a separate constraint (EMBRA_CONSTRAINT_PLANARITY): off the plane
/// C = 0 does not make the points co-circular. Not valid when an edge has zero length or a corner's
/// two edges are in line.
inline ConstraintEval<4> eval_cocircular(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  ConstraintEval<4> e;
  const Vec3* x[4] = {&x0, &x1, &x2, &x3};
  for (Vec3& g : e.grad) g.setZero();
  double value = 0.0;
  for (int k = 0; k < 4; ++k) {
    const int prev = (k + 3) % 4, next = (k + 1) % 4;
    const auto a = eval_edge_angle(*x[k], *x[prev], *x[next]);
    if (!a.valid) return ConstraintEval<4>{};
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    value += sign * a.value;
    e.grad[k] += sign * a.grad[0];
    e.grad[prev] += sign * a.grad[1];
    e.grad[next] += sign * a.grad[2];
  }
  e.value = value;
  e.valid = true;
  return e;
}

/// Signed distance of x4 from the sphere through x0, x1, x2, x3 (co-spherical points: 0; positive
/// outside): C = |x4 - c| - |x0 - c|, c the centre, solving (x_i - x0) . c = (|x_i|^2 - |x0|^2) / 2
/// for i = 1, 2, 3 (written about x0). A length, well conditioned while the tetrahedron x0..x3 is.
/// With A the matrix of rows a_i = x_i - x0, n4 = (x4 - c) / |x4 - c|, n0 = (x0 - c) / R and q the
/// solution of A^T q = n0 - n4 (the centre's motion, dc = A^-1 r with r_i = (x_i - c) . dx_i for
/// i = 1..3, and r_i = (c - x0) . dx0 for all i from x0):
///   grad_4 = n4,  grad_i = q_i (x_i - c) (i = 1, 2, 3),  grad_0 = -n0 + (q_1 + q_2 + q_3) (c - x0).
/// Not valid when the tetrahedron is flat (|det A| <= 1e-12 of its longest edge cubed) or x4 is
/// the centre.
inline ConstraintEval<5> eval_cospherical(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                          const Vec3& x4) {
  ConstraintEval<5> e;
  Eigen::Matrix3d a;
  a.row(0) = (x1 - x0).transpose();
  a.row(1) = (x2 - x0).transpose();
  a.row(2) = (x3 - x0).transpose();
  const double scale = std::max({a.row(0).norm(), a.row(1).norm(), a.row(2).norm()});
  const double det = a.determinant();
  if (!(std::abs(det) > 1e-12 * scale * scale * scale)) return e;
  // About x0: a_i . (c - x0) = |a_i|^2 / 2.
  const Vec3 rhs(0.5 * a.row(0).squaredNorm(), 0.5 * a.row(1).squaredNorm(), 0.5 * a.row(2).squaredNorm());
  const Eigen::Matrix3d inv = a.inverse();
  const Vec3 c = x0 + inv * rhs;
  const double r = (x0 - c).norm(), d = (x4 - c).norm();
  e.value = d - r;
  if (!(d > 1e-300) || !(r > 1e-300)) return e;
  const Vec3 n4 = (x4 - c) / d, n0 = (x0 - c) / r;
  const Vec3 q = inv.transpose() * (n0 - n4);
  e.grad[4] = n4;
  e.grad[1] = q[0] * (x1 - c);
  e.grad[2] = q[1] * (x2 - c);
  e.grad[3] = q[2] * (x3 - c);
  e.grad[0] = -n0 + (q[0] + q[1] + q[2]) * (c - x0);
  e.valid = true;
  return e;
}

}  // namespace embra
