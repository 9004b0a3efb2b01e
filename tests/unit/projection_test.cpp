// One constraint at a time, in a world of its own (gravity 0, no damping): a single projection
// reduces the constraint's residual, and a hard constraint converges to its rest value.
//
// For each kind, random well-conditioned rest configurations of the operands are drawn, the rest
// value is measured there, the particles are moved off it and the world is stepped. Residuals are
// computed here from the positions (test_support.hpp: deviation) and compared with the world's own
// report. Masses are random in [0.5, 2]; one operand in four is immovable (mass 0).
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace embra {
namespace {

using test::Rng;

constexpr int kCases = 25;

int operands(Kind kind) {
  return arity(kind);
}

/// Random operands with the constraint's function far from its singular configurations.
std::vector<Vec3> random_config(Kind kind, Rng& rng) {
  for (;;) {
    std::vector<Vec3> x(operands(kind));
    for (Vec3& p : x) p = rng.vec(-1, 1);
    switch (kind) {
      case Kind::distance:
      case Kind::tether:
      case Kind::weld:
        if ((x[0] - x[1]).norm() > 0.3) return x;
        break;
      case Kind::edge_angle: {
        const Vec3 u = x[1] - x[0], v = x[2] - x[0];
        if (u.norm() > 0.3 && v.norm() > 0.3 && u.normalized().cross(v.normalized()).norm() > 0.3) return x;
        break;
      }
      case Kind::dihedral: {
        const Vec3 edge = x[1] - x[0];
        if (edge.norm() < 0.3) break;
        const Vec3 eh = edge.normalized();
        const Vec3 a = (x[2] - x[0]) - (x[2] - x[0]).dot(eh) * eh;
        const Vec3 b = (x[3] - x[0]) - (x[3] - x[0]).dot(eh) * eh;
        if (a.norm() > 0.3 && b.norm() > 0.3 && a.normalized().dot(b.normalized()) < 0.9) return x;
        break;
      }
      case Kind::tet_volume:
        if (std::abs(eval_tet_volume(x[0], x[1], x[2], x[3]).value) > 0.03) return x;
        break;
      case Kind::planarity:  // diagonals far from parallel, and apart
        if ((x[2] - x[0]).normalized().cross((x[3] - x[1]).normalized()).norm() > 0.5 && (x[2] - x[0]).norm() > 0.5 &&
            (x[3] - x[1]).norm() > 0.5 && std::abs(eval_quad_planarity(x[0], x[1], x[2], x[3]).value) > 0.05)
          return x;
        break;
      case Kind::plane_offset:  // a well-shaped triangle, the point off its plane
        if ((x[2] - x[1]).cross(x[3] - x[1]).norm() > 0.5 &&
            std::abs(eval_plane_offset(x[0], x[1], x[2], x[3]).value) > 0.05)
          return x;
        break;
      case Kind::equal_length:  // two edges of some length, clearly unequal
        if ((x[1] - x[0]).norm() > 0.3 && (x[3] - x[2]).norm() > 0.3 &&
            std::abs(eval_equal_length(x[0], x[1], x[2], x[3]).value) > 0.05)
          return x;
        break;
      case Kind::conical: {  // four edges of some length, no two neighbours near one line, not conical
        bool shaped = std::abs(eval_conical(x[0], x[1], x[2], x[3], x[4]).value) > 0.05;
        for (int k = 1; k <= 4 && shaped; ++k) {
          const Vec3 u = x[k] - x[0], v = x[k % 4 + 1] - x[0];
          shaped = u.norm() > 0.3 && u.normalized().cross(v.normalized()).norm() > 0.3;
        }
        if (shaped) return x;
        break;
      }
      case Kind::length_min:
        if ((x[0] - x[1]).norm() > 0.3) return x;
        break;
      case Kind::angle_min:
      case Kind::angle_max: {
        const Vec3 u = x[1] - x[0], v = x[2] - x[0];
        if (u.norm() > 0.3 && v.norm() > 0.3 && u.normalized().cross(v.normalized()).norm() > 0.3) return x;
        break;
      }
      case Kind::colinear:  // a line of some length, the point off it
        if ((x[2] - x[0]).norm() > 0.5 && eval_colinear(x[0], x[1], x[2]).value > 0.1) return x;
        break;
      case Kind::direction: {  // two edges of some length, far from parallel
        const Vec3 u = x[1] - x[0], v = x[3] - x[2];
        if (u.norm() > 0.3 && v.norm() > 0.3 && u.normalized().cross(v.normalized()).norm() > 0.3) return x;
        break;
      }
      case Kind::cocircular: {  // no edge short, no corner near straight, not cyclic
        bool shaped = std::abs(eval_cocircular(x[0], x[1], x[2], x[3]).value) > 0.05;
        for (int k = 0; k < 4 && shaped; ++k) {
          const Vec3 u = x[(k + 3) % 4] - x[k], v = x[(k + 1) % 4] - x[k];
          shaped = u.norm() > 0.3 && u.normalized().cross(v.normalized()).norm() > 0.3;
        }
        if (shaped) return x;
        break;
      }
      case Kind::cospherical: {  // a fat tetrahedron, its sphere not huge, the fifth point off it
        if (std::abs(eval_tet_volume(x[0], x[1], x[2], x[3]).value) < 0.05) break;
        const auto e = eval_cospherical(x[0], x[1], x[2], x[3], x[4]);
        const Vec3 a = x[1] - x[0], b = x[2] - x[0], c = x[3] - x[0];
        const double r =
            (Eigen::Matrix3d() << a.transpose(), b.transpose(), c.transpose()).finished().inverse().row(0).norm();
        if (e.valid && std::abs(e.value) > 0.05 && std::abs(e.value) < 1.0 && r < 10.0) return x;
        break;
      }
    }
  }
}

std::vector<double> random_masses(int n, Rng& rng) {
  std::vector<double> m(n);
  bool any_free = false;
  for (double& v : m) {
    v = rng.uniform(0.0, 1.0) < 0.25 ? 0.0 : rng.uniform(0.5, 2.0);
    any_free = any_free || v > 0.0;
  }
  if (!any_free) m[0] = 1.0;
  return m;
}

double rest_of(Kind kind, const std::vector<Vec3>& x) {
  switch (kind) {
    case Kind::distance:
    case Kind::tether:
      return eval_distance(x[0], x[1]).value;
    case Kind::edge_angle:
      return eval_edge_angle(x[0], x[1], x[2]).value;
    case Kind::dihedral:
      return eval_dihedral(x[0], x[1], x[2], x[3]).value;
    case Kind::tet_volume:
      return eval_tet_volume(x[0], x[1], x[2], x[3]).value;
    case Kind::weld:
      return 0.0;
    case Kind::planarity:
      return eval_quad_planarity(x[0], x[1], x[2], x[3]).value;
    case Kind::plane_offset:
      return eval_plane_offset(x[0], x[1], x[2], x[3]).value;
    case Kind::equal_length:
      return eval_equal_length(x[0], x[1], x[2], x[3]).value;
    case Kind::conical:
      return eval_conical(x[0], x[1], x[2], x[3], x[4]).value;
    case Kind::length_min:
      return eval_distance(x[0], x[1]).value;
    case Kind::angle_min:
    case Kind::angle_max:
      return eval_edge_angle(x[0], x[1], x[2]).value;
    case Kind::colinear:
      return 0.0;  // the goal: onto the line
    case Kind::direction:
      return 0.0;  // the goal: parallel, the same way
    case Kind::cocircular:
      return 0.0;  // the goal: cyclic (planarity is another constraint)
    case Kind::cospherical:
      return 0.0;  // the goal: on the sphere
  }
  return 0.0;
}

struct Single {
  World world;
  std::vector<int32_t> ids;
  double rest = 0.0;
};

/// A world holding just the operands (at `start`) and one constraint of `kind` with `rest`.
void build(Single& s, Kind kind, const std::vector<Vec3>& start, const std::vector<double>& masses, double rest,
           double compliance) {
  const int32_t first = test::add_particles(s.world, start, masses);
  for (int k = 0; k < operands(kind); ++k) s.ids.push_back(first + k);
  s.rest = rest;
  std::vector<double> rests{rest};
  ConstraintDesc d;
  d.kind = kind;
  d.particles = s.ids;
  if (kind != Kind::weld) d.rest = rests;
  d.uniform_compliance = compliance;
  ASSERT_EQ(s.world.add_constraints(d), 1);
}

double residual(const Single& s, Kind kind) {
  return std::abs(test::deviation(kind, s.world.positions(), s.ids.data(), s.rest));
}

bool one_sided(Kind kind) {
  return kind == Kind::tether || kind == Kind::length_min || kind == Kind::angle_min || kind == Kind::angle_max;
}

/// C(x) - rest of a one-sided constraint, on either side of its bound.
double raw_deviation(const Single& s, Kind kind) {
  const auto& x = s.world.positions();
  const int32_t* p = s.ids.data();
  if (kind == Kind::tether || kind == Kind::length_min) return eval_distance(x[p[0]], x[p[1]]).value - s.rest;
  return eval_edge_angle(x[p[0]], x[p[1]], x[p[2]]).value - s.rest;
}

/// Every kind of the table (kinds.hpp).
std::vector<Kind> every_kind() {
  std::vector<Kind> kinds;
  for (const KindInfo& k : embra::kKinds) kinds.push_back(k.kind);
  return kinds;
}

// (b) One step with substeps = 1, iterations = 1 is exactly one projection. The residual must drop,
// both for a hard constraint and for a soft one (compliance alpha with alpha / h^2 = 1, comparable
// to the inverse masses, so the soft projection only goes part of the way). For a hard constraint
// the world's report (|C|, since alpha = 0) must agree with the residual computed here.
TEST(Projection, OneProjectionReducesTheResidualOfEveryKind) {
  const double h = 1.0 / 60.0;
  for (Kind kind : every_kind()) {
    Rng rng(100 + static_cast<int>(kind));
    for (double compliance : {0.0, h * h}) {
      double worst_ratio = 0.0;
      for (int c = 0; c < kCases; ++c) {
        const std::vector<Vec3> ref = random_config(kind, rng);
        std::vector<Vec3> start = ref;
        for (Vec3& p : start) p += rng.vec(-0.03, 0.03);
        // A tether only acts when overstretched: start it 3% beyond its rest length.
        double rest = rest_of(kind, ref);
        if (kind == Kind::tether) rest = eval_distance(start[0], start[1]).value / 1.03;
        // The one-sided kinds that push (length_min) or open or close a corner: start them violated.
        if (kind == Kind::length_min) rest = eval_distance(start[0], start[1]).value * 1.03;
        if (kind == Kind::angle_min || kind == Kind::angle_max) {
          const double a = eval_edge_angle(start[0], start[1], start[2]).value;
          rest = kind == Kind::angle_min ? a + 0.03 * (std::numbers::pi - a) : 0.97 * a;
        }
        Single s{World(test::settings(1, 1)), {}, 0.0};
        build(s, kind, start, random_masses(operands(kind), rng), rest, compliance);
        const double before = residual(s, kind);
        ASSERT_GT(before, 1e-5) << kind_name(kind);
        s.world.step();
        const double after = residual(s, kind);
        EXPECT_LT(after, before) << kind_name(kind) << " compliance " << compliance << " case " << c;
        worst_ratio = std::max(worst_ratio, after / before);
        if (compliance == 0.0) {
          // A one-sided kind that acted keeps its multiplier, and then its residual is |C| on either
          // side of its bound (a projection past it, as an angle's can be, has a multiplier left to
          // take back): the two-sided deviation.
          const double reported = one_sided(kind) ? std::abs(raw_deviation(s, kind)) : after;
          EXPECT_NEAR(s.world.report().residual_max, reported, 1e-14) << kind_name(kind) << " case " << c;
          EXPECT_NEAR(s.world.group(s.world.default_group()).report.residual_max, reported, 1e-14);
        }
      }
      RecordProperty(std::string(kind_name(kind)) + (compliance == 0.0 ? "_hard" : "_soft") + "_worst_ratio",
                     test::sci(worst_ratio));
    }
  }
}

// The solver's hand-written kernels (distance, dihedral, quad planarity, plane offset: lanes of
// core/src/solver.cpp) against the textbook projection written here from constraint_math.hpp's
// value and gradient: one hard projection moves particle k by w_k dlambda grad_k C with
// dlambda = -(C - rest) / sum_j w_j |grad_j C|^2. (scenes.kernels_same_bits shows the SSE2 and AVX2
// lanes give the scalar kernel's bits.)
TEST(Projection, KernelsMoveEachParticleAlongTheTextbookGradientStep) {
  for (Kind kind : {Kind::distance, Kind::dihedral, Kind::planarity, Kind::plane_offset}) {
    Rng rng(300 + static_cast<int>(kind));
    double worst = 0.0;
    for (int c = 0; c < kCases; ++c) {
      const std::vector<Vec3> ref = random_config(kind, rng);
      std::vector<Vec3> start = ref;
      for (Vec3& p : start) p += rng.vec(-0.03, 0.03);
      const std::vector<double> masses = random_masses(operands(kind), rng);
      Single s{World(test::settings(1, 1)), {}, 0.0};
      build(s, kind, start, masses, rest_of(kind, ref), 0.0);
      const int n = operands(kind);
      double value = 0.0;
      std::vector<Vec3> grad(n);
      auto take = [&](const auto& e) {
        value = e.value;
        for (int k = 0; k < n; ++k) grad[k] = e.grad[k];
      };
      if (kind == Kind::distance) take(eval_distance(start[0], start[1]));
      if (kind == Kind::dihedral) take(eval_dihedral(start[0], start[1], start[2], start[3]));
      if (kind == Kind::planarity) take(eval_quad_planarity(start[0], start[1], start[2], start[3]));
      if (kind == Kind::plane_offset) take(eval_plane_offset(start[0], start[1], start[2], start[3]));
      double c_dev = value - s.rest, denom = 0.0;
      if (kind == Kind::dihedral) c_dev = std::remainder(c_dev, 2.0 * std::numbers::pi);
      for (int k = 0; k < n; ++k) denom += (masses[k] > 0.0 ? 1.0 / masses[k] : 0.0) * grad[k].squaredNorm();
      const double dl = -c_dev / denom;
      s.world.step();
      for (int k = 0; k < n; ++k) {
        const double w = masses[k] > 0.0 ? 1.0 / masses[k] : 0.0;
        const Vec3 want = start[k] + (w * dl) * grad[k];
        const double off = (s.world.positions()[s.ids[k]] - want).norm();
        worst = std::max(worst, off);
        EXPECT_LT(off, 1e-13) << kind_name(kind) << " case " << c << " particle " << k;
      }
    }
    RecordProperty(std::string(kind_name(kind)) + "_largest_difference", test::sci(worst));
  }
}

// A slack tether (shorter than its rest length) is inactive: the particles keep their positions
// bit for bit and its residual is 0.
TEST(Projection, SlackTetherDoesNothing) {
  World w(test::settings(1, 1));
  const int32_t first = test::add_particles(w, {Vec3(0, 0, 0), Vec3(0.5, 0.1, 0)}, {1.0, 1.0});
  const std::vector<int32_t> ids{first, first + 1};
  const std::vector<double> rest{1.0};
  ConstraintDesc d;
  d.kind = Kind::tether;
  d.particles = ids;
  d.rest = rest;
  w.add_constraints(d);
  const std::vector<Vec3> before = w.positions();
  w.step();
  EXPECT_EQ(w.positions()[0], before[0]);
  EXPECT_EQ(w.positions()[1], before[1]);
  EXPECT_EQ(w.report().residual_max, 0.0);
}

// Linear constraints have exact one-projection answers. Weld x0 = x1 with masses m0, m1:
//   hard: both end at the centre of mass (m0 x0 + m1 x1) / (m0 + m1);
//   soft: the separation shrinks by alpha~ / (w0 + w1 + alpha~), alpha~ = alpha / h^2, and the
//         centre of mass stays where it was.
TEST(Projection, WeldProjectionIsExact) {
  Rng rng(7);
  const double h = 1.0 / 60.0;
  for (int c = 0; c < kCases; ++c) {
    const Vec3 x0 = rng.vec(-1, 1), x1 = rng.vec(-1, 1);
    const double m0 = rng.uniform(0.5, 2.0), m1 = rng.uniform(0.5, 2.0);
    const Vec3 com = (m0 * x0 + m1 * x1) / (m0 + m1);
    for (double alpha_t : {0.0, 0.7}) {
      World w(test::settings(1, 1));
      const int32_t first = test::add_particles(w, {x0, x1}, {m0, m1});
      const std::vector<int32_t> ids{first, first + 1};
      ConstraintDesc d;
      d.kind = Kind::weld;
      d.particles = ids;
      d.uniform_compliance = alpha_t * h * h;
      w.add_constraints(d);
      w.step();
      const Vec3 a = w.positions()[0], b = w.positions()[1];
      const double shrink = alpha_t / (1 / m0 + 1 / m1 + alpha_t);
      EXPECT_LT(((a - b) - shrink * (x0 - x1)).norm(), 1e-14) << "case " << c;
      EXPECT_LT(((m0 * a + m1 * b) / (m0 + m1) - com).norm(), 1e-14) << "case " << c;
    }
  }
}

// Pins: a hard pin puts its particle on the target (a new target is reached at the end of the next
// frame); a soft pin with compliance alpha moves the particle from x to
//   target + (x - target) alpha~ / (w + alpha~),   alpha~ = alpha / h^2.
TEST(Projection, PinProjectionIsExact) {
  Rng rng(8);
  const double h = 1.0 / 60.0;
  for (int c = 0; c < kCases; ++c) {
    const Vec3 x = rng.vec(-1, 1), target = rng.vec(-1, 1);
    const double m = rng.uniform(0.5, 2.0);
    {
      World w(test::settings(1, 1));
      const int32_t p = test::add_particles(w, {x}, {m});
      const Id pin = test::hard_pin(w, p, target);
      w.step();
      EXPECT_LT((w.positions()[p] - target).norm(), 1e-15) << "case " << c;
      EXPECT_LT(w.report().residual_max, 1e-15);
      const Vec3 moved = rng.vec(-1, 1);
      w.set_pin_target(pin, moved);
      w.step();
      EXPECT_LT((w.positions()[p] - moved).norm(), 1e-15) << "case " << c;
    }
    for (double alpha_t : {0.3, 3.0}) {
      World w(test::settings(1, 1));
      const int32_t p = test::add_particles(w, {x}, {m});
      PinDesc d;
      d.particle = p;
      d.target = target;
      d.compliance = alpha_t * h * h;
      w.create_pin(d);
      w.step();
      const Vec3 expected = target + (x - target) * (alpha_t / (1 / m + alpha_t));
      EXPECT_LT((w.positions()[p] - expected).norm(), 1e-14) << "case " << c;
      EXPECT_LT((w.positions()[p] - target).norm(), (x - target).norm());
    }
  }
}

// (c) A hard constraint converges: from a perturbation of up to 0.15 per coordinate, a few frames
// (substeps 4, iterations 10) bring |C - rest| below 1e-6 of the rest value's magnitude. The
// reference magnitude is |rest| for distance, tether, edge_angle, dihedral and tet_volume (all drawn
// away from 0 here), and 1 (one length unit, the size of the configurations; one radian) for weld,
// pins and the goals held at 0 from far off it: colinear (a point 0.1 to 1 off its line), direction
// (edges at least 0.3 rad from parallel), cocircular (|C| > 0.05 rad), cospherical (a point 0.05 to
// 1 off its sphere). The one-sided kinds start beyond their bound: tether and length_min by 20 % of
// the length, angle_min and angle_max by 10 % of the room to pi or to 0. (At 20 % one angle_min
// case, 0.53 rad to open with only the vertex movable, threw the vertex through the line of its
// neighbours and away: one linearised step of an angle moved by the vertex alone can overshoot.)
TEST(Projection, HardConstraintsConvergeToTheirRestValue) {
  for (Kind kind : every_kind()) {
    Rng rng(200 + static_cast<int>(kind));
    double worst = 0.0;
    for (int c = 0; c < kCases; ++c) {
      const std::vector<Vec3> ref = random_config(kind, rng);
      std::vector<Vec3> start = ref;
      for (Vec3& p : start) p += rng.vec(-0.15, 0.15);
      double rest = rest_of(kind, ref);
      if (kind == Kind::tether) rest = eval_distance(start[0], start[1]).value / 1.2;
      if (kind == Kind::length_min) rest = eval_distance(start[0], start[1]).value * 1.2;
      if (kind == Kind::angle_min || kind == Kind::angle_max) {
        const double a = eval_edge_angle(start[0], start[1], start[2]).value;
        rest = kind == Kind::angle_min ? a + 0.1 * (std::numbers::pi - a) : 0.9 * a;
      }
      Single s{World(test::settings(4, 10)), {}, 0.0};
      build(s, kind, start, random_masses(operands(kind), rng), rest, 0.0);
      for (int f = 0; f < 5; ++f) s.world.step();
      const double scale = rest != 0.0 ? std::abs(rest) : 1.0;
      const double r = residual(s, kind) / scale;
      EXPECT_LT(r, 1e-6) << kind_name(kind) << " case " << c << " rest " << rest;
      worst = std::max(worst, r);
    }
    RecordProperty(std::string(kind_name(kind)) + "_worst_relative_residual", test::sci(worst));
  }
  // Hard and soft pins: a hard pin holds exactly; a soft pin alone, with nothing else acting,
  // converges onto its target too (its XPBD residual C + alpha~ lambda is driven to 0 each substep
  // and the particle has no other load).
  Rng rng(300);
  for (int c = 0; c < kCases; ++c) {
    const Vec3 x = rng.vec(-1, 1), target = rng.vec(-1, 1);
    World w(test::settings(4, 10, Vec3::Zero(), 5.0));
    const int32_t p = test::add_particles(w, {x}, {rng.uniform(0.5, 2.0)});
    PinDesc d;
    d.particle = p;
    d.target = target;
    d.compliance = 1e-4;
    w.create_pin(d);
    for (int f = 0; f < 600; ++f) w.step();
    EXPECT_LT((w.positions()[p] - target).norm(), 1e-6) << "soft pin case " << c;
  }
}

}  // namespace
}  // namespace embra
