// Pins: hard or soft attachments of a particle to a target, and sliding supports (a pin that holds
// its particle on a plane or a line through the target, on a polyline or a triangle mesh, or some of
// its coordinates: a per-axis anchor).
#include "copy.hpp"
#include "guard.hpp"

#include "embra/core/limits.hpp"

using namespace embra::capi;

namespace {
constexpr std::tuple kPinCopies{Copy{&embra_pin_def::particle, &embra::PinDesc::particle},
                                Copy{&embra_pin_def::target, &embra::PinDesc::target},
                                Copy{&embra_pin_def::compliance, &embra::PinDesc::compliance}};
constexpr std::tuple kSupportCopies{Copy{&embra_support_def::particle, &embra::PinDesc::particle},
                                    Copy{&embra_support_def::target, &embra::PinDesc::target},
                                    Copy{&embra_support_def::axis, &embra::PinDesc::axis},
                                    Copy{&embra_support_def::compliance, &embra::PinDesc::compliance}};
}  // namespace

extern "C" {

embra_pin_def embra_default_pin_def(void) {
  embra_pin_def d{};
  d.version = EMBRA_PIN_DEF_VERSION;
  const embra::PinDesc core;
  to_c(kPinCopies, core, d);
  return d;
}

embra_status embra_pin_create(embra_world* world, const embra_pin_def* def, embra_pin_id* out_pin) {
  return guard("embra_pin_create", world, [&] {
    need(def, "def");
    need(out_pin, "out_pin");
    need_version(def->version, EMBRA_PIN_DEF_VERSION, "embra_pin_def");
    embra::PinDesc d;
    to_core(kPinCopies, *def, d);
    d.group = to_id(def->group);
    *out_pin = from_id<embra_pin_id>(world->world.create_pin(d));
  });
}

embra_support_def embra_default_support_def(void) {
  embra_support_def d{};
  d.version = EMBRA_SUPPORT_DEF_VERSION;
  embra::PinDesc core;
  core.support = embra::PinSupport::plane;
  to_c(kSupportCopies, core, d);
  d.support = static_cast<int32_t>(core.support);
  return d;
}

embra_status embra_support_create(embra_world* world, const embra_support_def* def, embra_pin_id* out_pin) {
  return guard("embra_support_create", world, [&] {
    need(def, "def");
    need(out_pin, "out_pin");
    need_version(def->version, EMBRA_SUPPORT_DEF_VERSION, "embra_support_def");
    if (def->support < 0 || def->support >= embra::kPinSupportCount)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "support " + num(def->support) + " is not an EMBRA_PIN_SUPPORT_* value");
    if (def->support == EMBRA_PIN_SUPPORT_POLYLINE)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT,
             "a polyline support is made by embra_polyline_support_create (its def carries the curve)");
    if (def->support == EMBRA_PIN_SUPPORT_MESH)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT,
             "a mesh support is made by embra_mesh_support_create (its def carries the mesh)");
    embra::PinDesc d;
    to_core(kSupportCopies, *def, d);
    d.support = static_cast<embra::PinSupport>(def->support);
    d.group = to_id(def->group);
    *out_pin = from_id<embra_pin_id>(world->world.create_pin(d));
  });
}

embra_polyline_support_def embra_default_polyline_support_def(void) {
  embra_polyline_support_def d{};
  d.version = EMBRA_POLYLINE_SUPPORT_DEF_VERSION;
  const embra::PinDesc core;
  for (int k = 0; k < 3; ++k) d.target[k] = core.target[k];
  d.compliance = core.compliance;
  return d;
}

embra_status embra_polyline_support_create(embra_world* world, const embra_polyline_support_def* def,
                                           embra_pin_id* out_pin) {
  return guard("embra_polyline_support_create", world, [&] {
    need(def, "def");
    need(out_pin, "out_pin");
    need_version(def->version, EMBRA_POLYLINE_SUPPORT_DEF_VERSION, "embra_polyline_support_def");
    need_flag(def->closed, "def.closed");
    if (def->point_count < 0 || def->point_count > embra::limits::kMaxParticles)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.point_count " + num(def->point_count) + " is out of range");
    const std::span<const double> xyz = view(def->points, 3 * static_cast<int64_t>(def->point_count), "def.points");
    embra::PinDesc d;
    d.particle = def->particle;
    d.target = vec(def->target);
    d.compliance = def->compliance;
    d.group = to_id(def->group);
    d.support = embra::PinSupport::polyline;
    d.curve.reserve(static_cast<size_t>(def->point_count));
    for (size_t i = 0; i + 2 < xyz.size(); i += 3) d.curve.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
    d.closed = def->closed == 1;
    *out_pin = from_id<embra_pin_id>(world->world.create_pin(d));
  });
}

embra_status embra_polyline_support_get_points(const embra_world* world, embra_pin_id pin, double* out_points,
                                               int32_t capacity, int32_t* out_count) {
  return guard("embra_polyline_support_get_points", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const embra::Pin& p = world->world.pin(to_id(pin));
    if (p.support != embra::PinSupport::polyline)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT,
             "pin " + num(static_cast<int64_t>(pin.index)) + " is not a polyline support");
    const int32_t n = static_cast<int32_t>(p.curve.size());
    if (fits(out_points, capacity, n, "polyline points"))
      for (int32_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) out_points[3 * i + k] = p.curve[static_cast<size_t>(i)][k];
    *out_count = n;
  });
}

embra_mesh_support_def embra_default_mesh_support_def(void) {
  embra_mesh_support_def d{};
  d.version = EMBRA_MESH_SUPPORT_DEF_VERSION;
  const embra::PinDesc core;
  for (int k = 0; k < 3; ++k) d.target[k] = core.target[k];
  d.compliance = core.compliance;
  return d;
}

embra_status embra_mesh_support_create(embra_world* world, const embra_mesh_support_def* def, embra_pin_id* out_pin) {
  return guard("embra_mesh_support_create", world, [&] {
    need(def, "def");
    need(out_pin, "out_pin");
    need_version(def->version, EMBRA_MESH_SUPPORT_DEF_VERSION, "embra_mesh_support_def");
    if (def->vertex_count < 0 || def->vertex_count > embra::limits::kMaxParticles)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.vertex_count " + num(def->vertex_count) + " is out of range");
    if (def->triangle_count < 0 || def->triangle_count > embra::limits::kMaxConstraints)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.triangle_count " + num(def->triangle_count) + " is out of range");
    const std::span<const double> xyz =
        view(def->vertices, 3 * static_cast<int64_t>(def->vertex_count), "def.vertices");
    const std::span<const int32_t> tri =
        view(def->triangles, 3 * static_cast<int64_t>(def->triangle_count), "def.triangles");
    embra::PinDesc d;
    d.particle = def->particle;
    d.target = vec(def->target);
    d.compliance = def->compliance;
    d.group = to_id(def->group);
    d.support = embra::PinSupport::mesh;
    d.curve.reserve(static_cast<size_t>(def->vertex_count));
    for (size_t i = 0; i + 2 < xyz.size(); i += 3) d.curve.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
    d.triangles.reserve(static_cast<size_t>(def->triangle_count));
    for (size_t i = 0; i + 2 < tri.size(); i += 3) d.triangles.push_back({tri[i], tri[i + 1], tri[i + 2]});
    *out_pin = from_id<embra_pin_id>(world->world.create_pin(d));
  });
}

embra_status embra_pin_destroy(embra_world* world, embra_pin_id pin) {
  return guard("embra_pin_destroy", world, [&] {
    world->world.destroy_pin(to_id(pin));
    drop_actions(world->meta, embra::io::Action::Type::pin_target, to_id(pin));
  });
}

embra_status embra_pin_set_target(embra_world* world, embra_pin_id pin, const double target[3]) {
  return guard("embra_pin_set_target", world, [&] {
    need(target, "target");
    world->world.set_pin_target(to_id(pin), vec(target));
    drop_actions(world->meta, embra::io::Action::Type::pin_target, to_id(pin));
  });
}

embra_status embra_pin_get_target(const embra_world* world, embra_pin_id pin, double out_target[3]) {
  return guard("embra_pin_get_target", world, [&] {
    need(out_target, "out_target");
    const embra::Vec3& t = world->world.pin(to_id(pin)).target;
    for (int k = 0; k < 3; ++k) out_target[k] = t[k];
  });
}

embra_status embra_pin_get_particle(const embra_world* world, embra_pin_id pin, int32_t* out_particle) {
  return guard("embra_pin_get_particle", world, [&] {
    need(out_particle, "out_particle");
    *out_particle = world->world.pin(to_id(pin)).particle;
  });
}

}  // extern "C"
