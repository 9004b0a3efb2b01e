// The world: creation, solver settings, counts and id listings, stepping, particle state.
#include "copy.hpp"
#include "guard.hpp"

#include <thread>

using namespace embra::capi;

namespace {

constexpr std::tuple kSolverCopies{Copy{&embra_solver_def::dt, &embra::Settings::dt},
                                   Copy{&embra_solver_def::substeps, &embra::Settings::substeps},
                                   Copy{&embra_solver_def::iterations, &embra::Settings::iterations},
                                   Copy{&embra_solver_def::gravity, &embra::Settings::gravity},
                                   Copy{&embra_solver_def::damping, &embra::Settings::damping},
                                   Copy{&embra_solver_def::settle_speed, &embra::Settings::settle_speed},
                                   Copy{&embra_solver_def::tethers, &embra::Settings::tethers},
                                   Copy{&embra_solver_def::realign_passes, &embra::Settings::realign_passes},
                                   Copy{&embra_solver_def::chebyshev_rho_milli, &embra::Settings::chebyshev_rho_milli},
                                   Copy{&embra_solver_def::self_collision, &embra::Settings::self_collision},
                                   Copy{&embra_solver_def::chain_solve, &embra::Settings::chain_solve},
                                   Copy{&embra_solver_def::threads, &embra::Settings::threads},
                                   Copy{&embra_solver_def::global_solve, &embra::Settings::global_solve}};

embra::Settings to_settings(const embra_solver_def& d) {
  embra::Settings s;
  to_core(kSolverCopies, d, s);
  return s;
}

embra_solver_def from_settings(const embra::Settings& s) {
  embra_solver_def d{};
  d.version = EMBRA_SOLVER_DEF_VERSION;
  to_c(kSolverCopies, s, d);
  return d;
}

/// Copies particles [first, first + count) of `values` (positions or velocities) to out as xyz,
/// after checking the range and the buffer.
void read_particles(const embra::World& w, const std::vector<embra::Vec3>& values, int64_t capacity, int32_t first,
                    int32_t count, double* out) {
  need(out, "out_xyz");
  if (first < 0 || count < 0 || static_cast<int64_t>(first) + count > w.particle_count())
    refuse(EMBRA_ERROR_INVALID_ARGUMENT, "particle range [" + num(first) + ", " +
                                             num(static_cast<int64_t>(first) + count) + ") is outside [0, " +
                                             num(w.particle_count()) + ")");
  if (capacity < 3 * static_cast<int64_t>(count))
    refuse(EMBRA_ERROR_BUFFER_TOO_SMALL,
           "buffer holds " + num(capacity) + " doubles, " + num(3 * static_cast<int64_t>(count)) + " needed");
  for (int32_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) out[3 * i + k] = values[first + i][k];
}

/// The two-call id listing of embra_world_get_bodies/groups/pins/colliders: of `slots` slots, the
/// live ones (`generation(i)` nonzero) as {slot index, generation}, in slot order (creation order).
template <class IdT, class Generation>
void list_ids(size_t slots, Generation generation, IdT* out, int32_t capacity, int32_t* out_count) {
  need(out_count, "out_count");
  need_count(capacity, "capacity");
  int32_t n = 0;
  for (size_t i = 0; i < slots; ++i) n += generation(i) != 0 ? 1 : 0;
  if (!fits(out, capacity, n, "ids")) {
    *out_count = n;
    return;
  }
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

namespace embra::capi {

StepControl frame_control(embra_world* world) {
  StepControl control;
  if (!world->meta.actions.empty())
    control.before_frame = [world](World& w) { io::apply_actions(w, world->meta, w.report().frame + 1); };
  control.cancel = &world->cancel;
  return control;
}

void consume_cancel(embra_world* world, embra_status status) {
  if (status == EMBRA_ERROR_CANCELLED) world->cancel.store(false, std::memory_order_relaxed);
}

}  // namespace embra::capi

namespace {

/// One value per constraint of `kind` in `group` (World::constraint_residuals, constraint_forces), in
/// the two-call pattern.
embra_status per_constraint(const char* function,
                            std::vector<double> (embra::World::*values)(embra::Id, embra::Kind) const,
                            const embra_world* world, embra_group_id group, int32_t kind, double* out, int64_t capacity,
                            int64_t* out_count) {
  return guard(function, world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    if (!embra::is_kind(kind))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "kind " + num(kind) + " is not an embra_constraint_kind");
    const std::vector<double> v = (world->world.*values)(to_id(group), static_cast<embra::Kind>(kind));
    const int64_t n = static_cast<int64_t>(v.size());
    if (fits(out, capacity, n, "doubles")) std::copy(v.begin(), v.end(), out);
    *out_count = n;
  });
}

}  // namespace

extern "C" {

embra_solver_def embra_default_solver_def(void) {
  return from_settings(embra::Settings());
}

embra_solver_def embra_form_finding_solver_def(void) {
  return from_settings(embra::form_finding_settings());
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

// --- stepping ----------------------------------------------------------------------------------

embra_status embra_world_step(embra_world* world) {
  const embra_status status = guard("embra_world_step", world, [&] { world->world.step(frame_control(world)); });
  consume_cancel(world, status);
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

const char* embra_residual_unit(int32_t kind) {
  if (kind == EMBRA_RESIDUAL_PINS || kind == EMBRA_RESIDUAL_CONTACTS) return "m";
  if (!embra::is_kind(kind)) return nullptr;
  return embra::kKinds[kind].unit.data();  // the table's string literals: NUL-terminated, static
}

const char* embra_residual_name(int32_t kind) {
  if (kind == EMBRA_RESIDUAL_PINS) return "pins";
  if (kind == EMBRA_RESIDUAL_CONTACTS) return "contacts";
  if (!embra::is_kind(kind)) return nullptr;
  return embra::kKinds[kind].name.data();  // the table's string literals (#name): NUL-terminated, static
}

embra_status embra_world_get_residuals(const embra_world* world, embra_kind_residual* out, int32_t capacity,
                                       int32_t* out_count) {
  return guard("embra_world_get_residuals", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const auto& by_kind = world->world.report().by_kind;
    const auto c_kind = [](int k) {
      return k == embra::kResidualPins       ? EMBRA_RESIDUAL_PINS
             : k == embra::kResidualContacts ? EMBRA_RESIDUAL_CONTACTS
                                             : k;
    };
    int32_t n = 0;
    for (const embra::KindResidual& r : by_kind) n += r.count > 0 ? 1 : 0;
    if (!fits(out, capacity, n, "residuals")) {
      *out_count = n;
      return;
    }
    int32_t i = 0;
    for (int k = 0; k < embra::kResidualKinds; ++k)
      if (by_kind[k].count > 0)
        out[i++] = embra_kind_residual{c_kind(k), 0, by_kind[k].count, by_kind[k].max, by_kind[k].rms};
    *out_count = n;
  });
}

embra_status embra_world_get_worst_constraints(const embra_world* world, embra_constraint_residual* out,
                                               int32_t capacity, int32_t* out_count) {
  return guard("embra_world_get_worst_constraints", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    if (capacity > 0) need(out, "out");
    const std::vector<embra::ConstraintResidual> worst = world->world.worst_constraints(static_cast<size_t>(capacity));
    for (size_t i = 0; i < worst.size(); ++i) {
      const embra::ConstraintResidual& c = worst[i];
      embra_constraint_residual o{};
      o.kind = c.kind == embra::kResidualPins ? EMBRA_RESIDUAL_PINS : c.kind;
      o.index = c.index;
      o.group = from_id<embra_group_id>(c.group);
      o.pin = from_id<embra_pin_id>(c.pin);
      for (int k = 0; k < 4; ++k) o.particles[k] = c.particles[k];
      o.residual = c.residual;
      o.violation = c.violation;
      o.force = c.force;
      out[i] = o;
    }
    *out_count = static_cast<int32_t>(worst.size());
  });
}

embra_status embra_world_get_group_conflicts(const embra_world* world, embra_group_conflict* out, int32_t capacity,
                                             int32_t* out_count) {
  return guard("embra_world_get_group_conflicts", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<embra::GroupConflict> conflicts = world->world.group_conflicts();
    const int32_t n = static_cast<int32_t>(conflicts.size());
    if (!fits(out, capacity, n, "conflicts")) {
      *out_count = n;
      return;
    }
    for (int32_t i = 0; i < n; ++i)
      out[i] = embra_group_conflict{from_id<embra_group_id>(conflicts[i].a), from_id<embra_group_id>(conflicts[i].b),
                                    conflicts[i].force, conflicts[i].particles};
    *out_count = n;
  });
}

embra_status embra_group_get_residuals(const embra_world* world, embra_group_id group, int32_t kind, double* out,
                                       int64_t capacity, int64_t* out_count) {
  return per_constraint("embra_group_get_residuals", &embra::World::constraint_residuals, world, group, kind, out,
                        capacity, out_count);
}

embra_status embra_group_get_forces(const embra_world* world, embra_group_id group, int32_t kind, double* out,
                                    int64_t capacity, int64_t* out_count) {
  return per_constraint("embra_group_get_forces", &embra::World::constraint_forces, world, group, kind, out, capacity,
                        out_count);
}

embra_status embra_world_get_reactions(const embra_world* world, embra_reaction* out, int32_t capacity,
                                       int32_t* out_count) {
  return guard("embra_world_get_reactions", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<embra::Reaction> r = world->world.reactions();
    const int32_t n = static_cast<int32_t>(r.size());
    if (!fits(out, capacity, n, "reactions")) {
      *out_count = n;
      return;
    }
    for (int32_t i = 0; i < n; ++i)
      out[i] = embra_reaction{
          from_id<embra_pin_id>(r[i].pin), r[i].particle, 0, {r[i].force.x(), r[i].force.y(), r[i].force.z()}};
    *out_count = n;
  });
}

embra_status embra_world_get_collider_reactions(const embra_world* world, embra_collider_reaction* out,
                                                int32_t capacity, int32_t* out_count) {
  return guard("embra_world_get_collider_reactions", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<embra::ColliderReaction> r = world->world.collider_reactions();
    const int32_t n = static_cast<int32_t>(r.size());
    if (!fits(out, capacity, n, "collider reactions")) {
      *out_count = n;
      return;
    }
    for (int32_t i = 0; i < n; ++i)
      out[i] = embra_collider_reaction{from_id<embra_collider_id>(r[i].collider),
                                       r[i].contacts,
                                       {r[i].force.x(), r[i].force.y(), r[i].force.z()},
                                       {r[i].moment.x(), r[i].moment.y(), r[i].moment.z()}};
    *out_count = n;
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
  return guard("embra_world_get_positions", world,
               [&] { read_particles(world->world, world->world.positions(), capacity, first, count, out_xyz); });
}

embra_status embra_world_get_velocities(const embra_world* world, double* out_xyz, int64_t capacity, int32_t first,
                                        int32_t count) {
  return guard("embra_world_get_velocities", world,
               [&] { read_particles(world->world, world->world.velocities(), capacity, first, count, out_xyz); });
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

embra_status embra_world_set_loads(embra_world* world, const double* xyz, int32_t first, int32_t count) {
  return guard("embra_world_set_loads", world, [&] {
    need_count(count, "count");
    world->world.set_loads(first, view(xyz, 3 * static_cast<int64_t>(count), "xyz"));
  });
}

embra_status embra_world_get_loads(const embra_world* world, double* out_xyz, int64_t capacity, int32_t first,
                                   int32_t count) {
  return guard("embra_world_get_loads", world,
               [&] { read_particles(world->world, world->world.loads(), capacity, first, count, out_xyz); });
}

embra_status embra_world_set_area_loads(embra_world* world, const embra_area_load* loads, int32_t count) {
  return guard("embra_world_set_area_loads", world, [&] {
    need_count(count, "count");
    std::vector<embra::AreaLoad> core;
    core.reserve(static_cast<size_t>(count));
    for (const embra_area_load& l : view(loads, count, "loads")) {
      embra::AreaLoad& a = core.emplace_back();
      for (int k = 0; k < 3; ++k) a.particles[k] = l.particles[k];
      a.mode = static_cast<embra::AreaLoadMode>(l.mode);  // World::set_area_loads refuses an unknown one
      a.pressure = l.pressure;
      a.direction = vec(l.direction);
    }
    world->world.set_area_loads(core);
  });
}

embra_status embra_world_get_area_loads(const embra_world* world, embra_area_load* out, int32_t capacity,
                                        int32_t* out_count) {
  return guard("embra_world_get_area_loads", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<embra::AreaLoad>& loads = world->world.area_loads();
    const int32_t n = static_cast<int32_t>(loads.size());
    if (fits(out, capacity, n, "area loads"))
      for (int32_t i = 0; i < n; ++i) {
        const embra::AreaLoad& l = loads[i];
        out[i] = embra_area_load{{l.particles[0], l.particles[1], l.particles[2]},
                                 static_cast<int32_t>(l.mode),
                                 l.pressure,
                                 {l.direction.x(), l.direction.y(), l.direction.z()}};
      }
    *out_count = n;
  });
}

embra_status embra_world_set_line_loads(embra_world* world, const embra_line_load* loads, int32_t count) {
  return guard("embra_world_set_line_loads", world, [&] {
    need_count(count, "count");
    std::vector<embra::LineLoad> core;
    core.reserve(static_cast<size_t>(count));
    for (const embra_line_load& l : view(loads, count, "loads"))
      core.push_back(embra::LineLoad{{l.particles[0], l.particles[1]}, vec(l.load)});
    world->world.set_line_loads(core);
  });
}

embra_status embra_world_get_line_loads(const embra_world* world, embra_line_load* out, int32_t capacity,
                                        int32_t* out_count) {
  return guard("embra_world_get_line_loads", world, [&] {
    need(out_count, "out_count");
    need_count(capacity, "capacity");
    const std::vector<embra::LineLoad>& loads = world->world.line_loads();
    const int32_t n = static_cast<int32_t>(loads.size());
    if (fits(out, capacity, n, "line loads"))
      for (int32_t i = 0; i < n; ++i)
        out[i] = embra_line_load{{loads[i].particles[0], loads[i].particles[1]},
                                 {loads[i].load.x(), loads[i].load.y(), loads[i].load.z()}};
    *out_count = n;
  });
}

}  // extern "C"
