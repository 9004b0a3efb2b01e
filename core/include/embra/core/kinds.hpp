// The constraint kinds, listed once. Everything that names, numbers or counts kinds derives from
// EMBRA_CONSTRAINT_KINDS: the enum embra::Kind, kKindCount, arity(), multipliers(), kind_name()
// and kind_from_name(). The per-kind math (function, rest checks, rest scaling) is KindTraits<K>
// (core/src/model/kind_traits.hpp), dispatched from one place (visit_kind).
//
// Adding a kind: one line here (its scene-format name, its number in the C ABI's
// embra_constraint_kind, its arity, its multipliers per constraint and what it holds), a
// KindTraits specialisation, and its place in the step's projection order (World::project_group).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace embra {

// X(name, number, arity, multipliers, unit, description). The numbers are part of the C ABI; the
// unit is that of the constraint's value and residual (model units: m for metres).
#define EMBRA_CONSTRAINT_KINDS(X)                                                                              \
  X(distance, 0, 2, 1, "m", "|x0 - x1| = rest (stretch)")                                                      \
  X(edge_angle, 1, 3, 1, "rad", "angle at x0 between x1 - x0 and x2 - x0 (shear)")                             \
  X(dihedral, 2, 4, 1, "rad", "angle between (x0,x1,x2) and (x1,x0,x3) (bend)")                                \
  X(tet_volume, 3, 4, 1, "m^3", "signed volume of (x0,x1,x2,x3) = rest")                                       \
  X(weld, 4, 2, 3, "m", "x0 = x1")                                                                             \
  X(tether, 5, 2, 1, "m", "|x0 - x1| <= rest (long-range attachment, unilateral)")                             \
  X(planarity, 6, 4, 1, "m", "distance between the diagonals x0-x2 and x1-x3 = rest (0: a planar quad)")       \
  X(plane_offset, 7, 4, 1, "m", "signed distance of x0 from the plane (x1, x2, x3) = rest (slides along it)")  \
  X(equal_length, 8, 4, 1, "m", "|x0 - x1| - |x2 - x3| = rest (0: two edges of equal length)")                 \
  X(conical, 9, 5, 1, "rad",                                                                                   \
    "angles at x0 between its neighbours x1..x4 in order round it: a12 - a23 + a34 - a41 = rest (0: conical)") \
  X(length_min, 10, 2, 1, "m", "|x0 - x1| >= rest (unilateral: pushes only; with a tether, a length range)")   \
  X(angle_min, 11, 3, 1, "rad", "angle at x0 between x1 - x0 and x2 - x0 >= rest (unilateral)")                \
  X(angle_max, 12, 3, 1, "rad", "angle at x0 between x1 - x0 and x2 - x0 <= rest (unilateral)")                \
  X(colinear, 13, 3, 1, "m", "distance of x1 from the line through x0 and x2 = rest (0: co-linear)")           \
  X(direction, 14, 4, 1, "rad", "angle between x1 - x0 and x3 - x2 = rest (0: edge x0-x1 along x2-x3)")        \
  X(cocircular, 15, 4, 1, "rad",                                                                               \
    "quad x0..x3, a_k its angle at x_k: a0 - a1 + a2 - a3 = rest (0 and planar: on one circle)")               \
  X(cospherical, 16, 5, 1, "m", "signed distance of x4 from the sphere through x0..x3 = rest (0: on it)")

/// Constraint kinds. The numbering is part of the C ABI (embra_constraint_kind).
enum class Kind : int32_t {
#define EMBRA_KIND_ENUM(name, number, arity, multipliers, unit, what) name = number,
  EMBRA_CONSTRAINT_KINDS(EMBRA_KIND_ENUM)
#undef EMBRA_KIND_ENUM
};

/// One row of the kind table.
struct KindInfo {
  Kind kind;
  std::string_view name;  // the name in the scene format
  int arity;              // particles per constraint
  int multipliers;        // Lagrange multipliers per constraint
  std::string_view unit;  // of the constraint's value and residual ("m", "rad", "m^3")
  std::string_view what;  // what the constraint holds
};

inline constexpr std::array kKinds = {
#define EMBRA_KIND_ROW(name, number, arity, multipliers, unit, what) \
  KindInfo{Kind::name, #name, arity, multipliers, unit, what},
    EMBRA_CONSTRAINT_KINDS(EMBRA_KIND_ROW)
#undef EMBRA_KIND_ROW
};

constexpr int kKindCount = static_cast<int>(kKinds.size());

/// The most particles one constraint of any kind takes.
constexpr int kMaxArity = [] {
  int most = 0;
  for (const KindInfo& k : kKinds) most = k.arity > most ? k.arity : most;
  return most;
}();

/// A constraint's particles: the first arity(kind) used, -1 past them.
using ParticleSlots = std::array<int32_t, kMaxArity>;
constexpr ParticleSlots no_particles() {
  ParticleSlots p{};
  for (int32_t& v : p) v = -1;
  return p;
}

/// The table is indexed by the kind's number: the numbers run 0, 1, ... in the listed order.
constexpr bool kinds_numbered_in_order() {
  for (int k = 0; k < kKindCount; ++k)
    if (static_cast<int>(kKinds[k].kind) != k) return false;
  return true;
}
static_assert(kinds_numbered_in_order(), "EMBRA_CONSTRAINT_KINDS lists the kinds by number, from 0");

constexpr bool is_kind(int number) {
  return number >= 0 && number < kKindCount;
}

/// Particles per constraint of `kind` (0 for a number that is no kind).
constexpr int arity(Kind kind) {
  return is_kind(static_cast<int>(kind)) ? kKinds[static_cast<int>(kind)].arity : 0;
}

/// Lagrange multipliers per constraint of `kind` (a weld has one per axis).
constexpr int multipliers(Kind kind) {
  return is_kind(static_cast<int>(kind)) ? kKinds[static_cast<int>(kind)].multipliers : 0;
}

/// The kind's name in the scene format ("unknown" for a number that is no kind).
constexpr const char* kind_name(Kind kind) {
  switch (kind) {
#define EMBRA_KIND_NAME(name, number, arity, multipliers, unit, what) \
  case Kind::name:                                                    \
    return #name;
    EMBRA_CONSTRAINT_KINDS(EMBRA_KIND_NAME)
#undef EMBRA_KIND_NAME
  }
  return "unknown";
}

/// The kind named `name` in the scene format, or nothing.
constexpr std::optional<Kind> kind_from_name(std::string_view name) {
  for (const KindInfo& k : kKinds)
    if (k.name == name) return k.kind;
  return std::nullopt;
}

}  // namespace embra
