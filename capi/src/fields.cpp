// Force fields: wind, pressure, surface tension, vortex.
#include "copy.hpp"
#include "guard.hpp"

using namespace embra::capi;

namespace {

/// The body index a field def names: -1 for {0,0} when `optional`, else a live body (or refused).
int32_t field_body(const embra_world* world, embra_body_id body, bool optional, const char* def) {
  const embra::Id id = to_id(body);
  if (id.is_null()) {
    if (optional) return -1;
    refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(def) + ".body is {0,0}: this field needs a body");
  }
  world->world.body(id);  // stale: refused
  return static_cast<int32_t>(id.index);
}

constexpr std::tuple kWindCopies{Copy{&embra_wind_def::direction, &embra::WindDesc::direction},
                                 Copy{&embra_wind_def::speed, &embra::WindDesc::speed},
                                 Copy{&embra_wind_def::air_density, &embra::WindDesc::air_density},
                                 Copy{&embra_wind_def::drag, &embra::WindDesc::drag},
                                 Copy{&embra_wind_def::lift, &embra::WindDesc::lift}};

constexpr std::tuple kPressureCopies{
    Copy{&embra_pressure_def::keep_volume, &embra::PressureDesc::keep_volume},
    Copy{&embra_pressure_def::inside_pressure, &embra::PressureDesc::inside_pressure},
    Copy{&embra_pressure_def::outside_pressure, &embra::PressureDesc::outside_pressure},
    Copy{&embra_pressure_def::volume_compliance, &embra::PressureDesc::volume_compliance},
    Copy{&embra_pressure_def::rest_volume, &embra::PressureDesc::rest_volume}};

constexpr std::tuple kSurfaceTensionCopies{
    Copy{&embra_surface_tension_def::tension, &embra::SurfaceTensionDesc::tension},
    Copy{&embra_surface_tension_def::regularisation, &embra::SurfaceTensionDesc::regularisation}};

constexpr std::tuple kVortexCopies{Copy{&embra_vortex_def::center, &embra::VortexDesc::center},
                                   Copy{&embra_vortex_def::axis, &embra::VortexDesc::axis},
                                   Copy{&embra_vortex_def::strength, &embra::VortexDesc::strength},
                                   Copy{&embra_vortex_def::radius, &embra::VortexDesc::radius},
                                   Copy{&embra_vortex_def::twist, &embra::VortexDesc::twist},
                                   Copy{&embra_vortex_def::decay, &embra::VortexDesc::decay},
                                   Copy{&embra_vortex_def::start_time, &embra::VortexDesc::start_time}};

embra_field_id create_field(embra_world* world, const embra::FieldDesc& d) {
  return from_id<embra_field_id>(world->world.create_field(d));
}

/// A field's desc for an edit: kind and body as the def gives them (set_field refuses others).
template <class Def, class Sub, class Rows>
void set_field(embra_world* world, embra_field_id field, const Def* def, int32_t version, const char* name,
               embra::FieldKind kind, Sub embra::FieldDesc::*sub, const Rows& rows, bool body_optional) {
  need(def, "def");
  need_version(def->version, version, name);
  const embra::Field& f = world->world.field(to_id(field));
  if (f.desc.kind != kind) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("the field is not one ") + name + " sets");
  embra::FieldDesc d = f.desc;
  d.body = field_body(world, def->body, body_optional, name);
  to_core(rows, *def, d.*sub);
  world->world.set_field(to_id(field), d);
}

/// A field's def as its embra_*_get gives it.
template <class Def, class Sub, class Rows>
void get_field(const embra_world* world, embra_field_id field, Def* out, Def def, embra::FieldKind kind,
               Sub embra::FieldDesc::*sub, const Rows& rows, const char* name) {
  need(out, "out_def");
  const embra::Field& f = world->world.field(to_id(field));
  if (f.desc.kind != kind) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("the field is not one ") + name + " reads");
  def.body = f.desc.body < 0 ? embra_body_id{0, 0} : embra_body_id{static_cast<uint32_t>(f.desc.body), 1};
  to_c(rows, f.desc.*sub, def);
  *out = def;
}

}  // namespace

extern "C" {

embra_wind_def embra_default_wind_def(void) {
  embra_wind_def d{};
  d.version = EMBRA_WIND_DEF_VERSION;
  const embra::WindDesc core;
  to_c(kWindCopies, core, d);
  return d;
}

embra_status embra_wind_create(embra_world* world, const embra_wind_def* def, embra_field_id* out_field) {
  return guard("embra_wind_create", world, [&] {
    need(def, "def");
    need(out_field, "out_field");
    need_version(def->version, EMBRA_WIND_DEF_VERSION, "embra_wind_def");
    embra::FieldDesc d;
    d.kind = embra::FieldKind::wind;
    d.body = field_body(world, def->body, true, "embra_wind_def");
    to_core(kWindCopies, *def, d.wind);
    *out_field = create_field(world, d);
  });
}

embra_pressure_def embra_default_pressure_def(void) {
  embra_pressure_def d{};
  d.version = EMBRA_PRESSURE_DEF_VERSION;
  const embra::PressureDesc core;
  to_c(kPressureCopies, core, d);
  return d;
}

embra_status embra_pressure_create(embra_world* world, const embra_pressure_def* def, embra_field_id* out_field) {
  return guard("embra_pressure_create", world, [&] {
    need(def, "def");
    need(out_field, "out_field");
    need_version(def->version, EMBRA_PRESSURE_DEF_VERSION, "embra_pressure_def");
    embra::FieldDesc d;
    d.kind = embra::FieldKind::pressure;
    d.body = field_body(world, def->body, false, "embra_pressure_def");
    to_core(kPressureCopies, *def, d.pressure);
    *out_field = create_field(world, d);
  });
}

embra_surface_tension_def embra_default_surface_tension_def(void) {
  embra_surface_tension_def d{};
  d.version = EMBRA_SURFACE_TENSION_DEF_VERSION;
  const embra::SurfaceTensionDesc core;
  to_c(kSurfaceTensionCopies, core, d);
  return d;
}

embra_status embra_surface_tension_create(embra_world* world, const embra_surface_tension_def* def,
                                          embra_field_id* out_field) {
  return guard("embra_surface_tension_create", world, [&] {
    need(def, "def");
    need(out_field, "out_field");
    need_version(def->version, EMBRA_SURFACE_TENSION_DEF_VERSION, "embra_surface_tension_def");
    embra::FieldDesc d;
    d.kind = embra::FieldKind::surface_tension;
    d.body = field_body(world, def->body, false, "embra_surface_tension_def");
    to_core(kSurfaceTensionCopies, *def, d.surface_tension);
    *out_field = create_field(world, d);
  });
}

embra_vortex_def embra_default_vortex_def(void) {
  embra_vortex_def d{};
  d.version = EMBRA_VORTEX_DEF_VERSION;
  const embra::VortexDesc core;
  to_c(kVortexCopies, core, d);
  return d;
}

embra_status embra_vortex_create(embra_world* world, const embra_vortex_def* def, embra_field_id* out_field) {
  return guard("embra_vortex_create", world, [&] {
    need(def, "def");
    need(out_field, "out_field");
    need_version(def->version, EMBRA_VORTEX_DEF_VERSION, "embra_vortex_def");
    embra::FieldDesc d;
    d.kind = embra::FieldKind::vortex;
    d.body = field_body(world, def->body, true, "embra_vortex_def");
    to_core(kVortexCopies, *def, d.vortex);
    *out_field = create_field(world, d);
  });
}

embra_status embra_wind_set(embra_world* world, embra_field_id field, const embra_wind_def* def) {
  return guard("embra_wind_set", world, [&] {
    set_field(world, field, def, EMBRA_WIND_DEF_VERSION, "embra_wind_def", embra::FieldKind::wind,
              &embra::FieldDesc::wind, kWindCopies, true);
  });
}

embra_status embra_wind_get(const embra_world* world, embra_field_id field, embra_wind_def* out_def) {
  return guard("embra_wind_get", world, [&] {
    get_field(world, field, out_def, embra_default_wind_def(), embra::FieldKind::wind, &embra::FieldDesc::wind,
              kWindCopies, "embra_wind_def");
  });
}

embra_status embra_pressure_set(embra_world* world, embra_field_id field, const embra_pressure_def* def) {
  return guard("embra_pressure_set", world, [&] {
    set_field(world, field, def, EMBRA_PRESSURE_DEF_VERSION, "embra_pressure_def", embra::FieldKind::pressure,
              &embra::FieldDesc::pressure, kPressureCopies, false);
  });
}

embra_status embra_pressure_get(const embra_world* world, embra_field_id field, embra_pressure_def* out_def) {
  return guard("embra_pressure_get", world, [&] {
    get_field(world, field, out_def, embra_default_pressure_def(), embra::FieldKind::pressure,
              &embra::FieldDesc::pressure, kPressureCopies, "embra_pressure_def");
  });
}

embra_status embra_surface_tension_set(embra_world* world, embra_field_id field, const embra_surface_tension_def* def) {
  return guard("embra_surface_tension_set", world, [&] {
    set_field(world, field, def, EMBRA_SURFACE_TENSION_DEF_VERSION, "embra_surface_tension_def",
              embra::FieldKind::surface_tension, &embra::FieldDesc::surface_tension, kSurfaceTensionCopies, false);
  });
}

embra_status embra_surface_tension_get(const embra_world* world, embra_field_id field,
                                       embra_surface_tension_def* out_def) {
  return guard("embra_surface_tension_get", world, [&] {
    get_field(world, field, out_def, embra_default_surface_tension_def(), embra::FieldKind::surface_tension,
              &embra::FieldDesc::surface_tension, kSurfaceTensionCopies, "embra_surface_tension_def");
  });
}

embra_status embra_vortex_set(embra_world* world, embra_field_id field, const embra_vortex_def* def) {
  return guard("embra_vortex_set", world, [&] {
    set_field(world, field, def, EMBRA_VORTEX_DEF_VERSION, "embra_vortex_def", embra::FieldKind::vortex,
              &embra::FieldDesc::vortex, kVortexCopies, true);
  });
}

embra_status embra_vortex_get(const embra_world* world, embra_field_id field, embra_vortex_def* out_def) {
  return guard("embra_vortex_get", world, [&] {
    get_field(world, field, out_def, embra_default_vortex_def(), embra::FieldKind::vortex, &embra::FieldDesc::vortex,
              kVortexCopies, "embra_vortex_def");
  });
}

embra_status embra_field_destroy(embra_world* world, embra_field_id field) {
  return guard("embra_field_destroy", world, [&] {
    world->world.destroy_field(to_id(field));
    world->meta.field_names.erase(field.index);
  });
}

embra_status embra_world_get_field_count(const embra_world* world, int32_t* out_count) {
  return guard("embra_world_get_field_count", world, [&] {
    need(out_count, "out_count");
    *out_count = static_cast<int32_t>(world->world.field_count());
  });
}

}  // extern "C"
