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
//
// Hard pins: a hard-pinned particle's reaction is what holds it against its weight, its load and
// the impulse the constraints handed it in the last substep (Pin::lambda), summed projection by
// projection as the projections gave it (solver/pin_track.hpp), not read from the multipliers at
// the end. Every projection is momentum-neutral (its gradients sum to zero), so what the pins took
// is exactly what the free particles' motion did not: at a static rest the reactions sum to minus
// the load to rounding, even where redundant hard constraints (a panel mesh's) leave the
// multipliers undetermined and growing against each other.
#include "collision/collider_shapes.hpp"
#include "common/check.hpp"
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"

#include <bit>
#include <set>

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
  // The loads as the last substep applied them: at a static rest its start is where it ended.
  bool any_hard = false;
  for (const Pin& p : pins_) any_hard = any_hard || (p.alive && p.kinematic());
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
      // What holds the particle against its weight, its load and the impulse the constraints handed
      // it in the last substep (Pin::lambda, tracked by PinTrack).
      const double inv_mass = inv_mass_[p.particle];
      const Vec3 weight = inv_mass > 0.0 ? Vec3(settings_.gravity / inv_mass) : Vec3(Vec3::Zero());
      r.force = -(weight + load[p.particle] + inv_h2 * p.lambda);
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

namespace {

/// A multiplier as a reset leaves it: +0 (a -0 is kept, so that a force read after a load has the
/// same sign bit).
bool is_reset(double v) {
  return std::bit_cast<uint64_t>(v) == 0;
}

bool all_reset(const std::vector<double>& v) {
  for (double x : v)
    if (!is_reset(x)) return false;
  return true;
}

}  // namespace

StaticsState World::statics_state() const {
  StaticsState s;
  for (uint32_t slot = 0; slot < groups_.size(); ++slot) {
    const Group& g = groups_[slot];
    if (!g.alive) continue;
    const Id id{slot, g.generation};
    for (int k = 0; k < kKindCount; ++k) {
      // What constraint_forces reads, in ConstraintArray order: end_frame's copy of the solver
      // arrays' multipliers, kept in step with the constraints by every edit.
      const std::vector<double>& lambda = g.arrays[k].lambda;
      if (!all_reset(lambda)) s.constraints.push_back({id, static_cast<Kind>(k), lambda});
    }
    if (!all_reset(g.tethers.lambda)) s.tethers.push_back({id, g.tethers.lambda});
  }
  for (uint32_t i = 0; i < pins_.size(); ++i) {
    const Pin& p = pins_[i];
    if (p.alive && !(is_reset(p.lambda.x()) && is_reset(p.lambda.y()) && is_reset(p.lambda.z())))
      s.pins.push_back({Id{i, p.generation}, p.lambda});
  }
  const auto live = [&](int32_t c) {
    return c >= 0 && static_cast<size_t>(c) < colliders_.size() && colliders_[c].alive;
  };
  if (settings_.contact_group.index < groups_.size())
    for (const Contact& ct : groups_[settings_.contact_group.index].contacts)
      if (ct.force_h2 != Vec3::Zero() && live(ct.collider)) s.contacts.push_back(ct);
  for (const FaceContact& fc : face_contacts_)
    if (fc.force_h2 != Vec3::Zero() && live(fc.collider)) s.face_contacts.push_back(fc);
  return s;
}

void World::set_statics_state(const StaticsState& s) {
  // The solver arrays as the next step would build them: the multipliers live there.
  if (solver_dirty_)
    rebuild_solver();
  else if (rest_dirty_)
    refresh_rest();
  const auto finite = [](const std::vector<double>& v, const std::string& what) {
    for (double x : v) check_finite(x, what);
  };
  const auto finite3 = [](const Vec3& v, const std::string& what) {
    for (int k = 0; k < 3; ++k) check_finite(v[k], what);
  };
  const auto live_collider = [&](int32_t c, const std::string& what) {
    if (c < 0 || static_cast<size_t>(c) >= colliders_.size() || !colliders_[c].alive)
      throw Error(ErrorCode::stale_id, what + ": collider " + std::to_string(c) + " is no live collider of this world");
  };
  std::set<std::pair<uint32_t, int>> kinds_seen;
  for (size_t i = 0; i < s.constraints.size(); ++i) {
    const StaticsState::Multipliers& m = s.constraints[i];
    const std::string what = "multipliers " + std::to_string(i);
    const Group& g = group(m.group);
    const int k = static_cast<int>(m.kind);
    if (k < 0 || k >= kKindCount) invalid(what + ": no constraint kind " + std::to_string(k));
    if (!kinds_seen.insert({m.group.index, k}).second)
      invalid(what + ": the group's " + kind_name(m.kind) + " multipliers are given twice");
    const size_t per = static_cast<size_t>(multipliers(m.kind));
    if (m.lambda.size() != per * g.arrays[k].size())
      invalid(what + ": " + std::to_string(m.lambda.size()) + " multipliers for the group's " +
              std::to_string(g.arrays[k].size()) + " " + kind_name(m.kind) + " constraints (" + std::to_string(per) +
              " each)");
    finite(m.lambda, what);
  }
  std::set<uint32_t> tethers_seen;
  for (size_t i = 0; i < s.tethers.size(); ++i) {
    const StaticsState::Tethers& t = s.tethers[i];
    const std::string what = "tether multipliers " + std::to_string(i);
    const Group& g = group(t.group);
    if (!tethers_seen.insert(t.group.index).second) invalid(what + ": the group's tethers are given twice");
    if (t.lambda.size() != g.tethers.size())
      invalid(what + ": " + std::to_string(t.lambda.size()) + " multipliers for the group's " +
              std::to_string(g.tethers.size()) + " automatic tethers");
    finite(t.lambda, what);
  }
  std::set<uint32_t> pins_seen;
  for (size_t i = 0; i < s.pins.size(); ++i) {
    const std::string what = "pin multiplier " + std::to_string(i);
    pin(s.pins[i].pin);  // a live pin (else stale_id)
    if (!pins_seen.insert(s.pins[i].pin.index).second) invalid(what + ": the pin is given twice");
    finite3(s.pins[i].lambda, what);
  }
  for (size_t i = 0; i < s.contacts.size(); ++i) {
    const Contact& ct = s.contacts[i];
    const std::string what = "contact " + std::to_string(i);
    check_particle(ct.particle, what.c_str());
    live_collider(ct.collider, what);
    finite3(ct.force_h2, what);
  }
  for (size_t i = 0; i < s.face_contacts.size(); ++i) {
    const FaceContact& fc = s.face_contacts[i];
    const std::string what = "face contact " + std::to_string(i);
    for (int k = 0; k < 3; ++k) check_particle(fc.ids[k], what.c_str());
    live_collider(fc.collider, what);
    finite3(fc.force_h2, what);
  }
  // Every check passed: set them all, the rest to 0. The constraint arrays keep the same copy
  // (end_frame's), which a step that fails restores.
  for (Group& g : groups_) {
    if (!g.alive) continue;
    for (int k = 0; k < kKindCount; ++k) {
      std::fill(g.arrays[k].lambda.begin(), g.arrays[k].lambda.end(), 0.0);
      std::fill(g.solve[k].lambda.begin(), g.solve[k].lambda.end(), 0.0);
    }
    std::fill(g.tethers.lambda.begin(), g.tethers.lambda.end(), 0.0);
  }
  for (const StaticsState::Multipliers& m : s.constraints) {
    Group& g = groups_[m.group.index];
    const int k = static_cast<int>(m.kind);
    const size_t per = static_cast<size_t>(multipliers(m.kind));
    g.arrays[k].lambda = m.lambda;
    SolverArray& a = g.solve[k];
    for (size_t i = 0; i < a.size(); ++i)
      for (size_t c = 0; c < per; ++c) a.lambda[per * i + c] = m.lambda[per * static_cast<size_t>(a.source[i]) + c];
  }
  for (const StaticsState::Tethers& t : s.tethers) groups_[t.group.index].tethers.lambda = t.lambda;
  for (Pin& p : pins_) p.lambda.setZero();
  for (const StaticsState::PinMultiplier& p : s.pins) pins_[p.pin.index].lambda = p.lambda;
  std::vector<Contact>& contacts = groups_[settings_.contact_group.index].contacts;
  contacts.clear();
  for (const Contact& given : s.contacts) {
    Contact ct{};
    ct.particle = given.particle;
    ct.collider = given.collider;
    ct.lambda = 0.0;
    ct.force_h2 = given.force_h2;
    contacts.push_back(ct);
  }
  face_contacts_.clear();
  for (const FaceContact& given : s.face_contacts) {
    FaceContact fc{};
    for (int k = 0; k < 3; ++k) fc.ids[k] = fc.partner[k] = given.ids[k];
    fc.collider = given.collider;
    fc.lambda = 0.0;
    fc.force_h2 = given.force_h2;
    face_contacts_.push_back(fc);
  }
}

}  // namespace embra
