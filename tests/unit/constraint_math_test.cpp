// Constraint functions and gradients (constraint_math.hpp), checked against independent formulas and
// central finite differences on random, well-conditioned configurations.
//
// Weld (x0 - x1) and pin (x - target) are linear: their gradients are +-identity and there is no
// function for them in constraint_math.hpp; their one-projection answers are checked exactly in
// projection_test.cpp instead. The tether uses eval_distance.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <array>
#include <functional>
#include <numbers>

namespace embra {
namespace {

using test::Rng;

constexpr int kConfigs = 200;

// Central difference step. With coordinates of order 1 the error of the quotient is about
// step^2/6 |f'''| + eps |f| / step, i.e. below 1e-9 for the well-conditioned configurations drawn
// here; a wrong gradient is off by order 1. The tolerance 1e-7 leaves room for |f'''| up to 1e5.
constexpr double kStep = 1e-6;
constexpr double kTol = 1e-7;

template <int N>
using Points = std::array<Vec3, N>;

template <int N>
double check_gradient(const std::function<ConstraintEval<N>(const Points<N>&)>& f, const Points<N>& x, const char* what,
                      int config) {
  const ConstraintEval<N> e = f(x);
  EXPECT_TRUE(e.valid) << what << " config " << config;
  if (!e.valid) return 0.0;
  double worst = 0.0;  // the largest |grad - fd| / max(1, |fd|)
  for (int k = 0; k < N; ++k)
    for (int c = 0; c < 3; ++c) {
      Points<N> xp = x, xm = x;
      xp[k][c] += kStep;
      xm[k][c] -= kStep;
      const double fd = (f(xp).value - f(xm).value) / (2 * kStep);
      EXPECT_NEAR(e.grad[k][c], fd, kTol * std::max(1.0, std::abs(fd)))
          << what << " config " << config << " operand " << k << " coordinate " << c;
      worst = std::max(worst, std::abs(e.grad[k][c] - fd) / std::max(1.0, std::abs(fd)));
    }
  // A function of the shape alone is invariant under translation and rotation: its gradients sum
  // to zero and have no net moment. (These two facts are what make a projection conserve linear
  // and angular momentum.)
  Vec3 sum = Vec3::Zero(), moment = Vec3::Zero();
  double scale = 0.0;
  for (int k = 0; k < N; ++k) {
    sum += e.grad[k];
    moment += x[k].cross(e.grad[k]);
    scale += e.grad[k].norm() * (1.0 + x[k].norm());
  }
  EXPECT_LT(sum.norm(), 1e-13 * scale) << what << " config " << config;
  EXPECT_LT(moment.norm(), 1e-13 * scale) << what << " config " << config;
  return worst;
}

// Two points: C = |x0 - x1|.
TEST(ConstraintMath, DistanceValueAndGradient) {
  Rng rng(1);
  for (int i = 0; i < kConfigs; ++i) {
    Points<2> x{rng.vec(-1, 1), rng.vec(-1, 1)};
    if ((x[0] - x[1]).norm() < 0.2) continue;
    const auto e = eval_distance(x[0], x[1]);
    const Vec3 d = x[0] - x[1];
    EXPECT_NEAR(e.value, std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z()), 1e-15);
    check_gradient<2>([](const Points<2>& p) { return eval_distance(p[0], p[1]); }, x, "distance", i);
  }
  EXPECT_FALSE(eval_distance(Vec3(1, 2, 3), Vec3(1, 2, 3)).valid);
}

// Angle at c between c->a and c->b:   a
//                                    /
//                                   c --- b
TEST(ConstraintMath, EdgeAngleValueAndGradient) {
  Rng rng(2);
  int checked = 0;
  for (int i = 0; i < 4 * kConfigs && checked < kConfigs; ++i) {
    Points<3> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const Vec3 u = x[1] - x[0], v = x[2] - x[0];
    if (u.norm() < 0.3 || v.norm() < 0.3) continue;
    const double expected = std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0));
    if (std::sin(expected) < 0.2) continue;  // the gradient is singular for parallel edges
    ++checked;
    EXPECT_NEAR(eval_edge_angle(x[0], x[1], x[2]).value, expected, 1e-13);
    check_gradient<3>([](const Points<3>& p) { return eval_edge_angle(p[0], p[1], p[2]); }, x, "edge_angle", i);
  }
  EXPECT_EQ(checked, kConfigs);
  // Right angle, and the documented singular case (parallel edges: no gradient).
  EXPECT_NEAR(eval_edge_angle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 2, 0)).value, std::numbers::pi / 2, 1e-15);
  EXPECT_FALSE(eval_edge_angle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)).valid);
}

// Hinge across edge x0-x1 between triangles (x0,x1,x2) and (x1,x0,x3):
//        x2
//       /  \  .
//     x0 -- x1      angle 0 when x2 and x3 lie on opposite sides in one plane (unfolded)
//       \  /
//        x3
// Expected value from elementary geometry: with a, b the components of x2 - x0 and x3 - x0
// perpendicular to the edge, |angle| = pi - angle(a, b); the sign is negative when x3 lies on the
// side the first triangle's right-hand normal points to.
TEST(ConstraintMath, DihedralValueAndGradient) {
  Rng rng(3);
  int checked = 0;
  for (int i = 0; i < 4 * kConfigs && checked < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const Vec3 edge = x[1] - x[0];
    if (edge.norm() < 0.3) continue;
    const Vec3 eh = edge.normalized();
    const Vec3 a = (x[2] - x[0]) - (x[2] - x[0]).dot(eh) * eh;
    const Vec3 b = (x[3] - x[0]) - (x[3] - x[0]).dot(eh) * eh;
    if (a.norm() < 0.3 || b.norm() < 0.3) continue;  // triangles far from degenerate
    const double between = std::acos(std::clamp(a.dot(b) / (a.norm() * b.norm()), -1.0, 1.0));
    if (between < 0.2) continue;  // stay away from the +-pi branch cut
    const Vec3 n1 = edge.cross(x[2] - x[0]);
    const double expected = ((x[3] - x[0]).dot(n1) > 0 ? -1.0 : 1.0) * (std::numbers::pi - between);
    ++checked;
    EXPECT_NEAR(eval_dihedral(x[0], x[1], x[2], x[3]).value, expected, 1e-12) << "config " << i;
    check_gradient<4>([](const Points<4>& p) { return eval_dihedral(p[0], p[1], p[2], p[3]); }, x, "dihedral", i);
  }
  EXPECT_EQ(checked, kConfigs);
  // Flat and unfolded: 0. Folded to a right angle with x3 above (+z, the side n1 = e_x cross e_y
  // points to): -pi/2.
  EXPECT_NEAR(eval_dihedral(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0)).value, 0.0, 1e-15);
  EXPECT_NEAR(eval_dihedral(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, 0, 1)).value,
              -std::numbers::pi / 2, 1e-15);
}

// Tetrahedron (x0,x1,x2,x3): V = det[x1-x0, x2-x0, x3-x0] / 6.
TEST(ConstraintMath, TetVolumeValueAndGradient) {
  Rng rng(4);
  int checked = 0;
  for (int i = 0; i < 4 * kConfigs && checked < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    Eigen::Matrix3d m;
    m << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    const double expected = m.determinant() / 6.0;
    if (std::abs(expected) < 0.02) continue;
    ++checked;
    EXPECT_NEAR(eval_tet_volume(x[0], x[1], x[2], x[3]).value, expected, 1e-14);
    check_gradient<4>([](const Points<4>& p) { return eval_tet_volume(p[0], p[1], p[2], p[3]); }, x, "tet_volume", i);
  }
  EXPECT_EQ(checked, kConfigs);
  // Unit right-corner tetrahedron: 1/6, positive for x3 on the side of (x0,x1,x2)'s normal.
  EXPECT_NEAR(eval_tet_volume(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)).value, 1.0 / 6.0, 1e-16);
}

// Quad (x0, x1, x2, x3), diagonals x0-x2 and x1-x3:   x3 --- x2
//                                                     |  \/  |   C = distance between the
//                                                     |  /\  |   diagonal lines, signed
//                                                     x0 --- x1
// Expected value from the closest points of the two lines (a 2x2 least-squares solve).
TEST(ConstraintMath, QuadPlanarityValueAndGradient) {
  Rng rng(5);
  int checked = 0;
  for (int i = 0; i < 4 * kConfigs && checked < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const Vec3 d1 = x[2] - x[0], d2 = x[3] - x[1];
    if (d1.norm() < 0.4 || d2.norm() < 0.4 || d1.normalized().cross(d2.normalized()).norm() < 0.3) continue;
    ++checked;
    // Closest points x0 + s d1 and x1 + t d2: minimise |x0 + s d1 - x1 - t d2|^2.
    Eigen::Matrix<double, 3, 2> a;
    a << d1, -d2;
    const Eigen::Vector2d st = a.colPivHouseholderQr().solve(x[1] - x[0]);
    const double distance = (x[0] + st[0] * d1 - x[1] - st[1] * d2).norm();
    const double sign = (x[1] - x[0]).dot(d1.cross(d2)) >= 0 ? 1.0 : -1.0;
    EXPECT_NEAR(eval_quad_planarity(x[0], x[1], x[2], x[3]).value, sign * distance, 1e-13);
    check_gradient<4>([](const Points<4>& p) { return eval_quad_planarity(p[0], p[1], p[2], p[3]); }, x, "planarity",
                      i);
  }
  EXPECT_EQ(checked, kConfigs);
  // A unit square is planar (0); raising one corner by d tilts its diagonal to (1, 1, d), and the
  // diagonals' common normal n = (1, 1, d) x (-1, 1, 0) = (-d, -d, 2) puts them
  // |(1, 0, 0) . n| / |n| = d / (2 sqrt(1 + d^2 / 2)) apart (d / 2 for small d).
  EXPECT_EQ(eval_quad_planarity(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)).value, 0.0);
  EXPECT_NEAR(std::abs(eval_quad_planarity(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0.2), Vec3(0, 1, 0)).value),
              0.2 / (2 * std::sqrt(1 + 0.02)), 1e-15);
  // Parallel diagonals (a collapsed quad): no gradient.
  EXPECT_FALSE(eval_quad_planarity(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)).valid);
}

// Point x0 and the plane through x1, x2, x3: C = signed distance, positive on the side of
// (x2 - x1) x (x3 - x1). Expected value from Eigen's Hyperplane.
TEST(ConstraintMath, PlaneOffsetValueAndGradient) {
  Rng rng(6);
  int checked = 0;
  for (int i = 0; i < 4 * kConfigs && checked < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const Vec3 n = (x[2] - x[1]).cross(x[3] - x[1]);
    if (n.norm() < 0.3) continue;
    ++checked;
    const Eigen::Hyperplane<double, 3> plane(n.normalized(), x[1]);
    EXPECT_NEAR(eval_plane_offset(x[0], x[1], x[2], x[3]).value, plane.signedDistance(x[0]), 1e-14);
    check_gradient<4>([](const Points<4>& p) { return eval_plane_offset(p[0], p[1], p[2], p[3]); }, x, "plane_offset",
                      i);
  }
  EXPECT_EQ(checked, kConfigs);
  // 0.3 above the plane z = 0 (counter-clockwise triangle seen from above: normal +z).
  EXPECT_NEAR(eval_plane_offset(Vec3(5, -2, 0.3), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)).value, 0.3, 1e-15);
  EXPECT_FALSE(eval_plane_offset(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)).valid);
}

// Two edges x0-x1 and x2-x3: C = |x0 - x1| - |x2 - x3|; also when they share a particle.
TEST(ConstraintMath, EqualLengthValueAndGradient) {
  Rng rng(8);
  for (int i = 0; i < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    EXPECT_NEAR(eval_equal_length(x[0], x[1], x[2], x[3]).value, (x[0] - x[1]).norm() - (x[2] - x[3]).norm(), 1e-15);
    check_gradient<4>([](const Points<4>& p) { return eval_equal_length(p[0], p[1], p[2], p[3]); }, x, "equal_length",
                      i);
  }
  // A 3-4-5 right angle: the legs differ by 1, the hypotenuse and a leg by 2 (the edges share x1).
  EXPECT_NEAR(eval_equal_length(Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 0, 0), Vec3(0, 4, 0)).value, -1.0, 1e-15);
  EXPECT_NEAR(eval_equal_length(Vec3(3, 0, 0), Vec3(0, 4, 0), Vec3(3, 0, 0), Vec3(0, 0, 0)).value, 2.0, 1e-15);
  EXPECT_FALSE(eval_equal_length(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(0, 0, 0), Vec3(1, 0, 0)).valid);
  EXPECT_FALSE(eval_equal_length(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 2, 3), Vec3(1, 2, 3)).valid);
}

// Point x1 and the line through x0 and x2: C = distance of x1 from it. Expected value from Eigen's
// ParametrizedLine.
TEST(ConstraintMath, ColinearValueAndGradient) {
  double worst = 0.0;  // gradient against central differences, relative (check_gradient)
  Rng rng(10);
  int checked = 0;
  for (int i = 0; i < 4 * kConfigs && checked < kConfigs; ++i) {
    Points<3> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    if ((x[2] - x[0]).norm() < 0.3) continue;
    ++checked;
    const auto line = Eigen::ParametrizedLine<double, 3>::Through(x[0], x[2]);
    EXPECT_NEAR(eval_colinear(x[0], x[1], x[2]).value, line.distance(x[1]), 1e-14);
    worst = std::max(
        worst, check_gradient<3>([](const Points<3>& p) { return eval_colinear(p[0], p[1], p[2]); }, x, "colinear", i));
  }
  EXPECT_EQ(checked, kConfigs);
  // 0.5 above the x axis, past the segment's end (the line, not the segment); on the line: 0.
  EXPECT_NEAR(eval_colinear(Vec3(0, 0, 0), Vec3(3, 0.5, 0), Vec3(1, 0, 0)).value, 0.5, 1e-15);
  EXPECT_EQ(eval_colinear(Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(1, 0, 0)).value, 0.0);
  EXPECT_FALSE(eval_colinear(Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(1, 0, 0)).valid);  // on it: no gradient
  EXPECT_FALSE(eval_colinear(Vec3(1, 1, 1), Vec3(3, 0, 0), Vec3(1, 1, 1)).valid);  // no line
  RecordProperty("colinear_gradient_worst_relative_error", test::sci(worst));
}

// Edges x0 -> x1 and x2 -> x3: C = the angle between them.
TEST(ConstraintMath, DirectionValueAndGradient) {
  double worst = 0.0;  // gradient against central differences, relative (check_gradient)
  Rng rng(11);
  for (int i = 0; i < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const double expected =
        std::acos(std::clamp((x[1] - x[0]).normalized().dot((x[3] - x[2]).normalized()), -1.0, 1.0));
    EXPECT_NEAR(eval_direction(x[0], x[1], x[2], x[3]).value, expected, 1e-12);
    worst = std::max(worst, check_gradient<4>([](const Points<4>& p) { return eval_direction(p[0], p[1], p[2], p[3]); },
                                              x, "direction", i));
  }
  // Along the z axis: 0; against it: pi; across: pi / 2. Parallel edges have no gradient.
  const Vec3 z0(5, 5, 0), z1(5, 5, 1);
  EXPECT_EQ(eval_direction(Vec3(0, 0, 0), Vec3(0, 0, 2), z0, z1).value, 0.0);
  EXPECT_NEAR(eval_direction(Vec3(0, 0, 2), Vec3(0, 0, 0), z0, z1).value, std::numbers::pi, 1e-15);
  EXPECT_NEAR(eval_direction(Vec3(0, 0, 0), Vec3(1, 2, 0), z0, z1).value, std::numbers::pi / 2, 1e-15);
  EXPECT_FALSE(eval_direction(Vec3(0, 0, 0), Vec3(0, 0, 2), z0, z1).valid);
  EXPECT_FALSE(eval_direction(Vec3(1, 0, 0), Vec3(1, 0, 0), z0, z1).valid);
  RecordProperty("direction_gradient_worst_relative_error", test::sci(worst));
}

// A quad x0 x1 x2 x3: C = a0 - a1 + a2 - a3, a_k its angle at x_k.
TEST(ConstraintMath, CocircularValueAndGradient) {
  double worst = 0.0;  // gradient against central differences, relative (check_gradient)
  Rng rng(12);
  auto angle = [](const Vec3& c, const Vec3& a, const Vec3& b) {
    return std::acos(std::clamp((a - c).normalized().dot((b - c).normalized()), -1.0, 1.0));
  };
  for (int i = 0; i < kConfigs; ++i) {
    Points<4> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const double expected =
        angle(x[0], x[3], x[1]) - angle(x[1], x[0], x[2]) + angle(x[2], x[1], x[3]) - angle(x[3], x[2], x[0]);
    EXPECT_NEAR(eval_cocircular(x[0], x[1], x[2], x[3]).value, expected, 1e-12);
    worst =
        std::max(worst, check_gradient<4>([](const Points<4>& p) { return eval_cocircular(p[0], p[1], p[2], p[3]); }, x,
                                          "cocircular", i));
  }
  // Four points at random places round one circle (in order, tilted in space): C = 0. A rhombus of
  // angles 60 and 120 degrees is not cyclic: C = 2 pi / 3 - 4 pi / 3.
  for (int i = 0; i < kConfigs; ++i) {
    const Vec3 c = rng.vec(-1, 1), u = rng.vec(-1, 1).normalized();
    const Vec3 v = u.cross(rng.vec(-1, 1)).normalized(), w = u.cross(v);
    const double r = rng.uniform(0.2, 2.0);
    double t[4];
    for (double& a : t) a = rng.uniform(0.0, 2.0 * std::numbers::pi);
    std::sort(t, t + 4);
    if (t[1] - t[0] < 0.2 || t[2] - t[1] < 0.2 || t[3] - t[2] < 0.2 || t[0] + 2 * std::numbers::pi - t[3] < 0.2)
      continue;
    Points<4> x;
    for (int k = 0; k < 4; ++k) x[k] = c + r * (std::cos(t[k]) * v + std::sin(t[k]) * w);
    EXPECT_NEAR(eval_cocircular(x[0], x[1], x[2], x[3]).value, 0.0, 1e-13) << "circle " << i;
  }
  const double h = std::sqrt(3.0) / 2;
  EXPECT_NEAR(eval_cocircular(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1.5, h, 0), Vec3(0.5, h, 0)).value,
              2 * std::numbers::pi / 3 - 4 * std::numbers::pi / 3, 1e-14);
  EXPECT_FALSE(eval_cocircular(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0)).valid);  // x1 straight
  EXPECT_FALSE(eval_cocircular(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(2, 1, 0), Vec3(0, 1, 0)).valid);  // zero edge
  RecordProperty("cocircular_gradient_worst_relative_error", test::sci(worst));
}

// Five points: C = signed distance of x4 from the sphere through x0..x3. Built on a known sphere
// (centre c, radius R): four points on it and the fifth at R + d from c must read d.
TEST(ConstraintMath, CosphericalValueAndGradient) {
  double worst = 0.0;  // gradient against central differences, relative (check_gradient)
  Rng rng(13);
  int checked = 0;
  for (int i = 0; i < 8 * kConfigs && checked < kConfigs; ++i) {
    const Vec3 c = rng.vec(-1, 1);
    const double r = rng.uniform(0.3, 2.0), d = rng.uniform(-0.25, 0.5) * r;
    Points<5> x;
    for (int k = 0; k < 5; ++k) x[k] = c + (k < 4 ? r : r + d) * rng.vec(-1, 1).normalized();
    if (std::abs(eval_tet_volume(x[0], x[1], x[2], x[3]).value) < 0.05 * r * r * r) continue;
    ++checked;
    EXPECT_NEAR(eval_cospherical(x[0], x[1], x[2], x[3], x[4]).value, d, 1e-13 * (1 + r)) << "config " << i;
    worst = std::max(
        worst, check_gradient<5>([](const Points<5>& p) { return eval_cospherical(p[0], p[1], p[2], p[3], p[4]); }, x,
                                 "cospherical", i));
  }
  EXPECT_EQ(checked, kConfigs);
  // Four corners of a flat square: no sphere through them. The fifth at the centre: no direction.
  const Vec3 o(0, 0, 0), ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  EXPECT_FALSE(eval_cospherical(o, ex, ey, Vec3(1, 1, 0), ez).valid);
  EXPECT_FALSE(eval_cospherical(o, ex, ey, ez, Vec3(0.5, 0.5, 0.5)).valid);
  EXPECT_NEAR(eval_cospherical(o, ex, ey, ez, Vec3(0.5, 0.5, 0.5) + 2.0 * ex).value, 2.0 - std::sqrt(0.75), 1e-15);
  RecordProperty("cospherical_gradient_worst_relative_error", test::sci(worst));
}

// A vertex and its four neighbours: C = a12 - a23 + a34 - a41, the angles at x0.
TEST(ConstraintMath, ConicalValueAndGradient) {
  Rng rng(9);
  auto angle = [](const Vec3& c, const Vec3& a, const Vec3& b) {
    return std::acos(std::clamp((a - c).normalized().dot((b - c).normalized()), -1.0, 1.0));
  };
  for (int i = 0; i < kConfigs; ++i) {
    Points<5> x{rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1), rng.vec(-1, 1)};
    const double expected =
        angle(x[0], x[1], x[2]) - angle(x[0], x[2], x[3]) + angle(x[0], x[3], x[4]) - angle(x[0], x[4], x[1]);
    EXPECT_NEAR(eval_conical(x[0], x[1], x[2], x[3], x[4]).value, expected, 1e-12);
    check_gradient<5>([](const Points<5>& p) { return eval_conical(p[0], p[1], p[2], p[3], p[4]); }, x, "conical", i);
  }
  // A vertex of a flat grid: four right angles, conical. A pyramid's apex over a rhombus (a
  // symmetric vertex): a12 = a34 and a23 = a41, conical; with x2 moved off it, not.
  const Vec3 o(0, 0, 0);
  EXPECT_NEAR(eval_conical(o, Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)).value, 0.0, 1e-15);
  const Vec3 top(0, 0, 1), a(2, 0, 0), b(0, 1, 0), c(-2, 0, 0), d(0, -1, 0);
  EXPECT_NEAR(eval_conical(top, a, b, c, d).value, 0.0, 1e-15);
  const Vec3 b2(1, 1, 0);  // x2 moved off the symmetric places: not conical
  EXPECT_NEAR(eval_conical(top, a, b2, c, d).value,
              angle(top, a, b2) - angle(top, b2, c) + angle(top, c, d) - angle(top, d, a), 1e-15);
  EXPECT_GT(std::abs(eval_conical(top, a, b2, c, d).value), 1e-3);
  EXPECT_FALSE(eval_conical(o, o, Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)).valid);              // a zero edge
  EXPECT_FALSE(eval_conical(o, Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)).valid);  // in line
}

TEST(ConstraintMath, WrapAngle) {
  constexpr double pi = std::numbers::pi;
  EXPECT_NEAR(wrap_angle(0.25), 0.25, 1e-16);
  EXPECT_NEAR(wrap_angle(2 * pi + 0.25), 0.25, 1e-15);
  EXPECT_NEAR(wrap_angle(-2 * pi - 0.25), -0.25, 1e-15);
  EXPECT_NEAR(wrap_angle(1.5 * pi), -0.5 * pi, 1e-15);
  EXPECT_DOUBLE_EQ(wrap_angle(pi), pi);  // (-pi, pi]
  EXPECT_DOUBLE_EQ(wrap_angle(-pi), pi);
}

}  // namespace
}  // namespace embra
