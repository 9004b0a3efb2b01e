// Constraints added by the host, one or a batch at a time.
#include "guard.hpp"

#include "embra/core/limits.hpp"
#include "embra/core/point_set.hpp"

#include <algorithm>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

using namespace embra::capi;

// The C values cast to core enums here are pinned to them in enum_pins_generated.hpp.

extern "C" {

int32_t embra_constraint_arity(embra_constraint_kind kind) {
  if (kind < 0 || kind >= embra::kKindCount) return 0;
  return embra::arity(static_cast<embra::Kind>(kind));
}

embra_constraint_def embra_default_constraint_def(void) {
  embra_constraint_def d{};
  d.version = EMBRA_CONSTRAINT_DEF_VERSION;
  d.kind = EMBRA_CONSTRAINT_DISTANCE;
  d.rest_from_current = 1;
  return d;
}

embra_status embra_constraint_add(embra_world* world, const embra_constraint_def* def) {
  return guard("embra_constraint_add", world, [&] {
    need(def, "def");
    need_version(def->version, EMBRA_CONSTRAINT_DEF_VERSION, "embra_constraint_def");
    const int32_t n = embra_constraint_arity(def->kind);
    if (n == 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "unknown constraint kind " + num(def->kind));
    if (n > static_cast<int32_t>(std::size(def->particles)))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(embra::kind_name(static_cast<embra::Kind>(def->kind))) +
                                               " takes " + num(n) + " particles and embra_constraint_def holds " +
                                               num(static_cast<int64_t>(std::size(def->particles))) +
                                               ": add it with embra_constraints_add");
    need_flag(def->rest_from_current, "def.rest_from_current");
    embra::ConstraintDesc d;
    d.kind = static_cast<embra::Kind>(def->kind);
    d.group = to_id(def->group);
    d.particles = std::span<const int32_t>(def->particles, static_cast<size_t>(n));
    if (!def->rest_from_current) d.rest = std::span<const double>(&def->rest, 1);
    d.uniform_compliance = def->compliance;
    world->world.add_constraints(d);
  });
}

embra_constraint_batch_def embra_default_constraint_batch_def(void) {
  embra_constraint_batch_def d{};
  d.version = EMBRA_CONSTRAINT_BATCH_DEF_VERSION;
  d.kind = EMBRA_CONSTRAINT_DISTANCE;
  return d;
}

embra_status embra_constraints_add(embra_world* world, const embra_constraint_batch_def* def) {
  return guard("embra_constraints_add", world, [&] {
    need(def, "def");
    need_version(def->version, EMBRA_CONSTRAINT_BATCH_DEF_VERSION, "embra_constraint_batch_def");
    const int32_t n = embra_constraint_arity(def->kind);
    if (n == 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "unknown constraint kind " + num(def->kind));
    if (def->count <= 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.count must be > 0");
    embra::ConstraintDesc d;
    d.kind = static_cast<embra::Kind>(def->kind);
    d.group = to_id(def->group);
    d.particles = view(def->particles, static_cast<int64_t>(def->count) * n, "def.particles");
    if (def->rest) d.rest = std::span<const double>(def->rest, static_cast<size_t>(def->count));
    if (def->compliances) d.compliance = std::span<const double>(def->compliances, static_cast<size_t>(def->count));
    d.uniform_compliance = def->compliance;
    world->world.add_constraints(d);
  });
}

embra_status embra_polygon_planarity_add(embra_world* world, embra_group_id group, const int32_t* particles,
                                         int32_t count, double compliance, int32_t* out_added) {
  return guard("embra_polygon_planarity_add", world, [&] {
    if (count < 4) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "count must be >= 4 (fewer corners are always planar)");
    if (count > embra::limits::kMaxConstraints)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "count must be <= " + num(embra::limits::kMaxConstraints));
    const std::span<const int32_t> corners = view(particles, count, "particles");
    const int32_t n = world->world.particle_count();
    for (int32_t i = 0; i < count; ++i)
      if (corners[i] < 0 || corners[i] >= n)
        refuse(EMBRA_ERROR_INVALID_ARGUMENT, "particles[" + num(i) + "] = " + num(corners[i]) +
                                                 " is outside the world's particles [0, " + num(n) + ")");
    if (const int32_t twice = embra::repeated_particle(corners); twice >= 0)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "the polygon is degenerate: particle " + num(twice) + " appears twice");
    // One window of four consecutive corners for a quad; every one of them, cyclically, for more.
    const int32_t windows = count == 4 ? 1 : count;
    std::vector<int32_t> ids(static_cast<size_t>(windows) * 4);
    const std::vector<embra::Vec3>& x = world->world.positions();
    for (int32_t w = 0; w < windows; ++w) {
      for (int k = 0; k < 4; ++k) ids[4 * static_cast<size_t>(w) + k] = corners[(w + k) % count];
      const int32_t* q = &ids[4 * static_cast<size_t>(w)];
      const embra::Vec3 d1 = x[q[2]] - x[q[0]], d2 = x[q[3]] - x[q[1]];
      if (!(d1.cross(d2).norm() > 1e-12 * d1.norm() * d2.norm()))
        refuse(EMBRA_ERROR_INVALID_ARGUMENT, "the polygon is degenerate: corners " + num(w) + " to " +
                                                 num((w + 3) % count) +
                                                 " have parallel diagonals (in line): no plane to pull them to");
    }
    const std::vector<double> rest(static_cast<size_t>(windows), 0.0);
    embra::ConstraintDesc d;
    d.kind = embra::Kind::planarity;
    d.group = to_id(group);
    d.particles = ids;
    d.rest = rest;
    d.uniform_compliance = compliance;
    world->world.add_constraints(d);
    if (out_added != nullptr) *out_added = windows;
  });
}

embra_status embra_rigid_set_add(embra_world* world, embra_group_id group, const int32_t* particles, int32_t count,
                                 double compliance, int32_t* out_added) {
  return guard("embra_rigid_set_add", world, [&] {
    if (count < 3) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "count must be >= 3 (two points: a distance constraint)");
    if (count > embra::limits::kMaxConstraints / 5)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "count must be <= " + num(embra::limits::kMaxConstraints / 5));
    const std::span<const int32_t> pts = view(particles, count, "particles");
    const int32_t n = world->world.particle_count();
    for (int32_t i = 0; i < count; ++i)
      if (pts[i] < 0 || pts[i] >= n)
        refuse(EMBRA_ERROR_INVALID_ARGUMENT,
               "particles[" + num(i) + "] = " + num(pts[i]) + " is outside the world's particles [0, " + num(n) + ")");
    if (const int32_t twice = embra::repeated_particle(pts); twice >= 0)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "the point set is degenerate: particle " + num(twice) + " appears twice");
    // The base: the first point, the farthest from it, the farthest from their line, the farthest
    // from the plane of those three (embra::point_set_base).
    const std::vector<embra::Vec3>& x = world->world.positions();
    const embra::PointSetBase set = embra::point_set_base(pts.size(), [&](size_t i) { return x[pts[i]]; });
    if (!set.spans_plane())
      refuse(EMBRA_ERROR_INVALID_ARGUMENT,
             "the point set is degenerate: its points are on one line (or coincide), no rigid frame to hold");
    // Solid when a point is 1e-3 of the set's size off the plane (its base tetrahedron then has a volume
    // the tet_volume kind measures: at least 1e-10 of the size cubed); else flat, each point held at
    // its offset from the base's plane.
    const bool solid = set.plane_distance > 1e-3 * set.reach;
    std::vector<int32_t> base{pts[0], pts[set.far], pts[set.off]};
    if (solid) base.push_back(pts[set.off_plane]);
    // Distances among the base; every other point's distances to each base point; a solid base's
    // volume (its handedness), a flat set's points held on the base's plane.
    std::vector<int32_t> pairs, tet, offsets;
    for (size_t i = 0; i < base.size(); ++i)
      for (size_t j = i + 1; j < base.size(); ++j) pairs.insert(pairs.end(), {base[i], base[j]});
    for (int32_t i = 0; i < count; ++i) {
      if (std::find(base.begin(), base.end(), pts[i]) != base.end()) continue;
      for (int32_t b : base) pairs.insert(pairs.end(), {pts[i], b});
      if (!solid) offsets.insert(offsets.end(), {pts[i], base[0], base[1], base[2]});
    }
    if (solid) tet = base;
    const int64_t total = static_cast<int64_t>(pairs.size() / 2 + tet.size() / 4 + offsets.size() / 4);
    if (world->world.constraint_count() + total > embra::limits::kMaxConstraints)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "a world holds at most " + num(embra::limits::kMaxConstraints) +
                                               " constraints; this set would make " +
                                               num(world->world.constraint_count() + total));
    // Every check that could refuse is done: the three batches are added together or the group is
    // stale for the first (refused before anything is added).
    const auto add = [&](embra::Kind kind, const std::vector<int32_t>& ids) {
      if (ids.empty()) return;
      embra::ConstraintDesc d;
      d.kind = kind;
      d.group = to_id(group);
      d.particles = ids;
      d.uniform_compliance = compliance;
      world->world.add_constraints(d);
    };
    add(embra::Kind::distance, pairs);
    add(embra::Kind::tet_volume, tet);
    add(embra::Kind::plane_offset, offsets);
    if (out_added != nullptr) *out_added = static_cast<int32_t>(total);
  });
}

// --- edits -------------------------------------------------------------------------------------

embra_status embra_shape_match_add(embra_world* world, embra_group_id group, const int32_t* particles, int32_t count,
                                   double compliance, int32_t* out_index) {
  return guard("embra_shape_match_add", world, [&] {
    if (count < 3) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "count must be >= 3 (fewer points have no rotation to fit)");
    if (count > embra::limits::kMaxParticles)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "count must be <= " + num(embra::limits::kMaxParticles));
    const std::span<const int32_t> ids = view(particles, count, "particles");
    const int64_t index = world->world.add_shape_match(to_id(group), ids, {}, compliance);
    if (out_index != nullptr) *out_index = static_cast<int32_t>(index);
  });
}

embra_status embra_shape_match_remove(embra_world* world, embra_group_id group, int32_t index) {
  return guard("embra_shape_match_remove", world, [&] { world->world.remove_shape_match(to_id(group), index); });
}

embra_status embra_group_get_shape_match_count(const embra_world* world, embra_group_id group, int32_t* out_count) {
  return guard("embra_group_get_shape_match_count", world, [&] {
    need(out_count, "out_count");
    *out_count = static_cast<int32_t>(world->world.shape_matches(to_id(group)).size());
  });
}

embra_status embra_group_get_constraint_count(const embra_world* world, embra_group_id group,
                                              embra_constraint_kind kind, int32_t* out_count, int32_t* out_generated) {
  return guard("embra_group_get_constraint_count", world, [&] {
    need(out_count, "out_count");
    const auto [count, generated] = world->world.constraint_count(to_id(group), static_cast<embra::Kind>(kind));
    *out_count = static_cast<int32_t>(count);
    if (out_generated) *out_generated = static_cast<int32_t>(generated);
  });
}

embra_status embra_constraint_get(const embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                  int32_t index, embra_constraint_def* out_def) {
  return guard("embra_constraint_get", world, [&] {
    need(out_def, "out_def");
    const embra::ConstraintInfo c = world->world.constraint(to_id(group), static_cast<embra::Kind>(kind), index);
    embra_constraint_def d = embra_default_constraint_def();
    const int32_t n = embra_constraint_arity(kind);
    if (n > static_cast<int32_t>(std::size(d.particles)))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(embra::kind_name(static_cast<embra::Kind>(kind))) + " takes " +
                                               num(n) + " particles and embra_constraint_def holds " +
                                               num(static_cast<int64_t>(std::size(d.particles))) +
                                               ": embra_world_save_json lists them");
    d.kind = kind;
    d.group = group;
    for (size_t k = 0; k < std::size(d.particles); ++k) d.particles[k] = c.particles[k];
    d.rest_from_current = 0;
    d.rest = c.rest;
    d.compliance = c.compliance;
    *out_def = d;
  });
}

embra_status embra_constraint_set_compliance(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                             int32_t index, double compliance) {
  return guard("embra_constraint_set_compliance", world, [&] {
    world->world.set_constraint_compliance(to_id(group), static_cast<embra::Kind>(kind), index, compliance);
  });
}

embra_status embra_constraint_set_rest(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                       int32_t index, double rest) {
  return guard("embra_constraint_set_rest", world,
               [&] { world->world.set_constraint_rest(to_id(group), static_cast<embra::Kind>(kind), index, rest); });
}

embra_status embra_constraint_set_group(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                        int32_t index, embra_group_id to, int32_t* out_new_index) {
  return guard("embra_constraint_set_group", world, [&] {
    const int64_t at = world->world.move_constraint(to_id(group), static_cast<embra::Kind>(kind), index, to_id(to));
    if (out_new_index) *out_new_index = static_cast<int32_t>(at);
  });
}

embra_status embra_constraint_remove(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                     int32_t index) {
  return guard("embra_constraint_remove", world,
               [&] { world->world.remove_constraint(to_id(group), static_cast<embra::Kind>(kind), index); });
}

embra_status embra_constraint_set_plasticity(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                             int32_t index, double yield, double rupture) {
  return guard("embra_constraint_set_plasticity", world, [&] {
    world->world.set_constraint_plasticity(to_id(group), static_cast<embra::Kind>(kind), index, yield, rupture);
  });
}

embra_status embra_constraint_get_plasticity(const embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                             int32_t index, double* out_yield, double* out_rupture) {
  return guard("embra_constraint_get_plasticity", world, [&] {
    need(out_yield, "out_yield");
    need(out_rupture, "out_rupture");
    const embra::ConstraintInfo c = world->world.constraint(to_id(group), static_cast<embra::Kind>(kind), index);
    *out_yield = c.yield;
    *out_rupture = c.rupture;
  });
}

embra_status embra_world_get_broken(embra_world* world, embra_broken_constraint* out, int32_t capacity,
                                    int32_t* out_count) {
  return guard("embra_world_get_broken", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<embra::BrokenConstraint>& b = world->world.broken();
    const int32_t n = static_cast<int32_t>(b.size());
    if (!fits(out, capacity, n, "broken constraints")) {
      *out_count = n;
      return;
    }
    for (int32_t i = 0; i < n; ++i) {
      embra_broken_constraint e{};
      e.group = from_id<embra_group_id>(b[i].group);
      e.kind = static_cast<int32_t>(b[i].kind);
      e.index = static_cast<int32_t>(b[i].index);
      for (int k = 0; k < 4; ++k) e.particles[k] = b[i].particles[k];
      e.frame = b[i].frame;
      e.strain = b[i].strain;
      out[i] = e;
    }
    *out_count = n;
    world->world.take_broken();
  });
}

}  // extern "C"
