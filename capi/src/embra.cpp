// The C ABI over embra::World. Every exported function runs inside guard(): exceptions become a
// status code and a thread-local message; nothing unwinds into the host.
#include "embra/embra.h"

#include "embra/core/limits.hpp"
#include "embra/core/panels.hpp"
#include "embra/core/world.hpp"
#include "embra/io/scene.hpp"

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <vector>

struct embra_world {
  embra::World world;
  embra::io::SceneMeta meta;  // names, actions and tolerances of a scene; empty for an API-built world
  /// Held by the call in progress (guard): a second concurrent call gets EMBRA_ERROR_LOCKED.
  mutable std::atomic<bool> busy{false};
  /// embra_world_cancel: set by any thread, consumed by the step that sees it.
  std::atomic<bool> cancel{false};
};

namespace {

thread_local std::string g_last_error;

/// Decimal text of an integer. Not std::to_string: its libstdc++ implementation has function-local
/// statics of default visibility (std::__detail::__to_chars_10_impl<...>::__digits) that would be
/// exported from libembra.so beside the embra_ functions.
std::string num(int64_t value) {
  char text[24];
  std::snprintf(text, sizeof text, "%lld", static_cast<long long>(value));
  return text;
}

struct Refused {
  embra_status status;
  std::string message;
};

[[noreturn]] void refuse(embra_status status, const std::string& message) {
  throw Refused{status, message};
}

embra_status map(embra::ErrorCode code) {
  switch (code) {
    case embra::ErrorCode::invalid_argument:
      return EMBRA_ERROR_INVALID_ARGUMENT;
    case embra::ErrorCode::stale_id:
      return EMBRA_ERROR_STALE_ID;
    case embra::ErrorCode::buffer_too_small:
      return EMBRA_ERROR_BUFFER_TOO_SMALL;
    case embra::ErrorCode::numerical:
      return EMBRA_ERROR_NUMERICAL;
    case embra::ErrorCode::internal:
      return EMBRA_ERROR_INTERNAL;
    case embra::ErrorCode::cancelled:
      return EMBRA_ERROR_CANCELLED;
  }
  return EMBRA_ERROR_INTERNAL;
}

/// Runs `body`, turning every exception into a status and the thread's last-error message.
template <class F>
embra_status guard(const char* function, F&& body) noexcept {
  try {
    body();
    return EMBRA_OK;
  } catch (const Refused& r) {
    g_last_error = std::string(function) + ": " + r.message;
    return r.status;
  } catch (const embra::io::SceneError& e) {
    g_last_error = std::string(function) + ": " + e.what();
    return EMBRA_ERROR_SCHEMA;
  } catch (const embra::Error& e) {
    g_last_error = std::string(function) + ": " + e.what();
    return map(e.code());
  } catch (const std::bad_alloc&) {
    g_last_error = std::string(function) + ": out of memory";
    return EMBRA_ERROR_INTERNAL;
  } catch (const std::exception& e) {
    g_last_error = std::string(function) + ": internal error: " + e.what();
    return EMBRA_ERROR_INTERNAL;
  } catch (...) {
    g_last_error = std::string(function) + ": internal error";
    return EMBRA_ERROR_INTERNAL;
  }
}

template <class T>
void need(const T* p, const char* name) {
  if (p == nullptr) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(name) + " is NULL");
}

/// One call at a time on a world: held for the call's duration, refused (never waited for) when
/// another call holds it.
class WorldLock {
 public:
  explicit WorldLock(const embra_world& world) : busy_(world.busy) {
    if (busy_.exchange(true, std::memory_order_acquire))
      refuse(EMBRA_ERROR_LOCKED, "the world is in use by a call in progress on another thread (one call at a time)");
  }
  ~WorldLock() { busy_.store(false, std::memory_order_release); }
  WorldLock(const WorldLock&) = delete;
  WorldLock& operator=(const WorldLock&) = delete;

 private:
  std::atomic<bool>& busy_;
};

/// guard() for a call on a world: the world must be non-null and not in use by another call.
template <class W, class F>
embra_status guard(const char* function, W* world, F&& body) noexcept {
  return guard(function, [&] {
    need(world, "world");
    const WorldLock lock(*world);
    body();
  });
}

void need_version(int32_t got, int32_t want, const char* def) {
  if (got != want)
    refuse(EMBRA_ERROR_VERSION, std::string(def) + ".version is " + num(got) + ", this library reads " + num(want) +
                                    " (start from its embra_default_ function)");
}

void need_count(int64_t count, const char* name) {
  if (count < 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(name) + " is negative");
}

template <class T>
std::span<const T> view(const T* p, int64_t n, const char* name) {
  if (n == 0) return {};
  need(p, name);
  return {p, static_cast<size_t>(n)};
}

template <class T>
embra::Id to_id(T id) {
  return embra::Id{id.index, id.generation};
}
template <class T>
T from_id(embra::Id id) {
  return T{id.index, id.generation};
}

/// A scene action that drives a destroyed pin or collider goes with it.
void drop_actions(embra::io::SceneMeta& meta, embra::io::Action::Type type, embra::Id id) {
  std::erase_if(meta.actions, [&](const embra::io::Action& a) { return a.type == type && a.target == id; });
}

embra::Vec3 vec(const double* p) {
  return embra::Vec3(p[0], p[1], p[2]);
}

embra::Settings to_settings(const embra_solver_def& d) {
  embra::Settings s;
  s.dt = d.dt;
  s.substeps = d.substeps;
  s.iterations = d.iterations;
  s.gravity = vec(d.gravity);
  s.damping = d.damping;
  s.settle_speed = d.settle_speed;
  s.tethers = d.tethers;
  s.realign_passes = d.realign_passes;
  s.chebyshev_rho_milli = d.chebyshev_rho_milli;
  s.self_collision = d.self_collision;
  s.chain_solve = d.chain_solve;
  return s;
}

embra_solver_def from_settings(const embra::Settings& s) {
  embra_solver_def d{};
  d.version = EMBRA_SOLVER_DEF_VERSION;
  d.substeps = s.substeps;
  d.dt = s.dt;
  d.iterations = s.iterations;
  for (int k = 0; k < 3; ++k) d.gravity[k] = s.gravity[k];
  d.damping = s.damping;
  d.settle_speed = s.settle_speed;
  d.tethers = s.tethers;
  d.realign_passes = s.realign_passes;
  d.chebyshev_rho_milli = s.chebyshev_rho_milli;
  d.self_collision = s.self_collision;
  d.chain_solve = s.chain_solve;
  return d;
}

embra::Material to_material(const embra_material& m) {
  embra::Material r;
  r.mass = m.mass;
  r.density = m.density;
  r.stretch_compliance = m.stretch_compliance;
  r.shear_compliance = m.shear_compliance;
  r.bend_compliance = m.bend_compliance;
  r.volume_compliance = m.volume_compliance;
  r.damping = m.damping;
  r.thickness = m.thickness;
  r.friction_static = m.friction_static;
  r.friction_dynamic = m.friction_dynamic;
  return r;
}

void read_range(const embra::World& w, int64_t capacity, int32_t first, int32_t count, const double* out) {
  need(out, "out_xyz");
  if (first < 0 || count < 0 || static_cast<int64_t>(first) + count > w.particle_count())
    refuse(EMBRA_ERROR_INVALID_ARGUMENT, "particle range [" + num(first) + ", " +
                                             num(static_cast<int64_t>(first) + count) + ") is outside [0, " +
                                             num(w.particle_count()) + ")");
  if (capacity < 3 * static_cast<int64_t>(count))
    refuse(EMBRA_ERROR_BUFFER_TOO_SMALL,
           "buffer holds " + num(capacity) + " doubles, " + num(3 * static_cast<int64_t>(count)) + " needed");
}

/// The two-call id listing of embra_world_get_bodies/groups/pins/colliders: of `slots` slots, the
/// live ones (`generation(i)` nonzero) as {slot index, generation}, in slot order (creation order).
template <class IdT, class Generation>
void list_ids(size_t slots, Generation generation, IdT* out, int32_t capacity, int32_t* out_count) {
  need(out_count, "out_count");
  if (capacity < 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "capacity is negative");
  int32_t n = 0;
  for (size_t i = 0; i < slots; ++i) n += generation(i) != 0 ? 1 : 0;
  if (out == nullptr && capacity == 0) {
    *out_count = n;
    return;
  }
  need(out, "out");
  if (capacity < n)
    refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " ids, " + num(n) + " needed");
  int32_t k = 0;
  for (size_t i = 0; i < slots; ++i)
    if (const uint32_t g = generation(i); g != 0) out[k++] = IdT{static_cast<uint32_t>(i), g};
  *out_count = n;
}

/// A slot's generation if it is alive, else 0.
template <class T>
auto live_generation(const std::vector<T>& slots) {
  return [&slots](size_t i) { return slots[i].alive ? slots[i].generation : 0u; };
}

}  // namespace

// The header's numbers are the core's (limits.hpp): a drift is a compile error.
static_assert(EMBRA_MAX_ABS_VALUE == embra::limits::kMaxAbsValue);
static_assert(EMBRA_MIN_POSITIVE == embra::limits::kMinPositive);
static_assert(EMBRA_MAX_DT == embra::limits::kMaxDt);
static_assert(EMBRA_MAX_UNIT_SCALE == embra::limits::kMaxUnitScale);
static_assert(EMBRA_MAX_PARTICLES == embra::limits::kMaxParticles);
static_assert(EMBRA_MAX_CONSTRAINTS == embra::limits::kMaxConstraints);
static_assert(EMBRA_MAX_PASSES_PER_STEP == embra::limits::kMaxPassesPerStep);
static_assert(EMBRA_MAX_OBJ_BYTES == embra::limits::kMaxObjBytes);

extern "C" {

const char* embra_last_error_message(void) {
  return g_last_error.c_str();
}

const char* embra_status_name(embra_status status) {
  switch (status) {
    case EMBRA_OK:
      return "EMBRA_OK";
    case EMBRA_ERROR_INVALID_ARGUMENT:
      return "EMBRA_ERROR_INVALID_ARGUMENT";
    case EMBRA_ERROR_STALE_ID:
      return "EMBRA_ERROR_STALE_ID";
    case EMBRA_ERROR_BUFFER_TOO_SMALL:
      return "EMBRA_ERROR_BUFFER_TOO_SMALL";
    case EMBRA_ERROR_SCHEMA:
      return "EMBRA_ERROR_SCHEMA";
    case EMBRA_ERROR_VERSION:
      return "EMBRA_ERROR_VERSION";
    case EMBRA_ERROR_LOCKED:
      return "EMBRA_ERROR_LOCKED";
    case EMBRA_ERROR_NUMERICAL:
      return "EMBRA_ERROR_NUMERICAL";
    case EMBRA_ERROR_INTERNAL:
      return "EMBRA_ERROR_INTERNAL";
    case EMBRA_ERROR_CANCELLED:
      return "EMBRA_ERROR_CANCELLED";
    default:
      return "EMBRA_UNKNOWN_STATUS";
  }
}

int32_t embra_version(void) {
  return EMBRA_VERSION_MAJOR * 10000 + EMBRA_VERSION_MINOR * 100 + EMBRA_VERSION_PATCH;
}
const char* embra_version_string(void) {
  return EMBRA_VERSION_STRING;
}
int32_t embra_abi_version(void) {
  return EMBRA_ABI_VERSION;
}

embra_status embra_check_abi(int32_t header_abi_version) {
  return guard("embra_check_abi", [&] {
    if (header_abi_version != EMBRA_ABI_VERSION)
      refuse(EMBRA_ERROR_VERSION, "the host was compiled against ABI " + num(header_abi_version) +
                                      ", this library is ABI " + num(EMBRA_ABI_VERSION));
  });
}

// --- world -------------------------------------------------------------------------------------

embra_solver_def embra_default_solver_def(void) {
  return from_settings(embra::Settings());
}

embra_status embra_world_create(embra_world** out_world, const embra_solver_def* def) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_create", [&] {
    need(out_world, "out_world");
    const embra_solver_def d = def ? *def : embra_default_solver_def();
    need_version(d.version, EMBRA_SOLVER_DEF_VERSION, "embra_solver_def");
    *out_world = new embra_world{embra::World(to_settings(d)), {}};
  });
}

void embra_world_destroy(embra_world* world) {
  if (world == nullptr) return;
  // A call still running on another thread finishes first (destroying under it would free what it
  // uses); later calls with this pointer are the host's use after free.
  while (world->busy.exchange(true, std::memory_order_acquire)) std::this_thread::yield();
  delete world;
}

embra_status embra_world_get_solver(const embra_world* world, embra_solver_def* out_def) {
  return guard("embra_world_get_solver", world, [&] {
    need(out_def, "out_def");
    const embra_solver_def d = from_settings(world->world.settings());
    *out_def = d;
  });
}

embra_status embra_world_set_solver(embra_world* world, const embra_solver_def* def) {
  return guard("embra_world_set_solver", world, [&] {
    need(def, "def");
    need_version(def->version, EMBRA_SOLVER_DEF_VERSION, "embra_solver_def");
    world->world.set_settings(to_settings(*def));
  });
}

embra_status embra_world_set_gravity(embra_world* world, const double gravity[3]) {
  return guard("embra_world_set_gravity", world, [&] {
    need(gravity, "gravity");
    world->world.set_gravity(vec(gravity));
    drop_actions(world->meta, embra::io::Action::Type::gravity, embra::Id{});
  });
}

embra_status embra_world_get_counts(const embra_world* world, embra_world_counts* out_counts) {
  return guard("embra_world_get_counts", world, [&] {
    need(out_counts, "out_counts");
    const embra::World& w = world->world;
    embra_world_counts c{};
    c.particles = w.particle_count();
    c.bodies = static_cast<int32_t>(w.body_count());
    c.groups = static_cast<int32_t>(w.group_count());
    c.pins = static_cast<int32_t>(w.pin_count());
    c.colliders = static_cast<int32_t>(w.collider_count());
    c.constraints = w.constraint_count();
    *out_counts = c;
  });
}

embra_status embra_world_get_bodies(const embra_world* world, embra_body_id* out, int32_t capacity,
                                    int32_t* out_count) {
  return guard("embra_world_get_bodies", world, [&] {
    // Bodies are never destroyed: each keeps generation 1.
    list_ids(
        world->world.body_count(), [](size_t) { return 1u; }, out, capacity, out_count);
  });
}

embra_status embra_world_get_groups(const embra_world* world, embra_group_id* out, int32_t capacity,
                                    int32_t* out_count) {
  return guard("embra_world_get_groups", world, [&] {
    list_ids(world->world.groups().size(), live_generation(world->world.groups()), out, capacity, out_count);
  });
}

embra_status embra_world_get_pins(const embra_world* world, embra_pin_id* out, int32_t capacity, int32_t* out_count) {
  return guard("embra_world_get_pins", world, [&] {
    list_ids(world->world.pins().size(), live_generation(world->world.pins()), out, capacity, out_count);
  });
}

embra_status embra_world_get_colliders(const embra_world* world, embra_collider_id* out, int32_t capacity,
                                       int32_t* out_count) {
  return guard("embra_world_get_colliders", world, [&] {
    list_ids(world->world.colliders().size(), live_generation(world->world.colliders()), out, capacity, out_count);
  });
}

// --- groups ------------------------------------------------------------------------------------

embra_group_def embra_default_group_def(void) {
  embra_group_def d{};
  d.version = EMBRA_GROUP_DEF_VERSION;
  d.order = 0;
  d.weight = 1;
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

// --- bodies ------------------------------------------------------------------------------------

embra_material embra_default_material(void) {
  const embra::Material m;
  embra_material r{};
  r.mass = m.mass;
  r.density = m.density;
  r.stretch_compliance = m.stretch_compliance;
  r.shear_compliance = m.shear_compliance;
  r.bend_compliance = m.bend_compliance;
  r.volume_compliance = m.volume_compliance;
  r.damping = m.damping;
  r.thickness = m.thickness;
  r.friction_static = m.friction_static;
  r.friction_dynamic = m.friction_dynamic;
  return r;
}

embra_body_def embra_default_body_def(void) {
  embra_body_def d{};
  d.version = EMBRA_BODY_DEF_VERSION;
  d.generate = EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_BEND | EMBRA_GENERATE_VOLUME;
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

// --- constraints -------------------------------------------------------------------------------

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
    if (def->rest_from_current != 0 && def->rest_from_current != 1)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.rest_from_current must be 0 or 1");
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

// --- pins --------------------------------------------------------------------------------------

embra_pin_def embra_default_pin_def(void) {
  embra_pin_def d{};
  d.version = EMBRA_PIN_DEF_VERSION;
  return d;
}

embra_status embra_pin_create(embra_world* world, const embra_pin_def* def, embra_pin_id* out_pin) {
  return guard("embra_pin_create", world, [&] {
    need(def, "def");
    need(out_pin, "out_pin");
    need_version(def->version, EMBRA_PIN_DEF_VERSION, "embra_pin_def");
    embra::PinDesc d;
    d.particle = def->particle;
    d.target = vec(def->target);
    d.compliance = def->compliance;
    d.group = to_id(def->group);
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

// --- colliders ---------------------------------------------------------------------------------

embra_collider_def embra_default_collider_def(void) {
  const embra::ColliderDesc c;
  embra_collider_def d{};
  d.version = EMBRA_COLLIDER_DEF_VERSION;
  d.shape = EMBRA_COLLIDER_PLANE;
  d.rotation[0] = 1.0;
  d.radius = c.radius;
  d.thickness = c.thickness;
  d.friction_static = c.friction_static;
  d.friction_dynamic = c.friction_dynamic;
  for (int k = 0; k < 3; ++k) d.half_extents[k] = c.half_extents[k];
  d.half_length = c.half_length;
  return d;
}

}  // extern "C"

namespace {
Eigen::Quaterniond quat(const double* wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}
}  // namespace

extern "C" {

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
    if (def->vertex_count < 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.vertex_count is negative");
    if (def->triangle_count < 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.triangle_count is negative");
    if (points && def->vertex_count > 0 && !def->vertices)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.vertices is NULL but def.vertex_count is " + num(def->vertex_count));
    if (mesh && def->triangle_count > 0 && !def->triangles)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT,
             "def.triangles is NULL but def.triangle_count is " + num(def->triangle_count));
    embra::ColliderDesc d;
    d.shape = static_cast<embra::ColliderShape>(def->shape);
    d.position = vec(def->position);
    d.rotation = quat(def->rotation);
    d.radius = def->radius;
    d.thickness = def->thickness;
    d.friction_static = def->friction_static;
    d.friction_dynamic = def->friction_dynamic;
    d.half_extents = vec(def->half_extents);
    d.half_length = def->half_length;
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

// --- stepping ----------------------------------------------------------------------------------

embra_status embra_world_step(embra_world* world) {
  const embra_status status = guard("embra_world_step", world, [&] {
    embra::StepControl control;
    if (!world->meta.actions.empty())
      control.before_frame = [world](embra::World& w) {
        embra::io::apply_actions(w, world->meta, w.report().frame + 1);
      };
    control.cancel = &world->cancel;
    world->world.step(control);
  });
  if (status == EMBRA_ERROR_CANCELLED) world->cancel.store(false, std::memory_order_relaxed);
  return status;
}

embra_status embra_world_cancel(embra_world* world) {
  return guard("embra_world_cancel", [&] {
    need(world, "world");
    world->cancel.store(true, std::memory_order_relaxed);
  });
}

embra_status embra_world_get_report(const embra_world* world, embra_step_report* out_report) {
  return guard("embra_world_get_report", world, [&] {
    need(out_report, "out_report");
    const embra::StepReport& r = world->world.report();
    embra_step_report o{};
    o.frame = r.frame;
    o.time = r.time;
    o.kinetic_energy = r.kinetic_energy;
    o.max_speed = r.max_speed;
    o.residual_max = r.residual_max;
    o.residual_rms = r.residual_rms;
    o.constraint_count = r.constraint_count;
    o.contact_count = r.contact_count;
    o.settled = r.settled ? 1 : 0;
    *out_report = o;
  });
}

embra_status embra_world_get_warning(const embra_world* world, embra_warning* out_warning) {
  return guard("embra_world_get_warning", world, [&] {
    need(out_warning, "out_warning");
    const embra::Warning& w = world->world.warning();
    *out_warning = embra_warning{w.frame, w.particle, 0};
  });
}

embra_status embra_world_get_positions(const embra_world* world, double* out_xyz, int64_t capacity, int32_t first,
                                       int32_t count) {
  return guard("embra_world_get_positions", world, [&] {
    read_range(world->world, capacity, first, count, out_xyz);
    const auto& x = world->world.positions();
    for (int32_t i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k) out_xyz[3 * i + k] = x[first + i][k];
  });
}

embra_status embra_world_get_velocities(const embra_world* world, double* out_xyz, int64_t capacity, int32_t first,
                                        int32_t count) {
  return guard("embra_world_get_velocities", world, [&] {
    read_range(world->world, capacity, first, count, out_xyz);
    const auto& v = world->world.velocities();
    for (int32_t i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k) out_xyz[3 * i + k] = v[first + i][k];
  });
}

embra_status embra_world_set_positions(embra_world* world, const double* xyz, int32_t first, int32_t count) {
  return guard("embra_world_set_positions", world, [&] {
    need_count(count, "count");
    world->world.set_positions(first, view(xyz, 3 * static_cast<int64_t>(count), "xyz"));
  });
}

embra_status embra_world_set_velocities(embra_world* world, const double* xyz, int32_t first, int32_t count) {
  return guard("embra_world_set_velocities", world, [&] {
    need_count(count, "count");
    world->world.set_velocities(first, view(xyz, 3 * static_cast<int64_t>(count), "xyz"));
  });
}

// --- geometry queries ---------------------------------------------------------------------------

embra_status embra_body_get_triangles(const embra_world* world, embra_body_id body, int32_t* out, int64_t capacity,
                                      int64_t* out_count) {
  return guard("embra_body_get_triangles", world, [&] {
    need(out_count, "out_count");
    const std::vector<int32_t>& t = world->world.body(to_id(body)).triangles;
    const int64_t n = static_cast<int64_t>(t.size());
    if (out == nullptr && capacity == 0) {
      *out_count = n;
      return;
    }
    need(out, "out");
    if (capacity < n)
      refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " values, " + num(n) + " needed");
    std::copy(t.begin(), t.end(), out);
    *out_count = n;
  });
}

// --- panel meshes ----------------------------------------------------------------------------

embra_panel_mesh_def embra_default_panel_mesh_def(void) {
  embra_panel_mesh_def d{};
  d.version = EMBRA_PANEL_MESH_DEF_VERSION;
  d.grid_columns = 4;
  d.grid_rows = 4;
  d.pins = EMBRA_PANEL_PINS_NONE;
  d.panel_size = 0.8;
  d.thickness = 0.01;
  d.density = 1.0;
  d.friction_static = 0.5;
  d.friction_dynamic = 0.3;
  d.slide_compliance = 1e-3;
  return d;
}

embra_status embra_panel_mesh_create(embra_world* world, const embra_panel_mesh_def* def, embra_body_id* out_body,
                                     int32_t* out_first_particle) {
  return guard("embra_panel_mesh_create", world, [&] {
    need(def, "def");
    need(out_body, "out_body");
    need_version(def->version, EMBRA_PANEL_MESH_DEF_VERSION, "embra_panel_mesh_def");
    need_count(def->vertex_count, "def.vertex_count");
    std::vector<double> grid_positions;
    std::vector<int32_t> grid_quads;
    embra::PanelMeshDesc d;
    if (def->vertex_count == 0) {
      if (def->quad_count != 0)
        refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.quad_count must be 0 for a grid (vertex_count 0)");
      embra::panel_grid(def->grid_columns, def->grid_rows, def->panel_size,
                        embra::Vec3(def->origin[0], def->origin[1], def->origin[2]), grid_positions, grid_quads);
      d.positions = grid_positions;
      d.quads = grid_quads;
    } else {
      if (def->quad_count <= 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.quad_count must be > 0");
      d.positions = view(def->positions, 3 * static_cast<int64_t>(def->vertex_count), "def.positions");
      d.quads = view(def->quads, 4 * static_cast<int64_t>(def->quad_count), "def.quads");
    }
    d.thickness = def->thickness;
    d.mass = def->mass;
    d.density = def->density;
    d.damping = def->damping;
    d.friction_static = def->friction_static;
    d.friction_dynamic = def->friction_dynamic;
    d.slide_compliance = def->slide_compliance;
    d.pins = static_cast<embra::PanelPins>(def->pins);
    d.group = to_id(def->group);
    const embra::Id id = embra::build_panel_mesh(world->world, d);
    *out_body = from_id<embra_body_id>(id);
    if (out_first_particle) *out_first_particle = world->world.body(id).first_particle;
  });
}

}  // extern "C"

namespace {
const embra::PanelLayout& layout_of(const embra_world* world, embra_body_id body) {
  world->world.body(to_id(body));  // stale ids: EMBRA_ERROR_STALE_ID
  const embra::PanelLayout* l = world->world.panel_layout(to_id(body));
  if (l == nullptr) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "the body is not a panel mesh");
  return *l;
}

embra::Tolerances to_tolerances(const embra_tolerances& t) {
  embra::Tolerances o;
  o.unit_scale = t.unit_scale;
  o.planarity = {t.planarity.target, t.planarity.max};
  o.planarity_distance = {t.planarity_distance.target, t.planarity_distance.max};
  o.thickness = {t.thickness.target, t.thickness.max};
  o.miter = {t.miter.target, t.miter.max};
  return o;
}

embra_tolerances from_tolerances(const embra::Tolerances& t) {
  embra_tolerances o{};
  o.version = EMBRA_TOLERANCES_VERSION;
  o.unit_scale = t.unit_scale;
  o.planarity = {t.planarity.target, t.planarity.max};
  o.planarity_distance = {t.planarity_distance.target, t.planarity_distance.max};
  o.thickness = {t.thickness.target, t.thickness.max};
  o.miter = {t.miter.target, t.miter.max};
  return o;
}

void check_tolerances(const embra_tolerances& t) {
  need_version(t.version, EMBRA_TOLERANCES_VERSION, "embra_tolerances");
  if (!(t.unit_scale >= embra::limits::kMinPositive && t.unit_scale <= embra::limits::kMaxUnitScale))
    refuse(EMBRA_ERROR_INVALID_ARGUMENT, "tolerances.unit_scale must be in [1e-300, 1e12]");
  const std::pair<const char*, embra_tolerance> all[] = {{"planarity", t.planarity},
                                                         {"planarity_distance", t.planarity_distance},
                                                         {"thickness", t.thickness},
                                                         {"miter", t.miter}};
  for (const auto& [name, v] : all) {
    if (!(v.target >= 0.0 && v.target <= embra::limits::kMaxAbsValue && v.max >= 0.0 &&
          v.max <= embra::limits::kMaxAbsValue))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("tolerances.") + name + " must be finite and in [0, 1e300]");
    if (v.target > v.max)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("tolerances.") + name + ".target is above its max");
  }
}

embra_metric_summary from_summary(const embra::MetricSummary& m) {
  return embra_metric_summary{m.max, m.rms, m.count, m.within_target, m.within_max, m.above_max};
}

void write_text(const std::string& text, char* out, int64_t capacity, int64_t* out_length) {
  const int64_t n = static_cast<int64_t>(text.size()) + 1;
  if (out == nullptr && capacity == 0) {
    *out_length = n;
    return;
  }
  need(out, "out");
  if (capacity < n) {
    *out_length = n;
    refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " bytes, " + num(n) + " needed");
  }
  std::memcpy(out, text.c_str(), static_cast<size_t>(n));
  *out_length = n;
}
}  // namespace

extern "C" {

embra_status embra_panel_mesh_get_panel_count(const embra_world* world, embra_body_id body, int32_t* out_count) {
  return guard("embra_panel_mesh_get_panel_count", world, [&] {
    need(out_count, "out_count");
    *out_count = layout_of(world, body).panel_count();
  });
}

embra_tolerances embra_default_tolerances(void) {
  return from_tolerances(embra::Tolerances{});
}

embra_status embra_world_get_tolerances(const embra_world* world, embra_tolerances* out_tolerances) {
  return guard("embra_world_get_tolerances", world, [&] {
    need(out_tolerances, "out_tolerances");
    *out_tolerances = from_tolerances(embra::io::parse_tolerances(world->meta.tolerances));
  });
}

embra_status embra_world_set_tolerances(embra_world* world, const embra_tolerances* tolerances) {
  return guard("embra_world_set_tolerances", world, [&] {
    need(tolerances, "tolerances");
    check_tolerances(*tolerances);
    world->meta.tolerances = embra::io::tolerances_json(to_tolerances(*tolerances));
  });
}

embra_status embra_panel_mesh_get_metrics(const embra_world* world, embra_body_id body,
                                          const embra_tolerances* tolerances, embra_panel_metrics* out_metrics) {
  return guard("embra_panel_mesh_get_metrics", world, [&] {
    need(out_metrics, "out_metrics");
    const embra::PanelLayout& l = layout_of(world, body);
    embra::Tolerances t;
    if (tolerances) {
      check_tolerances(*tolerances);
      t = to_tolerances(*tolerances);
    } else {
      t = embra::io::parse_tolerances(world->meta.tolerances);
    }
    const embra::PanelReport r = embra::report_panels(embra::measure_panels(l, world->world.positions()), t);
    embra_panel_metrics m{};
    m.version = EMBRA_PANEL_METRICS_VERSION;
    m.within_tolerance = r.within_tolerance ? 1 : 0;
    m.planarity_top = from_summary(r.planarity_top);
    m.planarity_bottom = from_summary(r.planarity_bottom);
    m.corner_distance_top = from_summary(r.corner_distance_top);
    m.corner_distance_bottom = from_summary(r.corner_distance_bottom);
    m.diagonal_top = from_summary(r.diagonal_top);
    m.diagonal_bottom = from_summary(r.diagonal_bottom);
    m.thickness = from_summary(r.thickness);
    m.miter = from_summary(r.miter);
    m.conical = from_summary(r.conical);
    *out_metrics = m;
  });
}

embra_status embra_panel_mesh_get_corner_gap(const embra_world* world, embra_body_id body,
                                             embra_metric_summary* out_summary) {
  return guard("embra_panel_mesh_get_corner_gap", world, [&] {
    need(out_summary, "out_summary");
    const embra::PanelLayout& l = layout_of(world, body);
    const embra::PanelReport r = embra::report_panels(embra::measure_panels(l, world->world.positions()), {});
    *out_summary = from_summary(r.corner_gap);
  });
}

embra_status embra_panel_mesh_get_vertex_errors(const embra_world* world, embra_body_id body, int32_t metric,
                                                double* out, int64_t capacity, int64_t* out_count) {
  return guard("embra_panel_mesh_get_vertex_errors", world, [&] {
    need(out_count, "out_count");
    const embra::PanelLayout& l = layout_of(world, body);
    if (metric < 0 || metric >= embra::kPanelMetricCount)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "metric " + num(metric) + " is not an EMBRA_PANEL_METRIC_ value");
    const int64_t n = 8 * static_cast<int64_t>(l.panel_count());
    if (out == nullptr && capacity == 0) {
      *out_count = n;
      return;
    }
    need(out, "out");
    if (capacity < n)
      refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " values, " + num(n) + " needed");
    const std::vector<double> v = embra::vertex_errors(l, embra::measure_panels(l, world->world.positions()),
                                                       static_cast<embra::PanelMetric>(metric));
    std::copy(v.begin(), v.end(), out);
    *out_count = n;
  });
}

embra_status embra_panel_mesh_export_cuts(const embra_world* world, embra_body_id body, int32_t format, char* out,
                                          int64_t capacity, int64_t* out_length) {
  return guard("embra_panel_mesh_export_cuts", world, [&] {
    need(out_length, "out_length");
    const embra::PanelLayout& l = layout_of(world, body);
    if (format != EMBRA_CUTS_JSON && format != EMBRA_CUTS_CSV)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "format must be EMBRA_CUTS_JSON or EMBRA_CUTS_CSV");
    const std::vector<embra::PanelCut> cuts = embra::panel_cuts(l, world->world.positions());
    write_text(format == EMBRA_CUTS_JSON ? embra::panel_cuts_json(cuts) : embra::panel_cuts_csv(cuts), out, capacity,
               out_length);
  });
}

// --- JSON scenes -------------------------------------------------------------------------------

}  // extern "C"

namespace {
embra_world* load_with(std::string_view text, const embra::io::LoadOptions& options) {
  embra::io::SceneMeta meta;
  std::unique_ptr<embra::World> w = embra::io::load_scene(text, options, meta);
  return new embra_world{std::move(*w), std::move(meta)};
}

embra_world* load(std::string_view text, const std::string& base_dir) {
  embra::io::LoadOptions options;
  options.base_dir = base_dir;
  return load_with(text, options);
}

std::string folder_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
}
}  // namespace

extern "C" {

embra_status embra_world_load_json(embra_world** out_world, const char* json, int64_t length, const char* base_dir) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_load_json", [&] {
    need(out_world, "out_world");
    need(json, "json");
    need_count(length, "length");
    *out_world = load(std::string_view(json, static_cast<size_t>(length)), base_dir ? base_dir : ".");
  });
}

embra_load_options embra_default_load_options(void) {
  embra_load_options o{};
  o.version = EMBRA_LOAD_OPTIONS_VERSION;
  return o;
}

embra_status embra_world_load_json_with_options(embra_world** out_world, const char* json, int64_t length,
                                                const embra_load_options* options) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_load_json_with_options", [&] {
    need(out_world, "out_world");
    need(json, "json");
    need_count(length, "length");
    need(options, "options");
    need_version(options->version, EMBRA_LOAD_OPTIONS_VERSION, "embra_load_options");
    if (options->allow_paths_outside_base != 0 && options->allow_paths_outside_base != 1)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "options.allow_paths_outside_base must be 0 or 1");
    embra::io::LoadOptions o;
    o.base_dir = options->base_dir ? options->base_dir : ".";
    o.allow_paths_outside_base = options->allow_paths_outside_base == 1;
    *out_world = load_with(std::string_view(json, static_cast<size_t>(length)), o);
  });
}

embra_status embra_world_load_file(embra_world** out_world, const char* path) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_load_file", [&] {
    need(out_world, "out_world");
    need(path, "path");
    std::string text, error;
    if (!embra::io::read_regular_file(path, embra::limits::kMaxSceneBytes, text, error))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(path) + " " + error);
    *out_world = load(text, folder_of(path));
  });
}

embra_status embra_world_save_json(const embra_world* world, char* out, int64_t capacity, int64_t* out_length) {
  return guard("embra_world_save_json", world, [&] {
    need(out_length, "out_length");
    const std::string text = embra::io::save_scene(world->world, world->meta);
    const int64_t n = static_cast<int64_t>(text.size()) + 1;
    if (out == nullptr && capacity == 0) {
      *out_length = n;
      return;
    }
    need(out, "out");
    if (capacity < n) {
      *out_length = n;
      refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " bytes, " + num(n) + " needed");
    }
    std::memcpy(out, text.c_str(), static_cast<size_t>(n));
    *out_length = n;
  });
}

embra_status embra_world_save_file(const embra_world* world, const char* path) {
  return guard("embra_world_save_file", world, [&] {
    need(path, "path");
    const std::string text = embra::io::save_scene(world->world, world->meta);
    const std::string tmp = std::string(path) + ".tmp";
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (f == nullptr) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "cannot write " + tmp + ": " + std::strerror(errno));
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok) {
      std::remove(tmp.c_str());
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "cannot write " + tmp);
    }
    if (std::rename(tmp.c_str(), path) != 0) {
      std::remove(tmp.c_str());
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("cannot replace ") + path + ": " + std::strerror(errno));
    }
  });
}

embra_status embra_world_get_scene_frames(const embra_world* world, int64_t* out_frames) {
  return guard("embra_world_get_scene_frames", world, [&] {
    need(out_frames, "out_frames");
    *out_frames = world->meta.frames;
  });
}

// --- fields ------------------------------------------------------------------------------------

}  // extern "C"

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

embra_field_id create_field(embra_world* world, const embra::FieldDesc& d) {
  return from_id<embra_field_id>(world->world.create_field(d));
}
}  // namespace

extern "C" {

embra_wind_def embra_default_wind_def(void) {
  const embra::WindDesc w;
  embra_wind_def d{};
  d.version = EMBRA_WIND_DEF_VERSION;
  for (int k = 0; k < 3; ++k) d.direction[k] = w.direction[k];
  d.speed = w.speed;
  d.air_density = w.air_density;
  d.drag = w.drag;
  d.lift = w.lift;
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
    d.wind.direction = vec(def->direction);
    d.wind.speed = def->speed;
    d.wind.air_density = def->air_density;
    d.wind.drag = def->drag;
    d.wind.lift = def->lift;
    *out_field = create_field(world, d);
  });
}

embra_pressure_def embra_default_pressure_def(void) {
  const embra::PressureDesc p;
  embra_pressure_def d{};
  d.version = EMBRA_PRESSURE_DEF_VERSION;
  d.keep_volume = p.keep_volume;
  d.inside_pressure = p.inside_pressure;
  d.outside_pressure = p.outside_pressure;
  d.volume_compliance = p.volume_compliance;
  d.rest_volume = p.rest_volume;
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
    d.pressure.keep_volume = def->keep_volume;
    d.pressure.inside_pressure = def->inside_pressure;
    d.pressure.outside_pressure = def->outside_pressure;
    d.pressure.volume_compliance = def->volume_compliance;
    d.pressure.rest_volume = def->rest_volume;
    *out_field = create_field(world, d);
  });
}

embra_surface_tension_def embra_default_surface_tension_def(void) {
  const embra::SurfaceTensionDesc t;
  embra_surface_tension_def d{};
  d.version = EMBRA_SURFACE_TENSION_DEF_VERSION;
  d.tension = t.tension;
  d.regularisation = t.regularisation;
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
    d.surface_tension.tension = def->tension;
    d.surface_tension.regularisation = def->regularisation;
    *out_field = create_field(world, d);
  });
}

embra_vortex_def embra_default_vortex_def(void) {
  const embra::VortexDesc v;
  embra_vortex_def d{};
  d.version = EMBRA_VORTEX_DEF_VERSION;
  for (int k = 0; k < 3; ++k) {
    d.center[k] = v.center[k];
    d.axis[k] = v.axis[k];
  }
  d.strength = v.strength;
  d.radius = v.radius;
  d.twist = v.twist;
  d.decay = v.decay;
  d.start_time = v.start_time;
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
    d.vortex.center = vec(def->center);
    d.vortex.axis = vec(def->axis);
    d.vortex.strength = def->strength;
    d.vortex.radius = def->radius;
    d.vortex.twist = def->twist;
    d.vortex.decay = def->decay;
    d.vortex.start_time = def->start_time;
    *out_field = create_field(world, d);
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
