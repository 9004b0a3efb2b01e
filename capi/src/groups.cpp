// Constraint groups: creation, order and weight, reports.
#include "guard.hpp"

using namespace embra::capi;

extern "C" {

embra_group_def embra_default_group_def(void) {
  const embra::GroupDesc g;
  embra_group_def d{};
  d.version = EMBRA_GROUP_DEF_VERSION;
  d.order = g.order;
  d.weight = g.weight;
  return d;
}

embra_status embra_group_create(embra_world* world, const embra_group_def* def, embra_group_id* out_group) {
  return guard("embra_group_create", world, [&] {
    need(def, "def");
    need(out_group, "out_group");
    need_version(def->version, EMBRA_GROUP_DEF_VERSION, "embra_group_def");
    embra::GroupDesc d;
    d.order = def->order;
    d.weight = def->weight;
    *out_group = from_id<embra_group_id>(world->world.create_group(d));
  });
}

embra_status embra_group_destroy(embra_world* world, embra_group_id group) {
  return guard("embra_group_destroy", world, [&] { world->world.destroy_group(to_id(group)); });
}

embra_status embra_group_set_order(embra_world* world, embra_group_id group, int32_t order) {
  return guard("embra_group_set_order", world, [&] { world->world.set_group_order(to_id(group), order); });
}

embra_status embra_group_set_weight(embra_world* world, embra_group_id group, int32_t weight) {
  return guard("embra_group_set_weight", world, [&] { world->world.set_group_weight(to_id(group), weight); });
}

embra_status embra_group_set_enabled(embra_world* world, embra_group_id group, int32_t enabled) {
  return guard("embra_group_set_enabled", world, [&] {
    need_flag(enabled, "enabled");
    world->world.set_group_enabled(to_id(group), enabled != 0);
  });
}

embra_status embra_group_get_enabled(const embra_world* world, embra_group_id group, int32_t* out_enabled) {
  return guard("embra_group_get_enabled", world, [&] {
    need(out_enabled, "out_enabled");
    *out_enabled = world->world.group(to_id(group)).desc.enabled ? 1 : 0;
  });
}

embra_status embra_world_default_group(const embra_world* world, embra_group_id* out_group) {
  return guard("embra_world_default_group", world, [&] {
    need(out_group, "out_group");
    *out_group = from_id<embra_group_id>(world->world.default_group());
  });
}

embra_status embra_world_contact_group(const embra_world* world, embra_group_id* out_group) {
  return guard("embra_world_contact_group", world, [&] {
    need(out_group, "out_group");
    *out_group = from_id<embra_group_id>(world->world.contact_group());
  });
}

embra_status embra_group_get_report(const embra_world* world, embra_group_id group, embra_group_report* out_report) {
  return guard("embra_group_get_report", world, [&] {
    need(out_report, "out_report");
    const embra::GroupReport& r = world->world.group(to_id(group)).report;
    *out_report = embra_group_report{r.count, r.residual_max, r.residual_rms};
  });
}

}  // extern "C"
