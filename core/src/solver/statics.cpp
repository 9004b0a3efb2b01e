// Statics of the last step: the force in each constraint, the reaction at each pin and the force
// of each collider, from the last substep's multipliers (World::constraint_forces,
// World::reactions, World::collider_reactions).
//
// An XPBD multiplier is an impulse times h: a constraint's projection moves particle k by
// w_k lambda grad_k C, which is the displacement a force lambda / h^2 grad_k C makes over a substep
// (x <- x + h^2 w f). At a static rest every substep starts where the last one ended, at rest: the
// prediction moves each free particle by h^2 w (m g + load) and the projections move it back, so
// the constraint forces on it balance its weight and load. They balance exactly when the
// projections' gradients are those of the end of the substep, which the realignment passes
// (Settings::realign_passes) make so; textbook XPBD leaves an imbalance of O(h^2 g / length) of
// the forces (World::realign, docs/design.md "Statics").
#include "collision/collider_shapes.hpp"
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"
#include "solver/forces.hpp"

namespace embra {

std::vector<double> World::constraint_forces(Id group_id, Kind kind) const {
  const Group& g = group(group_id);
  if (multipliers(kind) != 1)
    invalid(std::string("a ") + kind_name(kind) + " has " + std::to_string(multipliers(kind)) +
            " multipliers: its force is a vector, not one number");
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  const SolverArray& a = g.solve[static_cast<int>(kind)];
  // The solver arrays are the constraint arrays in colour order as of the last step; a constraint
  // added since has no force yet (0).
  std::vector<double> out(g.arrays[static_cast<int>(kind)].size(), 0.0);
  for (size_t i = 0; i < a.size(); ++i)
    if (a.source[i] >= 0 && static_cast<size_t>(a.source[i]) < out.size()) out[a.source[i]] = -a.lambda[i] * inv_h2;
  return out;
}

std::vector<Reaction> World::reactions() const {
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  std::vector<Vec3> f(x_.size(), Vec3::Zero());
  bool any_hard = false;
  for (const Pin& p : pins_) any_hard = any_hard || (p.alive && p.kinematic());
  // Every constraint's force on every particle (only a hard-pinned particle's sum is read).
  if (any_hard)
    for (int32_t slot : order_) {
      const Group& g = groups_[slot];
      add_group_forces(g, pins_, x_, inv_h2, f);
      const SolverArray& t = g.tethers;
      for (size_t i = 0; i < t.size(); ++i) {
        if (t.lambda.empty() || t.lambda[i] == 0.0) continue;
        const auto e = KindTraits<Kind::tether>::evaluate(&t.ids[2 * i], x_);
        if (!e.valid) continue;
        for (int m = 0; m < 2; ++m) f[t.ids[2 * i + m]] += (t.lambda[i] * inv_h2) * e.grad[m];
      }
    }
  // The loads as the last substep applied them: at a static rest its start is where it ended.
  const std::vector<Vec3> load = any_hard ? applied_loads() : std::vector<Vec3>();
  std::vector<Reaction> out;
  for (size_t i = 0; i < pins_.size(); ++i) {
    const Pin& p = pins_[i];
    if (!p.alive) continue;
    Reaction r;
    r.pin = Id{static_cast<uint32_t>(i), p.generation};
    r.particle = p.particle;
    if (!p.kinematic()) {
      r.force = inv_h2 * p.lambda;
    } else {
      const double inv_mass = inv_mass_[p.particle];
      const Vec3 weight = inv_mass > 0.0 ? Vec3(settings_.gravity / inv_mass) : Vec3(Vec3::Zero());
      r.force = -(weight + load[p.particle] + f[p.particle]);
    }
    out.push_back(r);
  }
  return out;
}

std::vector<ColliderReaction> World::collider_reactions() const {
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  std::vector<ColliderReaction> out;
  std::vector<int32_t> at(colliders_.size(), -1);  // slot -> index in out
  for (size_t c = 0; c < colliders_.size(); ++c) {
    if (!colliders_[c].alive) continue;
    at[c] = static_cast<int32_t>(out.size());
    ColliderReaction r;
    r.collider = Id{static_cast<uint32_t>(c), colliders_[c].generation};
    out.push_back(r);
  }
  const auto live = [&](int32_t collider) {  // a collider destroyed since the step reads nothing
    return collider >= 0 && static_cast<size_t>(collider) < at.size() && at[collider] >= 0;
  };
  const auto add = [&](int32_t collider, const Vec3& point, const Vec3& force) {
    ColliderReaction& r = out[at[collider]];
    r.contacts += 1;
    r.force += force;
    r.moment += (point - colliders_[collider].position).cross(force);
  };
  // Each contact keeps its force times h^2 (Contact::force_h2, FaceContact::force_h2): a particle
  // contact's projection moved its particle by lambda n (lambda a length, w cancels), what a force
  // lambda / (w h^2) n does over a substep; a face contact moved corner pair k by w_k b_k lambda n,
  // a force b_k lambda / h^2 n; friction and the push back onto the surface add theirs.
  if (!colliders_.empty() && settings_.contact_group.index < groups_.size())
    for (const Contact& ct : groups_[settings_.contact_group.index].contacts) {
      if (ct.force_h2 == Vec3::Zero() || !live(ct.collider)) continue;
      add(ct.collider, x_[ct.particle], inv_h2 * ct.force_h2);
    }
  for (const FaceContact& fc : face_contacts_) {
    if (fc.force_h2 == Vec3::Zero() || !live(fc.collider)) continue;
    const Collider& col = colliders_[fc.collider];
    const Vec3 bary = closest_barycentric(col.position, x_[fc.ids[0]], x_[fc.ids[1]], x_[fc.ids[2]]);
    add(fc.collider, bary[0] * x_[fc.ids[0]] + bary[1] * x_[fc.ids[1]] + bary[2] * x_[fc.ids[2]], inv_h2 * fc.force_h2);
  }
  return out;
}

}  // namespace embra
