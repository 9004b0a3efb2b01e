// Constraints added by the host, one or a batch at a time.
#include "guard.hpp"

#include <iterator>
#include <string>

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

// --- edits -------------------------------------------------------------------------------------

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
