// fuzz_capi: a libFuzzer target that reads its input as a sequence of C ABI calls on one world,
// through embra.h only, as a host would make them: bodies, constraints of every kind, pins,
// colliders, fields, panel meshes and groups built from arrays with random indices, values (NaN,
// Inf, 1e300 and its neighbours, denormals) and compliances; steps; reads; saves and reloads.
//
// What it checks, beside the sanitizers (address, undefined behaviour) and the absence of crashes
// and hangs:
//   - every call returns a known status, never EMBRA_ERROR_INTERNAL (a bug) or EMBRA_ERROR_LOCKED
//     (one thread only);
//   - a refused call changes nothing: the world's saved JSON is byte-identical before and after;
//   - a read changes nothing either, and the world can always be saved;
//   - every position, velocity, pin target and collider pose read back is finite;
//   - embra_world_cancel stops the next step with EMBRA_ERROR_CANCELLED;
//   - what the C API accepted, the scene format reads back: the saved world loads, saves to the
//     same bytes, and steps to the same bytes as the world it was saved from.
// A failed check prints the calls made so far and aborts, so libFuzzer reports the input.
// EMBRA_FUZZ_TRACE=1 in the environment prints every call as it is made.
//
// Work is bounded by the target (world size, passes per step), so an input never takes long.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "embra/embra.h"
#include "fuzz_support.hpp"

namespace {

using fuzz::check_finite;
using fuzz::check_state;
using fuzz::fail;
using fuzz::fmt;
using fuzz::note;
using fuzz::save;

constexpr int32_t kMaxParticlesInFuzz = 600;  // body and panel creation stop above this
constexpr int64_t kMaxStepWork = 300000;      // passes x (particles + constraints) per step
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The input, read front to back; zeros once it runs out.
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : p_(data), n_(size) {}
  bool done() const { return i_ >= n_; }
  uint8_t u8() { return i_ < n_ ? p_[i_++] : 0; }
  uint16_t u16() { return static_cast<uint16_t>(u8() | (u8() << 8)); }
  uint32_t u32() { return static_cast<uint32_t>(u16()) | (static_cast<uint32_t>(u16()) << 16); }
  bool chance(int one_in) { return u8() % one_in == 0; }

  /// A double: mostly ordinary magnitudes, often an edge of a range, sometimes raw bits.
  double value() {
    static const double table[] = {0.0,
                                   -0.0,
                                   1.0,
                                   -1.0,
                                   0.5,
                                   0.1,
                                   1e-3,
                                   1e-6,
                                   1e-9,
                                   1e-12,
                                   10.0,
                                   100.0,
                                   1e3,
                                   1e6,
                                   std::nextafter(1e6, kInf),
                                   1e9,
                                   1e12,
                                   std::nextafter(1e12, kInf),
                                   1e15,
                                   1e100,
                                   1e299,
                                   1e300,
                                   std::nextafter(1e300, kInf),
                                   1e301,
                                   -1e300,
                                   -std::nextafter(1e300, kInf),
                                   std::numeric_limits<double>::max(),
                                   -std::numeric_limits<double>::max(),
                                   1e-299,
                                   1e-300,
                                   std::nextafter(1e-300, 0.0),
                                   1e-301,
                                   -1e-300,
                                   std::numeric_limits<double>::min(),
                                   std::numeric_limits<double>::denorm_min(),
                                   kNaN,
                                   -kNaN,
                                   kInf,
                                   -kInf,
                                   3.141592653589793,
                                   -3.141592653589793,
                                   6.283185307179586,
                                   0.99,
                                   1.01,
                                   64.0,
                                   1e4};
    constexpr size_t n = sizeof table / sizeof table[0];
    const uint8_t b = u8();
    if (b < 96) return static_cast<int8_t>(u8()) / 8.0;  // [-16, 16) in eighths
    if (b < 128) return (1 + u8()) / 64.0;               // (0, 4]
    if (b < 248) return table[(b - 128) % n];
    double d;
    const uint64_t bits = static_cast<uint64_t>(u32()) | (static_cast<uint64_t>(u32()) << 32);
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }

  /// A small coordinate: [-2, 2) in sixteenths.
  double coordinate() { return static_cast<int8_t>(u8()) / 64.0; }

  /// An int32 setting: mostly small, often an edge of a range.
  int32_t integer() {
    static const int32_t table[] = {0,   1,    -1,   2,     3,      4,      63,        64,        65,    100,   101,
                                    990, 991,  1000, 1001,  9999,   10000,  10001,     100000,    46341, 65536, 1 << 21,
                                    -2,  -100, 4096, 40000, 100001, 100000, INT32_MAX, INT32_MIN, 8,     16};
    const uint8_t b = u8();
    if (b < 128) return b % 16 - 2;
    return table[b % (sizeof table / sizeof table[0])];
  }

 private:
  const uint8_t* p_;
  size_t n_;
  size_t i_ = 0;
};

template <class Id>
Id pick_id(Bytes& in, const std::vector<Id>& known) {
  const uint8_t k = in.u8() % 16;
  if (k == 0 || known.empty()) return Id{0, 0};
  if (k == 1) return Id{in.u32(), in.u32()};
  const Id& id = known[in.u8() % known.size()];
  if (k == 2) return Id{id.index, id.generation + 1};
  if (k == 3) return Id{id.index + 1, id.generation};
  return id;
}

/// One input's session: the world, what was created in it, the trace of calls.
class Session {
 public:
  explicit Session(Bytes& in) : in_(in) { fuzz::trace().clear(); }
  ~Session() { embra_world_destroy(world_); }

  void run();

 private:
  Bytes& in_;
  embra_world* world_ = nullptr;
  std::string saved_;  // the world's saved JSON after the last accepted change
  std::vector<embra_group_id> groups_;
  std::vector<embra_body_id> bodies_;
  std::vector<embra_pin_id> pins_;
  std::vector<embra_collider_id> colliders_;
  std::vector<embra_field_id> fields_;

  int32_t particle_count() {
    embra_world_counts c{};
    if (embra_world_get_counts(world_, &c) != EMBRA_OK) fail("embra_world_get_counts refused on a live world");
    return c.particles;
  }

  int32_t particle() {
    const int32_t n = particle_count();
    switch (in_.u8() % 16) {
      case 0:
        return -1;
      case 1:
        return n;
      case 2:
        return INT32_MAX;
      case 3:
        return INT32_MIN;
      default:
        return n > 0 ? in_.u16() % n : 0;
    }
  }

  int32_t version(int32_t right) { return in_.chance(64) ? right + 1 - 2 * (in_.u8() & 1) : right; }

  /// Every call goes through here: `mutating` calls may change the world when accepted.
  template <class F>
  embra_status call(const std::string& what, bool mutating, F&& f) {
    const embra_status s = f();
    note(what + " -> " + embra_status_name(s));
    if (std::strcmp(embra_status_name(s), "EMBRA_UNKNOWN_STATUS") == 0) fail(what + " returned an unknown status");
    if (s == EMBRA_ERROR_INTERNAL) fail(what + " returned EMBRA_ERROR_INTERNAL");
    if (s == EMBRA_ERROR_LOCKED) fail(what + " returned EMBRA_ERROR_LOCKED on one thread");
    if (s != EMBRA_OK && embra_last_error_message()[0] == '\0') fail(what + " was refused without a message");
    if (s == EMBRA_OK && mutating) {
      saved_ = save(world_, "after " + what);
    } else if (const std::string now = save(world_, "after " + what); now != saved_) {
      fail(what +
           (s == EMBRA_OK ? " (a read) changed the saved world: " : " was refused but changed the saved world: ") +
           fuzz::difference(saved_, now));
    }
    return s;
  }

  /// One of the two-call id listings: ask the count only, or fill `capacity` ids.
  template <class Id, class List>
  void list_ids(const char* name, int32_t capacity, bool ask, List list) {
    std::vector<Id> out(300);
    int32_t n = 0;
    call(std::string(name) + "(capacity " + std::to_string(capacity) + ")", false,
         [&] { return list(world_, ask ? nullptr : out.data(), capacity, &n); });
  }

  void start();
  void refresh_ids();
  void op_solver();
  void op_body();
  void op_constraint();
  void op_constraints();
  void op_pin();
  void op_collider();
  void op_field();
  void op_set_state();
  void op_panel_mesh();
  void op_tolerances();
  void op_read();
  void op_misuse();
  void op_step();
  void op_solve();
  void op_diagnose();
  void op_edit();
  void op_cancel();
  void roundtrip(bool replace);

  void fill_rotation(double* q) {
    switch (in_.u8() % 4) {
      case 0:
        q[0] = 1, q[1] = q[2] = q[3] = 0;
        break;
      case 1: {  // a unit quaternion from small integers
        double n2 = 0;
        for (int k = 0; k < 4; ++k) q[k] = static_cast<int8_t>(in_.u8()), n2 += q[k] * q[k];
        if (n2 == 0) q[0] = n2 = 1;
        for (int k = 0; k < 4; ++k) q[k] /= std::sqrt(n2);
        break;
      }
      default:
        for (int k = 0; k < 4; ++k) q[k] = in_.value();
    }
  }
  void fill_vec3(double* v, bool small) {
    for (int k = 0; k < 3; ++k) v[k] = small && !in_.chance(8) ? in_.coordinate() : in_.value();
  }
};

// A scene with every action type, for sequences that start from a loaded world.
const char kStartScene[] = R"({
  "format": "embra-scene", "version": 1, "name": "fuzz_start", "frames": 12,
  "solver": {"substeps": 2, "iterations": 2},
  "groups": [{"name": "soft", "order": 3, "weight": 2}],
  "bodies": [
    {"name": "sheet", "mesh": {"generator": "grid", "size": [1, 1], "resolution": [3, 3], "origin": [0, 0, 1]},
     "material": {"mass": 0.2, "stretch_compliance": 1e-4}, "generate": ["stretch", "bend"], "bend_group": "soft"},
    {"name": "rod", "mesh": {"vertices": [[2, 0, 1], [2.2, 0, 1], [2.4, 0, 1]], "edges": [[0, 1], [1, 2]]}}
  ],
  "pins": [
    {"name": "a", "particle": {"body": "sheet", "vertex": 0}},
    {"name": "b", "particle": {"body": "sheet", "vertex": 2}, "compliance": 0.01, "group": "soft"},
    {"name": "c", "particle": {"body": "rod", "vertex": 0}}
  ],
  "colliders": [{"name": "ball", "shape": "sphere", "position": [0.5, 0.5, 0.4], "radius": 0.2}],
  "actions": [
    {"type": "rest_scale", "body": "sheet", "keys": [{"frame": 0, "value": [1, 1, 1]}, {"frame": 8, "value": [0.9, 1, 0.95]}]},
    {"type": "pin_target", "pin": "a", "keys": [{"frame": 0, "value": [-0.5, -0.5, 1]}, {"frame": 6, "value": [-0.5, -0.5, 1.3]}]},
    {"type": "pin_target", "pin": "b", "keys": [{"frame": 2, "value": [0.5, -0.5, 1]}, {"frame": 9, "value": [0.6, -0.5, 1.1]}]},
    {"type": "collider_pose", "collider": "ball", "keys": [{"frame": 0, "value": [0.5, 0.5, 0.4, 1, 0, 0, 0]}, {"frame": 10, "value": [0, 0, 0.6, 0.9950041652780258, 0.09983341664682815, 0, 0]}]},
    {"type": "gravity", "keys": [{"frame": 0, "value": [0, 0, -9.81]}, {"frame": 5, "value": [0, 0, 9.81]}]}
  ]
})";

void Session::refresh_ids() {
  int32_t n = 0;
  groups_.resize(64);
  if (embra_world_get_groups(world_, groups_.data(), 64, &n) != EMBRA_OK) fail("embra_world_get_groups refused");
  groups_.resize(static_cast<size_t>(n));
  bodies_.resize(64);
  if (embra_world_get_bodies(world_, bodies_.data(), 64, &n) != EMBRA_OK) fail("embra_world_get_bodies refused");
  bodies_.resize(static_cast<size_t>(n));
  pins_.resize(256);
  if (embra_world_get_pins(world_, pins_.data(), 256, &n) != EMBRA_OK) fail("embra_world_get_pins refused");
  pins_.resize(static_cast<size_t>(n));
  colliders_.resize(64);
  if (embra_world_get_colliders(world_, colliders_.data(), 64, &n) != EMBRA_OK)
    fail("embra_world_get_colliders refused");
  colliders_.resize(static_cast<size_t>(n));
}

void Session::start() {
  const uint8_t mode = in_.u8() % 4;
  embra_status s = EMBRA_ERROR_INVALID_ARGUMENT;
  if (mode == 1) {
    embra_solver_def d = embra_default_solver_def();
    d.substeps = in_.chance(2) ? 1 + in_.u8() % 4 : in_.integer();
    d.iterations = in_.chance(2) ? 1 + in_.u8() % 4 : in_.integer();
    d.dt = in_.chance(2) ? d.dt : in_.value();
    fill_vec3(d.gravity, true);
    d.self_collision = in_.chance(2) ? 1 : in_.integer();
    s = embra_world_create(&world_, &d);
    note("embra_world_create(substeps " + std::to_string(d.substeps) + ", iterations " + std::to_string(d.iterations) +
         ", dt " + fmt(d.dt) + ", self_collision " + std::to_string(d.self_collision) + ") -> " + embra_status_name(s));
  } else if (mode == 2) {
    s = embra_world_load_json(&world_, kStartScene, static_cast<int64_t>(sizeof kStartScene - 1), nullptr);
    note(std::string("embra_world_load_json(the start scene) -> ") + embra_status_name(s));
    if (s != EMBRA_OK) fail("the start scene does not load");
  }
  if (s != EMBRA_OK) {
    if (world_ != nullptr) fail("a refused embra_world_create left a world");
    if (embra_world_create(&world_, nullptr) != EMBRA_OK) fail("embra_world_create(NULL) refused");
    note("embra_world_create(NULL)");
  }
  refresh_ids();
  saved_ = save(world_, "when created");
}

void Session::op_solver() {
  embra_solver_def d{};
  if (embra_world_get_solver(world_, &d) != EMBRA_OK) fail("embra_world_get_solver refused");
  const uint16_t which = in_.u16();
  if (which & 1) d.substeps = in_.integer();
  if (which & 2) d.iterations = in_.integer();
  if (which & 4) d.dt = in_.value();
  if (which & 8) fill_vec3(d.gravity, false);
  if (which & 16) d.damping = in_.value();
  if (which & 32) d.settle_speed = in_.value();
  if (which & 64) d.tethers = in_.integer();
  if (which & 128) d.realign_passes = in_.integer();
  if (which & 256) d.chebyshev_rho_milli = in_.chance(2) ? in_.u16() % 1100 : in_.integer();
  if (which & 512) d.self_collision = in_.integer();
  if (which & 1024) d.chain_solve = in_.integer();
  d.version = version(EMBRA_SOLVER_DEF_VERSION);
  if (which & 2048) {
    double g[3];
    fill_vec3(g, false);
    call("embra_world_set_gravity(" + fmt(g[0]) + ", " + fmt(g[1]) + ", " + fmt(g[2]) + ")", true,
         [&] { return embra_world_set_gravity(world_, g); });
    return;
  }
  call("embra_world_set_solver(substeps " + std::to_string(d.substeps) + ", iterations " +
           std::to_string(d.iterations) + ", dt " + fmt(d.dt) + ", damping " + fmt(d.damping) + ", settle " +
           fmt(d.settle_speed) + ", tethers " + std::to_string(d.tethers) + ", realign " +
           std::to_string(d.realign_passes) + ", rho " + std::to_string(d.chebyshev_rho_milli) + ", self " +
           std::to_string(d.self_collision) + ", chain " + std::to_string(d.chain_solve) + ")",
       true, [&] { return embra_world_set_solver(world_, &d); });
}

void Session::op_body() {
  if (particle_count() > kMaxParticlesInFuzz) return;
  std::vector<double> x;
  std::vector<int32_t> edges, tris, tets;
  const uint8_t shape = in_.u8() % 6;
  const double h = 0.05 * (1 + in_.u8() % 8);
  const double o[3] = {in_.coordinate(), in_.coordinate(), in_.coordinate()};
  auto vertex = [&](double a, double b, double c) {
    x.push_back(o[0] + a * h);
    x.push_back(o[1] + b * h);
    x.push_back(o[2] + c * h);
  };
  switch (shape) {
    case 0: {  // a chain of edges
      const int n = 2 + in_.u8() % 10;
      for (int i = 0; i < n; ++i) vertex(i, 0, 0);
      for (int i = 0; i + 1 < n; ++i) edges.insert(edges.end(), {i, i + 1});
      break;
    }
    case 1: {  // a cloth grid, two triangles a cell
      const int nx = 1 + in_.u8() % 5, ny = 1 + in_.u8() % 5;
      for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) vertex(i, j, 0);
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
          tris.insert(tris.end(), {a, b, d, a, d, c});
        }
      break;
    }
    case 2: {  // a cube of five tetrahedra
      for (int k = 0; k < 8; ++k) vertex(k & 1, (k >> 1) & 1, (k >> 2) & 1);
      tets = {0, 1, 2, 4, 1, 3, 2, 7, 1, 4, 5, 7, 2, 4, 7, 6, 1, 2, 4, 7};
      break;
    }
    case 3: {  // loose points
      const int n = 1 + in_.u8() % 6;
      for (int i = 0; i < n; ++i) vertex(i, i % 2, 0);
      break;
    }
    case 4: {  // a closed octahedron, triangles facing out
      vertex(1, 0, 0), vertex(-1, 0, 0), vertex(0, 1, 0), vertex(0, -1, 0), vertex(0, 0, 1), vertex(0, 0, -1);
      tris = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
      break;
    }
    default: {  // anything
      const int n = 1 + in_.u8() % 8;
      for (int i = 0; i < 3 * n; ++i) x.push_back(in_.value());
      for (int i = in_.u8() % 4; i > 0; --i) edges.insert(edges.end(), {in_.u8() % (n + 1), in_.u8() % (n + 1)});
      for (int i = in_.u8() % 4; i > 0; --i)
        tris.insert(tris.end(), {in_.u8() % (n + 1), in_.u8() % (n + 1), in_.u8() % (n + 1)});
      for (int i = in_.u8() % 3; i > 0; --i)
        tets.insert(tets.end(), {in_.u8() % (n + 1), in_.u8() % (n + 1), in_.u8() % (n + 1), in_.u8() % (n + 1)});
    }
  }
  const int32_t n = static_cast<int32_t>(x.size() / 3);
  for (int k = in_.u8() % 4; k > 0; --k) x[in_.u8() % x.size()] = in_.value();
  for (int k = in_.u8() % 3; k > 0; --k) {
    std::vector<int32_t>* lists[] = {&edges, &tris, &tets};
    std::vector<int32_t>& l = *lists[in_.u8() % 3];
    if (!l.empty()) l[in_.u8() % l.size()] = in_.chance(4) ? in_.integer() : in_.u8() % (n + 2) - 1;
  }
  std::vector<double> masses, uvs;
  if (in_.chance(4))
    for (int i = 0; i < n; ++i) masses.push_back(in_.chance(2) ? 0.1 : in_.value());
  if (in_.chance(4))
    for (int i = 0; i < n; ++i) {
      uvs.push_back(in_.chance(8) ? in_.value() : x[3 * i]);
      uvs.push_back(x[3 * i + 1]);
    }
  embra_body_def d = embra_default_body_def();
  d.version = version(EMBRA_BODY_DEF_VERSION);
  d.vertex_count = n;
  d.positions = in_.chance(64) ? nullptr : x.data();
  d.masses = masses.empty() ? nullptr : masses.data();
  d.uvs = uvs.empty() ? nullptr : uvs.data();
  d.edge_count = static_cast<int32_t>(edges.size() / 2);
  d.edges = edges.empty() ? nullptr : edges.data();
  d.triangle_count = static_cast<int32_t>(tris.size() / 3);
  d.triangles = tris.empty() ? nullptr : tris.data();
  d.tet_count = static_cast<int32_t>(tets.size() / 4);
  d.tets = tets.empty() ? nullptr : tets.data();
  if (in_.chance(32)) {  // counts that disagree with the arrays (never beyond them)
    switch (in_.u8() % 4) {
      case 0:
        d.vertex_count = in_.chance(2) ? 0 : -1;
        break;
      case 1:
        d.edge_count = d.edge_count > 0 ? d.edge_count - 1 : -1;
        break;
      case 2:
        d.triangle_count = -1;
        break;
      default:
        d.tet_count = d.tet_count > 0 ? d.tet_count - 1 : INT32_MIN;
    }
  }
  const uint16_t which = in_.chance(2) ? in_.u16() : 0;
  double* m[] = {&d.material.mass,
                 &d.material.density,
                 &d.material.stretch_compliance,
                 &d.material.shear_compliance,
                 &d.material.bend_compliance,
                 &d.material.volume_compliance,
                 &d.material.damping,
                 &d.material.thickness,
                 &d.material.friction_static,
                 &d.material.friction_dynamic};
  for (int k = 0; k < 10; ++k)
    if (which & (1 << k)) *m[k] = in_.value();
  if (in_.chance(2)) d.generate = in_.u8() % 32;
  if (in_.chance(2)) d.stretch_group = pick_id(in_, groups_);
  if (in_.chance(2)) d.shear_group = pick_id(in_, groups_);
  if (in_.chance(2)) d.bend_group = pick_id(in_, groups_);
  if (in_.chance(2)) d.volume_group = pick_id(in_, groups_);
  embra_body_id id{};
  int32_t first = -1;
  const bool null_out = in_.chance(64);
  const embra_status s =
      call("embra_body_create(shape " + std::to_string(shape) + ", vertices " + std::to_string(d.vertex_count) +
               ", edges " + std::to_string(d.edge_count) + ", triangles " + std::to_string(d.triangle_count) +
               ", tets " + std::to_string(d.tet_count) + ", generate " + std::to_string(d.generate) +
               ", material mask " + std::to_string(which) + ")",
           true, [&] { return embra_body_create(world_, &d, null_out ? nullptr : &id, &first); });
  if (s == EMBRA_OK) bodies_.push_back(id);
}

/// A constraint kind, or one just outside the list (-1, or one past the last kind).
int32_t any_kind(Bytes& in) {
  int32_t count = 0;
  while (embra_constraint_arity(count) > 0) ++count;
  return static_cast<int32_t>(in.u8() % (count + 2)) - 1;
}

void Session::op_constraint() {
  embra_constraint_def d = embra_default_constraint_def();
  d.version = version(EMBRA_CONSTRAINT_DEF_VERSION);
  d.kind = any_kind(in_);
  if (in_.chance(2)) d.group = pick_id(in_, groups_);
  for (int k = 0; k < 4; ++k) d.particles[k] = particle();
  if (in_.chance(2)) d.rest_from_current = in_.chance(8) ? in_.integer() : 0;
  d.rest = in_.value();
  if (in_.chance(2)) d.compliance = in_.value();
  call("embra_constraint_add(kind " + std::to_string(d.kind) + ", particles " + std::to_string(d.particles[0]) + " " +
           std::to_string(d.particles[1]) + " " + std::to_string(d.particles[2]) + " " +
           std::to_string(d.particles[3]) + ", from current " + std::to_string(d.rest_from_current) + ", rest " +
           fmt(d.rest) + ", compliance " + fmt(d.compliance) + ")",
       true, [&] { return embra_constraint_add(world_, &d); });
}

void Session::op_constraints() {
  embra_constraint_batch_def d = embra_default_constraint_batch_def();
  d.version = version(EMBRA_CONSTRAINT_BATCH_DEF_VERSION);
  d.kind = any_kind(in_);
  if (in_.chance(2)) d.group = pick_id(in_, groups_);
  const int count = in_.u8() % 7;
  std::vector<int32_t> particles;
  std::vector<double> rest, compliances;
  for (int i = 0; i < 4 * count; ++i) particles.push_back(particle());
  if (in_.chance(2))
    for (int i = 0; i < count; ++i) rest.push_back(in_.value());
  if (in_.chance(3))
    for (int i = 0; i < count; ++i) compliances.push_back(in_.chance(2) ? 1e-3 : in_.value());
  d.count = in_.chance(32) ? in_.integer() % (count + 1) : count;  // never beyond the arrays
  d.particles = particles.empty() || in_.chance(64) ? nullptr : particles.data();
  d.rest = rest.empty() ? nullptr : rest.data();
  d.compliances = compliances.empty() ? nullptr : compliances.data();
  if (in_.chance(2)) d.compliance = in_.value();
  call("embra_constraints_add(kind " + std::to_string(d.kind) + ", count " + std::to_string(d.count) + ", rest " +
           (d.rest ? "given" : "current") + ", compliances " + (d.compliances ? "given" : fmt(d.compliance)) + ")",
       true, [&] { return embra_constraints_add(world_, &d); });
}

void Session::op_pin() {
  const uint8_t what = in_.u8() % 3;
  if (what == 0) {
    embra_pin_def d = embra_default_pin_def();
    d.version = version(EMBRA_PIN_DEF_VERSION);
    d.particle = particle();
    fill_vec3(d.target, true);
    if (in_.chance(2)) d.compliance = in_.value();
    if (in_.chance(2)) d.group = pick_id(in_, groups_);
    embra_pin_id id{};
    const embra_status s =
        call("embra_pin_create(particle " + std::to_string(d.particle) + ", target " + fmt(d.target[0]) + " " +
                 fmt(d.target[1]) + " " + fmt(d.target[2]) + ", compliance " + fmt(d.compliance) + ")",
             true, [&] { return embra_pin_create(world_, &d, &id); });
    if (s == EMBRA_OK) pins_.push_back(id);
  } else if (what == 1) {
    const embra_pin_id id = pick_id(in_, pins_);
    call("embra_pin_destroy({" + std::to_string(id.index) + ", " + std::to_string(id.generation) + "})", true,
         [&] { return embra_pin_destroy(world_, id); });
  } else {
    const embra_pin_id id = pick_id(in_, pins_);
    double t[3];
    fill_vec3(t, true);
    call("embra_pin_set_target(" + fmt(t[0]) + ", " + fmt(t[1]) + ", " + fmt(t[2]) + ")", true,
         [&] { return embra_pin_set_target(world_, id, t); });
  }
}

void Session::op_collider() {
  const uint8_t what = in_.u8() % 3;
  if (what == 1) {
    const embra_collider_id id = pick_id(in_, colliders_);
    call("embra_collider_destroy({" + std::to_string(id.index) + ", " + std::to_string(id.generation) + "})", true,
         [&] { return embra_collider_destroy(world_, id); });
    return;
  }
  if (what == 2) {
    const embra_collider_id id = pick_id(in_, colliders_);
    double p[3], q[4];
    fill_vec3(p, true);
    fill_rotation(q);
    call("embra_collider_set_transform(" + fmt(p[0]) + " " + fmt(p[1]) + " " + fmt(p[2]) + ", " + fmt(q[0]) + " " +
             fmt(q[1]) + " " + fmt(q[2]) + " " + fmt(q[3]) + ")",
         true, [&] { return embra_collider_set_transform(world_, id, p, q); });
    return;
  }
  embra_collider_def d = embra_default_collider_def();
  d.version = version(EMBRA_COLLIDER_DEF_VERSION);
  d.shape = in_.u8() % 8 - 1;
  fill_vec3(d.position, true);
  if (in_.chance(2)) fill_rotation(d.rotation);
  const uint8_t which = in_.chance(2) ? in_.u8() : 0;
  if (which & 1) d.radius = in_.value();
  if (which & 2) d.thickness = in_.value();
  if (which & 4) d.friction_static = in_.value();
  if (which & 8) d.friction_dynamic = in_.value();
  if (which & 16) fill_vec3(d.half_extents, false);
  if (which & 32) d.half_length = in_.value();
  std::vector<double> v;
  std::vector<int32_t> t;
  const uint8_t geometry = in_.u8() % 4;
  if (geometry == 0) {  // a tetrahedron, closed
    v = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    t = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  } else if (geometry == 1) {  // a cube, closed
    for (int k = 0; k < 8; ++k) v.insert(v.end(), {k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5});
    t = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  } else if (geometry == 2) {  // an open square sheet
    v = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    t = {0, 1, 2, 0, 2, 3};
  } else {  // anything
    const int n = 1 + in_.u8() % 6;
    for (int i = 0; i < 3 * n; ++i) v.push_back(in_.value());
    for (int i = in_.u8() % 4; i > 0; --i)
      t.insert(t.end(), {in_.u8() % (n + 1), in_.u8() % (n + 1), in_.u8() % (n + 1)});
  }
  for (int k = in_.u8() % 3; k > 0; --k) v[in_.u8() % v.size()] = in_.value();
  if (!t.empty() && in_.chance(4)) t[in_.u8() % t.size()] = in_.chance(2) ? -1 : in_.integer();
  d.vertex_count = static_cast<int32_t>(v.size() / 3);
  d.vertices = in_.chance(64) ? nullptr : v.data();
  d.triangle_count = static_cast<int32_t>(t.size() / 3);
  d.triangles = t.empty() ? nullptr : t.data();
  if (in_.chance(32)) d.vertex_count = in_.chance(2) ? -1 : d.vertex_count - 1;
  if (in_.chance(32)) d.triangle_count = in_.chance(2) ? -1 : 0;
  embra_collider_id id{};
  const embra_status s =
      call("embra_collider_create(shape " + std::to_string(d.shape) + ", position " + fmt(d.position[0]) + " " +
               fmt(d.position[1]) + " " + fmt(d.position[2]) + ", mask " + std::to_string(which) + ", vertices " +
               std::to_string(d.vertex_count) + ", triangles " + std::to_string(d.triangle_count) + ")",
           true, [&] { return embra_collider_create(world_, &d, &id); });
  if (s == EMBRA_OK) colliders_.push_back(id);
}

void Session::op_field() {
  const uint8_t what = in_.u8() % 5;
  embra_field_id id{};
  embra_status s = EMBRA_OK;
  if (what == 0) {
    embra_wind_def d = embra_default_wind_def();
    d.version = version(EMBRA_WIND_DEF_VERSION);
    if (in_.chance(2)) d.body = pick_id(in_, bodies_);
    if (in_.chance(2)) fill_vec3(d.direction, false);
    d.speed = in_.value();
    if (in_.chance(2)) d.air_density = in_.value();
    if (in_.chance(2)) d.drag = in_.value();
    if (in_.chance(2)) d.lift = in_.value();
    s = call("embra_wind_create(speed " + fmt(d.speed) + ", density " + fmt(d.air_density) + ", drag " + fmt(d.drag) +
                 ", lift " + fmt(d.lift) + ")",
             true, [&] { return embra_wind_create(world_, &d, &id); });
  } else if (what == 1) {
    embra_pressure_def d = embra_default_pressure_def();
    d.version = version(EMBRA_PRESSURE_DEF_VERSION);
    d.body = pick_id(in_, bodies_);
    d.keep_volume = in_.chance(2) ? in_.u8() % 2 : in_.integer();
    d.inside_pressure = in_.value();
    if (in_.chance(2)) d.outside_pressure = in_.value();
    if (in_.chance(2)) d.volume_compliance = in_.value();
    if (in_.chance(2)) d.rest_volume = in_.value();
    s = call("embra_pressure_create(keep " + std::to_string(d.keep_volume) + ", inside " + fmt(d.inside_pressure) +
                 ", outside " + fmt(d.outside_pressure) + ", compliance " + fmt(d.volume_compliance) + ", rest " +
                 fmt(d.rest_volume) + ")",
             true, [&] { return embra_pressure_create(world_, &d, &id); });
  } else if (what == 2) {
    embra_surface_tension_def d = embra_default_surface_tension_def();
    d.version = version(EMBRA_SURFACE_TENSION_DEF_VERSION);
    d.body = pick_id(in_, bodies_);
    d.tension = in_.value();
    if (in_.chance(2)) d.regularisation = in_.value();
    s = call(
        "embra_surface_tension_create(tension " + fmt(d.tension) + ", regularisation " + fmt(d.regularisation) + ")",
        true, [&] { return embra_surface_tension_create(world_, &d, &id); });
  } else if (what == 3) {
    embra_vortex_def d = embra_default_vortex_def();
    d.version = version(EMBRA_VORTEX_DEF_VERSION);
    if (in_.chance(2)) d.body = pick_id(in_, bodies_);
    fill_vec3(d.center, true);
    if (in_.chance(2)) fill_vec3(d.axis, false);
    d.strength = in_.value();
    if (in_.chance(2)) d.radius = in_.value();
    if (in_.chance(2)) d.twist = in_.value();
    if (in_.chance(2)) d.decay = in_.value();
    if (in_.chance(2)) d.start_time = in_.value();
    s = call("embra_vortex_create(strength " + fmt(d.strength) + ", radius " + fmt(d.radius) + ", twist " +
                 fmt(d.twist) + ", decay " + fmt(d.decay) + ", start " + fmt(d.start_time) + ")",
             true, [&] { return embra_vortex_create(world_, &d, &id); });
  } else {
    const embra_field_id f = pick_id(in_, fields_);
    call("embra_field_destroy({" + std::to_string(f.index) + ", " + std::to_string(f.generation) + "})", true,
         [&] { return embra_field_destroy(world_, f); });
    return;
  }
  if (s == EMBRA_OK) fields_.push_back(id);
}

void Session::op_set_state() {
  const bool velocities = in_.chance(2);
  const int32_t first = particle();
  const int32_t count = in_.chance(16) ? -1 : in_.u8() % 8;
  std::vector<double> xyz(3 * static_cast<size_t>(count > 0 ? count : 0));
  for (double& v : xyz) v = in_.chance(4) ? in_.value() : in_.coordinate();
  const double* p = in_.chance(64) ? nullptr : xyz.data();
  if (velocities)
    call("embra_world_set_velocities(first " + std::to_string(first) + ", count " + std::to_string(count) + ")", true,
         [&] { return embra_world_set_velocities(world_, p, first, count); });
  else
    call("embra_world_set_positions(first " + std::to_string(first) + ", count " + std::to_string(count) + ")", true,
         [&] { return embra_world_set_positions(world_, p, first, count); });
}

void Session::op_panel_mesh() {
  if (particle_count() > kMaxParticlesInFuzz) return;
  embra_panel_mesh_def d = embra_default_panel_mesh_def();
  d.version = version(EMBRA_PANEL_MESH_DEF_VERSION);
  std::vector<double> x;
  std::vector<int32_t> q;
  if (in_.chance(2)) {  // a grid of square panels
    static const int32_t sizes[] = {1, 2, 3, 4, 0, -1, 46341, 65536, INT32_MAX, 2};
    d.grid_columns = sizes[in_.u8() % 10];
    d.grid_rows = sizes[in_.u8() % 10];
    const int64_t panels = int64_t{d.grid_columns} * d.grid_rows;
    // Within the world's limits but large: valid and slow, not what this target is for.
    if (d.grid_columns > 0 && d.grid_rows > 0 && panels > 16 && panels <= EMBRA_MAX_PARTICLES / 8) return;
    if (in_.chance(4)) d.panel_size = in_.value();
    if (in_.chance(4)) fill_vec3(d.origin, false);
  } else {  // a quad mesh, each quad planar
    const int nx = 1 + in_.u8() % 3, ny = 1 + in_.u8() % 3;
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) x.insert(x.end(), {0.5 * i, 0.5 * j, 0.0});
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int a = j * (nx + 1) + i;
        q.insert(q.end(), {a, a + 1, a + nx + 2, a + nx + 1});
      }
    for (int k = in_.u8() % 3; k > 0; --k) x[in_.u8() % x.size()] = in_.chance(2) ? in_.coordinate() : in_.value();
    if (in_.chance(4)) q[in_.u8() % q.size()] = in_.chance(2) ? in_.u8() % 20 - 1 : in_.integer();
    d.vertex_count = static_cast<int32_t>(x.size() / 3);
    d.positions = in_.chance(64) ? nullptr : x.data();
    d.quad_count = static_cast<int32_t>(q.size() / 4);
    d.quads = q.data();
    if (in_.chance(32)) d.quad_count = in_.chance(2) ? 0 : -1;
  }
  const uint8_t which = in_.chance(2) ? in_.u8() : 0;
  if (which & 1) d.thickness = in_.value();
  if (which & 2) d.mass = in_.value();
  if (which & 4) d.density = in_.value();
  if (which & 8) d.damping = in_.value();
  if (which & 16) d.friction_static = in_.value();
  if (which & 32) d.friction_dynamic = in_.value();
  if (which & 64) d.slide_compliance = in_.value();
  if (in_.chance(2)) d.pins = in_.u8() % 5 - 1;
  if (in_.chance(2)) d.corners = in_.u8() % 4 - 1;
  if (in_.chance(2)) d.precision = in_.u8() % 4 - 1;
  if (in_.chance(2)) d.group = pick_id(in_, groups_);
  embra_body_id id{};
  const embra_status s =
      call("embra_panel_mesh_create(vertices " + std::to_string(d.vertex_count) + ", quads " +
               std::to_string(d.quad_count) + ", grid " + std::to_string(d.grid_columns) + " x " +
               std::to_string(d.grid_rows) + ", size " + fmt(d.panel_size) + ", mask " + std::to_string(which) +
               ", pins " + std::to_string(d.pins) + ", corners " + std::to_string(d.corners) + ")",
           true, [&] { return embra_panel_mesh_create(world_, &d, &id, nullptr); });
  if (s == EMBRA_OK) {
    bodies_.push_back(id);
    refresh_ids();  // the mesh's pins
  }
}

void Session::op_tolerances() {
  embra_tolerances t = embra_default_tolerances();
  t.version = version(EMBRA_TOLERANCES_VERSION);
  const uint16_t which = in_.u16();
  if (which & 1) t.unit_scale = in_.value();
  embra_tolerance* each[] = {&t.planarity, &t.planarity_distance, &t.thickness, &t.miter};
  for (int k = 0; k < 4; ++k) {
    if (which & (2 << k)) each[k]->target = in_.value();
    if (which & (32 << k)) each[k]->max = in_.value();
  }
  call("embra_world_set_tolerances(mask " + std::to_string(which) + ", unit_scale " + fmt(t.unit_scale) + ")", true,
       [&] { return embra_world_set_tolerances(world_, &t); });
}

void Session::op_read() {
  const uint8_t what = in_.u8() % 18;
  switch (what) {
    case 0:
    case 1: {
      const int32_t first = particle();
      const int32_t count = in_.chance(16) ? -1 : in_.u8() % 8;
      const int64_t capacity = 3 * int64_t{count > 0 ? count : 0} - (in_.chance(8) ? 1 : 0);
      std::vector<double> out(static_cast<size_t>(capacity > 0 ? capacity : 0) + 1, 12345.0);
      const embra_status s = call(std::string(what == 0 ? "embra_world_get_positions" : "embra_world_get_velocities") +
                                      "(first " + std::to_string(first) + ", count " + std::to_string(count) +
                                      ", capacity " + std::to_string(capacity) + ")",
                                  false, [&] {
                                    return what == 0
                                               ? embra_world_get_positions(world_, out.data(), capacity, first, count)
                                               : embra_world_get_velocities(world_, out.data(), capacity, first, count);
                                  });
      if (s == EMBRA_OK) check_finite(out.data(), 3 * int64_t{count}, what == 0 ? "position" : "velocity");
      if (s != EMBRA_OK)
        for (double v : out)
          if (v != 12345.0) fail("a refused read wrote into the buffer");
      break;
    }
    case 2: {
      embra_step_report r{};
      if (call("embra_world_get_report", false, [&] { return embra_world_get_report(world_, &r); }) == EMBRA_OK) {
        const double v[] = {r.time, r.kinetic_energy, r.max_speed, r.residual_max, r.residual_rms};
        for (double e : v)
          if (std::isnan(e)) fail("the step report holds NaN");
      }
      break;
    }
    case 3: {
      embra_warning w{};
      call("embra_world_get_warning", false, [&] { return embra_world_get_warning(world_, &w); });
      break;
    }
    case 4: {
      embra_group_report r{};
      const embra_group_id g = pick_id(in_, groups_);
      if (call("embra_group_get_report", false, [&] { return embra_group_get_report(world_, g, &r); }) == EMBRA_OK &&
          (std::isnan(r.residual_max) || std::isnan(r.residual_rms)))
        fail("a group report holds NaN");
      break;
    }
    case 5: {
      const uint8_t kind = in_.u8() % 4;
      const bool ask = in_.chance(2);
      const int32_t capacity = ask ? 0 : in_.u8() % 300;
      if (kind == 0)
        list_ids<embra_group_id>("embra_world_get_groups", capacity, ask, embra_world_get_groups);
      else if (kind == 1)
        list_ids<embra_body_id>("embra_world_get_bodies", capacity, ask, embra_world_get_bodies);
      else if (kind == 2)
        list_ids<embra_pin_id>("embra_world_get_pins", capacity, ask, embra_world_get_pins);
      else
        list_ids<embra_collider_id>("embra_world_get_colliders", capacity, ask, embra_world_get_colliders);
      break;
    }
    case 6: {
      const embra_body_id b = pick_id(in_, bodies_);
      int32_t first = 0, count = 0;
      call("embra_body_get_particles", false, [&] { return embra_body_get_particles(world_, b, &first, &count); });
      int64_t n = 0;
      if (call("embra_body_get_triangles(count)", false,
               [&] { return embra_body_get_triangles(world_, b, nullptr, 0, &n); }) == EMBRA_OK) {
        std::vector<int32_t> t(static_cast<size_t>(n) + 1);
        const int64_t capacity = in_.chance(8) ? n - 1 : n;
        call("embra_body_get_triangles(capacity " + std::to_string(capacity) + ")", false,
             [&] { return embra_body_get_triangles(world_, b, t.data(), capacity, &n); });
      }
      break;
    }
    case 7: {
      const embra_pin_id p = pick_id(in_, pins_);
      double t[3];
      int32_t particle_index = 0;
      if (call("embra_pin_get_target", false, [&] { return embra_pin_get_target(world_, p, t); }) == EMBRA_OK)
        check_finite(t, 3, "pin target");
      call("embra_pin_get_particle", false, [&] { return embra_pin_get_particle(world_, p, &particle_index); });
      break;
    }
    case 8: {
      const embra_collider_id c = pick_id(in_, colliders_);
      double p[3], q[4];
      if (call("embra_collider_get_transform", false, [&] { return embra_collider_get_transform(world_, c, p, q); }) ==
          EMBRA_OK) {
        check_finite(p, 3, "collider position");
        check_finite(q, 4, "collider rotation");
      }
      break;
    }
    case 9: {
      embra_world_counts c{};
      embra_solver_def s{};
      embra_tolerances t{};
      int64_t frames = 0;
      int32_t fields = 0;
      call("embra_world_get_counts", false, [&] { return embra_world_get_counts(world_, &c); });
      call("embra_world_get_solver", false, [&] { return embra_world_get_solver(world_, &s); });
      call("embra_world_get_tolerances", false, [&] { return embra_world_get_tolerances(world_, &t); });
      call("embra_world_get_scene_frames", false, [&] { return embra_world_get_scene_frames(world_, &frames); });
      call("embra_world_get_field_count", false, [&] { return embra_world_get_field_count(world_, &fields); });
      break;
    }
    case 10: {
      const embra_body_id b = pick_id(in_, bodies_);
      int32_t panels = 0;
      embra_metric_summary gap{};
      call("embra_panel_mesh_get_panel_count", false,
           [&] { return embra_panel_mesh_get_panel_count(world_, b, &panels); });
      call("embra_panel_mesh_get_corner_gap", false, [&] { return embra_panel_mesh_get_corner_gap(world_, b, &gap); });
      int64_t n = 0;
      if (call("embra_panel_mesh_get_corner_particles(count)", false,
               [&] { return embra_panel_mesh_get_corner_particles(world_, b, nullptr, 0, &n); }) == EMBRA_OK) {
        std::vector<int32_t> c(static_cast<size_t>(n) + 1);
        const int64_t capacity = in_.chance(8) ? n - 1 : n;
        call("embra_panel_mesh_get_corner_particles(capacity " + std::to_string(capacity) + ")", false,
             [&] { return embra_panel_mesh_get_corner_particles(world_, b, c.data(), capacity, &n); });
      }
      break;
    }
    case 11: {
      const embra_body_id b = pick_id(in_, bodies_);
      embra_panel_metrics m{};
      embra_tolerances t = embra_default_tolerances();
      if (in_.chance(2)) t.planarity.target = in_.value();
      if (in_.chance(4)) t.unit_scale = in_.value();
      const bool given = in_.chance(2);
      call("embra_panel_mesh_get_metrics(tolerances " + std::string(given ? "given" : "the world's") + ")", false,
           [&] { return embra_panel_mesh_get_metrics(world_, b, given ? &t : nullptr, &m); });
      break;
    }
    case 12: {
      const embra_body_id b = pick_id(in_, bodies_);
      const int32_t metric = in_.u8() % 7 - 1;
      int64_t n = 0;
      if (call("embra_panel_mesh_get_vertex_errors(count, metric " + std::to_string(metric) + ")", false,
               [&] { return embra_panel_mesh_get_vertex_errors(world_, b, metric, nullptr, 0, &n); }) == EMBRA_OK) {
        std::vector<double> v(static_cast<size_t>(n) + 1);
        const int64_t capacity = in_.chance(8) ? n - 1 : n;
        call("embra_panel_mesh_get_vertex_errors(capacity " + std::to_string(capacity) + ")", false,
             [&] { return embra_panel_mesh_get_vertex_errors(world_, b, metric, v.data(), capacity, &n); });
      }
      break;
    }
    case 13: {
      const embra_body_id b = pick_id(in_, bodies_);
      const int32_t format = in_.u8() % 4 - 1;
      int64_t n = 0;
      if (call("embra_panel_mesh_export_cuts(length, format " + std::to_string(format) + ")", false,
               [&] { return embra_panel_mesh_export_cuts(world_, b, format, nullptr, 0, &n); }) == EMBRA_OK) {
        std::string text(static_cast<size_t>(n) + 1, '\0');
        const int64_t capacity = in_.chance(8) ? n - 1 : n;
        call("embra_panel_mesh_export_cuts(capacity " + std::to_string(capacity) + ")", false,
             [&] { return embra_panel_mesh_export_cuts(world_, b, format, text.data(), capacity, &n); });
      }
      break;
    }
    case 14: {  // a save into too small a buffer writes nothing
      int64_t n = 0;
      if (embra_world_save_json(world_, nullptr, 0, &n) != EMBRA_OK) fail("the world cannot be saved");
      std::string text(static_cast<size_t>(n), '#');
      const int64_t capacity = in_.u16() % n;
      if (call("embra_world_save_json(capacity " + std::to_string(capacity) + ")", false,
               [&] { return embra_world_save_json(world_, text.data(), capacity, &n); }) == EMBRA_OK)
        fail("embra_world_save_json accepted too small a buffer");
      if (text.find_first_not_of('#') != std::string::npos) fail("a refused embra_world_save_json wrote into out");
      break;
    }
    default: {
      embra_group_id g{};
      call("embra_world_default_group", false, [&] { return embra_world_default_group(world_, &g); });
      call("embra_world_contact_group", false, [&] { return embra_world_contact_group(world_, &g); });
    }
  }
}

void Session::op_misuse() {
  switch (in_.u8() % 10) {
    case 0:
      call("embra_world_get_counts(NULL)", false, [&] { return embra_world_get_counts(world_, nullptr); });
      break;
    case 1:
      call("embra_body_create(NULL def)", true, [&] {
        embra_body_id id;
        return embra_body_create(world_, nullptr, &id, nullptr);
      });
      break;
    case 2: {
      int64_t n = 0;
      call("embra_world_save_json(NULL out, capacity 5)", false,
           [&] { return embra_world_save_json(world_, nullptr, 5, &n); });
      break;
    }
    case 3:
      call("embra_world_set_gravity(NULL)", true, [&] { return embra_world_set_gravity(world_, nullptr); });
      break;
    case 4: {
      const embra_pin_id p = pick_id(in_, pins_);
      call("embra_pin_set_target(NULL)", true, [&] { return embra_pin_set_target(world_, p, nullptr); });
      break;
    }
    case 5: {
      const embra_collider_id c = pick_id(in_, colliders_);
      const double p[3] = {0, 0, 0};
      call("embra_collider_set_transform(NULL rotation)", true,
           [&] { return embra_collider_set_transform(world_, c, p, nullptr); });
      break;
    }
    case 6:
      call("embra_group_create(NULL out)", true, [&] {
        const embra_group_def d = embra_default_group_def();
        return embra_group_create(world_, &d, nullptr);
      });
      break;
    case 7:
      call("embra_world_set_solver(NULL)", true, [&] { return embra_world_set_solver(world_, nullptr); });
      break;
    case 8: {
      const embra_body_id b = pick_id(in_, bodies_);
      call("embra_panel_mesh_get_metrics(NULL out)", false,
           [&] { return embra_panel_mesh_get_metrics(world_, b, nullptr, nullptr); });
      break;
    }
    default:
      call("embra_world_set_tolerances(NULL)", true, [&] { return embra_world_set_tolerances(world_, nullptr); });
  }
}

void Session::op_step() {
  if (!fuzz::small_step(world_, kMaxStepWork)) {
    note("(step skipped: beyond the target's work bound)");
    return;
  }
  if (call("embra_world_step", true, [&] { return embra_world_step(world_); }) == EMBRA_OK)
    check_state(world_, "after a step");
}

/// embra_world_solve over a few frames: like steps, frames before a failing one stay stepped.
void Session::op_solve() {
  if (!fuzz::small_step(world_, kMaxStepWork)) {
    note("(solve skipped: beyond the target's work bound)");
    return;
  }
  embra_solve_def d = embra_default_solve_def();
  d.version = version(EMBRA_SOLVE_DEF_VERSION);
  d.until = in_.chance(8) ? in_.integer() : in_.u8() % 2;
  d.max_frames = in_.chance(8) ? in_.integer() : 1 + in_.u8() % 3;
  d.hold_frames = in_.chance(8) ? in_.integer() : 1 + in_.u8() % 3;
  if (in_.chance(8)) d.max_seconds = in_.value();
  embra_solve_result r{};
  const embra_status s = embra_world_solve(world_, &d, in_.chance(32) ? nullptr : &r);
  const std::string what = "embra_world_solve(until " + std::to_string(d.until) + ", frames " +
                           std::to_string(d.max_frames) + ", hold " + std::to_string(d.hold_frames) + ")";
  note(what + " -> " + embra_status_name(s));
  if (s == EMBRA_ERROR_INTERNAL) fail(what + " returned EMBRA_ERROR_INTERNAL");
  if (s != EMBRA_OK && embra_last_error_message()[0] == '\0') fail(what + " was refused without a message");
  if (s == EMBRA_OK) {
    if (r.outcome < EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE || r.outcome > EMBRA_SOLVE_DRIFTING)
      fail(what + " returned outcome " + std::to_string(r.outcome));
    if (r.frames < 1 || r.frames > d.max_frames) fail(what + " stepped " + std::to_string(r.frames) + " frames");
    if (!std::isfinite(r.period) || r.period < 0.0) fail(what + " returned a period of " + fmt(r.period));
    check_state(world_, "after a solve");
  }
  // Accepted, or a step that failed after others: the frames stepped stay (embra.h).
  saved_ = save(world_, "after " + what);
}

/// The diagnostics of the last step: residuals by kind, the worst constraints, group conflicts and
/// a group's per-constraint residuals. Reads: nothing may change.
void Session::op_diagnose() {
  const uint8_t what = in_.u8() % 4;
  if (what == 0) {
    std::vector<embra_kind_residual> out(64);
    int32_t n = 0;
    const int32_t capacity = in_.chance(4) ? in_.integer() : in_.u8() % 20;
    if (call("embra_world_get_residuals(capacity " + std::to_string(capacity) + ")", false, [&] {
          return embra_world_get_residuals(world_, capacity > 0 ? out.data() : nullptr, std::min(capacity, 64), &n);
        }) == EMBRA_OK)
      for (int32_t i = 0; i < n && i < 64 && capacity > 0; ++i)
        if (!std::isfinite(out[i].max) || embra_residual_unit(out[i].kind) == nullptr)
          fail("a residual by kind is not finite or has no unit");
  } else if (what == 1) {
    std::vector<embra_constraint_residual> out(32);
    int32_t n = 0;
    const int32_t capacity = in_.chance(8) ? in_.integer() : in_.u8() % 32;
    call("embra_world_get_worst_constraints(capacity " + std::to_string(capacity) + ")", false, [&] {
      return embra_world_get_worst_constraints(world_, in_.chance(16) ? nullptr : out.data(), std::min(capacity, 32),
                                               &n);
    });
  } else if (what == 2) {
    std::vector<embra_group_conflict> out(16);
    int32_t n = 0;
    const int32_t capacity = in_.chance(2) ? 0 : in_.u8() % 16;
    call("embra_world_get_group_conflicts(capacity " + std::to_string(capacity) + ")", false,
         [&] { return embra_world_get_group_conflicts(world_, capacity > 0 ? out.data() : nullptr, capacity, &n); });
  } else {
    const embra_group_id g = pick_id(in_, groups_);
    const int32_t kind = in_.chance(8) ? in_.integer() : in_.u8() % 9;
    std::vector<double> out(4096);
    int64_t n = 0;
    const int64_t capacity = in_.chance(2) ? 0 : in_.u8() * 16;
    call("embra_group_get_residuals(kind " + std::to_string(kind) + ", capacity " + std::to_string(capacity) + ")",
         false,
         [&] { return embra_group_get_residuals(world_, g, kind, capacity > 0 ? out.data() : nullptr, capacity, &n); });
  }
}

void Session::op_cancel() {
  call("embra_world_cancel", false, [&] { return embra_world_cancel(world_); });
  const embra_status s = call("embra_world_step (cancelled)", true, [&] { return embra_world_step(world_); });
  if (s != EMBRA_ERROR_CANCELLED)
    fail("the step after embra_world_cancel returned " + std::string(embra_status_name(s)));
}

/// The saved world loads, saves to the same bytes, and steps as the world it came from.
void Session::roundtrip(bool replace) {
  embra_world* copy = nullptr;
  const embra_status s = embra_world_load_json(&copy, saved_.data(), static_cast<int64_t>(saved_.size()), nullptr);
  note(std::string("embra_world_load_json(the saved world) -> ") + embra_status_name(s));
  if (s != EMBRA_OK) fail("the saved world does not load back");
  const std::string again = save(copy, "after loading");
  if (again != saved_) fail("the saved world, loaded and saved again, differs: " + fuzz::difference(saved_, again));
  if (replace) {
    embra_world_destroy(world_);
    world_ = copy;
    refresh_ids();
    fields_.clear();
    return;
  }
  if (fuzz::small_step(world_, kMaxStepWork)) {
    const embra_status a = embra_world_step(world_);
    const embra_status b = embra_world_step(copy);
    note(std::string("embra_world_step, both -> ") + embra_status_name(a) + ", " + embra_status_name(b));
    if (a != b) fail("the world and its saved copy step with different statuses");
    const std::string after = save(world_, "after the twin steps");
    const std::string twin = save(copy, "after the twin steps");
    if (twin != after) fail("the world and its saved copy step to different states: " + fuzz::difference(after, twin));
    if (a == EMBRA_OK) check_state(world_, "after a step");
    if (a != EMBRA_OK && after != saved_)
      fail("a refused step changed the saved world: " + fuzz::difference(saved_, after));
    saved_ = after;
  }
  embra_world_destroy(copy);
}

void Session::op_edit() {
  const embra_group_id g = pick_id(in_, groups_);
  const int32_t kind = any_kind(in_);
  const int32_t index = in_.chance(2) ? in_.u8() % 8 : in_.integer();
  const std::string at = "(group {" + std::to_string(g.index) + ", " + std::to_string(g.generation) + "}, kind " +
                         std::to_string(kind) + ", index " + std::to_string(index);
  switch (in_.u8() % 18) {
    case 17: {  // plasticity and rupture, then the broken constraints, into a buffer sized or not
      const double y = in_.value(), r = in_.value();
      call("embra_constraint_set_plasticity" + at + ", " + fmt(y) + ", " + fmt(r) + ")", true,
           [&] { return embra_constraint_set_plasticity(world_, g, kind, index, y, r); });
      double got_yield = 0.0, got_rupture = 0.0;
      call("embra_constraint_get_plasticity" + at + ")", false, [&] {
        return embra_constraint_get_plasticity(world_, g, kind, index, in_.chance(16) ? nullptr : &got_yield,
                                               &got_rupture);
      });
      std::vector<embra_broken_constraint> out(8);
      int32_t n = 0;
      call("embra_world_get_broken", false,
           [&] { return embra_world_get_broken(world_, in_.chance(4) ? nullptr : out.data(), in_.u8() % 9, &n); });
      break;
    }
    case 10: {  // point loads
      const int32_t first = particle();
      const int32_t count = in_.chance(16) ? -1 : in_.u8() % 6;
      std::vector<double> xyz(3 * static_cast<size_t>(count > 0 ? count : 0));
      for (double& v : xyz) v = in_.chance(4) ? in_.value() : in_.coordinate();
      const double* p = in_.chance(32) ? nullptr : xyz.data();
      call("embra_world_set_loads(first " + std::to_string(first) + ", count " + std::to_string(count) + ")", true,
           [&] { return embra_world_set_loads(world_, p, first, count); });
      std::vector<double> out(3 * 8);
      call("embra_world_get_loads", false,
           [&] { return embra_world_get_loads(world_, out.data(), in_.chance(8) ? 2 : 24, first, in_.u8() % 9); });
      break;
    }
    case 11: {  // a support: a pin on a plane or a line
      embra_support_def d = embra_default_support_def();
      d.version = version(EMBRA_SUPPORT_DEF_VERSION);
      d.particle = particle();
      d.support = in_.chance(4) ? in_.integer() : in_.u8() % 4;  // 3, a polyline, is refused here
      fill_vec3(d.target, true);
      if (in_.chance(2)) fill_vec3(d.axis, !in_.chance(4));
      if (in_.chance(2)) d.compliance = in_.chance(2) ? 1e-3 : in_.value();
      if (in_.chance(2)) d.group = pick_id(in_, groups_);
      embra_pin_id pin{};
      if (call("embra_support_create(support " + std::to_string(d.support) + ", particle " +
                   std::to_string(d.particle) + ", compliance " + fmt(d.compliance) + ")",
               true, [&] { return embra_support_create(world_, &d, &pin); }) == EMBRA_OK)
        pins_.push_back(pin);
      break;
    }
    case 12: {  // forces out: member forces, pin and collider reactions, sized or not
      int64_t n = 0;
      std::vector<double> forces(64);
      const bool ask = in_.chance(2);
      call("embra_group_get_forces" + at + ")", false, [&] {
        return embra_group_get_forces(world_, g, kind, ask ? nullptr : forces.data(), ask ? 0 : in_.u8() % 65, &n);
      });
      std::vector<embra_reaction> reactions(32);
      int32_t m = 0;
      call("embra_world_get_reactions", false, [&] {
        return embra_world_get_reactions(world_, in_.chance(4) ? nullptr : reactions.data(), in_.u8() % 33, &m);
      });
      std::vector<embra_collider_reaction> colliders(32);
      call("embra_world_get_collider_reactions", false, [&] {
        return embra_world_get_collider_reactions(world_, in_.chance(4) ? nullptr : colliders.data(), in_.u8() % 33,
                                                  &m);
      });
      break;
    }
    case 16: {  // a support on a polyline, some points repeated
      embra_polyline_support_def d = embra_default_polyline_support_def();
      d.version = version(EMBRA_POLYLINE_SUPPORT_DEF_VERSION);
      d.particle = particle();
      fill_vec3(d.target, true);
      if (in_.chance(2)) d.compliance = in_.chance(2) ? 1e-3 : in_.value();
      if (in_.chance(2)) d.group = pick_id(in_, groups_);
      // Out of range (refused before the points are read), or the size of the buffer given.
      d.point_count = in_.chance(16) ? (in_.chance(2) ? -1 - in_.u8() : INT32_MAX) : in_.u8() % 7;
      std::vector<double> points(3 * static_cast<size_t>(std::max(d.point_count, 0) % 7));
      for (size_t i = 0; i < points.size(); i += 3) {
        if (i >= 3 && in_.chance(8))
          std::copy_n(&points[i - 3], 3, &points[i]);
        else
          fill_vec3(&points[i], !in_.chance(8));
      }
      d.points = in_.chance(32) ? nullptr : points.data();
      d.closed = in_.chance(8) ? in_.integer() : in_.u8() % 2;
      embra_pin_id pin{};
      if (call("embra_polyline_support_create(points " + std::to_string(d.point_count) + ", closed " +
                   std::to_string(d.closed) + ")",
               true, [&] { return embra_polyline_support_create(world_, &d, &pin); }) == EMBRA_OK)
        pins_.push_back(pin);
      break;
    }
    case 14: {  // area loads: triangles of particles (some repeated or out of range), every mode
      const int32_t count = in_.chance(16) ? -1 : in_.u8() % 5;
      std::vector<embra_area_load> loads(static_cast<size_t>(count > 0 ? count : 0));
      for (embra_area_load& l : loads) {
        for (int32_t& c : l.particles) c = particle();
        l.mode = in_.chance(8) ? in_.integer() : in_.u8() % 3;
        l.pressure = in_.chance(4) ? in_.value() : in_.coordinate();
        fill_vec3(l.direction, !in_.chance(4));
      }
      const embra_area_load* p = in_.chance(32) ? nullptr : loads.data();
      call("embra_world_set_area_loads(count " + std::to_string(count) + ")", true,
           [&] { return embra_world_set_area_loads(world_, p, count); });
      std::vector<embra_area_load> out(8);
      int32_t n = 0;
      call("embra_world_get_area_loads", false,
           [&] { return embra_world_get_area_loads(world_, in_.chance(4) ? nullptr : out.data(), in_.u8() % 9, &n); });
      break;
    }
    case 15: {  // line loads
      const int32_t count = in_.chance(16) ? -1 : in_.u8() % 5;
      std::vector<embra_line_load> loads(static_cast<size_t>(count > 0 ? count : 0));
      for (embra_line_load& l : loads) {
        for (int32_t& c : l.particles) c = particle();
        fill_vec3(l.load, !in_.chance(4));
      }
      const embra_line_load* p = in_.chance(32) ? nullptr : loads.data();
      call("embra_world_set_line_loads(count " + std::to_string(count) + ")", true,
           [&] { return embra_world_set_line_loads(world_, p, count); });
      std::vector<embra_line_load> out(8);
      int32_t n = 0;
      call("embra_world_get_line_loads", false,
           [&] { return embra_world_get_line_loads(world_, in_.chance(4) ? nullptr : out.data(), in_.u8() % 9, &n); });
      break;
    }
    case 13: {  // the OBJ text, into a buffer sized or not
      int64_t length = 0;
      std::vector<char> text(static_cast<size_t>(1 + in_.u16() % 4096));
      call("embra_world_export_obj", false, [&] {
        return embra_world_export_obj(world_, in_.chance(4) ? nullptr : text.data(),
                                      static_cast<int64_t>(in_.chance(4) ? 0 : text.size()), &length);
      });
      break;
    }
    case 0: {
      const double c = in_.value();
      call("embra_constraint_set_compliance" + at + ", " + fmt(c) + ")", true,
           [&] { return embra_constraint_set_compliance(world_, g, kind, index, c); });
      break;
    }
    case 1: {
      const double r = in_.value();
      call("embra_constraint_set_rest" + at + ", " + fmt(r) + ")", true,
           [&] { return embra_constraint_set_rest(world_, g, kind, index, r); });
      break;
    }
    case 2: {
      const embra_group_id to = pick_id(in_, groups_);
      int32_t out = 0;
      int32_t* p = in_.chance(4) ? nullptr : &out;
      call("embra_constraint_set_group" + at + ", to {" + std::to_string(to.index) + ", " +
               std::to_string(to.generation) + "})",
           true, [&] { return embra_constraint_set_group(world_, g, kind, index, to, p); });
      break;
    }
    case 3:
      call("embra_constraint_remove" + at + ")", true, [&] { return embra_constraint_remove(world_, g, kind, index); });
      break;
    case 4: {
      const int32_t e = in_.chance(4) ? in_.integer() : in_.u8() % 2;
      call("embra_group_set_enabled" + at + ", " + std::to_string(e) + ")", true,
           [&] { return embra_group_set_enabled(world_, g, e); });
      break;
    }
    case 5: {
      embra_constraint_def d{};
      int32_t count = 0, generated = 0;
      call("embra_constraint_get" + at + ")", false,
           [&] { return embra_constraint_get(world_, g, kind, index, in_.chance(16) ? nullptr : &d); });
      call("embra_group_get_constraint_count" + at + ")", false, [&] {
        return embra_group_get_constraint_count(world_, g, kind, &count, in_.chance(2) ? nullptr : &generated);
      });
      int32_t enabled = 0;
      call("embra_group_get_enabled" + at + ")", false, [&] { return embra_group_get_enabled(world_, g, &enabled); });
      break;
    }
    case 7: {  // a body's masses: its own, one changed, at its count or another
      const embra_body_id b = pick_id(in_, bodies_);
      int32_t n = 0;
      embra_body_get_masses(world_, b, nullptr, 0, &n);
      std::vector<double> masses(static_cast<size_t>(n) + 2, 0.0);
      embra_body_get_masses(world_, b, masses.data(), n, &n);
      if (n > 0) masses[in_.u16() % static_cast<size_t>(n)] = in_.chance(2) ? 0.0 : in_.value();
      const int32_t count = in_.chance(8) ? n + static_cast<int32_t>(in_.u8() % 3) - 1 : n;
      const double* p = in_.chance(32) ? nullptr : masses.data();
      call("embra_body_set_masses(count " + std::to_string(count) + ")", true,
           [&] { return embra_body_set_masses(world_, b, p, count); });
      break;
    }
    case 6: {  // a body's material: its own, one setting changed
      const embra_body_id b = pick_id(in_, bodies_);
      embra_material m = embra_default_material();
      embra_body_get_material(world_, b, &m);
      double* settings[] = {&m.mass,
                            &m.density,
                            &m.stretch_compliance,
                            &m.shear_compliance,
                            &m.bend_compliance,
                            &m.volume_compliance,
                            &m.damping,
                            &m.thickness,
                            &m.friction_static,
                            &m.friction_dynamic};
      const uint8_t which = in_.u8() % 10;
      *settings[which] = in_.value();
      call("embra_body_set_material(setting " + std::to_string(which) + " = " + fmt(*settings[which]) + ")", true,
           [&] { return embra_body_set_material(world_, b, &m); });
      break;
    }
    default: {  // a field's parameters: its own, through the setter of a kind (maybe not its own)
      const embra_field_id f = pick_id(in_, fields_);
      const double v = in_.value();
      switch (in_.u8() % 4) {
        case 0: {
          embra_wind_def d = embra_default_wind_def();
          embra_wind_get(world_, f, &d);
          d.speed = v;
          call("embra_wind_set(speed " + fmt(v) + ")", true, [&] { return embra_wind_set(world_, f, &d); });
          break;
        }
        case 1: {
          embra_pressure_def d = embra_default_pressure_def();
          embra_pressure_get(world_, f, &d);
          d.inside_pressure = v;
          call("embra_pressure_set(inside " + fmt(v) + ")", true, [&] { return embra_pressure_set(world_, f, &d); });
          break;
        }
        case 2: {
          embra_surface_tension_def d = embra_default_surface_tension_def();
          embra_surface_tension_get(world_, f, &d);
          d.tension = v;
          call("embra_surface_tension_set(tension " + fmt(v) + ")", true,
               [&] { return embra_surface_tension_set(world_, f, &d); });
          break;
        }
        default: {
          embra_vortex_def d = embra_default_vortex_def();
          embra_vortex_get(world_, f, &d);
          d.strength = v;
          if (in_.chance(4)) d.radius = in_.value();
          call("embra_vortex_set(strength " + fmt(v) + ", radius " + fmt(d.radius) + ")", true,
               [&] { return embra_vortex_set(world_, f, &d); });
        }
      }
    }
  }
}

void Session::run() {
  start();
  int calls = 0;
  while (!in_.done() && calls++ < 64) {
    const uint8_t op = in_.u8();
    if (op >= 240) {  // the edits (bytes below 240 decode as they did before the edits came)
      op_edit();
      continue;
    }
    switch (op % 30) {
      case 0:
        op_solver();
        break;
      case 1:
      case 2: {
        embra_group_def d = embra_default_group_def();
        d.version = version(EMBRA_GROUP_DEF_VERSION);
        d.order = in_.integer();
        if (in_.chance(2)) d.weight = in_.integer();
        embra_group_id id{};
        if (call("embra_group_create(order " + std::to_string(d.order) + ", weight " + std::to_string(d.weight) + ")",
                 true, [&] { return embra_group_create(world_, &d, &id); }) == EMBRA_OK)
          groups_.push_back(id);
        break;
      }
      case 3: {
        const embra_group_id g = pick_id(in_, groups_);
        call("embra_group_destroy({" + std::to_string(g.index) + ", " + std::to_string(g.generation) + "})", true,
             [&] { return embra_group_destroy(world_, g); });
        break;
      }
      case 4: {
        const embra_group_id g = pick_id(in_, groups_);
        const int32_t v = in_.integer();
        if (in_.chance(2))
          call("embra_group_set_order(" + std::to_string(v) + ")", true,
               [&] { return embra_group_set_order(world_, g, v); });
        else
          call("embra_group_set_weight(" + std::to_string(v) + ")", true,
               [&] { return embra_group_set_weight(world_, g, v); });
        break;
      }
      case 5:
      case 6:
      case 7:
        op_body();
        break;
      case 8: {
        const embra_body_id b = pick_id(in_, bodies_);
        const double s = in_.chance(2) ? 0.5 + in_.u8() / 256.0 : in_.value();
        const double u = in_.chance(2) ? 1.0 : in_.value(), v = in_.chance(2) ? 1.0 : in_.value();
        call("embra_body_set_rest_scale(" + fmt(s) + ", " + fmt(u) + ", " + fmt(v) + ")", true,
             [&] { return embra_body_set_rest_scale(world_, b, s, u, v); });
        break;
      }
      case 9:
      case 10:
        op_constraint();
        break;
      case 11:
        op_constraints();
        break;
      case 12:
      case 13:
        op_pin();
        break;
      case 14:
      case 15:
        op_collider();
        break;
      case 16:
        op_field();
        break;
      case 17:
        op_set_state();
        break;
      case 18:
      case 19:
      case 20:
        op_step();
        break;
      case 21:
        op_panel_mesh();
        break;
      case 22:
        op_tolerances();
        break;
      case 23:
        op_read();
        break;
      case 24:
        op_misuse();
        break;
      case 25:
        op_cancel();
        break;
      case 26:
        roundtrip(false);
        break;
      case 27:
        roundtrip(true);
        break;
      case 28:
        op_solve();
        break;
      default:
        op_diagnose();
    }
  }
  roundtrip(false);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Bytes in(data, size);
  Session session(in);
  session.run();
  return 0;
}
