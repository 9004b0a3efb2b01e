// Error handling at core level: every refused call throws embra::Error with the documented code and
// leaves the world exactly as it was (world.hpp: "a refused call leaves the world exactly as it
// was").
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>

namespace embra {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Everything observable about a world that a refused call must not change.
struct Snapshot {
  int32_t particles;
  int64_t constraints;
  size_t groups, pins, colliders, bodies;
  std::vector<Vec3> x, v;
  std::vector<double> inv_mass;
  Settings settings;
  int64_t frame;

  explicit Snapshot(const World& w)
      : particles(w.particle_count()),
        constraints(w.constraint_count()),
        groups(w.group_count()),
        pins(w.pin_count()),
        colliders(w.collider_count()),
        bodies(w.body_count()),
        x(w.positions()),
        v(w.velocities()),
        inv_mass(w.inverse_masses()),
        settings(w.settings()),
        frame(w.report().frame) {}

  void expect_same(const World& w, const std::string& what) const {
    EXPECT_EQ(w.particle_count(), particles) << what;
    EXPECT_EQ(w.constraint_count(), constraints) << what;
    EXPECT_EQ(w.group_count(), groups) << what;
    EXPECT_EQ(w.pin_count(), pins) << what;
    EXPECT_EQ(w.collider_count(), colliders) << what;
    EXPECT_EQ(w.body_count(), bodies) << what;
    ASSERT_EQ(w.positions().size(), x.size()) << what;
    EXPECT_EQ(std::memcmp(w.positions().data(), x.data(), sizeof(Vec3) * x.size()), 0) << what;
    EXPECT_EQ(std::memcmp(w.velocities().data(), v.data(), sizeof(Vec3) * v.size()), 0) << what;
    EXPECT_EQ(w.inverse_masses(), inv_mass) << what;
    EXPECT_EQ(w.settings().dt, settings.dt) << what;
    EXPECT_EQ(w.settings().substeps, settings.substeps) << what;
    EXPECT_EQ(w.settings().iterations, settings.iterations) << what;
    EXPECT_EQ(w.settings().gravity, settings.gravity) << what;
    EXPECT_EQ(w.settings().damping, settings.damping) << what;
    EXPECT_EQ(w.report().frame, frame) << what;
  }
};

void expect_refused(World& w, ErrorCode code, const std::string& what, const std::function<void()>& call) {
  const Snapshot before(w);
  try {
    call();
    ADD_FAILURE() << what << ": no error thrown";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << what << ": " << e.what();
    EXPECT_GT(std::strlen(e.what()), 0u) << what;
  }
  before.expect_same(w, what);
}

/// Four particles (a tetrahedron), one distance constraint, a soft pin in an extra group, a plane.
struct Fixture {
  World w;
  Id body, group, soft_pin, hard_pin, collider;
  Fixture() : w(test::settings(4, 2, Vec3(0, 0, -9.81))) {
    const std::vector<double> x{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const std::vector<int32_t> edges{0, 1};
    BodyDesc d;
    d.positions = x;
    d.edges = edges;
    body = w.create_body(d);
    group = w.create_group(GroupDesc{});
    PinDesc sp;
    sp.particle = 2;
    sp.target = Vec3(0, 1, 0);
    sp.compliance = 1e-3;
    sp.group = group;
    soft_pin = w.create_pin(sp);
    hard_pin = test::hard_pin(w, 0, Vec3::Zero());
    collider = w.create_collider(ColliderDesc{});
    w.step();  // some state: velocities, multipliers
  }
};

TEST(Errors, AddConstraintsRefusesInvalidInput) {
  Fixture f;
  World& w = f.w;
  auto add = [&](Kind kind, std::vector<int32_t> ids, std::vector<double> rest, double compliance = 0.0,
                 Id group = Id{}) {
    return [&w, kind, ids, rest, compliance, group] {
      ConstraintDesc d;
      d.kind = kind;
      d.particles = ids;
      d.rest = rest;
      d.uniform_compliance = compliance;
      d.group = group;
      w.add_constraints(d);
    };
  };
  const ErrorCode bad = ErrorCode::invalid_argument;
  expect_refused(w, bad, "particle out of range", add(Kind::distance, {0, 4}, {}));
  expect_refused(w, bad, "negative particle", add(Kind::distance, {-1, 2}, {}));
  expect_refused(w, bad, "repeated particle", add(Kind::dihedral, {0, 1, 2, 1}, {}));
  expect_refused(w, bad, "length not a multiple of the arity", add(Kind::edge_angle, {0, 1, 2, 3}, {}));
  expect_refused(w, bad, "empty", add(Kind::distance, {}, {}));
  expect_refused(w, bad, "rest array length", add(Kind::distance, {0, 1, 1, 2}, {1.0}));
  expect_refused(w, bad, "negative compliance", add(Kind::distance, {0, 1}, {}, -1.0));
  expect_refused(w, bad, "NaN rest", add(Kind::distance, {0, 1}, {kNaN}));
  expect_refused(w, bad, "negative rest length", add(Kind::tether, {0, 1}, {-0.5}));
  expect_refused(w, bad, "rest angle above pi", add(Kind::edge_angle, {0, 1, 2}, {4.0}));
  expect_refused(w, bad, "dihedral rest -pi", add(Kind::dihedral, {0, 1, 2, 3}, {-std::numbers::pi}));
  expect_refused(w, bad, "weld rest not 0", add(Kind::weld, {0, 1}, {0.1}));
  expect_refused(w, bad, "unknown kind", add(static_cast<Kind>(17), {0, 1}, {}));
  // All or nothing: the first constraint is fine, the second is not.
  expect_refused(w, bad, "second of two invalid", add(Kind::distance, {0, 1, 2, 2}, {}));
  expect_refused(w, bad, "second rest invalid", add(Kind::distance, {0, 1, 1, 2}, {1.0, kNaN}));
  // A rest value measured from coincident particles does not exist.
  w.set_positions(3, std::vector<double>{0, 0, 0});
  expect_refused(w, bad, "zero-length rest measured", add(Kind::distance, {0, 3}, {}));
  expect_refused(w, bad, "zero-volume rest measured", add(Kind::tet_volume, {0, 1, 2, 3}, {}));
  // A destroyed group's id is stale.
  const Id g = w.create_group(GroupDesc{});
  w.destroy_group(g);
  expect_refused(w, ErrorCode::stale_id, "destroyed group", add(Kind::distance, {0, 1}, {}, 0.0, g));
  // The valid call still works afterwards.
  const int64_t before = w.constraint_count();
  add(Kind::distance, {1, 2}, {})();
  EXPECT_EQ(w.constraint_count(), before + 1);
}

TEST(Errors, CreateBodyRefusesInvalidInput) {
  Fixture f;
  World& w = f.w;
  const ErrorCode bad = ErrorCode::invalid_argument;
  const std::vector<double> tri{0, 0, 0, 1, 0, 0, 0, 1, 0};
  auto body = [&w](std::vector<double> x, std::vector<int32_t> triangles, std::vector<double> masses = {},
                   std::vector<double> uvs = {}, Material m = Material{}) {
    return [&w, x, triangles, masses, uvs, m] {
      BodyDesc d;
      d.positions = x;
      d.triangles = triangles;
      d.masses = masses;
      d.uvs = uvs;
      d.material = m;
      w.create_body(d);
    };
  };
  expect_refused(w, bad, "no positions", body({}, {}));
  expect_refused(w, bad, "positions not a multiple of 3", body({0, 0}, {}));
  expect_refused(w, bad, "NaN coordinate", body({0, 0, kNaN, 1, 0, 0, 0, 1, 0}, {0, 1, 2}));
  expect_refused(w, bad, "vertex out of range", body(tri, {0, 1, 3}));
  expect_refused(w, bad, "repeated vertex", body(tri, {0, 1, 1}));
  expect_refused(w, bad, "zero-area triangle", body({0, 0, 0, 1, 0, 0, 2, 0, 0}, {0, 1, 2}));
  expect_refused(w, bad, "masses length", body(tri, {0, 1, 2}, {1.0, 1.0}));
  expect_refused(w, bad, "negative mass", body(tri, {0, 1, 2}, {1.0, -1.0, 1.0}));
  expect_refused(w, bad, "uvs length", body(tri, {0, 1, 2}, {}, {0, 0, 1, 0}));
  Material m;
  m.stretch_compliance = -1.0;
  expect_refused(w, bad, "negative compliance", body(tri, {0, 1, 2}, {}, {}, m));
  m = Material{};
  m.mass = 0.0;
  m.density = 0.0;
  expect_refused(w, bad, "no mass and no density", body(tri, {0, 1, 2}, {}, {}, m));
  // Stale body ids.
  expect_refused(w, ErrorCode::stale_id, "body index out of range", [&] { w.body(Id{7, 1}); });
  expect_refused(w, ErrorCode::stale_id, "body generation", [&] { w.set_rest_scale(Id{0, 2}, 0.5, 1, 1); });
  expect_refused(w, bad, "negative rest scale", [&] { w.set_rest_scale(f.body, -0.5, 1, 1); });
  expect_refused(w, bad, "NaN rest scale u", [&] { w.set_rest_scale(f.body, 1, kNaN, 1); });
  EXPECT_EQ(w.body(f.body).rest_scale, 1.0);
}

TEST(Errors, PinsGroupsCollidersAndSettingsRefuseInvalidInput) {
  Fixture f;
  World& w = f.w;
  const ErrorCode bad = ErrorCode::invalid_argument, stale = ErrorCode::stale_id;
  auto pin = [&w](int32_t particle, Vec3 target, double compliance, Id group = Id{}) {
    return [&w, particle, target, compliance, group] {
      PinDesc d;
      d.particle = particle;
      d.target = target;
      d.compliance = compliance;
      d.group = group;
      w.create_pin(d);
    };
  };
  expect_refused(w, bad, "pin particle out of range", pin(4, Vec3::Zero(), 0.0));
  expect_refused(w, bad, "second hard pin", pin(0, Vec3::Zero(), 0.0));
  expect_refused(w, bad, "negative pin compliance", pin(1, Vec3::Zero(), -1.0));
  expect_refused(w, bad, "NaN pin target", pin(1, Vec3(0, kNaN, 0), 0.0));
  const Id dead = w.create_group(GroupDesc{});
  w.destroy_group(dead);
  expect_refused(w, stale, "soft pin in a destroyed group", pin(1, Vec3::Zero(), 1e-3, dead));
  expect_refused(w, bad, "NaN pin target update", [&] { w.set_pin_target(f.soft_pin, Vec3(kNaN, 0, 0)); });
  const size_t pins = w.pin_count();
  PinDesc pd;
  pd.particle = 3;
  const Id p3 = w.create_pin(pd);
  w.destroy_pin(p3);
  EXPECT_EQ(w.pin_count(), pins);
  expect_refused(w, stale, "destroyed pin", [&] { w.set_pin_target(p3, Vec3::Zero()); });
  expect_refused(w, stale, "destroyed pin twice", [&] { w.destroy_pin(p3); });

  expect_refused(w, bad, "group weight 0", [&] { w.create_group(GroupDesc{0, 0, "x"}); });
  expect_refused(w, bad, "group weight 1001", [&] { w.set_group_weight(f.group, 1001); });
  expect_refused(w, bad, "destroy the default group", [&] { w.destroy_group(w.default_group()); });
  expect_refused(w, bad, "destroy the contact group", [&] { w.destroy_group(w.contact_group()); });
  expect_refused(w, bad, "destroy a group holding a soft pin", [&] { w.destroy_group(f.group); });
  expect_refused(w, stale, "order of a destroyed group", [&] { w.set_group_order(dead, 3); });

  ColliderDesc c;
  c.rotation = Eigen::Quaterniond(2, 0, 0, 0);
  expect_refused(w, bad, "non-unit quaternion", [&] { w.create_collider(c); });
  c = ColliderDesc{};
  c.shape = ColliderShape::sphere;
  c.radius = 0.0;
  expect_refused(w, bad, "sphere radius 0", [&] { w.create_collider(c); });
  c = ColliderDesc{};
  c.shape = static_cast<ColliderShape>(5);
  expect_refused(w, bad, "unknown shape", [&] { w.create_collider(c); });
  c = ColliderDesc{};
  c.friction_dynamic = -0.1;
  expect_refused(w, bad, "negative friction", [&] { w.create_collider(c); });
  expect_refused(w, bad, "NaN collider position",
                 [&] { w.set_collider_transform(f.collider, Vec3(kNaN, 0, 0), Eigen::Quaterniond::Identity()); });
  expect_refused(w, stale, "collider id", [&] { w.collider(Id{9, 1}); });

  auto set = [&w](auto edit) {
    return [&w, edit] {
      Settings s = w.settings();
      edit(s);
      w.set_settings(s);
    };
  };
  expect_refused(w, bad, "dt 0", set([](Settings& s) { s.dt = 0.0; }));
  expect_refused(w, bad, "dt NaN", set([](Settings& s) { s.dt = kNaN; }));
  expect_refused(w, bad, "substeps 0", set([](Settings& s) { s.substeps = 0; }));
  expect_refused(w, bad, "iterations 10001", set([](Settings& s) { s.iterations = 10001; }));
  expect_refused(w, bad, "gravity NaN", set([](Settings& s) { s.gravity.y() = kNaN; }));
  expect_refused(w, bad, "negative damping", set([](Settings& s) { s.damping = -1.0; }));
  expect_refused(w, bad, "set_gravity NaN", [&] { w.set_gravity(Vec3(0, 0, kNaN)); });

  expect_refused(w, bad, "positions out of range", [&] { w.set_positions(3, std::vector<double>{0, 0, 0, 1, 1, 1}); });
  expect_refused(w, bad, "positions length", [&] { w.set_positions(0, std::vector<double>{0, 0}); });
  expect_refused(w, bad, "NaN position", [&] { w.set_positions(1, std::vector<double>{0, kNaN, 0}); });
  expect_refused(w, bad, "negative first", [&] { w.set_velocities(-1, std::vector<double>{0, 0, 0}); });
  expect_refused(w, bad, "velocity NaN", [&] { w.set_velocities(0, std::vector<double>{0, 0, kNaN}); });
}

// A step that produces a non-finite state is undone: the world returns to the state it had before
// the call, records a warning naming the particle and frame, and throws Error(numerical). Here two
// particles 2e300 apart (each coordinate within the accepted range) are held by a distance
// constraint whose length overflows.
TEST(Errors, NumericalFailureRestoresTheWorld) {
  World w(test::settings(1, 1, Vec3(0, 0, -9.81), 0.0, 1.0));
  const int32_t first = test::add_particles(w, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}, {1.0, 1.0, 1.0});
  const std::vector<int32_t> ids{first + 1, first + 2};
  ConstraintDesc d;
  d.particles = ids;
  w.add_constraints(d);
  w.step();  // a good frame first
  // Accepted values (|v| <= 1e300) whose distance squared overflows: the projection goes NaN.
  w.set_positions(first + 1, std::vector<double>{-1e300, 0, 0, 1e300, 0, 0});
  expect_refused(w, ErrorCode::numerical, "overflowing step", [&] { w.step(); });
  EXPECT_EQ(w.warning().frame, 1);
  EXPECT_TRUE(w.warning().particle == first + 1 || w.warning().particle == first + 2) << w.warning().particle;
  EXPECT_FALSE(w.warning().message.empty());
  // Fixing the cause lets the world step on.
  w.set_positions(first + 1, std::vector<double>{1, 0, 0, 2, 0, 0});
  w.step();
  EXPECT_EQ(w.report().frame, 2);
}

// The automatic tethers' multipliers are state a save writes and the reactions read: a cancelled
// frame leaves them as the last completed frame did (each substep resets them before projecting).
TEST(Errors, CancelledStepKeepsTheTethersMultipliers) {
  // One pass a frame, so the cloth stretches; the tethers keep multipliers (for the realignment)
  // only with realignment passes.
  Settings s = test::settings(1, 1, Vec3(0, 0, -9.81));
  s.realign_passes = 1;
  World w(s);
  const test::Grid g = test::make_grid(9, 9, 0.05, Vec3::Zero());
  BodyDesc d;
  d.positions = g.positions;
  d.triangles = g.triangles;
  d.generate = generate_stretch;  // inextensible (the default material): tethers to the pins
  const Id body = w.create_body(d);
  const int32_t first = w.body(body).first_particle;
  test::hard_pin(w, first + g.index(0, 0), Vec3(0, 0, 0));
  test::hard_pin(w, first + g.index(8, 0), Vec3(0.4, 0, 0));
  for (int f = 0; f < 30; ++f) w.step();  // hanging: the far corners' tethers taut
  const StaticsState before = w.statics_state();
  ASSERT_EQ(before.tethers.size(), 1u);  // the stretch group's
  std::atomic<bool> cancel{true};
  StepControl control;
  control.cancel = &cancel;
  expect_refused(w, ErrorCode::cancelled, "cancelled step", [&] { w.step(control); });
  const StaticsState after = w.statics_state();
  ASSERT_EQ(after.tethers.size(), 1u);
  EXPECT_EQ(after.tethers[0].lambda, before.tethers[0].lambda);
}

}  // namespace
}  // namespace embra
