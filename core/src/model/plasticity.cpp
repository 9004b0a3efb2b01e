// Plasticity and rupture of added distances and dihedrals (World::set_constraint_plasticity),
// applied after every step at the step's end positions, one constraint after another in a fixed
// order (groups by slot, then the constraints from last to first), so the result does not depend
// on the thread count.
#include "common/check.hpp"
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"

#include <cmath>
#include <string>

namespace embra {

namespace {

bool plastic_kind(Kind kind) {
  return kind == Kind::distance || kind == Kind::dihedral;
}

}  // namespace

void World::set_constraint_plasticity(Id group_id, Kind kind, int64_t index, double yield, double rupture) {
  if (!plastic_kind(kind))
    invalid(std::string("plasticity and rupture are for distance and dihedral constraints, not ") + kind_name(kind) +
            " (kind " + std::to_string(static_cast<int>(kind)) + ")");
  ConstraintArray& a = edited_array(group_id, kind, index);
  check_non_negative(yield, "yield");
  check_non_negative(rupture, "rupture");
  const auto i = static_cast<size_t>(index);
  if (kind == Kind::distance && (yield > 0.0 || rupture > 0.0) && !(a.rest[i] > 0.0))
    invalid("distance constraint " + std::to_string(index) +
            " has rest length 0: it has no strain to yield or break at");
  a.yield[i] = yield;
  a.rupture[i] = rupture;
}

std::vector<BrokenConstraint> World::take_broken() {
  std::vector<BrokenConstraint> out;
  out.swap(broken_);
  return out;
}

void World::apply_plasticity() {
  bool removed = false;
  for (size_t slot = 0; slot < groups_.size(); ++slot) {
    Group& g = groups_[slot];
    if (!g.alive || !g.desc.enabled) continue;
    for (const Kind kind : {Kind::distance, Kind::dihedral}) {
      ConstraintArray& a = g.arrays[static_cast<int>(kind)];
      const int n = arity(kind);
      for (size_t i = a.size(); i-- > a.generated;) {
        if (a.yield[i] == 0.0 && a.rupture[i] == 0.0) continue;
        const int32_t* p = &a.ids[i * static_cast<size_t>(n)];
        double strain = 0.0, value = 0.0;
        bool valid = true;
        visit_kind(kind, [&](auto kt) {
          if constexpr (decltype(kt)::value == Kind::distance || decltype(kt)::value == Kind::dihedral) {
            using T = KindTraits<decltype(kt)::value>;
            const auto e = T::evaluate(p, x_);
            valid = e.valid;
            value = e.value;
            strain = T::deviation(value, a.rest[i]);
          }
        });
        if (!valid) continue;  // a degenerate hinge has no angle this frame
        if (kind == Kind::distance) strain /= a.rest[i];
        if (a.rupture[i] > 0.0 && std::abs(strain) > a.rupture[i]) {
          BrokenConstraint b;
          b.group = Id{static_cast<uint32_t>(slot), g.generation};
          b.kind = kind;
          b.index = static_cast<int64_t>(i);
          for (int k = 0; k < n; ++k) b.particles[k] = p[k];
          b.frame = report_.frame;
          b.strain = strain;
          broken_.push_back(b);
          remove_constraint(b.group, kind, b.index);
          removed = true;
          continue;
        }
        if (a.yield[i] > 0.0 && std::abs(strain) > a.yield[i]) {
          const double set = std::copysign(a.yield[i], strain);
          a.rest[i] = kind == Kind::distance ? value / (1.0 + set) : wrap_angle(value - set);
          rest_dirty_ = true;
        }
      }
    }
  }
  // Rebuilt now, so that the forces and residuals read after this step name the constraints that
  // remain (the multipliers of the last step were copied back to the arrays by end_frame).
  if (removed) rebuild_solver();
}

}  // namespace embra
