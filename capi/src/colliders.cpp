// Colliders: shapes, poses.
#include "copy.hpp"
#include "guard.hpp"

#include <cmath>

using namespace embra::capi;

// The C values cast to core enums here are pinned to them in enum_pins_generated.hpp.

namespace {
constexpr std::tuple kColliderCopies{
    Copy{&embra_collider_def::position, &embra::ColliderDesc::position},
    Copy{&embra_collider_def::radius, &embra::ColliderDesc::radius},
    Copy{&embra_collider_def::thickness, &embra::ColliderDesc::thickness},
    Copy{&embra_collider_def::friction_static, &embra::ColliderDesc::friction_static},
    Copy{&embra_collider_def::friction_dynamic, &embra::ColliderDesc::friction_dynamic},
    Copy{&embra_collider_def::half_extents, &embra::ColliderDesc::half_extents},
    Copy{&embra_collider_def::half_length, &embra::ColliderDesc::half_length}};
}  // namespace

extern "C" {

embra_collider_def embra_default_collider_def(void) {
  const embra::ColliderDesc c;
  embra_collider_def d{};
  d.version = EMBRA_COLLIDER_DEF_VERSION;
  d.shape = static_cast<int32_t>(c.shape);
  d.rotation[0] = c.rotation.w();
  d.rotation[1] = c.rotation.x();
  d.rotation[2] = c.rotation.y();
  d.rotation[3] = c.rotation.z();
  to_c(kColliderCopies, c, d);
  return d;
}

embra_status embra_collider_create(embra_world* world, const embra_collider_def* def, embra_collider_id* out_collider) {
  return guard("embra_collider_create", world, [&] {
    need(def, "def");
    need(out_collider, "out_collider");
    need_version(def->version, EMBRA_COLLIDER_DEF_VERSION, "embra_collider_def");
    // Core checks the radius of spheres only; a non-finite number is refused in every field.
    if (!std::isfinite(def->radius)) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.radius is not a finite number");
    if (!std::isfinite(def->half_length))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.half_length is not a finite number");
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(def->half_extents[k]))
        refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.half_extents is not a finite number");
    const bool points = def->shape == EMBRA_COLLIDER_CONVEX || def->shape == EMBRA_COLLIDER_MESH;
    const bool mesh = def->shape == EMBRA_COLLIDER_MESH;
    need_count(def->vertex_count, "def.vertex_count");
    need_count(def->triangle_count, "def.triangle_count");
    if (points && def->vertex_count > 0 && !def->vertices)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.vertices is NULL but def.vertex_count is " + num(def->vertex_count));
    if (mesh && def->triangle_count > 0 && !def->triangles)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT,
             "def.triangles is NULL but def.triangle_count is " + num(def->triangle_count));
    embra::ColliderDesc d;
    d.shape = static_cast<embra::ColliderShape>(def->shape);
    d.rotation = quat(def->rotation);
    to_core(kColliderCopies, *def, d);
    if (points) d.vertices.assign(def->vertices, def->vertices + 3 * static_cast<int64_t>(def->vertex_count));
    if (mesh) d.triangles.assign(def->triangles, def->triangles + 3 * static_cast<int64_t>(def->triangle_count));
    *out_collider = from_id<embra_collider_id>(world->world.create_collider(d));
  });
}

embra_status embra_collider_destroy(embra_world* world, embra_collider_id collider) {
  return guard("embra_collider_destroy", world, [&] {
    world->world.destroy_collider(to_id(collider));
    drop_actions(world->meta, embra::io::Action::Type::collider_pose, to_id(collider));
  });
}

embra_status embra_collider_set_transform(embra_world* world, embra_collider_id collider, const double position[3],
                                          const double rotation[4]) {
  return guard("embra_collider_set_transform", world, [&] {
    need(position, "position");
    need(rotation, "rotation");
    world->world.set_collider_transform(to_id(collider), vec(position), quat(rotation));
    drop_actions(world->meta, embra::io::Action::Type::collider_pose, to_id(collider));
  });
}

embra_status embra_collider_get_transform(const embra_world* world, embra_collider_id collider, double out_position[3],
                                          double out_rotation[4]) {
  return guard("embra_collider_get_transform", world, [&] {
    need(out_position, "out_position");
    need(out_rotation, "out_rotation");
    const embra::ColliderDesc& d = world->world.collider(to_id(collider)).desc;
    for (int k = 0; k < 3; ++k) out_position[k] = d.position[k];
    out_rotation[0] = d.rotation.w();
    out_rotation[1] = d.rotation.x();
    out_rotation[2] = d.rotation.y();
    out_rotation[3] = d.rotation.z();
  });
}

}  // extern "C"
