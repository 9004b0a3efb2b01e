// The force a group's constraints exert on each particle after the last step: the sum over its
// constraints of lambda / h^2 grad C (the last substep's multipliers), for the diagnostics
// (World::group_conflicts) and the statics (World::reactions).
#pragma once

#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"

#include <vector>

namespace embra {

/// Adds lambda / h^2 grad C of every constraint of a group's solver arrays (kinds in table order,
/// welds as their three multipliers) and of its soft pins to f (one entry per particle); returns
/// whether any multiplier was nonzero. The automatic tethers (g.tethers) are not included.
inline bool add_group_forces(const Group& g, const std::vector<Pin>& pins, const std::vector<Vec3>& x, double inv_h2,
                             std::vector<Vec3>& f) {
  bool any = false;
  for (const KindInfo& info : kKinds)
    visit_kind(info.kind, [&](auto k) {
      const SolverArray& a = g.solve[static_cast<int>(info.kind)];
      if constexpr (k == Kind::weld) {
        for (size_t i = 0; i < a.size(); ++i) {
          const Vec3 l = inv_h2 * Vec3(a.lambda[3 * i], a.lambda[3 * i + 1], a.lambda[3 * i + 2]);
          f[a.ids[2 * i]] += l;
          f[a.ids[2 * i + 1]] -= l;
          any = any || !l.isZero();
        }
      } else {
        constexpr int N = arity(k);
        for (size_t i = 0; i < a.size(); ++i) {
          if (a.lambda[i] == 0.0) continue;
          const auto e = KindTraits<k>::evaluate(&a.ids[i * N], x);
          if (!e.valid) continue;
          for (int m = 0; m < N; ++m) f[a.ids[i * N + m]] += (a.lambda[i] * inv_h2) * e.grad[m];
          any = true;
        }
      }
    });
  for (int32_t pi : g.soft_pins) {
    f[pins[pi].particle] += inv_h2 * pins[pi].lambda;
    any = any || !pins[pi].lambda.isZero();
  }
  return any;
}

}  // namespace embra
