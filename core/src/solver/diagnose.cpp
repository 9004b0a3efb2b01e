// Which constraints are fighting: the last step's residual and force of every constraint, ranked,
// and the groups whose forces on shared particles oppose (World::worst_constraints,
// World::group_conflicts, World::constraint_residuals).
//
// A constraint's force is its multiplier of the last substep over h^2 (the XPBD multiplier is an
// impulse times h), in the unit conjugate to its value: N for a length, N m for an angle, N/m^2 for
// a volume. Its violation |C| (how far from its rest) times its force is then an energy for every
// kind, which ranks constraints of different units on one scale: a constraint held far from its rest
// while pushing hard ranks first. (A compliant constraint that has converged has a residual near 0
// however hard it is stretched: the violation is what shows it fighting.)
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"
#include "solver/forces.hpp"
#include "solver/residuals.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace embra {

namespace {

/// Calls f(kind, i, residual, violation, force) for every constraint of a group's solver arrays (i
/// the solver-array index), of kind `only` when given.
template <class F>
void each_constraint(ThreadPool& pool, const Group& g, const std::vector<Vec3>& x, double inv_h2, F&& f,
                     std::optional<Kind> only = std::nullopt) {
  std::vector<double> values, each, violation;
  for (const KindInfo& info : kKinds)
    visit_kind(info.kind, [&](auto k) {
      if (only && *only != info.kind) return;
      const SolverArray& a = g.solve[static_cast<int>(info.kind)];
      if (a.size() == 0) return;
      if constexpr (k == Kind::weld) {
        for (size_t i = 0; i < a.size(); ++i) {
          const Vec3 l(a.lambda[3 * i], a.lambda[3 * i + 1], a.lambda[3 * i + 2]);
          const Vec3 c = x[a.ids[2 * i]] - x[a.ids[2 * i + 1]];
          f(info.kind, i, (c + a.compliance[i] * inv_h2 * l).norm(), c.norm(), l.norm() * inv_h2);
        }
      } else {
        double max = 0.0, sq = 0.0;
        residuals<k>(pool, a, inv_h2, x, max, sq, values, &each, &violation);
        for (size_t i = 0; i < a.size(); ++i) f(info.kind, i, each[i], violation[i], std::abs(a.lambda[i]) * inv_h2);
      }
    });
}

}  // namespace

std::vector<ConstraintResidual> World::worst_constraints(size_t count) const {
  if (count == 0) return {};
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  // Ranked by largest violation x force first, then the larger residual, then the projection order
  // (group order, kind, colour order). Only the `count` first are kept while the constraints are
  // visited: a heap whose top is the last of them, which a constraint has to come before to enter
  // (a few comparisons for most, instead of a record each and a sort of them all).
  struct Ranked {
    double energy, residual;
    size_t order;
    ConstraintResidual c;
  };
  const auto before = [](const Ranked& a, const Ranked& b) {
    if (a.energy != b.energy) return a.energy > b.energy;
    if (a.residual != b.residual) return a.residual > b.residual;
    return a.order < b.order;
  };
  std::vector<Ranked> kept;
  kept.reserve(std::min<size_t>(count, 1024));  // (a host may ask for far more than there are)
  size_t order = 0;
  auto offer = [&](double residual, double violation, double force, auto&& record) {
    Ranked r{violation * force, residual, order++, {}};
    if (kept.size() == count) {
      if (!before(r, kept.front())) return;
      std::pop_heap(kept.begin(), kept.end(), before);
      kept.pop_back();
    }
    r.c = record();
    r.c.residual = residual;
    r.c.violation = violation;
    r.c.force = force;
    kept.push_back(r);
    std::push_heap(kept.begin(), kept.end(), before);
  };
  for (int32_t slot : order_) {
    const Group& g = groups_[slot];
    const Id gid{static_cast<uint32_t>(slot), g.generation};
    each_constraint(*pool_, g, x_, inv_h2, [&](Kind kind, size_t i, double residual, double violation, double force) {
      offer(residual, violation, force, [&] {
        const SolverArray& a = g.solve[static_cast<int>(kind)];
        ConstraintResidual c;
        c.kind = static_cast<int32_t>(kind);
        c.group = gid;
        c.index = a.source[i];
        const int n = arity(kind);
        for (int m = 0; m < n; ++m) c.particles[m] = a.ids[i * n + m];
        return c;
      });
    });
    for (int32_t pi : g.soft_pins) {
      const Pin& p = pins_[pi];
      offer((p.held(x_[p.particle] - p.target) + p.compliance * inv_h2 * p.lambda).norm(),
            p.held(x_[p.particle] - p.target).norm(), p.lambda.norm() * inv_h2, [&] {
              ConstraintResidual c;
              c.kind = kResidualPins;
              c.group = gid;
              c.pin = Id{static_cast<uint32_t>(pi), p.generation};
              c.particles[0] = p.particle;
              return c;
            });
    }
  }
  std::sort_heap(kept.begin(), kept.end(), before);
  std::vector<ConstraintResidual> out;
  out.reserve(kept.size());
  for (const Ranked& r : kept) out.push_back(r.c);
  return out;
}

std::vector<GroupConflict> World::group_conflicts() const {
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  // Fewer than two groups with constraints or soft pins: no pair to weigh, no force to add up.
  const auto holds_any = [](const Group& g) {
    return !g.soft_pins.empty() || std::ranges::any_of(g.solve, [](const SolverArray& a) { return a.size() > 0; });
  };
  if (std::ranges::count_if(order_, [&](int32_t slot) { return holds_any(groups_[slot]); }) < 2) return {};
  // Each group's force on each particle: sum over its constraints of lambda / h^2 grad C.
  std::vector<std::vector<Vec3>> force;
  std::vector<int32_t> slots;
  for (int32_t slot : order_) {
    const Group& g = groups_[slot];
    std::vector<Vec3> f(x_.size(), Vec3::Zero());
    const bool any = add_group_forces(g, pins_, x_, inv_h2, f);
    if (!any) continue;
    force.push_back(std::move(f));
    slots.push_back(slot);
  }
  std::vector<GroupConflict> out;
  for (size_t a = 0; a < slots.size(); ++a)
    for (size_t b = a + 1; b < slots.size(); ++b) {
      GroupConflict c;
      c.a = Id{static_cast<uint32_t>(slots[a]), groups_[slots[a]].generation};
      c.b = Id{static_cast<uint32_t>(slots[b]), groups_[slots[b]].generation};
      for (size_t p = 0; p < x_.size(); ++p) {
        if (w_[p] == 0.0) continue;
        const Vec3& fa = force[a][p];
        const Vec3& fb = force[b][p];
        const double na = fa.norm(), nb = fb.norm();
        if (na == 0.0 || nb == 0.0) continue;
        const double cosine = fa.dot(fb) / (na * nb);
        if (cosine >= 0.0) continue;
        c.force += std::min(na, nb) * -cosine;
        if (cosine < -0.5) ++c.particles;
      }
      if (c.force > 0.0) out.push_back(c);
    }
  std::stable_sort(out.begin(), out.end(),
                   [](const GroupConflict& l, const GroupConflict& r) { return l.force > r.force; });
  return out;
}

std::vector<double> World::constraint_residuals(Id group_id, Kind kind) const {
  const Group& g = group(group_id);
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  const SolverArray& a = g.solve[static_cast<int>(kind)];
  std::vector<double> out(g.arrays[static_cast<int>(kind)].size(), 0.0);
  // The solver arrays are the constraint arrays in colour order as of the last step; a constraint
  // added since has no residual yet (0).
  each_constraint(
      *pool_, g, x_, inv_h2,
      [&](Kind, size_t i, double residual, double, double) {
        if (a.source[i] >= 0 && static_cast<size_t>(a.source[i]) < out.size()) out[a.source[i]] = residual;
      },
      kind);
  return out;
}

}  // namespace embra
