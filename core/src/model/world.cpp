// World construction and editing: everything but the step (core/src/solver). Each mutating call
// validates everything first and only then changes the world.
#include "embra/core/world.hpp"

#include "collision/collider_shapes.hpp"
#include "common/check.hpp"
#include "common/pool.hpp"
#include "common/slots.hpp"
#include "embra/core/panels.hpp"
#include "embra/core/point_set.hpp"
#include "model/kind_traits.hpp"
#include "solver/global_solve.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <sstream>

namespace embra {

namespace {

[[noreturn]] void fail(ErrorCode code, const std::string& message) {
  throw Error(code, message);
}

void check_material(const Material& m) {
  check_zero_or_positive(m.mass, "material.mass");
  check_zero_or_positive(m.density, "material.density");
  check_non_negative(m.stretch_compliance, "material.stretch_compliance");
  check_non_negative(m.shear_compliance, "material.shear_compliance");
  check_non_negative(m.bend_compliance, "material.bend_compliance");
  check_non_negative(m.volume_compliance, "material.volume_compliance");
  check_non_negative(m.damping, "material.damping");
  check_non_negative(m.thickness, "material.thickness");
  check_non_negative(m.friction_static, "material.friction_static");
  check_non_negative(m.friction_dynamic, "material.friction_dynamic");
  if (m.mass == 0.0 && m.density == 0.0) invalid("material needs a mass or a density greater than 0");
}

Vec3 at(std::span<const double> xyz, int64_t i) {
  return Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
}

std::string element_name(const char* kind, int64_t i) {
  std::ostringstream s;
  s << kind << " " << i;
  return s.str();
}

/// Validates an element list (edges, triangles, tets) against the vertex count: indices in range
/// and distinct within an element.
void check_elements(std::span<const int32_t> ids, int n, int64_t vertex_count, const char* kind) {
  if (ids.size() % n != 0) invalid(std::string(kind) + " index array length is not a multiple of " + std::to_string(n));
  for (size_t e = 0; e < ids.size() / n; ++e) {
    for (int k = 0; k < n; ++k) {
      const int32_t v = ids[e * n + k];
      if (v < 0 || v >= vertex_count)
        invalid(element_name(kind, static_cast<int64_t>(e)) + " refers to vertex " + std::to_string(v) +
                ", outside [0, " + std::to_string(vertex_count) + ")");
      for (int j = 0; j < k; ++j)
        if (ids[e * n + j] == v)
          invalid(element_name(kind, static_cast<int64_t>(e)) + " is degenerate: vertex " + std::to_string(v) +
                  " appears twice");
    }
  }
}

}  // namespace

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

World::World(const Settings& settings) {
  Settings s = settings;
  s.contact_group = Id{};
  set_settings(s);
  GroupDesc d;
  d.name = "default";
  default_group_ = create_group(d);
  GroupDesc c;
  c.name = "contacts";
  c.order = 1000;  // after everything else: collisions take precedence
  settings_.contact_group = create_group(c);
}

void World::set_settings(const Settings& s) {
  check_positive(s.dt, "settings.dt");
  if (s.dt > limits::kMaxDt) invalid("settings.dt must be <= 1e6 s");
  if (s.substeps < 1 || s.substeps > 10000) invalid("settings.substeps must be in [1, 10000]");
  if (s.iterations < 1 || s.iterations > 10000) invalid("settings.iterations must be in [1, 10000]");
  if (int64_t{s.substeps} * s.iterations > limits::kMaxPassesPerStep)
    invalid("settings.substeps x settings.iterations must be <= 100000 (passes per step)");
  if (s.tethers < 0 || s.tethers > 64) invalid("settings.tethers must be in [0, 64]");
  if (s.realign_passes < 0 || s.realign_passes > 100) invalid("settings.realign_passes must be in [0, 100]");
  if (s.chebyshev_rho_milli < 0 || s.chebyshev_rho_milli > 990)
    invalid("settings.chebyshev_rho_milli must be in [0, 990]");
  if (s.self_collision != 0 && s.self_collision != 1) invalid("settings.self_collision must be 0 or 1");
  if (s.chain_solve != 0 && s.chain_solve != 1) invalid("settings.chain_solve must be 0 or 1");
  if (s.global_solve < 0 || s.global_solve > kGlobalSolveAuto) invalid("settings.global_solve must be 0, 1 or 2");
  if (s.threads < 0 || s.threads > limits::kMaxThreads) invalid("settings.threads must be in [0, 256]");
  for (int k = 0; k < 3; ++k) check_finite(s.gravity[k], "settings.gravity");
  check_non_negative(s.damping, "settings.damping");
  check_non_negative(s.settle_speed, "settings.settle_speed");
  const Id contacts = settings_.contact_group;
  if (s.tethers != settings_.tethers || s.chain_solve != settings_.chain_solve ||
      (s.realign_passes > 0) != (settings_.realign_passes > 0))
    solver_dirty_ = true;  // the chains (build_chains: cables only with realignment passes)
  if (!pool_ || s.threads != settings_.threads) {
    pool_ = std::make_unique<ThreadPool>(s.threads);
    solver_dirty_ = true;  // the chain scratch has one share per thread
  }
  settings_ = s;
  settings_.contact_group = contacts;
}

void World::set_gravity(const Vec3& g) {
  for (int k = 0; k < 3; ++k) check_finite(g[k], "gravity");
  settings_.gravity = g;
}

// --- groups ------------------------------------------------------------------------------------

const Group* World::find_group(Id id) const {
  return slots::find(groups_, id);
}

const Group& World::group(Id id) const {
  const Group* g = find_group(id);
  if (g == nullptr) fail(ErrorCode::stale_id, "group id does not name a live group of this world");
  return *g;
}

Group& World::group_mut(Id id) {
  return const_cast<Group&>(group(id));
}

Id World::resolve_group(Id id) const {
  if (id.is_null()) return default_group_;
  group(id);
  return id;
}

size_t World::group_count() const {
  return slots::live_count(groups_);
}

Id World::create_group(const GroupDesc& desc) {
  if (desc.weight < 1 || desc.weight > 1000) invalid("group weight must be in [1, 1000]");
  Group g;
  g.desc = desc;
  g.serial = serial_++;
  const Id id = slots::create(groups_, std::move(g));
  rebuild_order();
  return id;
}

void World::destroy_group(Id id) {
  Group& g = group_mut(id);
  if (id == default_group_ || id == settings_.contact_group)
    invalid("the default and contact groups cannot be destroyed");
  if (!g.soft_pins.empty()) invalid("group still holds soft pins; destroy them first");
  // A body names a group for each kind it generates; bodies are never destroyed, so a group holding
  // a body's generated constraints stays. A body that names it for a kind it does not generate
  // names the default group instead (what a zeroed id means).
  static constexpr std::array<std::pair<uint32_t, const char*>, 4> kGenerated = {
      {{generate_stretch, "stretch"}, {generate_shear, "shear"}, {generate_bend, "bend"}, {generate_volume, "volume"}}};
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const BodyInfo& b = bodies_[i];
    const std::array<Id, 4> named = {b.stretch_group, b.shear_group, b.bend_group, b.volume_group};
    for (size_t k = 0; k < named.size(); ++k)
      if (named[k] == id && (b.generate & kGenerated[k].first))
        invalid("group holds the " + std::string(kGenerated[k].second) + " constraints body " + std::to_string(i) +
                " generated (bodies are never destroyed)");
  }
  for (BodyInfo& b : bodies_)
    for (Id* named : {&b.stretch_group, &b.shear_group, &b.bend_group, &b.volume_group})
      if (*named == id) *named = Id{};
  slots::destroy(groups_, id);
  rebuild_order();
  solver_dirty_ = true;
}

void World::set_group_order(Id id, int32_t order) {
  group_mut(id).desc.order = order;
  rebuild_order();
}

void World::set_group_weight(Id id, int32_t weight) {
  Group& g = group_mut(id);
  if (weight < 1 || weight > 1000) invalid("group weight must be in [1, 1000]");
  g.desc.weight = weight;
}

void World::rebuild_order() {
  order_.clear();
  for (size_t i = 0; i < groups_.size(); ++i)
    if (groups_[i].alive && groups_[i].desc.enabled) order_.push_back(static_cast<int32_t>(i));
  std::sort(order_.begin(), order_.end(), [&](int32_t a, int32_t b) {
    const Group& ga = groups_[a];
    const Group& gb = groups_[b];
    if (ga.desc.order != gb.desc.order) return ga.desc.order < gb.desc.order;
    return ga.serial < gb.serial;
  });
}

// --- constraints -------------------------------------------------------------------------------

void World::check_particle(int64_t index, const char* what) const {
  if (index < 0 || index >= particle_count())
    invalid(std::string(what) + " " + std::to_string(index) + " is outside [0, " + std::to_string(particle_count()) +
            ")");
}

namespace {

/// Measures a constraint's function at the current positions (rest "from current"); throws for a
/// degenerate element, for which no rest value can be measured.
double measure_rest(Kind kind, const int32_t* p, const std::vector<Vec3>& x, int64_t i) {
  const std::string name = element_name(kind_name(kind), i);
  return visit_kind(kind, [&](auto k) { return KindTraits<k>::measure_rest(p, x, name); });
}

void check_rest(Kind kind, double rest, int64_t i) {
  const std::string name = element_name(kind_name(kind), i);
  check_finite(rest, (name + " rest value").c_str());
  visit_kind(kind, [&](auto k) { KindTraits<k>::check_rest(rest, name); });
}

}  // namespace

int64_t World::add_constraints(const ConstraintDesc& desc) {
  const int k = static_cast<int>(desc.kind);
  if (!is_kind(k)) invalid("unknown constraint kind " + std::to_string(k));
  const int n = arity(desc.kind);
  const Id gid = resolve_group(desc.group);
  if (desc.particles.empty()) invalid("no constraints given (particle array is empty)");
  if (desc.particles.size() % n != 0)
    invalid(std::string("particle array length is not a multiple of ") + std::to_string(n) + " (the arity of " +
            kind_name(desc.kind) + ")");
  const size_t count = desc.particles.size() / n;
  if (constraint_count() + static_cast<int64_t>(count) > limits::kMaxConstraints)
    invalid("a world holds at most 16777216 constraints; these would make " +
            std::to_string(constraint_count() + static_cast<int64_t>(count)));
  if (!desc.rest.empty() && desc.rest.size() != count) invalid("rest array length differs from the constraint count");
  if (!desc.compliance.empty() && desc.compliance.size() != count)
    invalid("compliance array length differs from the constraint count");
  check_non_negative(desc.uniform_compliance, "compliance");
  std::vector<double> rest(count);
  for (size_t i = 0; i < count; ++i) {
    const int32_t* p = &desc.particles[i * n];
    for (int a = 0; a < n; ++a) {
      check_particle(p[a], (element_name(kind_name(desc.kind), static_cast<int64_t>(i)) + " particle").c_str());
      for (int b = 0; b < a; ++b)
        if (p[a] == p[b] && !visit_kind(desc.kind, [&](auto kt) { return KindTraits<kt>::may_share(a, b); }))
          invalid(element_name(kind_name(desc.kind), static_cast<int64_t>(i)) + " is degenerate: particle " +
                  std::to_string(p[a]) + " appears twice");
    }
    if (!desc.compliance.empty()) check_non_negative(desc.compliance[i], "compliance");
    if (desc.rest.empty()) {
      rest[i] = measure_rest(desc.kind, p, x_, static_cast<int64_t>(i));
    } else {
      check_rest(desc.kind, desc.rest[i], static_cast<int64_t>(i));
      rest[i] = desc.rest[i];
    }
  }
  // Everything is valid: append.
  ConstraintArray& a = group_mut(gid).arrays[k];
  a.ids.insert(a.ids.end(), desc.particles.begin(), desc.particles.end());
  for (size_t i = 0; i < count; ++i) {
    a.rest.push_back(rest[i]);
    a.rest_u.push_back(0.0);
    a.rest_v.push_back(0.0);
    a.body.push_back(-1);
    a.compliance.push_back(desc.compliance.empty() ? desc.uniform_compliance : desc.compliance[i]);
    a.rest_now.push_back(rest[i]);
    for (int c = 0; c < multipliers(desc.kind); ++c) a.lambda.push_back(0.0);
    a.yield.push_back(0.0);
    a.rupture.push_back(0.0);
  }
  rest_dirty_ = true;
  solver_dirty_ = true;
  return static_cast<int64_t>(count);
}

int64_t World::add_tethers(Id body_id, Id group, int32_t per_particle) {
  const BodyInfo& b = body(body_id);
  resolve_group(group);
  if (per_particle < 1 || per_particle > 64) invalid("tethers per particle must be in [1, 64]");
  std::vector<int32_t> anchors;
  for (int32_t i = b.first_particle; i < b.first_particle + b.particle_count; ++i)
    if (w_[i] == 0.0) anchors.push_back(i);
  const std::vector<Attachment> links = long_range_attachments(b, anchors, per_particle);
  if (links.empty()) return 0;
  std::vector<int32_t> ids;
  std::vector<double> rest;
  for (const Attachment& l : links) {
    ids.insert(ids.end(), {l.particle, l.anchor});
    rest.push_back(l.rest);
  }
  ConstraintDesc d;
  d.kind = Kind::tether;
  d.group = group;
  d.particles = ids;
  d.rest = rest;
  return add_constraints(d);
}

int64_t World::constraint_count() const {
  int64_t n = 0;
  for (const Group& g : groups_)
    if (g.alive)
      for (const ConstraintArray& a : g.arrays) n += static_cast<int64_t>(a.size());
  return n;
}

// --- edits -------------------------------------------------------------------------------------

namespace {

Kind known_kind(Kind kind) {
  if (!is_kind(static_cast<int>(kind))) invalid("unknown constraint kind " + std::to_string(static_cast<int>(kind)));
  return kind;
}

/// Erases constraint i of an array of `kind`; returns it as a one-constraint array.
ConstraintArray take(ConstraintArray& a, Kind kind, size_t i) {
  const auto n = static_cast<std::ptrdiff_t>(arity(kind)), per = static_cast<std::ptrdiff_t>(multipliers(kind));
  const auto at = static_cast<std::ptrdiff_t>(i);
  ConstraintArray one;
  const auto move = [&](auto& from, auto& to, std::ptrdiff_t width) {
    to.assign(from.begin() + at * width, from.begin() + (at + 1) * width);
    from.erase(from.begin() + at * width, from.begin() + (at + 1) * width);
  };
  move(a.ids, one.ids, n);
  move(a.rest, one.rest, 1);
  move(a.rest_u, one.rest_u, 1);
  move(a.rest_v, one.rest_v, 1);
  move(a.body, one.body, 1);
  move(a.compliance, one.compliance, 1);
  move(a.rest_now, one.rest_now, 1);
  move(a.lambda, one.lambda, per);
  move(a.yield, one.yield, 1);
  move(a.rupture, one.rupture, 1);
  return one;
}

}  // namespace

const ConstraintArray& World::constraint_array(Id group_id, Kind kind, int64_t index) const {
  const ConstraintArray& a = group(resolve_group(group_id)).arrays[static_cast<int>(known_kind(kind))];
  if (index < 0 || index >= static_cast<int64_t>(a.size()))
    invalid(std::string(kind_name(kind)) + " constraint " + std::to_string(index) + " is outside [0, " +
            std::to_string(a.size()) + ") of its group");
  return a;
}

ConstraintArray& World::edited_array(Id group_id, Kind kind, int64_t index) {
  constraint_array(group_id, kind, index);
  ConstraintArray& a = group_mut(resolve_group(group_id)).arrays[static_cast<int>(kind)];
  if (static_cast<size_t>(index) < a.generated)
    invalid(std::string(kind_name(kind)) + " constraint " + std::to_string(index) + " was generated by body " +
            std::to_string(a.body[static_cast<size_t>(index)]) +
            ": it follows the body's material (embra_body_set_material); only added constraints are edited one "
            "at a time");
  return a;
}

std::pair<int64_t, int64_t> World::constraint_count(Id group_id, Kind kind) const {
  const ConstraintArray& a = group(resolve_group(group_id)).arrays[static_cast<int>(known_kind(kind))];
  return {static_cast<int64_t>(a.size()), static_cast<int64_t>(a.generated)};
}

ConstraintInfo World::constraint(Id group_id, Kind kind, int64_t index) const {
  const ConstraintArray& a = constraint_array(group_id, kind, index);
  const auto i = static_cast<size_t>(index);
  const int n = arity(kind);
  ConstraintInfo c;
  c.kind = kind;
  for (int k = 0; k < n; ++k) c.particles[k] = a.ids[i * n + k];
  c.rest = a.rest[i];
  c.compliance = a.compliance[i];
  c.body = i < a.generated ? a.body[i] : -1;
  c.yield = a.yield[i];
  c.rupture = a.rupture[i];
  return c;
}

void World::set_constraint_compliance(Id group_id, Kind kind, int64_t index, double compliance) {
  ConstraintArray& a = edited_array(group_id, kind, index);
  check_non_negative(compliance, "compliance");
  a.compliance[static_cast<size_t>(index)] = compliance;
  // The solver's copy in place: no new colouring.
  SolverArray& sa = group_mut(resolve_group(group_id)).solve[static_cast<int>(kind)];
  if (!solver_dirty_)
    for (size_t j = 0; j < sa.size(); ++j)
      if (sa.source[j] == index) sa.compliance[j] = compliance;
}

void World::set_constraint_rest(Id group_id, Kind kind, int64_t index, double rest) {
  ConstraintArray& a = edited_array(group_id, kind, index);
  check_rest(kind, rest, index);
  const auto i = static_cast<size_t>(index);
  if (kind == Kind::distance && rest == 0.0 && (a.yield[i] != 0.0 || a.rupture[i] != 0.0))
    invalid("distance constraint " + std::to_string(index) +
            " yields or breaks at a strain: its rest length cannot be 0 (set its plasticity to 0 first)");
  a.rest[i] = rest;
  rest_dirty_ = true;  // refresh_rest copies it to the solver's array
}

int64_t World::move_constraint(Id group_id, Kind kind, int64_t index, Id to) {
  const Id from = resolve_group(group_id);
  edited_array(from, kind, index);
  const Id target = resolve_group(to);
  ConstraintArray& dest = group_mut(target).arrays[static_cast<int>(kind)];
  if (target == from) return index;
  if (target == settings_.contact_group) invalid("the contact group holds contacts only");
  const ConstraintArray one = take(group_mut(from).arrays[static_cast<int>(kind)], kind, static_cast<size_t>(index));
  dest.ids.insert(dest.ids.end(), one.ids.begin(), one.ids.end());
  for (auto [d, s] : {std::pair{&dest.rest, &one.rest},
                      {&dest.rest_u, &one.rest_u},
                      {&dest.rest_v, &one.rest_v},
                      {&dest.compliance, &one.compliance},
                      {&dest.rest_now, &one.rest_now},
                      {&dest.lambda, &one.lambda},
                      {&dest.yield, &one.yield},
                      {&dest.rupture, &one.rupture}})
    d->insert(d->end(), s->begin(), s->end());
  dest.body.insert(dest.body.end(), one.body.begin(), one.body.end());
  rest_dirty_ = true;
  solver_dirty_ = true;
  return static_cast<int64_t>(dest.size()) - 1;
}

void World::remove_constraint(Id group_id, Kind kind, int64_t index) {
  ConstraintArray& a = edited_array(group_id, kind, index);
  take(a, kind, static_cast<size_t>(index));
  rest_dirty_ = true;
  solver_dirty_ = true;
}

int64_t World::add_shape_match(Id group_id, std::span<const int32_t> particles, std::span<const Vec3> rest,
                               double compliance) {
  const Id gid = resolve_group(group_id);
  const size_t n = particles.size();
  if (n < 3)
    invalid("a shape match takes at least 3 particles (fewer have no rotation to fit), not " + std::to_string(n));
  if (n > static_cast<size_t>(limits::kMaxParticles))
    invalid("a shape match takes at most " + std::to_string(limits::kMaxParticles) + " particles");
  if (!rest.empty() && rest.size() != n)
    invalid("a shape match takes one rest point per particle: " + std::to_string(rest.size()) + " for " +
            std::to_string(n));
  check_non_negative(compliance, "shape match compliance");
  for (size_t i = 0; i < n; ++i) check_particle(particles[i], ("shape match particle " + std::to_string(i)).c_str());
  if (const int32_t twice = repeated_particle(particles); twice >= 0)
    invalid("shape match particle " + std::to_string(twice) + " appears twice");
  std::vector<Vec3> r(n);
  for (size_t i = 0; i < n; ++i) {
    r[i] = rest.empty() ? x_[particles[i]] : rest[i];
    for (int k = 0; k < 3; ++k) check_finite(r[i][k], "shape match rest point " + std::to_string(i));
  }
  // A rotation to fit needs the rest shape off one line (point_set_base).
  const PointSetBase base = point_set_base(n, [&](size_t i) { return r[i]; });
  if (!(base.reach > 0.0)) invalid("the shape match's rest points are all at one place: no rotation to fit");
  if (!base.spans_plane())
    invalid(
        "the shape match's rest points are on one line (within 1e-6 of their reach): no rotation about it to "
        "fit");
  // Everything is valid: append.
  ShapeMatch s;
  s.particles.assign(particles.begin(), particles.end());
  s.rest = std::move(r);
  s.compliance = compliance;
  s.lambda.assign(n, Vec3::Zero());
  std::vector<ShapeMatch>& list = group_mut(gid).shapes;
  list.push_back(std::move(s));
  return static_cast<int64_t>(list.size()) - 1;
}

void World::remove_shape_match(Id group_id, int64_t index) {
  std::vector<ShapeMatch>& list = group_mut(resolve_group(group_id)).shapes;
  if (index < 0 || index >= static_cast<int64_t>(list.size()))
    invalid("shape match " + std::to_string(index) + " is outside the group's [0, " + std::to_string(list.size()) +
            ")");
  list.erase(list.begin() + index);
}

const std::vector<ShapeMatch>& World::shape_matches(Id group_id) const {
  return group(resolve_group(group_id)).shapes;
}

void World::set_group_enabled(Id id, bool enabled) {
  Group& g = group_mut(id);
  if (id == settings_.contact_group && !enabled)
    invalid("the contact group cannot be disabled (it keeps particles out of the colliders)");
  if (g.desc.enabled == enabled) return;
  g.desc.enabled = enabled;
  g.report = GroupReport{};
  rebuild_order();
}

void World::set_material(Id id, const Material& m) {
  body(id);
  check_material(m);
  BodyInfo& b = bodies_[id.index];
  if (m.mass != b.material.mass || m.density != b.material.density)
    invalid("a body's mass and density are fixed at creation (its particles' masses were set from them)");
  const bool thicker = m.thickness != b.material.thickness;
  b.material = m;
  for (int32_t i = b.first_particle; i < b.first_particle + b.particle_count; ++i) {
    radius_[i] = 0.5 * m.thickness;
    damping_[i] = m.damping;
    mu_s_[i] = m.friction_static;
    mu_k_[i] = m.friction_dynamic;
  }
  // The generated constraints of each kind: the body's block in its group's array.
  const std::array<std::pair<Kind, double>, 4> compliance = {{{Kind::distance, m.stretch_compliance},
                                                              {Kind::edge_angle, m.shear_compliance},
                                                              {Kind::dihedral, m.bend_compliance},
                                                              {Kind::tet_volume, m.volume_compliance}}};
  const std::array<Id, 4> groups = {b.stretch_group, b.shear_group, b.bend_group, b.volume_group};
  for (size_t k = 0; k < groups.size(); ++k) {
    ConstraintArray& a = group_mut(resolve_group(groups[k])).arrays[static_cast<int>(compliance[k].first)];
    for (size_t i = 0; i < a.generated; ++i)
      if (a.body[i] == static_cast<int32_t>(id.index)) a.compliance[i] = compliance[k].second;
  }
  if (thicker) self_cache_ = SelfCollisionCache{};  // its pairs were kept for the old thickness
  solver_dirty_ = true;  // the compliances, and whether its stretch is inextensible (automatic tethers)
}

void World::set_masses(Id id, std::span<const double> masses) {
  body(id);
  BodyInfo& b = bodies_[id.index];
  if (static_cast<int64_t>(masses.size()) != b.particle_count)
    invalid("masses has " + std::to_string(masses.size()) + " values; the body has " +
            std::to_string(b.particle_count) + " particles (one mass each)");
  for (size_t i = 0; i < masses.size(); ++i)
    check_zero_or_positive(masses[i], "mass " + std::to_string(i) + " (kg, 0 = immovable)");
  b.masses.assign(masses.begin(), masses.end());  // saved with the body, so a reloaded world agrees
  for (int32_t k = 0; k < b.particle_count; ++k) {
    const int32_t i = b.first_particle + k;
    inv_mass_[i] = masses[static_cast<size_t>(k)] > 0.0 ? 1.0 / masses[static_cast<size_t>(k)] : 0.0;
    w_[i] = hard_pin_of_[i] >= 0 ? 0.0 : inv_mass_[i];
  }
  // Anchors (immovable particles) decide the automatic tethers and the colouring: rebuilt as a
  // loaded world builds them.
  solver_dirty_ = true;
}

// --- bodies ------------------------------------------------------------------------------------

Id World::create_body(const BodyDesc& d) {
  if (d.positions.empty() || d.positions.size() % 3 != 0)
    invalid("body positions must be a non-empty array of 3 numbers per vertex");
  const int64_t nv = static_cast<int64_t>(d.positions.size() / 3);
  if (nv + particle_count() > limits::kMaxParticles)
    invalid("a world holds at most 2097152 particles; this body would make " + std::to_string(nv + particle_count()));
  for (double c : d.positions) check_finite(c, "body vertex coordinate");
  if (!d.masses.empty()) {
    if (static_cast<int64_t>(d.masses.size()) != nv) invalid("body masses must have one value per vertex");
    for (double m : d.masses) check_zero_or_positive(m, "body vertex mass");
  }
  if (!d.uvs.empty()) {
    if (static_cast<int64_t>(d.uvs.size()) != 2 * nv) invalid("body uvs must have two values per vertex");
    for (double c : d.uvs) check_finite(c, "body uv coordinate");
  }
  // Generated constraints, at most: one per edge (a triangle's edges when none are given), a shear
  // and a bend per triangle edge, one per tetrahedron.
  const int64_t elements = static_cast<int64_t>(d.edges.size() / 2 + 6 * (d.triangles.size() / 3) + d.tets.size() / 4);
  if (constraint_count() + elements > limits::kMaxConstraints)
    invalid("a world holds at most 16777216 constraints; this body's elements could generate " +
            std::to_string(elements) + " beside the " + std::to_string(constraint_count()) + " there are");
  check_elements(d.edges, 2, nv, "edge");
  check_elements(d.triangles, 3, nv, "triangle");
  check_elements(d.tets, 4, nv, "tetrahedron");
  if (d.masses.empty())
    check_material(d.material);
  else {
    Material m = d.material;
    if (m.mass == 0.0 && m.density == 0.0) m.density = 1.0;  // not used: masses are given
    check_material(m);
  }
  const Id groups[4] = {resolve_group(d.stretch_group), resolve_group(d.shear_group), resolve_group(d.bend_group),
                        resolve_group(d.volume_group)};

  // Degenerate elements, measured against the body's size.
  Vec3 lo = at(d.positions, 0), hi = lo;
  for (int64_t i = 1; i < nv; ++i) {
    lo = lo.cwiseMin(at(d.positions, i));
    hi = hi.cwiseMax(at(d.positions, i));
  }
  const double diag = std::max((hi - lo).norm(), 1e-300);
  // Element measures take powers of lengths (an edge's squared length, a tetrahedron's triple
  // product, a triangle's squared cross product): a body whose elements are too large for that in
  // double precision is refused here rather than stepped into infinities. Free points have none.
  const int power = !d.triangles.empty() ? 4 : !d.tets.empty() ? 3 : !d.edges.empty() ? 2 : 0;
  if (power > 0 && !in_range(std::pow(diag, power)))
    invalid("the body is too large: its bounding box diagonal (" + std::to_string(diag) + " m) to the power " +
            std::to_string(power) + " overflows double precision (its elements' measures would)");
  const double eps_len = 1e-12 * diag;
  auto P = [&](int32_t i) { return at(d.positions, i); };
  std::vector<double> weight(nv, 0.0);
  std::vector<double> edge_w(nv, 0.0), tri_w(nv, 0.0), tet_w(nv, 0.0);
  for (size_t e = 0; e < d.edges.size() / 2; ++e) {
    const double len = (P(d.edges[2 * e]) - P(d.edges[2 * e + 1])).norm();
    if (len <= eps_len) invalid(element_name("edge", static_cast<int64_t>(e)) + " is degenerate: zero length");
    edge_w[d.edges[2 * e]] += len / 2;
    edge_w[d.edges[2 * e + 1]] += len / 2;
  }
  for (size_t t = 0; t < d.triangles.size() / 3; ++t) {
    const int32_t* v = &d.triangles[3 * t];
    const double area = 0.5 * (P(v[1]) - P(v[0])).cross(P(v[2]) - P(v[0])).norm();
    if (area <= eps_len * diag)
      invalid(element_name("triangle", static_cast<int64_t>(t)) + " is degenerate: zero area");
    for (int k = 0; k < 3; ++k) tri_w[v[k]] += area / 3;
  }
  for (size_t t = 0; t < d.tets.size() / 4; ++t) {
    const int32_t* v = &d.tets[4 * t];
    const double vol = std::abs((P(v[1]) - P(v[0])).cross(P(v[2]) - P(v[0])).dot(P(v[3]) - P(v[0]))) / 6;
    if (vol <= eps_len * diag * diag)
      invalid(element_name("tetrahedron", static_cast<int64_t>(t)) + " is degenerate: zero volume");
    for (int k = 0; k < 4; ++k) tet_w[v[k]] += vol / 4;
  }

  // Lumped masses: by volume when there are tetrahedra, else area, else length, else equal.
  std::vector<double> mass(nv);
  if (!d.masses.empty()) {
    std::copy(d.masses.begin(), d.masses.end(), mass.begin());
  } else {
    const std::vector<double>* w = !d.tets.empty()        ? &tet_w
                                   : !d.triangles.empty() ? &tri_w
                                   : !d.edges.empty()     ? &edge_w
                                                          : nullptr;
    double total = 0.0;
    int64_t covered = 0;
    for (int64_t i = 0; i < nv; ++i) {
      weight[i] = w ? (*w)[i] : 1.0;
      total += weight[i];
      covered += weight[i] > 0.0;
    }
    const double fill = total / static_cast<double>(covered);  // isolated vertices get the mean
    for (int64_t i = 0; i < nv; ++i)
      if (weight[i] == 0.0) weight[i] = fill;
    total = std::accumulate(weight.begin(), weight.end(), 0.0);
    for (int64_t i = 0; i < nv; ++i)
      mass[i] = d.material.mass > 0.0 ? d.material.mass * weight[i] / total : d.material.density * weight[i];
  }
  for (int64_t i = 0; i < nv; ++i)
    if (mass[i] != 0.0 && !(mass[i] >= limits::kMinPositive && mass[i] <= limits::kMaxAbsValue))
      invalid("vertex " + std::to_string(i) + " gets a mass of " + std::to_string(mass[i]) +
              " kg from the material and the geometry: outside [1e-300, 1e300], so its inverse is not finite");

  // Unique edges from the explicit list, the triangles and the tetrahedra.
  std::vector<std::pair<int32_t, int32_t>> edges;
  auto add_edge = [&](int32_t a, int32_t b) { edges.emplace_back(std::min(a, b), std::max(a, b)); };
  for (size_t e = 0; e < d.edges.size() / 2; ++e) add_edge(d.edges[2 * e], d.edges[2 * e + 1]);
  for (size_t t = 0; t < d.triangles.size() / 3; ++t)
    for (int k = 0; k < 3; ++k) add_edge(d.triangles[3 * t + k], d.triangles[3 * t + (k + 1) % 3]);
  for (size_t t = 0; t < d.tets.size() / 4; ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) add_edge(d.tets[4 * t + a], d.tets[4 * t + b]);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  // Hinges: pairs of triangles sharing an edge (consecutive pairs around a non-manifold edge).
  std::map<std::pair<int32_t, int32_t>, std::vector<std::pair<int32_t, int32_t>>> wings;  // edge -> (triangle, wing)
  for (size_t t = 0; t < d.triangles.size() / 3; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t a = d.triangles[3 * t + k], b = d.triangles[3 * t + (k + 1) % 3],
                    c = d.triangles[3 * t + (k + 2) % 3];
      wings[{std::min(a, b), std::max(a, b)}].emplace_back(static_cast<int32_t>(t), c);
    }

  // Everything is valid: commit.
  const int32_t first = particle_count();
  const int32_t body_index = static_cast<int32_t>(bodies_.size());
  for (int64_t i = 0; i < nv; ++i) {
    x_.push_back(P(static_cast<int32_t>(i)));
    x_prev_.push_back(x_.back());
    v_.push_back(Vec3::Zero());
    inv_mass_.push_back(mass[i] > 0.0 ? 1.0 / mass[i] : 0.0);
    w_.push_back(inv_mass_.back());
    radius_.push_back(0.5 * d.material.thickness);
    damping_.push_back(d.material.damping);
    load_.push_back(Vec3::Zero());
    mu_s_.push_back(d.material.friction_static);
    mu_k_.push_back(d.material.friction_dynamic);
    body_of_.push_back(body_index);
    hard_pin_of_.push_back(-1);
  }
  BodyInfo info;
  info.first_particle = first;
  info.particle_count = static_cast<int32_t>(nv);
  info.material = d.material;
  info.has_uv = !d.uvs.empty();
  for (int32_t v : d.triangles) info.triangles.push_back(first + v);
  for (int32_t v : d.tets) info.tets.push_back(first + v);
  for (auto [a, b] : edges) info.edges.insert(info.edges.end(), {first + a, first + b});
  for (int64_t i = 0; i < nv; ++i) info.rest_positions.push_back(P(static_cast<int32_t>(i)));
  info.stretch_group = groups[0];
  info.generated_stretch = (d.generate & generate_stretch) != 0 && !edges.empty();
  info.masses = mass;
  info.uvs.assign(d.uvs.begin(), d.uvs.end());
  info.generate = d.generate;
  info.shear_group = groups[1];
  info.bend_group = groups[2];
  info.volume_group = groups[3];
  bodies_.push_back(info);
  tether_cache_.emplace_back();

  // Generated constraints go after earlier bodies' and before added ones (ConstraintArray::generated).
  struct Touched {
    ConstraintArray* array;
    int kind;
    size_t before;  // size before this body
    bool operator<(const Touched& o) const { return array < o.array; }
    bool operator==(const Touched& o) const { return array == o.array; }
  };
  std::vector<Touched> touched;
  for (const Id gid : groups)
    for (int k = 0; k < kKindCount; ++k)
      touched.push_back({&group_mut(gid).arrays[k], k, group_mut(gid).arrays[k].size()});
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  auto append = [&](Kind kind, Id gid, std::initializer_list<int32_t> local, double rest, double compliance, double ru,
                    double rv) {
    ConstraintArray& a = group_mut(gid).arrays[static_cast<int>(kind)];
    for (int32_t v : local) a.ids.push_back(first + v);
    a.rest.push_back(rest);
    a.rest_u.push_back(ru);
    a.rest_v.push_back(rv);
    a.body.push_back(body_index);
    a.compliance.push_back(compliance);
    a.rest_now.push_back(rest);
    a.lambda.push_back(0.0);
    a.yield.push_back(0.0);
    a.rupture.push_back(0.0);
  };
  const Material& m = d.material;
  if (d.generate & generate_stretch)
    for (auto [a, b] : edges) {
      const double rest = (P(a) - P(b)).norm();
      double ru = 0.0, rv = 0.0;
      if (info.has_uv) {
        const double du = std::abs(d.uvs[2 * a] - d.uvs[2 * b]);
        const double dv = std::abs(d.uvs[2 * a + 1] - d.uvs[2 * b + 1]);
        const double duv = std::hypot(du, dv);
        if (duv > 0.0) {
          ru = rest * du / duv;
          rv = rest * dv / duv;
        }
      }
      append(Kind::distance, groups[0], {a, b}, rest, m.stretch_compliance, ru, rv);
    }
  if (d.generate & generate_shear)
    for (size_t t = 0; t < d.triangles.size() / 3; ++t)
      for (int k = 0; k < 3; ++k) {
        const int32_t c = d.triangles[3 * t + k], a = d.triangles[3 * t + (k + 1) % 3],
                      b = d.triangles[3 * t + (k + 2) % 3];
        append(Kind::edge_angle, groups[1], {c, a, b}, eval_edge_angle(P(c), P(a), P(b)).value, m.shear_compliance, 0,
               0);
      }
  if (d.generate & generate_bend)
    for (const auto& [edge, list] : wings)
      for (size_t i = 0; i + 1 < list.size(); ++i) {
        const int32_t* t = &d.triangles[3 * list[i].first];
        // Orient the hinge edge as it runs in the first triangle.
        int32_t a = edge.first, b = edge.second;
        for (int k = 0; k < 3; ++k)
          if (t[k] == b && t[(k + 1) % 3] == a) std::swap(a, b);
        const int32_t c = list[i].second, e = list[i + 1].second;
        if (c == e) continue;  // two triangles on the same three vertices: no hinge
        append(Kind::dihedral, groups[2], {a, b, c, e}, eval_dihedral(P(a), P(b), P(c), P(e)).value, m.bend_compliance,
               0, 0);
      }
  if (d.generate & generate_volume)
    for (size_t t = 0; t < d.tets.size() / 4; ++t) {
      const int32_t* v = &d.tets[4 * t];
      append(Kind::tet_volume, groups[3], {v[0], v[1], v[2], v[3]},
             eval_tet_volume(P(v[0]), P(v[1]), P(v[2]), P(v[3])).value, m.volume_compliance, 0, 0);
    }
  for (const Touched& t : touched) {
    ConstraintArray& a = *t.array;
    const size_t added = a.size() - t.before;
    if (added == 0) continue;
    if (a.generated < t.before) {  // added constraints exist: move this body's block in front of them
      const auto move_block = [&](auto& v, size_t per) {
        std::rotate(v.begin() + static_cast<std::ptrdiff_t>(a.generated * per),
                    v.begin() + static_cast<std::ptrdiff_t>(t.before * per), v.end());
      };
      move_block(a.ids, static_cast<size_t>(arity(static_cast<Kind>(t.kind))));
      move_block(a.rest, 1);
      move_block(a.rest_u, 1);
      move_block(a.rest_v, 1);
      move_block(a.body, 1);
      move_block(a.compliance, 1);
      move_block(a.rest_now, 1);
      move_block(a.lambda, 1);
      move_block(a.yield, 1);
      move_block(a.rupture, 1);
    }
    a.generated += added;
  }
  rest_dirty_ = true;
  solver_dirty_ = true;
  return Id{static_cast<uint32_t>(body_index), 1};
}

const BodyInfo& World::body(Id id) const {
  if (id.generation != 1 || id.index >= bodies_.size())
    fail(ErrorCode::stale_id, "body id does not name a body of this world");
  return bodies_[id.index];
}

void World::set_panel_layout(const PanelLayout& layout) {
  const BodyInfo& b = body(layout.body);
  if (layout.quads.empty() || layout.quads.size() % 4 != 0) invalid("panel layout quads must be 4 indices per panel");
  const int64_t panels = static_cast<int64_t>(layout.quads.size() / 4);
  if (layout.vertex_count < 1) invalid("panel layout vertex_count must be >= 1");
  if (layout.particle_count() != b.particle_count)
    invalid("panel layout has " + std::to_string(panels) + " panels on " + std::to_string(layout.vertex_count) +
            " vertices but the body has " + std::to_string(b.particle_count) + " particles (" +
            (layout.shared ? "2 per vertex, corners shared" : "8 per panel, corners welded") + " expected)");
  for (size_t q = 0; q < layout.quads.size(); q += 4)
    for (size_t k = 0; k < 4; ++k) {
      const int32_t v = layout.quads[q + k];
      if (v < 0 || v >= layout.vertex_count)
        invalid("panel layout quad " + std::to_string(q / 4) + " vertex " + std::to_string(v) + " is outside [0, " +
                std::to_string(layout.vertex_count) + ")");
      for (size_t j = 0; j < k; ++j)
        if (layout.quads[q + j] == v)
          invalid("panel layout quad " + std::to_string(q / 4) + " repeats vertex " + std::to_string(v));
    }
  check_positive(layout.thickness, "panel thickness");
  for (const PanelLayout& l : panel_layouts_)
    if (l.body == layout.body) invalid("the body already has a panel layout");
  PanelLayout copy = layout;
  copy.first_particle = b.first_particle;
  copy.topology = std::make_shared<const PanelTopology>(panel_topology(copy));
  panel_layouts_.push_back(std::move(copy));
  solver_dirty_ = true;  // its panels may become islands (build_islands)
}

const PanelLayout* World::panel_layout(Id body_id) const {
  for (const PanelLayout& l : panel_layouts_)
    if (l.body == body_id) return &l;
  return nullptr;
}

void World::set_clock(int64_t frame, double time) {
  if (frame < 0) invalid("frame must be >= 0");
  check_non_negative(time, "time");
  report_.frame = frame;
  report_.time = time;
}

void World::set_rest_scale(Id id, double scale, double scale_u, double scale_v) {
  body(id);
  check_non_negative(scale, "rest scale");
  check_non_negative(scale_u, "rest scale u");
  check_non_negative(scale_v, "rest scale v");
  BodyInfo& b = bodies_[id.index];
  b.rest_scale = scale;
  b.rest_scale_u = scale_u;
  b.rest_scale_v = scale_v;
  rest_dirty_ = true;
}

void World::refresh_rest() {
  for (Group& g : groups_) {
    if (!g.alive) continue;
    for (int k = 0; k < kKindCount; ++k) {
      ConstraintArray& a = g.arrays[k];
      visit_kind(static_cast<Kind>(k), [&](auto kind) {
        for (size_t i = 0; i < a.size(); ++i)
          a.rest_now[i] = a.body[i] < 0 ? a.rest[i] : KindTraits<kind>::scaled_rest(a, i, bodies_[a.body[i]]);
      });
      SolverArray& sa = g.solve[k];
      for (size_t i = 0; i < sa.size(); ++i) sa.rest[i] = a.rest_now[sa.source[i]];
    }
    // An automatic tether's rest is a path length over the body; no rest scale can lengthen such a
    // path by more than the largest of the scales, so the tether never holds a legal shape back.
    SolverArray& t = g.tethers;
    for (size_t i = 0; i < t.size(); ++i) {
      const BodyInfo& b = bodies_[t.body[i]];
      const double directional = b.has_uv ? std::max({b.rest_scale_u, b.rest_scale_v, 1.0}) : 1.0;
      t.rest[i] = t.base_rest[i] * b.rest_scale * directional;
    }
  }
  rest_dirty_ = false;
}

namespace {

/// Orders `count` constraints of arity `n` by greedy graph colouring: each constraint takes the
/// lowest colour none of its particles has yet (particles with ignore[p] set do not count: they
/// never move). Constraints keep their relative order within a colour. At most 64 colours; what
/// does not fit goes to one last colour whose constraints may share particles (`shared_tail`).
void colour_order(const int32_t* ids, size_t count, int n, size_t particle_count, const std::vector<uint8_t>& ignore,
                  std::vector<int32_t>& order, std::vector<int32_t>& colour_start, bool& shared_tail) {
  constexpr int kMaxColours = 64;
  std::vector<uint64_t> used(particle_count, 0);
  std::vector<int32_t> colour(count);
  std::vector<int32_t> per_colour(kMaxColours + 1, 0);
  for (size_t i = 0; i < count; ++i) {
    uint64_t taken = 0;
    for (int k = 0; k < n; ++k) {
      const int32_t p = ids[i * n + k];
      if (!ignore[p]) taken |= used[p];
    }
    const int c = std::countr_one(taken);  // 64 when all are taken
    colour[i] = c;
    ++per_colour[c];
    if (c < kMaxColours)
      for (int k = 0; k < n; ++k) used[ids[i * n + k]] |= uint64_t{1} << c;
  }
  int colours = kMaxColours + 1;
  while (colours > 0 && per_colour[colours - 1] == 0) --colours;
  shared_tail = per_colour[kMaxColours] > 0;
  colour_start.assign(colours + 1, 0);
  for (int c = 0; c < colours; ++c) colour_start[c + 1] = colour_start[c] + per_colour[c];
  std::vector<int32_t> next(colour_start.begin(), colour_start.end() - 1);
  order.resize(count);
  for (size_t i = 0; i < count; ++i) order[next[colour[i]]++] = static_cast<int32_t>(i);
}

/// The body's rest shape as a surface: vertex neighbours (sorted) and triangle adjacency, for
/// straight walks over it (body-local indices).
class RestSurface {
 public:
  explicit RestSurface(const BodyInfo& body) : p_(body.rest_positions) {
    const int32_t first = body.first_particle;
    const size_t nv = p_.size();
    std::vector<std::vector<int32_t>> nbr(nv);
    for (size_t e = 0; e + 1 < body.edges.size(); e += 2) {
      nbr[body.edges[e] - first].push_back(body.edges[e + 1] - first);
      nbr[body.edges[e + 1] - first].push_back(body.edges[e] - first);
    }
    nbr_start_.assign(nv + 1, 0);
    for (size_t v = 0; v < nv; ++v) {
      std::sort(nbr[v].begin(), nbr[v].end());
      nbr[v].erase(std::unique(nbr[v].begin(), nbr[v].end()), nbr[v].end());
      nbr_start_[v + 1] = nbr_start_[v] + static_cast<int32_t>(nbr[v].size());
      nbr_.insert(nbr_.end(), nbr[v].begin(), nbr[v].end());
    }
    for (int32_t v : body.triangles) tri_.push_back(v - first);
    const size_t nt = tri_.size() / 3;
    std::vector<std::vector<int32_t>> vt(nv);
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) vt[tri_[3 * t + k]].push_back(static_cast<int32_t>(t));
    vt_start_.assign(nv + 1, 0);
    for (size_t v = 0; v < nv; ++v) {
      vt_start_[v + 1] = vt_start_[v] + static_cast<int32_t>(vt[v].size());
      vt_.insert(vt_.end(), vt[v].begin(), vt[v].end());
    }
    // across_[3 t + k]: the triangle on the other side of edge (tri[k], tri[k + 1]); -1 on the
    // boundary, -2 where more than two triangles share the edge.
    across_.assign(tri_.size(), -1);
    std::map<std::pair<int32_t, int32_t>, int32_t> seen;  // edge -> 3 t + k of its first triangle
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        const int32_t a = tri_[3 * t + k], b = tri_[3 * t + (k + 1) % 3];
        const auto [it, fresh] =
            seen.emplace(std::pair{std::min(a, b), std::max(a, b)}, static_cast<int32_t>(3 * t + k));
        if (fresh) continue;
        const int32_t other = it->second;
        if (across_[other] == -1 && other / 3 != static_cast<int32_t>(t)) {
          across_[other] = static_cast<int32_t>(t);
          across_[3 * t + k] = other / 3;
          opposed_ = opposed_ && tri_[other] == b;  // the two triangles run the edge both ways
        } else {
          across_[other] = -2;
          across_[3 * t + k] = -2;
        }
      }
  }

  size_t size() const { return p_.size(); }
  const Vec3& at(int32_t v) const { return p_[v]; }

  /// Whether the rest shape is one flat sheet covering the convex hull of its vertices once: every
  /// vertex on a triangle and in one plane (to 1e-15 of the shape's size), every triangle turning
  /// the same way in it and every interior edge run both ways (a consistently oriented sheet, no
  /// fold), each boundary edge on the hull's boundary (so no hole), and the triangles' areas adding
  /// up to the hull's (to 1e-9: so it is covered once). On such a sheet every straight segment
  /// between two vertices lies on it: straight() holds for every pair, without its walk.
  bool flat_convex() const {
    const size_t nt = tri_.size() / 3;
    if (nt == 0 || !opposed_) return false;
    // A vertex of edges only (a bar hanging off the sheet) is reached over its edges, not across.
    for (size_t v = 0; v < p_.size(); ++v)
      if (vt_start_[v] == vt_start_[v + 1]) return false;
    // The plane: the normal of the largest triangle, through the first vertex.
    Vec3 normal = Vec3::Zero();
    double largest = 0.0;
    for (size_t t = 0; t < nt; ++t) {
      const Vec3 n = (p_[tri_[3 * t + 1]] - p_[tri_[3 * t]]).cross(p_[tri_[3 * t + 2]] - p_[tri_[3 * t]]);
      if (n.squaredNorm() > largest) largest = n.squaredNorm(), normal = n;
    }
    if (!(largest > 0.0)) return false;
    normal.normalize();
    const Vec3 o = p_[0];
    double size = 0.0;
    for (const Vec3& q : p_) size = std::max(size, (q - o).norm());
    const double flat_tol = 1e-15 * size;
    for (const Vec3& q : p_)
      if (!(std::abs(normal.dot(q - o)) <= flat_tol)) return false;
    // Plane coordinates, then the hull (Andrew's monotone chain, collinear points left out).
    const Vec3 u = normal.unitOrthogonal(), v = normal.cross(u);
    std::vector<Eigen::Vector2d> q(p_.size());
    for (size_t i = 0; i < p_.size(); ++i) q[i] = {u.dot(p_[i] - o), v.dot(p_[i] - o)};
    auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
      return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    };
    double area = 0.0, sign = 0.0;
    for (size_t t = 0; t < nt; ++t) {
      const double a = cross2(q[tri_[3 * t]], q[tri_[3 * t + 1]], q[tri_[3 * t + 2]]);
      if (a == 0.0 || (sign != 0.0 && (a > 0.0) != (sign > 0.0))) return false;
      sign = a;
      area += std::abs(a);
    }
    std::vector<int32_t> order(q.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](int32_t a, int32_t b) { return q[a].x() != q[b].x() ? q[a].x() < q[b].x() : q[a].y() < q[b].y(); });
    std::vector<int32_t> hull;
    for (int pass = 0; pass < 2; ++pass) {
      const size_t floor = hull.size();
      for (int32_t i : order) {
        while (hull.size() >= floor + 2 && cross2(q[hull[hull.size() - 2]], q[hull.back()], q[i]) <= 0.0)
          hull.pop_back();
        hull.push_back(i);
      }
      hull.pop_back();
      std::reverse(order.begin(), order.end());
    }
    if (hull.size() < 3) return false;
    double hull_area = 0.0;
    for (size_t i = 1; i + 1 < hull.size(); ++i) hull_area += cross2(q[hull[0]], q[hull[i]], q[hull[i + 1]]);
    if (!(std::abs(area - hull_area) <= 1e-9 * hull_area)) return false;
    // Every boundary edge along one of the hull's edges.
    const double line_tol = 1e-9 * size;
    for (size_t e = 0; e < tri_.size(); ++e) {
      if (across_[e] != -1) continue;
      const Eigen::Vector2d& a = q[tri_[e]];
      const Eigen::Vector2d& b = q[tri_[3 * (e / 3) + (e % 3 + 1) % 3]];  // edge e runs tri[k] -> tri[k + 1]
      bool on = false;
      for (size_t h = 0; h < hull.size() && !on; ++h) {
        const Eigen::Vector2d& h0 = q[hull[h]];
        const Eigen::Vector2d& h1 = q[hull[(h + 1) % hull.size()]];
        const double len = (h1 - h0).norm();
        on = std::abs(cross2(h0, h1, a)) <= line_tol * len && std::abs(cross2(h0, h1, b)) <= line_tol * len;
      }
      if (!on) return false;
    }
    return true;
  }
  std::span<const int32_t> neighbours(int32_t v) const {
    return {nbr_.data() + nbr_start_[v], nbr_.data() + nbr_start_[v + 1]};
  }
  bool adjacent(int32_t a, int32_t b) const {
    const auto n = neighbours(a);
    return std::binary_search(n.begin(), n.end(), b);
  }

  /// Whether the straight segment from vertex a to vertex b lies on the surface: it runs through a
  /// chain of coplanar triangles (crossing their edges or passing through their vertices). Then
  /// its length is a path length over the surface, never shorter than the geodesic distance.
  bool straight(int32_t a, int32_t b) const {
    if (a == b || adjacent(a, b)) return true;
    if (tri_.empty()) return false;
    const Vec3 A = p_[a], d = p_[b] - A;
    const double len = d.norm();
    if (!(len > 0.0)) return false;
    const Vec3 dir = d / len;
    const double tol = 1e-9 * len;
    Vec3 normal = Vec3::Zero(), side = Vec3::Zero();  // the walk's plane, fixed by its first triangle
    bool plane = false;
    auto on_plane = [&](int32_t v) { return std::abs(normal.dot(p_[v] - A)) <= tol; };
    auto s_of = [&](int32_t v) { return side.dot(p_[v] - A); };
    auto t_of = [&](int32_t v) { return dir.dot(p_[v] - A); };
    int32_t vertex = a;  // walking from a vertex on the segment, or
    int32_t tri = -1;    // across edge (e0, e1) out of triangle tri
    int32_t e0 = -1, e1 = -1;
    const size_t max_steps = 4 * (tri_.size() / 3) + 16;
    for (size_t step = 0; step < max_steps; ++step) {
      if (vertex >= 0) {
        if (vertex == b) return true;
        const double tv = t_of(vertex);
        bool moved = false;
        for (int32_t k = vt_start_[vertex]; k < vt_start_[vertex + 1] && !moved; ++k) {
          const int32_t t = vt_[k];
          int32_t c = -1, e = -1;
          for (int j = 0; j < 3; ++j) {
            const int32_t u = tri_[3 * t + j];
            if (u == vertex) continue;
            (c < 0 ? c : e) = u;
          }
          if (!plane) {
            const Vec3 n = (p_[c] - p_[vertex]).cross(p_[e] - p_[vertex]);
            const double nn = n.norm();
            if (!(nn > 0.0) || std::abs(n.dot(dir)) > 1e-9 * nn) continue;
            normal = n / nn;
            side = normal.cross(dir);
            if (!on_plane(c) || !on_plane(e)) continue;
            plane = true;
          } else if (!on_plane(c) || !on_plane(e)) {
            continue;
          }
          const double sc = s_of(c), se = s_of(e);
          for (const int32_t u : {c, e})
            if (std::abs(s_of(u)) <= tol && t_of(u) > tv + tol) {  // along the edge vertex-u
              if (t_of(u) > len + tol) return false;
              vertex = u;
              moved = true;
              break;
            }
          if (moved) break;
          if ((sc > tol && se < -tol) || (sc < -tol && se > tol)) {
            const double tx = t_of(c) + (t_of(e) - t_of(c)) * sc / (sc - se);
            if (tx > tv + tol) {  // through the triangle's interior to its far edge
              tri = t;
              e0 = c;
              e1 = e;
              vertex = -1;
              moved = true;
            }
          }
        }
        if (!moved) return false;
      } else {
        // Cross edge (e0, e1) into the neighbouring triangle.
        int32_t next = -1;
        for (int k = 0; k < 3; ++k) {
          const int32_t a0 = tri_[3 * tri + k], a1 = tri_[3 * tri + (k + 1) % 3];
          if ((a0 == e0 && a1 == e1) || (a0 == e1 && a1 == e0)) next = across_[3 * tri + k];
        }
        if (next < 0) return false;  // off the boundary, or a non-manifold edge
        const int32_t* v = &tri_[3 * next];
        const int32_t r = v[0] != e0 && v[0] != e1 ? v[0] : v[1] != e0 && v[1] != e1 ? v[1] : v[2];
        if (!on_plane(r)) return false;  // over a fold
        if (r == b) return true;
        const double sr = s_of(r);
        if (std::abs(sr) <= tol) {
          if (t_of(r) > len + tol) return false;
          vertex = r;
          continue;
        }
        if ((sr > 0.0) == (s_of(e0) > 0.0))
          e0 = r;  // leaves through (r, e1)
        else
          e1 = r;  // leaves through (e0, r)
        tri = next;
      }
    }
    return false;
  }

 private:
  const std::vector<Vec3>& p_;
  std::vector<int32_t> nbr_start_, nbr_, tri_, vt_start_, vt_, across_;
  bool opposed_ = true;  // every interior edge run one way by one triangle, the other way by the other
};

/// Clears a solver array's chains (Settings::chain_solve): its distances run in their pass.
void drop_chains(SolverArray& a) {
  a.chain_start.clear();
  a.chain_edge.clear();
  a.chain_part.clear();
  a.chain_colour_start.clear();
  a.chain_shared_tail = false;
}

/// An island's rows in projection order: (row kind: 0 distance, 1 planarity, 2 plane offset; index
/// into that kind's solver array).
using IslandRows = std::vector<std::pair<int8_t, int32_t>>;

/// The plan of `islands`, colour by colour: colour c holds islands [colour_start[c],
/// colour_start[c + 1]), which share no particle. Islands of one shape (the rows' kinds on the
/// same local particles, numbered by first use) go in items of up to kItemIslands, per colour.
/// None when an island uses more than kSlots particles.
IslandPlan plan_islands(const Group& g, size_t particle_count, const std::vector<IslandRows>& islands,
                        const std::vector<int32_t>& colour_start, const std::vector<uint8_t>& single) {
  IslandPlan plan;
  std::map<std::vector<int8_t>, int32_t> shape_of;
  std::vector<int32_t> local(particle_count, -1);
  plan.colour_start.push_back(0);
  std::vector<std::vector<int32_t>> order;  // per shape: each island's place in the list
  for (size_t c = 0; c + 1 < colour_start.size(); ++c) {
    std::vector<int32_t> first(plan.shapes.size(), -1);  // per shape: its first island of this colour
    for (int32_t is = colour_start[c]; is < colour_start[c + 1]; ++is) {
      const IslandRows& list = islands[static_cast<size_t>(is)];
      std::vector<int8_t> key, slots;
      std::vector<int32_t> particles, row;
      for (const auto& [kr, i] : list) {
        const SolverArray& a = g.solve[static_cast<int>(IslandPlan::kRowKind[kr])];
        const int n = arity(IslandPlan::kRowKind[kr]);
        key.push_back(kr);
        for (int j = 0; j < 4; ++j) {
          int8_t slot = 0;
          if (j < n) {
            const int32_t p = a.ids[n * static_cast<size_t>(i) + j];
            if (local[p] < 0) {
              if (particles.size() == static_cast<size_t>(IslandPlan::kSlots)) return {};
              local[p] = static_cast<int32_t>(particles.size());
              particles.push_back(p);
            }
            slot = static_cast<int8_t>(local[p]);
          }
          slots.push_back(slot);
          key.push_back(slot);
        }
        row.push_back(i);
      }
      for (int32_t q : particles) local[q] = -1;
      key.push_back(static_cast<int8_t>(particles.size()));
      key.push_back(static_cast<int8_t>(single[static_cast<size_t>(particles[0])]));
      const auto [it, fresh] = shape_of.emplace(key, static_cast<int32_t>(plan.shapes.size()));
      if (fresh) {
        IslandPlan::Shape shape;
        shape.slots = static_cast<int32_t>(particles.size());
        shape.steps = static_cast<int32_t>(list.size());
        for (const auto& [kr, i] : list) shape.kind.push_back(kr);
        shape.slot = slots;
        shape.single = single[static_cast<size_t>(particles[0])] != 0;
        plan.shapes.push_back(std::move(shape));
        first.push_back(-1);
        order.emplace_back();
      }
      IslandPlan::Shape& shape = plan.shapes[it->second];
      if (first[it->second] < 0) first[it->second] = static_cast<int32_t>(shape.islands());
      shape.particle.insert(shape.particle.end(), particles.begin(), particles.end());
      shape.row.insert(shape.row.end(), row.begin(), row.end());
      order[it->second].push_back(is);
    }
    const size_t colour_first = plan.items.size();
    for (size_t sh = 0; sh < plan.shapes.size(); ++sh) {
      if (first[sh] < 0) continue;
      const int32_t count = static_cast<int32_t>(plan.shapes[sh].islands());
      for (int32_t at = first[sh]; at < count; at += IslandPlan::kItemIslands) {
        const int32_t is = order[sh][static_cast<size_t>(at)];
        const double place = static_cast<double>(is - colour_start[c]) / (colour_start[c + 1] - colour_start[c]);
        plan.items.push_back({static_cast<int32_t>(sh), at, std::min(IslandPlan::kItemIslands, count - at), place});
      }
    }
    // A colour's items in the order of their first islands: the threads' parts of a colour, cut at
    // the same places (islands_colour), then cover the same stretch of the list (of a mesh) colour
    // after colour, and share only the particles along their borders (each particle a core reads
    // that another wrote crosses between their caches).
    std::stable_sort(plan.items.begin() + static_cast<std::ptrdiff_t>(colour_first), plan.items.end(),
                     [](const IslandPlan::Item& a, const IslandPlan::Item& b) { return a.place < b.place; });
    plan.colour_start.push_back(static_cast<int32_t>(plan.items.size()));
  }
  return plan;
}

/// The rows as the panels of panel meshes with shared corners hold them: each row goes to the
/// first panel (in layout, then panel order) whose 8 corner particles hold all its particles, each
/// panel's rows by kind and then in the order they were added (so panels alike have one shape),
/// and the panels coloured greedily, in order, so that no two of a colour share a corner particle
/// (four colours on a grid). False when a row lies in no panel or a panel holds over kSteps rows.
bool panel_islands(const Group& g, size_t particle_count, const std::vector<PanelLayout>& layouts,
                   std::vector<IslandRows>& islands, std::vector<int32_t>& colour_start) {
  std::vector<std::array<int32_t, 8>> cells;
  for (const PanelLayout& l : layouts) {
    if (!l.shared) continue;
    for (int32_t p = 0; p < l.panel_count(); ++p) {
      std::array<int32_t, 8> cell{};
      for (int k = 0; k < 4; ++k) cell[k] = l.top(p, k), cell[4 + k] = l.bottom(p, k);
      if (std::all_of(cell.begin(), cell.end(),
                      [&](int32_t q) { return q >= 0 && static_cast<size_t>(q) < particle_count; }))
        cells.push_back(cell);
    }
  }
  if (cells.empty()) return false;
  // The cells on each particle (compressed rows).
  std::vector<int32_t> start(particle_count + 1, 0), on;
  for (const auto& cell : cells)
    for (int32_t q : cell) ++start[static_cast<size_t>(q) + 1];
  for (size_t i = 0; i < particle_count; ++i) start[i + 1] += start[i];
  on.resize(static_cast<size_t>(start.back()));
  std::vector<int32_t> fill(start.begin(), start.end() - 1);
  for (size_t c = 0; c < cells.size(); ++c)
    for (int32_t q : cells[c]) on[static_cast<size_t>(fill[static_cast<size_t>(q)]++)] = static_cast<int32_t>(c);
  // Each row to its first cell; per cell (row kind, the row's constraint index, its solver index).
  std::vector<std::vector<std::array<int32_t, 3>>> rows_of(cells.size());
  for (int kr = 0; kr < IslandPlan::kRowKinds; ++kr) {
    const SolverArray& a = g.solve[static_cast<int>(IslandPlan::kRowKind[kr])];
    const int n = arity(IslandPlan::kRowKind[kr]);
    for (size_t i = 0; i < a.size(); ++i) {
      const int32_t* ids = &a.ids[n * i];
      int32_t home = -1;
      for (int32_t at = start[static_cast<size_t>(ids[0])]; at < start[static_cast<size_t>(ids[0]) + 1] && home < 0;
           ++at) {
        const auto& cell = cells[static_cast<size_t>(on[static_cast<size_t>(at)])];
        bool all = true;
        for (int j = 1; j < n && all; ++j) all = std::find(cell.begin(), cell.end(), ids[j]) != cell.end();
        if (all) home = on[static_cast<size_t>(at)];
      }
      if (home < 0) return false;
      auto& list = rows_of[static_cast<size_t>(home)];
      list.push_back({kr, a.source[i], static_cast<int32_t>(i)});
      if (list.size() > static_cast<size_t>(IslandPlan::kSteps)) return false;
    }
  }
  // Greedy colours: each cell with rows takes the first colour none of its coloured neighbours has.
  std::vector<int8_t> colour(cells.size(), -1);
  int colours = 0;
  for (size_t c = 0; c < cells.size(); ++c) {
    if (rows_of[c].empty()) continue;
    uint64_t taken = 0;
    for (int32_t q : cells[c])
      for (int32_t at = start[static_cast<size_t>(q)]; at < start[static_cast<size_t>(q) + 1]; ++at)
        if (const int8_t k = colour[static_cast<size_t>(on[static_cast<size_t>(at)])]; k >= 0)
          taken |= uint64_t{1} << k;
    const int k = std::countr_one(taken);
    if (k >= 64) return false;
    colour[c] = static_cast<int8_t>(k);
    colours = std::max(colours, k + 1);
  }
  islands.clear();
  colour_start.assign(1, 0);
  for (int k = 0; k < colours; ++k) {
    for (size_t c = 0; c < cells.size(); ++c) {
      if (colour[c] != k) continue;
      auto list = rows_of[c];
      std::sort(list.begin(), list.end());
      IslandRows& rows = islands.emplace_back();
      for (const auto& r : list) rows.emplace_back(static_cast<int8_t>(r[0]), r[2]);
    }
    colour_start.push_back(static_cast<int32_t>(islands.size()));
  }
  return true;
}

/// The group's distance, planarity and plane-offset rows as islands (IslandPlan), or none when they
/// do not form islands or when another kind is projected between them. Islands are the sets of rows
/// joined by shared particles when each is small and the distances are not chained (a panel mesh
/// with welded corners: its panels, in one colour), else a panel mesh's panels with shared corners,
/// coloured (panel_islands), whose plan takes the place of the distances' chains (the caller drops
/// them). The kinds World::project_group projects before the distances are listed here: any other
/// kind with rows keeps the passes.
IslandPlan build_islands(const Group& g, size_t particle_count, const std::vector<PanelLayout>& layouts) {
  for (int k = 0; k < kKindCount; ++k) {
    const Kind kind = static_cast<Kind>(k);
    const bool before =
        kind == Kind::weld || kind == Kind::edge_angle || kind == Kind::dihedral || kind == Kind::tether;
    const bool row = kind == Kind::distance || kind == Kind::planarity || kind == Kind::plane_offset;
    if (!before && !row && g.solve[k].size() > 0) return {};
  }
  // Union-find over the particles the rows join.
  std::vector<int32_t> parent(particle_count, -1);
  auto find = [&](int32_t p) {
    int32_t r = p;
    while (parent[r] >= 0) r = parent[r];
    while (parent[p] >= 0) {
      const int32_t next = parent[p];
      parent[p] = r;
      p = next;
    }
    return r;
  };
  size_t rows = 0;
  for (Kind kind : IslandPlan::kRowKind) {
    const SolverArray& a = g.solve[static_cast<int>(kind)];
    const int n = arity(kind);
    rows += a.size();
    for (size_t i = 0; i < a.size(); ++i)
      for (int j = 1; j < n; ++j) {
        const int32_t r0 = find(a.ids[n * i]), r1 = find(a.ids[n * i + j]);
        if (r0 != r1) parent[std::max(r0, r1)] = std::min(r0, r1);
      }
  }
  if (rows == 0) return {};
  // The particles of panel meshes in single precision: an island takes its first particle's.
  std::vector<uint8_t> single(particle_count, 0);
  for (const PanelLayout& l : layouts)
    if (l.single)
      for (int64_t i = l.first_particle; i < l.first_particle + l.particle_count(); ++i)
        if (static_cast<size_t>(i) < particle_count) single[static_cast<size_t>(i)] = 1;
  // Each island's rows in the passes' order, islands in the order of their first row.
  std::vector<int32_t> island_of(particle_count, -1);
  std::vector<IslandRows> islands;
  bool small = g.solve[static_cast<int>(Kind::distance)].chain_start.empty();
  for (int kr = 0; kr < IslandPlan::kRowKinds && small; ++kr) {
    const SolverArray& a = g.solve[static_cast<int>(IslandPlan::kRowKind[kr])];
    const int n = arity(IslandPlan::kRowKind[kr]);
    for (size_t i = 0; i < a.size() && small; ++i) {
      int32_t& island = island_of[find(a.ids[n * i])];
      if (island < 0) {
        island = static_cast<int32_t>(islands.size());
        islands.emplace_back();
      }
      islands[island].emplace_back(static_cast<int8_t>(kr), static_cast<int32_t>(i));
      small = islands[island].size() <= static_cast<size_t>(IslandPlan::kSteps);
    }
  }
  if (small) {
    IslandPlan plan = plan_islands(g, particle_count, islands, {0, static_cast<int32_t>(islands.size())}, single);
    if (plan.active()) return plan;
  }
  std::vector<int32_t> colour_start;
  if (!panel_islands(g, particle_count, layouts, islands, colour_start)) return {};
  return plan_islands(g, particle_count, islands, colour_start, single);
}

/// Puts a group's solver array of `kind` in a new order within each colour (whose rows share no
/// particle, so any order projects the same): by key(row), ascending, ties in the present order; the
/// last colour keeps its order where its rows may share particles (projected in order). Built before
/// any other index of the rows is kept; returns each old row's new place.
template <class Key>
std::vector<int32_t> reorder_rows(SolverArray& a, Kind kind, Key&& key) {
  std::vector<int32_t> order(a.size());
  std::iota(order.begin(), order.end(), 0);
  const size_t colours = a.colours() - (a.shared_tail ? 1 : 0);
  for (size_t c = 0; c < colours; ++c)
    std::stable_sort(order.begin() + a.colour_start[c], order.begin() + a.colour_start[c + 1],
                     [&](int32_t u, int32_t v) { return key(u) < key(v); });
  const int n = arity(kind), per = multipliers(kind);
  SolverArray sorted = a;
  std::vector<int32_t> new_of(a.size());
  for (size_t j = 0; j < order.size(); ++j) {
    const size_t i = static_cast<size_t>(order[j]);
    new_of[i] = static_cast<int32_t>(j);
    std::copy_n(a.ids.begin() + static_cast<ptrdiff_t>(i) * n, n, sorted.ids.begin() + static_cast<ptrdiff_t>(j) * n);
    std::copy_n(a.lambda.begin() + static_cast<ptrdiff_t>(i) * per, per,
                sorted.lambda.begin() + static_cast<ptrdiff_t>(j) * per);
    sorted.source[j] = a.source[i];
    sorted.rest[j] = a.rest[i];
    sorted.compliance[j] = a.compliance[i];
  }
  a = std::move(sorted);
  return new_of;
}

/// A distance array's rows in memory in the order its chains take them: within each colour, by their
/// places in the chains (SolverArray::chain_edge). A chain step reads each link's rest length, compliance and
/// multiplier and writes the multiplier; in colour order alone consecutive links lie far apart, and on the 256 x 256
/// cloth (4.7 MB of them) those reads missed the caches in every link.
void order_chain_rows(SolverArray& a) {
  if (a.chain_start.empty()) return;
  std::vector<int32_t> place(a.size());
  for (size_t k = 0; k < a.chain_edge.size(); ++k)
    place[static_cast<size_t>(a.chain_edge[k])] = static_cast<int32_t>(k);
  const std::vector<int32_t> new_of =
      reorder_rows(a, Kind::distance, [&](int32_t row) { return place[static_cast<size_t>(row)]; });
  for (int32_t& e : a.chain_edge) e = new_of[static_cast<size_t>(e)];
}

/// A coloured plan's rows in memory as its threads take them: within each colour of the three
/// kinds' arrays (whose rows share no particle, so any order projects the same), the rows go in the
/// order of their items' places in their own colours, and the plan's row indices follow. A thread
/// takes the same stretch of every colour's items (islands_colour), so its rows' multipliers lie
/// together in each array colour and most cache lines of them are written by one core only. A line
/// two cores write crosses between their caches at each colour: on the benchmarks' machine about
/// 250 ns a crossing; on two threads the 32 x 32 drape's three arrays hold 43 such lines of 1,561
/// this way, 159 in the passes' order.
void order_island_rows(Group& g) {
  IslandPlan& plan = g.islands;
  if (plan.colour_start.size() <= 2) return;  // one colour: the rows keep the passes' order
  for (int kr = 0; kr < IslandPlan::kRowKinds; ++kr) {
    SolverArray& a = g.solve[static_cast<int>(IslandPlan::kRowKind[kr])];
    // Per row: its item's place in its colour (IslandPlan::Item::place).
    std::vector<double> place(a.size(), 0.0);
    for (const IslandPlan::Item& item : plan.items) {
      const IslandPlan::Shape& shape = plan.shapes[static_cast<size_t>(item.shape)];
      for (int32_t is = item.first; is < item.first + item.count; ++is)
        for (int32_t st = 0; st < shape.steps; ++st)
          if (shape.kind[static_cast<size_t>(st)] == kr)
            place[static_cast<size_t>(shape.row[static_cast<size_t>(is * shape.steps + st)])] = item.place;
    }
    const std::vector<int32_t> new_of =
        reorder_rows(a, IslandPlan::kRowKind[kr], [&](int32_t row) { return place[static_cast<size_t>(row)]; });
    for (IslandPlan::Shape& shape : plan.shapes)
      for (size_t r = 0; r < shape.row.size(); ++r)
        if (shape.kind[r % static_cast<size_t>(shape.steps)] == kr)
          shape.row[r] = new_of[static_cast<size_t>(shape.row[r])];
  }
}

}  // namespace

std::vector<Attachment> long_range_attachments(const BodyInfo& body, std::span<const int32_t> anchors, int32_t k,
                                               bool walk_always) {
  std::vector<Attachment> out;
  if (k <= 0 || anchors.empty()) return out;
  const RestSurface surface(body);
  // A straight link's walk crosses every triangle between its ends: on a fine flat sheet the walks
  // are most of the cost (n^3 on an n x n grid). A flat, convex sheet has every link on it.
  const bool all_straight = !walk_always && surface.flat_convex();
  const int32_t first = body.first_particle;
  const size_t nv = surface.size();
  // Up to k labels per vertex (source, distance, parent), settled in increasing distance: a
  // multi-source Dijkstra over the edges that, as in Theta*, tries to reach each vertex straight
  // from its predecessor's parent. A straight link is taken only if it lies on the surface, so every
  // distance is the length of a path over the surface: never shorter than the geodesic (safe for a
  // tether), and exact on a flat, convex piece of it.
  struct Label {
    int32_t source;
    int32_t parent;
    double dist;
  };
  std::vector<Label> labels(nv * static_cast<size_t>(k));
  std::vector<int32_t> count(nv, 0);
  auto find = [&](int32_t v, int32_t s) -> const Label* {
    for (int32_t i = 0; i < count[v]; ++i)
      if (labels[v * static_cast<size_t>(k) + i].source == s) return &labels[v * static_cast<size_t>(k) + i];
    return nullptr;
  };
  struct Entry {
    double dist;
    int32_t vertex, source, parent;
    bool operator>(const Entry& o) const {
      if (dist != o.dist) return dist > o.dist;
      if (vertex != o.vertex) return vertex > o.vertex;
      if (source != o.source) return source > o.source;
      return parent > o.parent;
    }
  };
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (int32_t a : anchors) queue.push(Entry{0.0, a - first, a - first, a - first});
  while (!queue.empty()) {
    const Entry e = queue.top();
    queue.pop();
    const int32_t v = e.vertex, s = e.source;
    if (count[v] >= k || find(v, s)) continue;
    if (e.parent != v && !all_straight && !surface.straight(e.parent, v)) {
      // The straight link leaves the surface: come from the best settled neighbour instead.
      double best = std::numeric_limits<double>::infinity();
      int32_t from = -1;
      for (int32_t u : surface.neighbours(v))
        if (const Label* l = find(u, s)) {
          const double d = l->dist + (surface.at(u) - surface.at(v)).norm();
          if (d < best) best = d, from = u;
        }
      if (from >= 0) queue.push(Entry{best, v, s, from});
      continue;
    }
    labels[v * static_cast<size_t>(k) + count[v]++] = Label{s, e.parent, e.dist};
    const int32_t via = v == s ? v : e.parent;
    const double via_dist = v == s ? 0.0 : find(via, s)->dist;
    for (int32_t u : surface.neighbours(v))
      if (count[u] < k && !find(u, s))
        queue.push(Entry{via_dist + (surface.at(via) - surface.at(u)).norm(), u, s, via});
  }
  for (size_t v = 0; v < nv; ++v)
    for (int32_t i = 0; i < count[v]; ++i) {
      const Label& l = labels[v * static_cast<size_t>(k) + i];
      if (l.source != static_cast<int32_t>(v) && l.dist > 0.0)
        out.push_back(Attachment{first + static_cast<int32_t>(v), first + l.source, l.dist});
    }
  return out;
}

/// Lays a distance array's constraints end to end into chains (SolverArray::chain_start): from each
/// constraint not yet in a chain, in array order, the chain grows at both ends: through a particle
/// that two of the array's constraints meet at (a cable, a rope, a polyline of any shape) by the
/// other one, whatever the angle, unless a third joins their far ends (a triangle's corner); through
/// any other particle by the constraint that continues it
/// straightest (over `rest`, the particles' rest positions), within about 26 degrees; never to a
/// particle the chain already has. On a regular grid the chains are its rows, columns and
/// diagonals; a cable is one chain however it curves; elsewhere they are whatever straight runs the
/// mesh has, down to single constraints, which the chain pass projects exactly as the plain pass
/// does. Without `straight_runs` (realignment passes) a chain grows through particles of two
/// constraints only: cables, not a grid's rows; those were measured to slow the realigned
/// convergence of the hanging-net example (its square's symmetry 1.3e-7 -> 1.0e-6 m after 600
/// frames) where a cable's one-at-a-time projection is what converges worst.
void build_chains(SolverArray& a, const std::vector<Vec3>& rest, bool straight_runs) {
  constexpr double kStraight = 0.9;  // cosine: the turn a chain may take at a particle
  const size_t n = a.size();
  std::vector<int32_t> start(rest.size() + 1, 0), incident(2 * n);
  for (int32_t p : a.ids) ++start[p + 1];
  for (size_t p = 0; p < rest.size(); ++p) start[p + 1] += start[p];
  std::vector<int32_t> fill(start.begin(), start.end() - 1);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 2; ++k) incident[fill[a.ids[2 * i + k]]++] = static_cast<int32_t>(i);
  std::vector<uint8_t> used(n, 0), in_chain(rest.size(), 0);
  auto other = [&](int32_t e, int32_t p) { return a.ids[2 * e] == p ? a.ids[2 * e + 1] : a.ids[2 * e]; };
  // Whether the two constraints at `at` (a particle of two) end at particles joined by a third.
  auto closes_triangle = [&](int32_t at) {
    const int32_t q0 = other(incident[start[at]], at), q1 = other(incident[start[at] + 1], at);
    for (int32_t j = start[q0]; j < start[q0 + 1]; ++j)
      if (other(incident[j], q0) == q1) return true;
    return false;
  };
  // Grows the chain from `at` (reached from `from`), appending its constraints and particles.
  auto grow = [&](int32_t from, int32_t at, std::vector<int32_t>& edges, std::vector<int32_t>& parts) {
    for (;;) {
      const Vec3 dir = (rest[at] - rest[from]).normalized();
      int32_t best = -1;
      // Two constraints meet here: the chain goes on through the other, at any angle (the rest
      // shape of a hand-built cable may be anything, even all at one point), unless a third joins
      // their far ends: then `at` is a triangle's corner (a cloth grid's free corner), and turning
      // there joins a row to a column. (Measured on the 128 x 128 acceptance cloth: through the two
      // free corners, 0.67 % max edge strain after 200 frames and 45 frames above 1 %; not, 0.54 %
      // and 36.)
      const bool through = start[at + 1] - start[at] == 2 && !closes_triangle(at);
      if (!through && !straight_runs) return;
      double best_cos = through ? -std::numeric_limits<double>::infinity() : kStraight;
      for (int32_t j = start[at]; j < start[at + 1]; ++j) {
        const int32_t e = incident[j], q = other(e, at);
        if (used[e] || in_chain[q]) continue;
        const double c = through ? 0.0 : (rest[q] - rest[at]).normalized().dot(dir);
        if (c > best_cos) best_cos = c, best = e;
      }
      if (best < 0) return;
      used[best] = 1;
      from = at;
      at = other(best, at);
      in_chain[at] = 1;
      edges.push_back(best);
      parts.push_back(at);
    }
  };
  a.chain_start.assign(1, 0);
  a.chain_edge.clear();
  a.chain_part.clear();
  std::vector<int32_t> fe, fp, be, bp;
  for (size_t i = 0; i < n; ++i) {
    if (used[i]) continue;
    used[i] = 1;
    const int32_t p0 = a.ids[2 * i], p1 = a.ids[2 * i + 1];
    fe.clear(), fp.clear(), be.clear(), bp.clear();
    in_chain[p0] = in_chain[p1] = 1;
    grow(p0, p1, fe, fp);
    grow(p1, p0, be, bp);
    a.chain_part.insert(a.chain_part.end(), bp.rbegin(), bp.rend());
    a.chain_part.insert(a.chain_part.end(), {p0, p1});
    a.chain_part.insert(a.chain_part.end(), fp.begin(), fp.end());
    a.chain_edge.insert(a.chain_edge.end(), be.rbegin(), be.rend());
    a.chain_edge.push_back(static_cast<int32_t>(i));
    a.chain_edge.insert(a.chain_edge.end(), fe.begin(), fe.end());
    a.chain_start.push_back(static_cast<int32_t>(a.chain_edge.size()));
    in_chain[p0] = in_chain[p1] = 0;
    for (int32_t q : fp) in_chain[q] = 0;
    for (int32_t q : bp) in_chain[q] = 0;
  }
  // Colour the chains (greedy, in order: the lowest colour none of its particles has yet), then order
  // them by colour and, within one, longest first, so that neighbours have similar lengths.
  constexpr int kMaxColours = 64;
  const size_t chains = a.chain_start.size() - 1;
  std::vector<uint64_t> taken(rest.size(), 0);
  std::vector<int32_t> colour(chains);
  for (size_t c = 0; c < chains; ++c) {
    const int32_t* parts = &a.chain_part[a.chain_start[c] + c];
    const int32_t count = a.chain_start[c + 1] - a.chain_start[c] + 1;
    uint64_t used_colours = 0;
    for (int32_t j = 0; j < count; ++j) used_colours |= taken[parts[j]];
    colour[c] = std::countr_one(used_colours);  // 64 when all are taken: the shared tail
    if (colour[c] < kMaxColours)
      for (int32_t j = 0; j < count; ++j) taken[parts[j]] |= uint64_t{1} << colour[c];
  }
  std::vector<int32_t> order(chains);
  for (size_t c = 0; c < chains; ++c) order[c] = static_cast<int32_t>(c);
  auto length = [&](int32_t c) { return a.chain_start[c + 1] - a.chain_start[c]; };
  std::stable_sort(order.begin(), order.end(), [&](int32_t l, int32_t r) {
    return colour[l] != colour[r] ? colour[l] < colour[r] : length(l) > length(r);
  });
  std::vector<int32_t> sorted_start{0}, edge, part;
  edge.reserve(a.chain_edge.size());
  part.reserve(a.chain_part.size());
  a.chain_colour_start.assign(1, 0);
  for (size_t j = 0; j < chains; ++j) {
    const int32_t c = order[j], first = a.chain_start[c], m = length(c);
    edge.insert(edge.end(), a.chain_edge.begin() + first, a.chain_edge.begin() + first + m);
    part.insert(part.end(), a.chain_part.begin() + first + c, a.chain_part.begin() + first + c + m + 1);
    sorted_start.push_back(static_cast<int32_t>(edge.size()));
    if (j + 1 == chains || colour[order[j + 1]] != colour[c])
      a.chain_colour_start.push_back(static_cast<int32_t>(j + 1));
  }
  a.chain_shared_tail = colour[order.back()] == kMaxColours;
  a.chain_start = std::move(sorted_start);
  a.chain_edge = std::move(edge);
  a.chain_part = std::move(part);
}

void World::rebuild_solver() {
  std::vector<uint8_t> none(x_.size(), 0);
  std::vector<int32_t> order;
  std::vector<Vec3> rest;
  size_t longest = 0;
  for (Group& g : groups_) {
    if (!g.alive) continue;
    for (int k = 0; k < kKindCount; ++k) {
      const ConstraintArray& a = g.arrays[k];
      SolverArray& sa = g.solve[k];
      const int n = arity(static_cast<Kind>(k));
      const int per = multipliers(static_cast<Kind>(k));
      sa = SolverArray{};
      colour_order(a.ids.data(), a.size(), n, x_.size(), none, order, sa.colour_start, sa.shared_tail);
      for (int32_t i : order) {
        sa.ids.insert(sa.ids.end(), a.ids.begin() + static_cast<ptrdiff_t>(i) * n,
                      a.ids.begin() + static_cast<ptrdiff_t>(i + 1) * n);
        sa.source.push_back(i);
        sa.compliance.push_back(a.compliance[i]);
        sa.rest.push_back(a.rest_now[i]);
      }
      sa.lambda.assign(per * a.size(), 0.0);
      if (k == static_cast<int>(Kind::distance) && settings_.chain_solve && sa.size() > 0) {
        if (rest.empty()) {  // every particle's rest position: its body's rest shape
          rest.assign(x_.size(), Vec3::Zero());
          for (const BodyInfo& b : bodies_)
            std::copy(b.rest_positions.begin(), b.rest_positions.end(), rest.begin() + b.first_particle);
        }
        build_chains(sa, rest, settings_.realign_passes == 0);
        size_t own = 0;
        for (size_t c = 0; c + 1 < sa.chain_start.size(); ++c)
          own = std::max<size_t>(own, static_cast<size_t>(sa.chain_start[c + 1] - sa.chain_start[c]));
        // Chains of one constraint each (a panel mesh's braced quads and slides: no straight run
        // goes on past a panel): the chain pass projects them as the plain pass does, at 2.5 times
        // its cost (4.5-8 % of the 32 x 32 drape's frame against 1.8 %), so the array keeps none.
        if (own <= 1) drop_chains(sa);
        longest = std::max(longest, own);
      }
    }
    g.tethers = SolverArray{};
    g.islands = build_islands(g, x_.size(), panel_layouts_);
    // A panel mesh with shared corners: its panels are the islands, not its edges' runs.
    if (g.islands.active()) {
      drop_chains(g.solve[static_cast<int>(Kind::distance)]);
      order_island_rows(g);
    } else {
      order_chain_rows(g.solve[static_cast<int>(Kind::distance)]);
    }
  }
  // Automatic long-range attachments: every particle of an inextensible body to its nearest
  // anchors (hard-pinned or immovable particles of the body), in the body's stretch group.
  if (settings_.tethers > 0) {
    std::vector<uint8_t> anchor(x_.size(), 0);
    for (size_t i = 0; i < x_.size(); ++i) anchor[i] = w_[i] == 0.0;
    for (size_t bi = 0; bi < bodies_.size(); ++bi) {
      const BodyInfo& b = bodies_[bi];
      if (!b.generated_stretch || b.material.stretch_compliance != 0.0 || !find_group(b.stretch_group)) continue;
      std::vector<int32_t> anchors;
      for (int32_t i = b.first_particle; i < b.first_particle + b.particle_count; ++i)
        if (anchor[i]) anchors.push_back(i);
      if (anchors.empty() || anchors.size() == static_cast<size_t>(b.particle_count)) continue;
      TetherCache& cache = tether_cache_[bi];
      if (cache.anchors != anchors || cache.per_particle != settings_.tethers) {
        cache.anchors = anchors;
        cache.per_particle = settings_.tethers;
        cache.links = long_range_attachments(b, anchors, settings_.tethers);
      }
      SolverArray& t = groups_[b.stretch_group.index].tethers;
      for (const Attachment& link : cache.links) {
        t.ids.insert(t.ids.end(), {link.particle, link.anchor});
        t.source.push_back(-1);
        t.base_rest.push_back(link.rest);
        t.body.push_back(static_cast<int32_t>(bi));
        t.rest.push_back(link.rest);
        t.compliance.push_back(0.0);
      }
    }
    for (Group& g : groups_) {
      SolverArray& t = g.tethers;
      if (!g.alive || t.size() == 0) continue;
      colour_order(t.ids.data(), t.size(), 2, x_.size(), anchor, order, t.colour_start, t.shared_tail);
      SolverArray sorted = t;
      sorted.ids.clear();
      for (size_t j = 0; j < order.size(); ++j) {
        const int32_t i = order[j];
        sorted.ids.insert(sorted.ids.end(), {t.ids[2 * i], t.ids[2 * i + 1]});
        sorted.base_rest[j] = t.base_rest[i];
        sorted.body[j] = t.body[i];
        sorted.rest[j] = t.rest[i];
      }
      // The runs: a particle's tethers, in the order made (long_range_attachments lists a particle's
      // attachments together, nearest anchor first).
      sorted.run_start.assign(1, 0);
      sorted.run_entry.resize(order.size());
      std::vector<int32_t> position(order.size());
      for (size_t j = 0; j < order.size(); ++j) position[order[j]] = static_cast<int32_t>(j);
      for (size_t i = 0; i < order.size(); ++i) {
        if (i > 0 && t.ids[2 * i] != t.ids[2 * i - 2]) sorted.run_start.push_back(static_cast<int32_t>(i));
        sorted.run_entry[i] = position[i];
      }
      sorted.run_start.push_back(static_cast<int32_t>(order.size()));
      for (size_t r = 0; r + 1 < sorted.run_start.size(); ++r)
        (sorted.run_start[r + 1] - sorted.run_start[r] == 2 ? sorted.pair_runs : sorted.other_runs)
            .push_back(static_cast<int32_t>(r));
      t = std::move(sorted);
      t.lambda.assign(t.size(), 0.0);
    }
  }
  chain_scratch_.assign(kChainScratch * (longest + 1) * static_cast<size_t>(pool_->size()), 0.0);
  find_pinned_slots();
  find_particle_parts();
  solver_dirty_ = false;
  refresh_rest();
}

void World::find_particle_parts() {
  particle_runs_.clear();
  const int parts = pool_->size();
  if (parts <= 1) return;
  std::vector<int32_t> part(x_.size(), -1);
  bool any = false;
  for (int32_t slot : order_) {
    const IslandPlan& plan = groups_[static_cast<size_t>(slot)].islands;
    if (plan.colour_start.size() <= 2) continue;  // one colour or none: cut by equal item counts
    any = true;
    // islands_colour's cut: an item placed at `place` goes to part floor(place * parts).
    for (size_t i = 0; i < plan.items.size(); ++i) {
      const int32_t p = std::min(parts - 1, static_cast<int32_t>(plan.items[i].place * parts));
      plan.each_particle(i, [&](size_t k) {
        if (part[k] < 0) part[k] = p;
      });
    }
  }
  if (!any) return;
  const size_t n = x_.size();
  for (size_t i = 0; i < n; ++i) {
    const int32_t p = part[i] >= 0 ? part[i] : static_cast<int32_t>(i * static_cast<size_t>(parts) / n);
    if (!particle_runs_.empty() && particle_runs_.back()[2] == p && particle_runs_.back()[1] == static_cast<int32_t>(i))
      ++particle_runs_.back()[1];
    else
      particle_runs_.push_back({static_cast<int32_t>(i), static_cast<int32_t>(i + 1), p});
  }
}

// --- pins --------------------------------------------------------------------------------------

Id World::create_pin(const PinDesc& desc) {
  check_particle(desc.particle, "pin particle");
  for (int k = 0; k < 3; ++k) check_finite(desc.target[k], "pin target");
  check_non_negative(desc.compliance, "pin compliance");
  const int32_t support = static_cast<int32_t>(desc.support);
  if (support < 0 || support >= kPinSupportCount)
    invalid("pin support " + std::to_string(support) +
            " is not point (0), plane (1), line (2), polyline (3), axes (4) or mesh (5)");
  for (int k = 0; k < 3; ++k) check_finite(desc.axis[k], "pin axis");
  const bool polyline = desc.support == PinSupport::polyline;
  if (polyline) {
    const size_t n = desc.curve.size();
    if (n < (desc.closed ? 3u : 2u) || n > static_cast<size_t>(limits::kMaxParticles))
      invalid("a polyline support needs 2 to 2097152 points (3 when closed); " + std::to_string(n) + " given");
    for (const Vec3& c : desc.curve)
      for (int k = 0; k < 3; ++k) check_finite(c[k], "polyline point");
    const size_t segments = desc.closed ? n : n - 1;
    for (size_t s = 0; s < segments; ++s) {
      const double length2 = (desc.curve[(s + 1) % n] - desc.curve[s]).squaredNorm();
      // Squared, so a segment too short to divide by (squared length 0 or below the smallest
      // positive double's range) is degenerate too.
      if (!(length2 >= limits::kMinPositive) || !std::isfinite(length2))
        invalid("polyline segment " + std::to_string(s) + " (points " + std::to_string(s) + " and " +
                std::to_string((s + 1) % n) + ") has zero length (or one beyond range): it is degenerate");
    }
  } else if (desc.support == PinSupport::mesh) {
    const size_t n = desc.curve.size(), t = desc.triangles.size();
    if (n < 3u || n > static_cast<size_t>(limits::kMaxParticles))
      invalid("a mesh support needs 3 to 2097152 vertices; " + std::to_string(n) + " given");
    if (t < 1u || t > static_cast<size_t>(limits::kMaxConstraints))
      invalid("a mesh support needs 1 to 16777216 triangles; " + std::to_string(t) + " given");
    for (const Vec3& c : desc.curve)
      for (int k = 0; k < 3; ++k) check_finite(c[k], "mesh support vertex");
    for (size_t f = 0; f < t; ++f) {
      const auto& tri = desc.triangles[f];
      for (int k = 0; k < 3; ++k)
        if (tri[k] < 0 || static_cast<size_t>(tri[k]) >= n)
          invalid("mesh support triangle " + std::to_string(f) + " vertex " + std::to_string(tri[k]) +
                  " is outside [0, " + std::to_string(n) + ")");
      // Zero area: its sides parallel to 1e-12 (a sliver whose closest points are rounding), or a
      // squared area too small to divide by (as a polyline's segments) or beyond range.
      const Vec3 a = desc.curve[static_cast<size_t>(tri[0])], b = desc.curve[static_cast<size_t>(tri[1])],
                 c = desc.curve[static_cast<size_t>(tri[2])];
      const double area2 = (b - a).cross(c - a).squaredNorm();
      const double sides2 = (b - a).squaredNorm() * (c - a).squaredNorm();
      if (!(area2 >= limits::kMinPositive) || !std::isfinite(area2) || !(area2 > 1e-24 * sides2))
        invalid("mesh support triangle " + std::to_string(f) + " (vertices " + std::to_string(tri[0]) + ", " +
                std::to_string(tri[1]) + ", " + std::to_string(tri[2]) +
                ") has zero area (its sides parallel, or an area beyond range): it is degenerate");
    }
  } else if (!desc.curve.empty()) {
    invalid("polyline points are given for a support that is not a polyline");
  }
  if (desc.support != PinSupport::mesh && !desc.triangles.empty())
    invalid("mesh triangles are given for a support that is not a mesh");
  const bool axes = desc.support == PinSupport::axes;
  if (axes) {
    for (int k = 0; k < 3; ++k)
      if (desc.axis[k] != 0.0 && desc.axis[k] != 1.0)
        invalid("an axes support's axis[" + std::to_string(k) + "] is " + std::to_string(desc.axis[k]) +
                ": each component is 1 (that coordinate held) or 0 (free)");
    if (desc.axis == Vec3::Zero())
      invalid("an axes support holds no coordinate (axis is {0, 0, 0}): hold at least one");
  }
  const double axis_length = desc.axis.norm();
  const bool on_mesh = desc.support == PinSupport::mesh;
  if (desc.support != PinSupport::point && !polyline && !axes && !on_mesh &&
      !(axis_length > 0.0 && std::isfinite(axis_length) && (desc.axis / axis_length).allFinite()))
    invalid(std::string("pin axis is zero (or too short to normalise): a ") +
            (desc.support == PinSupport::plane ? "plane" : "line") + " support needs a direction (its " +
            (desc.support == PinSupport::plane ? "normal" : "line") + ")");
  const bool kinematic = desc.compliance == 0.0 && desc.support == PinSupport::point;
  Id gid;
  if (kinematic) {
    if (hard_pin_of_[desc.particle] >= 0)
      invalid("particle " + std::to_string(desc.particle) + " already has a hard pin");
  } else {
    gid = resolve_group(desc.group);
  }
  Pin p;
  p.particle = desc.particle;
  p.target = desc.target;
  p.compliance = desc.compliance;
  p.group = gid;
  p.support = desc.support;
  if (desc.support != PinSupport::point && !polyline && !on_mesh)
    p.axis = axes ? Vec3(desc.axis.cwiseAbs()) : Vec3(desc.axis / axis_length);  // -0 as 0
  p.curve = desc.curve;
  p.closed = polyline && desc.closed;
  p.triangles = desc.triangles;
  const Id id = slots::create(pins_, p);
  const int32_t slot = static_cast<int32_t>(id.index);
  if (kinematic) {
    hard_pin_of_[desc.particle] = slot;
    w_[desc.particle] = 0.0;
    solver_dirty_ = true;  // automatic tethers attach to hard pins
  } else {
    group_mut(gid).soft_pins.push_back(slot);
  }
  return id;
}

const Pin& World::pin(Id id) const {
  const Pin* p = slots::find(pins_, id);
  if (p == nullptr) fail(ErrorCode::stale_id, "pin id does not name a live pin of this world");
  return *p;
}

void World::destroy_pin(Id id) {
  const Pin& p = pin(id);
  if (p.kinematic()) {
    hard_pin_of_[p.particle] = -1;
    w_[p.particle] = inv_mass_[p.particle];
    solver_dirty_ = true;
  } else {
    auto& list = group_mut(p.group).soft_pins;
    list.erase(std::find(list.begin(), list.end(), static_cast<int32_t>(id.index)));
  }
  slots::destroy(pins_, id);
}

void World::set_pin_target(Id id, const Vec3& target) {
  pin(id);
  for (int k = 0; k < 3; ++k) check_finite(target[k], "pin target");
  pins_[id.index].target = target;
}

size_t World::pin_count() const {
  return slots::live_count(pins_);
}

// --- colliders ---------------------------------------------------------------------------------

namespace {
void check_transform(const Vec3& position, const Eigen::Quaterniond& rotation) {
  for (int k = 0; k < 3; ++k) check_finite(position[k], "collider position");
  for (int k = 0; k < 4; ++k) check_finite(rotation.coeffs()[k], "collider rotation");
  if (std::abs(rotation.norm() - 1.0) > limits::kUnitQuaternionTolerance)
    invalid("collider rotation must be a unit quaternion");
}
}  // namespace

Id World::create_collider(const ColliderDesc& desc) {
  const int shape = static_cast<int>(desc.shape);
  if (shape < 0 || shape >= kColliderShapeCount) invalid("unknown collider shape " + std::to_string(shape));
  check_transform(desc.position, desc.rotation);
  check_non_negative(desc.thickness, "collider thickness");
  check_non_negative(desc.friction_static, "collider friction_static");
  check_non_negative(desc.friction_dynamic, "collider friction_dynamic");
  if (desc.shape == ColliderShape::sphere) check_positive(desc.radius, "sphere radius");
  std::shared_ptr<const ColliderGeometry> geometry = build_collider_geometry(desc);  // validates the shape
  Collider c;
  c.desc = desc;
  c.desc.rotation = unit_rotation(desc.rotation);
  c.geometry = std::move(geometry);
  c.frame_position = c.position = c.position_prev = desc.position;
  c.frame_rotation = c.rotation = c.rotation_prev = c.desc.rotation;
  return slots::create(colliders_, std::move(c));
}

const Collider& World::collider(Id id) const {
  const Collider* c = slots::find(colliders_, id);
  if (c == nullptr) fail(ErrorCode::stale_id, "collider id does not name a live collider of this world");
  return *c;
}

void World::destroy_collider(Id id) {
  collider(id);
  slots::destroy(colliders_, id);
}

void World::set_collider_transform(Id id, const Vec3& position, const Eigen::Quaterniond& rotation) {
  collider(id);
  check_transform(position, rotation);
  colliders_[id.index].desc.position = position;
  colliders_[id.index].desc.rotation = unit_rotation(rotation);
}

size_t World::collider_count() const {
  return slots::live_count(colliders_);
}

// --- particles ---------------------------------------------------------------------------------

void World::set_positions(int32_t first, std::span<const double> xyz) {
  if (xyz.size() % 3 != 0) invalid("position array length is not a multiple of 3");
  const int64_t n = static_cast<int64_t>(xyz.size() / 3);
  if (first < 0 || first + n > particle_count()) invalid("particle range is outside the world's particles");
  for (double c : xyz) check_finite(c, "position coordinate");
  for (int64_t i = 0; i < n; ++i) x_[first + i] = at(xyz, i);
}

void World::set_velocities(int32_t first, std::span<const double> xyz) {
  if (xyz.size() % 3 != 0) invalid("velocity array length is not a multiple of 3");
  const int64_t n = static_cast<int64_t>(xyz.size() / 3);
  if (first < 0 || first + n > particle_count()) invalid("particle range is outside the world's particles");
  for (double c : xyz) check_finite(c, "velocity coordinate");
  for (int64_t i = 0; i < n; ++i) v_[first + i] = at(xyz, i);
}

void World::set_loads(int32_t first, std::span<const double> xyz) {
  if (xyz.size() % 3 != 0) invalid("load array length is not a multiple of 3");
  const int64_t n = static_cast<int64_t>(xyz.size() / 3);
  if (first < 0 || first + n > particle_count()) invalid("particle range is outside the world's particles");
  for (double c : xyz) check_finite(c, "load coordinate");
  for (int64_t i = 0; i < n; ++i) load_[first + i] = at(xyz, i);
}

}  // namespace embra
