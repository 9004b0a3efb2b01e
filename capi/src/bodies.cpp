// Bodies: materials, creation from a mesh, particles, rest scale, triangles.
#include "copy.hpp"
#include "guard.hpp"

using namespace embra::capi;

static_assert(EMBRA_FRICTION_STRIBECK_SPEED == embra::kFrictionStribeckSpeed, "embra.h states the friction law");

// EMBRA_GENERATE_* flags are passed to the core as they are: each is pinned to its core flag.
static_assert(static_cast<uint32_t>(EMBRA_GENERATE_STRETCH) == embra::generate_stretch);
static_assert(static_cast<uint32_t>(EMBRA_GENERATE_SHEAR) == embra::generate_shear);
static_assert(static_cast<uint32_t>(EMBRA_GENERATE_BEND) == embra::generate_bend);
static_assert(static_cast<uint32_t>(EMBRA_GENERATE_VOLUME) == embra::generate_volume);

namespace {

constexpr std::tuple kMaterialCopies{Copy{&embra_material::mass, &embra::Material::mass},
                                     Copy{&embra_material::density, &embra::Material::density},
                                     Copy{&embra_material::stretch_compliance, &embra::Material::stretch_compliance},
                                     Copy{&embra_material::shear_compliance, &embra::Material::shear_compliance},
                                     Copy{&embra_material::bend_compliance, &embra::Material::bend_compliance},
                                     Copy{&embra_material::volume_compliance, &embra::Material::volume_compliance},
                                     Copy{&embra_material::damping, &embra::Material::damping},
                                     Copy{&embra_material::thickness, &embra::Material::thickness},
                                     Copy{&embra_material::friction_static, &embra::Material::friction_static},
                                     Copy{&embra_material::friction_dynamic, &embra::Material::friction_dynamic}};

embra::Material to_material(const embra_material& m) {
  embra::Material r;
  to_core(kMaterialCopies, m, r);
  return r;
}

}  // namespace

extern "C" {

embra_material embra_default_material(void) {
  embra_material r{};
  const embra::Material core;
  to_c(kMaterialCopies, core, r);
  return r;
}

embra_body_def embra_default_body_def(void) {
  embra_body_def d{};
  d.version = EMBRA_BODY_DEF_VERSION;
  d.generate = static_cast<int32_t>(embra::BodyDesc{}.generate);
  d.material = embra_default_material();
  return d;
}

embra_status embra_body_create(embra_world* world, const embra_body_def* def, embra_body_id* out_body,
                               int32_t* out_first_particle) {
  return guard("embra_body_create", world, [&] {
    need(def, "def");
    need(out_body, "out_body");
    need_version(def->version, EMBRA_BODY_DEF_VERSION, "embra_body_def");
    if (def->vertex_count <= 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.vertex_count must be > 0");
    need_count(def->edge_count, "def.edge_count");
    need_count(def->triangle_count, "def.triangle_count");
    need_count(def->tet_count, "def.tet_count");
    if (def->generate & ~0xF) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.generate has unknown flags");
    const int64_t n = def->vertex_count;
    embra::BodyDesc d;
    d.positions = view(def->positions, 3 * n, "def.positions");
    d.masses = def->masses ? std::span<const double>(def->masses, n) : std::span<const double>();
    d.uvs = def->uvs ? std::span<const double>(def->uvs, 2 * n) : std::span<const double>();
    d.edges = view(def->edges, 2 * static_cast<int64_t>(def->edge_count), "def.edges");
    d.triangles = view(def->triangles, 3 * static_cast<int64_t>(def->triangle_count), "def.triangles");
    d.tets = view(def->tets, 4 * static_cast<int64_t>(def->tet_count), "def.tets");
    d.material = to_material(def->material);
    d.generate = static_cast<uint32_t>(def->generate);
    d.stretch_group = to_id(def->stretch_group);
    d.shear_group = to_id(def->shear_group);
    d.bend_group = to_id(def->bend_group);
    d.volume_group = to_id(def->volume_group);
    const embra::Id id = world->world.create_body(d);
    *out_body = from_id<embra_body_id>(id);
    if (out_first_particle) *out_first_particle = world->world.body(id).first_particle;
  });
}

embra_status embra_body_get_particles(const embra_world* world, embra_body_id body, int32_t* out_first,
                                      int32_t* out_count) {
  return guard("embra_body_get_particles", world, [&] {
    need(out_first, "out_first");
    need(out_count, "out_count");
    const embra::BodyInfo& b = world->world.body(to_id(body));
    *out_first = b.first_particle;
    *out_count = b.particle_count;
  });
}

embra_status embra_body_set_rest_scale(embra_world* world, embra_body_id body, double scale, double scale_u,
                                       double scale_v) {
  return guard("embra_body_set_rest_scale", world, [&] {
    world->world.set_rest_scale(to_id(body), scale, scale_u, scale_v);
    drop_actions(world->meta, embra::io::Action::Type::rest_scale, to_id(body));
  });
}

embra_status embra_body_get_triangles(const embra_world* world, embra_body_id body, int32_t* out, int64_t capacity,
                                      int64_t* out_count) {
  return guard("embra_body_get_triangles", world, [&] {
    need(out_count, "out_count");
    const std::vector<int32_t>& t = world->world.body(to_id(body)).triangles;
    const int64_t n = static_cast<int64_t>(t.size());
    if (fits(out, capacity, n, "values")) std::copy(t.begin(), t.end(), out);
    *out_count = n;
  });
}

embra_status embra_body_set_material(embra_world* world, embra_body_id body, const embra_material* material) {
  return guard("embra_body_set_material", world, [&] {
    need(material, "material");
    world->world.set_material(to_id(body), to_material(*material));
  });
}

embra_status embra_body_get_material(const embra_world* world, embra_body_id body, embra_material* out_material) {
  return guard("embra_body_get_material", world, [&] {
    need(out_material, "out_material");
    embra_material m{};
    to_c(kMaterialCopies, world->world.body(to_id(body)).material, m);
    *out_material = m;
  });
}

embra_status embra_body_set_masses(embra_world* world, embra_body_id body, const double* masses, int32_t count) {
  return guard("embra_body_set_masses", world, [&] {
    need(masses, "masses");
    need_count(count, "count");
    world->world.set_masses(to_id(body), std::span<const double>(masses, static_cast<size_t>(count)));
  });
}

embra_status embra_body_get_masses(const embra_world* world, embra_body_id body, double* out, int32_t capacity,
                                   int32_t* out_count) {
  return guard("embra_body_get_masses", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<double>& m = world->world.body(to_id(body)).masses;
    const int32_t n = static_cast<int32_t>(m.size());
    if (fits(out, capacity, n, "masses")) std::copy(m.begin(), m.end(), out);
    *out_count = n;
  });
}

}  // extern "C"
