// The per-kind math of the constraint kinds (kinds.hpp lists them): one KindTraits<K> per kind, and
// visit_kind, the one place a kind number is turned into its traits.
//
// KindTraits<K>:
//   evaluate(p, x)                value and gradients at the positions x (constraint_math.hpp);
//                                 absent for a weld, which is three multipliers, not one function
//   deviation(value, rest)        C(x) - rest, angles wrapped so a hinge never takes the long way
//   measure_rest(p, x, name)      the rest value measured at x ("rest from current"); throws
//                                 Error(invalid_argument) for a degenerate element
//   check_rest(rest, name)        throws Error(invalid_argument) for a rest value the kind refuses
//   may_share(a, b)               whether operand slots a and b may hold the same particle (equal
//                                 length's two edges may share one); by default every operand differs
//   scaled_rest(a, i, body)       the rest of constraint i of `a` under its body's rest scales
#pragma once

#include "common/check.hpp"
#include "embra/core/constraint_math.hpp"
#include "embra/core/kinds.hpp"
#include "embra/core/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <type_traits>
#include <vector>

namespace embra {

template <Kind K>
using KindTag = std::integral_constant<Kind, K>;

/// Calls f(KindTag<kind>{}) and returns what it returns: the one switch over the kinds.
template <class F>
decltype(auto) visit_kind(Kind kind, F&& f) {
  switch (kind) {
#define EMBRA_KIND_VISIT(name, number, arity, multipliers, unit, what) \
  case Kind::name:                                                     \
    return f(KindTag<Kind::name>{});
    EMBRA_CONSTRAINT_KINDS(EMBRA_KIND_VISIT)
#undef EMBRA_KIND_VISIT
  }
  invalid("unknown constraint kind " + std::to_string(static_cast<int>(kind)));
}

/// What most kinds share: C(x) - rest unwrapped, any finite rest, the rest not scaled, every
/// operand a different particle, two-sided (C(x) = rest).
struct KindDefaults {
  /// Which side of its rest the constraint holds: 0 both (value = rest), -1 below (value <= rest: its
  /// multiplier only pulls, lambda <= 0), +1 above (value >= rest: lambda >= 0). A one-sided
  /// constraint that holds and has no multiplier left does nothing and has no residual.
  static constexpr int side = 0;
  static constexpr bool may_share(int, int) { return false; }
  static double deviation(double value, double rest) { return value - rest; }
  static void check_rest(double, const std::string&) {}
  static double scaled_rest(const ConstraintArray& a, size_t i, const BodyInfo&) { return a.rest[i]; }
};

template <Kind K>
struct KindTraits;

/// Distance and tether share the function |x0 - x1| and a rest length that is never negative.
struct LengthTraits : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) { return eval_distance(x[p[0]], x[p[1]]); }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const double len = (x[p[0]] - x[p[1]]).norm();
    if (!(len > 0.0)) invalid(name + " is degenerate: its particles coincide (zero length)");
    return len;
  }
  static void check_rest(double rest, const std::string& name) {
    if (rest < 0.0) invalid(name + " rest length must be >= 0");
  }
};

template <>
struct KindTraits<Kind::distance> : LengthTraits {
  /// The rest length under the body's scales: the u and v parts of the rest (the edge's extent along
  /// the material's u/v directions) scaled by those, the rest by neither, all by the overall scale.
  static double scaled_rest(const ConstraintArray& a, size_t i, const BodyInfo& b) {
    const double ru = a.rest_u[i] * b.rest_scale_u, rv = a.rest_v[i] * b.rest_scale_v;
    const double rn2 = std::max(0.0, a.rest[i] * a.rest[i] - a.rest_u[i] * a.rest_u[i] - a.rest_v[i] * a.rest_v[i]);
    return b.rest_scale * std::sqrt(ru * ru + rv * rv + rn2);
  }
};

template <>
struct KindTraits<Kind::tether> : LengthTraits {
  static constexpr int side = -1;
};

/// |x0 - x1| >= rest: pushes only. With a tether on the same two particles, min <= |x0 - x1| <= max.
template <>
struct KindTraits<Kind::length_min> : LengthTraits {
  static constexpr int side = 1;
};

/// The angle at x0 (edge angle and the angle range's two sides): a rest in [0, pi].
struct AngleTraits : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_edge_angle(x[p[0]], x[p[1]], x[p[2]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if ((x[p[1]] - x[p[0]]).norm() == 0.0 || (x[p[2]] - x[p[0]]).norm() == 0.0)
      invalid(name + " is degenerate: an edge has zero length");
    return e.value;
  }
  static void check_rest(double rest, const std::string& name) {
    if (rest < 0.0 || rest > std::numbers::pi) invalid(name + " rest angle must be in [0, pi]");
  }
};

template <>
struct KindTraits<Kind::edge_angle> : AngleTraits {};

/// angle >= rest: opens only. With an angle_max on the same corner, min <= angle <= max.
template <>
struct KindTraits<Kind::angle_min> : AngleTraits {
  static constexpr int side = 1;
};

/// angle <= rest: closes only.
template <>
struct KindTraits<Kind::angle_max> : AngleTraits {
  static constexpr int side = -1;
};

template <>
struct KindTraits<Kind::dihedral> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_dihedral(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double deviation(double value, double rest) { return wrap_angle(value - rest); }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid) invalid(name + " is degenerate: a triangle has zero area");
    return e.value;
  }
  static void check_rest(double rest, const std::string& name) {
    if (rest <= -std::numbers::pi || rest > std::numbers::pi) invalid(name + " rest angle must be in (-pi, pi]");
  }
};

template <>
struct KindTraits<Kind::tet_volume> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_tet_volume(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    const double scale = std::max({(x[p[1]] - x[p[0]]).norm(), (x[p[2]] - x[p[0]]).norm(), (x[p[3]] - x[p[0]]).norm()});
    if (!(std::abs(e.value) > 1e-12 * scale * scale * scale)) invalid(name + " is degenerate: zero volume");
    return e.value;
  }
  /// A volume scales with the cube of the body's overall rest scale.
  static double scaled_rest(const ConstraintArray& a, size_t i, const BodyInfo& b) {
    return a.rest[i] * b.rest_scale * b.rest_scale * b.rest_scale;
  }
};

template <>
struct KindTraits<Kind::weld> : KindDefaults {
  static double measure_rest(const int32_t*, const std::vector<Vec3>&, const std::string&) { return 0.0; }
  static void check_rest(double rest, const std::string& name) {
    if (rest != 0.0) invalid(name + ": a weld has no rest value other than 0");
  }
};

template <>
struct KindTraits<Kind::planarity> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_quad_planarity(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid) invalid(name + " is degenerate: the quad's diagonals are parallel");
    return e.value;
  }
};

template <>
struct KindTraits<Kind::plane_offset> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_plane_offset(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid) invalid(name + " is degenerate: the plane's triangle has zero area");
    return e.value;
  }
};

/// The two edges may share a particle (x1 = x2: the links either side of it held equal), but an
/// edge may not join a particle to itself.
template <>
struct KindTraits<Kind::equal_length> : KindDefaults {
  static constexpr bool may_share(int a, int b) { return a / 2 != b / 2; }
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_equal_length(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid) invalid(name + " is degenerate: an edge's particles coincide (zero length)");
    return e.value;
  }
  /// A difference of lengths scales with the body's overall rest scale.
  static double scaled_rest(const ConstraintArray& a, size_t i, const BodyInfo& b) { return a.rest[i] * b.rest_scale; }
};

/// The conical vertex condition: a sum of four angles in [0, pi] with alternating signs, so its
/// value (and rest) is in [-2 pi, 2 pi]; angles do not scale with the body.
template <>
struct KindTraits<Kind::conical> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_conical(x[p[0]], x[p[1]], x[p[2]], x[p[3]], x[p[4]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid)
      invalid(name + " is degenerate: an edge has zero length or two neighbours are in line with the vertex");
    return e.value;
  }
  static void check_rest(double rest, const std::string& name) {
    if (!(std::abs(rest) <= 2.0 * std::numbers::pi)) invalid(name + " rest angle must be in [-2 pi, 2 pi]");
  }
};

/// Distance of x1 from the line x0-x2: a length >= 0 that scales with the body's overall rest scale.
template <>
struct KindTraits<Kind::colinear> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_colinear(x[p[0]], x[p[1]], x[p[2]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    if (!((x[p[2]] - x[p[0]]).norm() > 0.0)) invalid(name + " is degenerate: x0 and x2 coincide (no line)");
    return evaluate(p, x).value;
  }
  static void check_rest(double rest, const std::string& name) {
    if (rest < 0.0) invalid(name + " rest distance must be >= 0");
  }
  static double scaled_rest(const ConstraintArray& a, size_t i, const BodyInfo& b) { return a.rest[i] * b.rest_scale; }
};

/// The angle between two edges; they may share a particle (x1 = x2: consecutive edges), but an edge
/// may not join a particle to itself.
template <>
struct KindTraits<Kind::direction> : KindDefaults {
  static constexpr bool may_share(int a, int b) { return a / 2 != b / 2; }
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_direction(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    if (!((x[p[1]] - x[p[0]]).norm() > 0.0) || !((x[p[3]] - x[p[2]]).norm() > 0.0))
      invalid(name + " is degenerate: an edge's particles coincide (zero length)");
    return evaluate(p, x).value;
  }
  static void check_rest(double rest, const std::string& name) {
    if (rest < 0.0 || rest > std::numbers::pi) invalid(name + " rest angle must be in [0, pi]");
  }
};

/// The cyclic-quad angle criterion: four angles in [0, pi] with alternating signs, in [-2 pi, 2 pi].
template <>
struct KindTraits<Kind::cocircular> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_cocircular(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid) invalid(name + " is degenerate: an edge has zero length or a corner's edges are in line");
    return e.value;
  }
  static void check_rest(double rest, const std::string& name) {
    if (!(std::abs(rest) <= 2.0 * std::numbers::pi)) invalid(name + " rest angle must be in [-2 pi, 2 pi]");
  }
};

/// Signed distance of x4 from the sphere through x0..x3: a length that scales with the body.
template <>
struct KindTraits<Kind::cospherical> : KindDefaults {
  static auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
    return eval_cospherical(x[p[0]], x[p[1]], x[p[2]], x[p[3]], x[p[4]]);
  }
  static double measure_rest(const int32_t* p, const std::vector<Vec3>& x, const std::string& name) {
    const auto e = evaluate(p, x);
    if (!e.valid) invalid(name + " is degenerate: x0..x3 are flat (no sphere through them) or x4 is its centre");
    return e.value;
  }
  static double scaled_rest(const ConstraintArray& a, size_t i, const BodyInfo& b) { return a.rest[i] * b.rest_scale; }
};

/// Whether any two operand slots of kind K may hold the same particle (KindTraits<K>::may_share).
template <Kind K>
constexpr bool shares_operands() {
  for (int a = 0; a < arity(K); ++a)
    for (int b = 0; b < a; ++b)
      if (KindTraits<K>::may_share(a, b)) return true;
  return false;
}

#define EMBRA_KIND_HAS_TRAITS(name, number, arity, multipliers, unit, what) \
  static_assert(sizeof(KindTraits<Kind::name>) > 0, "every kind has its KindTraits");
EMBRA_CONSTRAINT_KINDS(EMBRA_KIND_HAS_TRAITS)
#undef EMBRA_KIND_HAS_TRAITS

}  // namespace embra
