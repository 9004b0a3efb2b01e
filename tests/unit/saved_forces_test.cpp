// Forces survive a save and a load (the scene's state.forces, World::statics_state): a settled
// world saved and loaded reads the same member forces, pin reactions and collider reactions, bit
// for bit, before its first step; those forces still balance the applied load (worked out here
// from the masses, gravity and loads), and the member forces are still the method of joints'. The
// section changes no step: a world loaded with it and one loaded without it step the same bits.
#include "test_support.hpp"

#include "embra/io/scene.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace embra {
namespace {

using nlohmann::json;

constexpr double kG = 9.81;

/// Every number the force readers give, in one list: each live group's forces of every kind
/// but the weld (constraint_forces), every pin's reaction, every collider's force, moment and
/// contact count.
std::vector<double> forces_read(const World& w) {
  std::vector<double> out;
  for (uint32_t slot = 0; slot < w.groups().size(); ++slot) {
    const Group& g = w.groups()[slot];
    if (!g.alive) continue;
    for (const KindInfo& info : kKinds) {
      if (info.kind == Kind::weld) continue;
      const std::vector<double> f = w.constraint_forces(Id{slot, g.generation}, info.kind);
      out.insert(out.end(), f.begin(), f.end());
    }
  }
  for (const Reaction& r : w.reactions()) out.insert(out.end(), {r.force.x(), r.force.y(), r.force.z()});
  for (const ColliderReaction& r : w.collider_reactions())
    out.insert(out.end(), {r.force.x(), r.force.y(), r.force.z(), r.moment.x(), r.moment.y(), r.moment.z(),
                           static_cast<double>(r.contacts)});
  return out;
}

/// The same bits (memcmp: a -0 is not a +0).
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

std::unique_ptr<World> load(const std::string& text) {
  io::SceneMeta meta;
  return io::load_scene(text, ".", meta);
}

std::string save(const World& w) {
  return io::save_scene(w, io::SceneMeta{});
}

/// |sum of the pins' and colliders' reactions + the applied load| over |the applied load|.
double imbalance(const World& w) {
  Vec3 sum = Vec3::Zero();
  for (const Reaction& r : w.reactions()) sum += r.force;
  for (const ColliderReaction& r : w.collider_reactions()) sum += r.force;
  const Vec3 load = test::applied_load(w);
  return (sum + load).norm() / load.norm();
}

/// The scene text without its state.forces (a scene saved before this section existed).
std::string without_forces(const std::string& text) {
  json doc = json::parse(text);
  doc["state"].erase("forces");
  return doc.dump(1) + "\n";
}

/// Steps both worlds `frames` frames; true when their positions and velocities stay the same bits.
bool step_alike(World& a, World& b, int frames) {
  for (int f = 0; f < frames; ++f) {
    a.step();
    b.step();
    if (!same_bits(test::flatten(a.positions()), test::flatten(b.positions())) ||
        !same_bits(test::flatten(a.velocities()), test::flatten(b.velocities())))
      return false;
  }
  return true;
}

/// The collider-reaction scene (ColliderReactions.NetOnSphereAndPinsSumToTheLoad): a 9 x 9 stretchy
/// net hard-pinned at two corners, draped over a sphere, a point load in its middle, settled.
/// Saved and loaded, it reads the same reactions, which sum to minus the weight and load as
/// before; loaded without state.forces (as before it existed) the sphere's force reads 0.
TEST(SavedForces, NetOnSphereReactionsAreTheSameBitsAfterALoad) {
  Settings s = test::settings(4, 100, Vec3(0.0, 0.0, -kG), 4.0);
  s.realign_passes = 4;
  s.tethers = 0;
  World w(s);
  ColliderDesc ball;
  ball.shape = ColliderShape::sphere;
  ball.radius = 0.6;
  ball.position = Vec3(1.0, 1.1, -0.3);
  w.create_collider(ball);
  constexpr int n = 9;
  std::vector<Vec3> x;
  const int32_t first = test::add_net(w, n, 0.25, 0.5, 0.2, 1e-3, x);
  test::hard_pin(w, first, x[0]);
  test::hard_pin(w, first + n - 1, x[n - 1]);
  const double point_load[] = {0.0, 0.0, -3.0};
  w.set_loads(first + 4 * n + 4, std::span<const double>(point_load, 3));
  for (int f = 0; f < 800; ++f) w.step();

  const std::vector<double> before = forces_read(w);
  const std::string text = save(w);
  const std::unique_ptr<World> loaded = load(text);
  const std::vector<double> after = forces_read(*loaded);
  EXPECT_TRUE(same_bits(before, after));
  const double sphere_before = w.collider_reactions()[0].force.norm();
  const double sphere_after = loaded->collider_reactions()[0].force.norm();
  EXPECT_GT(loaded->collider_reactions()[0].contacts, 4);
  const double imbalance_after = imbalance(*loaded);
  EXPECT_LT(imbalance_after, 1e-9);
  // Load then save: the same bytes.
  EXPECT_EQ(save(*loaded), text);
  // As before the section existed: the sphere's force and the pins' share of the constraint forces
  // read 0, and the reactions miss most of the load.
  const std::unique_ptr<World> bare = load(without_forces(text));
  EXPECT_EQ(bare->collider_reactions()[0].force, Vec3::Zero());
  const double missing = imbalance(*bare);
  EXPECT_GT(missing, 0.5);
  RecordProperty("load_N", test::sci(test::applied_load(w).norm()));
  RecordProperty("sphere_force_before_save_N", test::sci(sphere_before));
  RecordProperty("sphere_force_after_load_N", test::sci(sphere_after));
  RecordProperty("imbalance_after_load", test::sci(imbalance_after));
  RecordProperty("imbalance_without_forces", test::sci(missing));
  // The forces change no step: loaded with and without them, the same bits frame after frame, and
  // the same as the world that was never saved.
  EXPECT_TRUE(step_alike(*loaded, *bare, 5));
  for (int f = 0; f < 5; ++f) w.step();
  EXPECT_TRUE(same_bits(test::flatten(w.positions()), test::flatten(loaded->positions()))) << "after 5 more frames";
  EXPECT_TRUE(same_bits(forces_read(w), forces_read(*loaded)));
}

/// A pin-jointed truss: two hard members from wall pins at (+-a, 0, 0) to a joint C, a second joint
/// D welded to C that carries a slanted point load, and a particle hanging on a soft pin beside
/// them. Settled, saved and loaded: the member forces are the same bits, and still the method of
/// joints' at the loaded positions (C and D, welded, one joint: T1 u1 + T2 u2 = -(their weight and
/// load), u the unit vectors from C toward the pins) to 1e-6 relative; the soft pin's reaction is
/// still its particle's weight; every reaction the same bits.
TEST(SavedForces, TrussMemberForcesWeldAndSoftPinAreTheSameBitsAfterALoad) {
  constexpr double a = 2.0, h = 1.5, m = 1e4;
  Settings s = test::settings(4, 600, Vec3(0.0, 0.0, -kG), 4.0);
  s.realign_passes = 4;
  s.tethers = 0;
  World w(s);
  const std::vector<Vec3> joints = {Vec3(-a, 0.0, 0.0), Vec3(a, 0.0, 0.0), Vec3(0.0, 0.0, -h), Vec3(0.0, 0.0, -h),
                                    Vec3(3.0, 0.0, -1.0)};
  const int32_t first = test::add_particles(w, joints, std::vector<double>(joints.size(), m));
  ConstraintDesc members;
  members.kind = Kind::distance;
  const std::vector<int32_t> member_ids = {first, first + 2, first + 1, first + 2};
  members.particles = member_ids;
  w.add_constraints(members);
  ConstraintDesc weld;
  weld.kind = Kind::weld;
  const std::vector<int32_t> weld_ids = {first + 2, first + 3};
  weld.particles = weld_ids;
  w.add_constraints(weld);
  test::hard_pin(w, first, joints[0]);
  test::hard_pin(w, first + 1, joints[1]);
  PinDesc soft;
  soft.particle = first + 4;
  soft.target = joints[4];
  soft.compliance = 1e-7;
  w.create_pin(soft);
  const Vec3 point(3.0e4, 0.0, -8.0e4);
  w.set_loads(first + 3, std::span<const double>(point.data(), 3));
  for (int f = 0; f < 300; ++f) w.step();

  const std::vector<double> before = forces_read(w);
  const std::string text = save(w);
  ASSERT_NE(text.find("\"weld\""), std::string::npos) << "the weld's multipliers are saved";
  const std::unique_ptr<World> loaded = load(text);
  EXPECT_TRUE(same_bits(before, forces_read(*loaded)));
  EXPECT_EQ(save(*loaded), text);

  // The method of joints at the loaded positions.
  const std::vector<Vec3>& p = loaded->positions();
  const Vec3 u1 = (p[first] - p[first + 2]).normalized(), u2 = (p[first + 1] - p[first + 2]).normalized();
  const Vec3 applied = point + 2.0 * m * s.gravity;
  Eigen::Matrix<double, 3, 2> A;
  A.col(0) = u1;
  A.col(1) = u2;
  const Eigen::Vector2d exact = A.colPivHouseholderQr().solve(-applied);
  const std::vector<double> f = loaded->constraint_forces(loaded->default_group(), Kind::distance);
  ASSERT_EQ(f.size(), 2u);
  const double error = std::max(std::abs(f[0] - exact[0]), std::abs(f[1] - exact[1])) / exact.cwiseAbs().maxCoeff();
  RecordProperty("member_forces_N", test::sci(f[0]) + " " + test::sci(f[1]));
  RecordProperty("method_of_joints_relative_error", test::sci(error));
  EXPECT_LT(error, 1e-6);
  EXPECT_GT(exact.minCoeff(), 0.0) << "both members in tension";
  // The soft pin (the third live pin) holds its particle's weight.
  const std::vector<Reaction> r = loaded->reactions();
  ASSERT_EQ(r.size(), 3u);
  const Vec3 weight = m * s.gravity;
  EXPECT_LT((r[2].force + weight).norm(), 1e-6 * weight.norm());
  const double balance = imbalance(*loaded);
  RecordProperty("imbalance_after_load", test::sci(balance));
  EXPECT_LT(balance, 1e-9);
  // Without the section, the members read 0.
  const std::unique_ptr<World> bare = load(without_forces(text));
  EXPECT_EQ(bare->constraint_forces(bare->default_group(), Kind::distance), std::vector<double>(2, 0.0));
  EXPECT_TRUE(step_alike(*loaded, *bare, 5));
}

/// An inextensible cloth hanging from two hard-pinned corners with automatic tethers
/// (Settings::tethers): the tethers' multipliers are saved too, and the pins' reactions (which
/// count the tethers' forces) are the same bits after a load.
TEST(SavedForces, AutomaticTethersAreSavedWithTheirGroup) {
  Settings s = test::settings(8, 4, Vec3(0.0, 0.0, -kG), 1.0);
  s.tethers = 2;
  s.realign_passes = 1;
  World w(s);
  constexpr int n = 6;
  std::vector<double> xyz;
  std::vector<int32_t> tri;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) xyz.insert(xyz.end(), {0.2 * i, 0.0, -0.2 * j});
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int32_t p = j * n + i;
      tri.insert(tri.end(), {p, p + 1, p + n + 1, p, p + n + 1, p + n});
    }
  BodyDesc b;
  b.positions = xyz;
  b.triangles = tri;
  b.material.stretch_compliance = 0.0;
  const Id body = w.create_body(b);
  const int32_t first = w.body(body).first_particle;
  test::hard_pin(w, first, Vec3(xyz[0], xyz[1], xyz[2]));
  test::hard_pin(w, first + n - 1, Vec3(xyz[3 * (n - 1)], xyz[3 * (n - 1) + 1], xyz[3 * (n - 1) + 2]));
  for (int f = 0; f < 60; ++f) w.step();
  const std::string text = save(w);
  ASSERT_TRUE(json::parse(text)["state"]["forces"].contains("tethers"));
  const std::unique_ptr<World> loaded = load(text);
  EXPECT_TRUE(same_bits(forces_read(w), forces_read(*loaded)));
  EXPECT_EQ(save(*loaded), text);
  const std::unique_ptr<World> bare = load(without_forces(text));
  EXPECT_TRUE(step_alike(*loaded, *bare, 3));
}

/// What does not match the world built from the scene is refused, and nothing is built: a wrong
/// count of multipliers, a kind the group does not hold, tethers of the wrong count, a pin or
/// collider that is not in the scene, a pin given twice, a particle out of range, a number beyond 1e300.
/// The core's own check refuses a wrong count and leaves every force as it was.
TEST(SavedForces, StateThatDoesNotMatchTheWorldIsRefused) {
  Settings s = test::settings(4, 20, Vec3(0.0, 0.0, -kG), 4.0);
  s.realign_passes = 1;
  s.tethers = 0;
  World w(s);
  ColliderDesc ground;
  ground.position = Vec3(0.0, 0.0, -0.3);
  w.create_collider(ground);
  std::vector<Vec3> x;
  const int32_t first = test::add_net(w, 4, 0.25, 0.0, 0.2, 1e-3, x);
  test::hard_pin(w, first, x[0]);
  PinDesc soft;
  soft.particle = first + 3;
  soft.target = x[3];
  soft.compliance = 1e-4;
  w.create_pin(soft);
  for (int f = 0; f < 30; ++f) w.step();
  const std::string text = save(w);
  const json doc = json::parse(text);
  const json& forces = doc["state"]["forces"];
  ASSERT_TRUE(forces.contains("constraints") && forces.contains("pins") && forces.contains("contacts"));
  EXPECT_EQ(forces["pins"].size(), 2u) << "the soft pin's multiplier and the hard pin's impulse";

  const auto refused = [&](const std::function<void(json&)>& edit, const std::string& where) {
    json d = doc;
    edit(d);
    try {
      load(d.dump(1));
      ADD_FAILURE() << "accepted: " << where;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  };
  refused([](json& d) { d["state"]["forces"]["constraints"][0]["multipliers"].push_back(1.0); },
          "/state/forces/constraints/0/multipliers");
  refused([](json& d) { d["state"]["forces"]["constraints"][0]["multipliers"].erase(0); },
          "/state/forces/constraints/0/multipliers");
  refused([](json& d) { d["state"]["forces"]["constraints"][0]["kind"] = "dihedral"; },
          "/state/forces/constraints/0/multipliers");
  refused([](json& d) { d["state"]["forces"]["constraints"][0]["group"] = "nowhere"; },
          "/state/forces/constraints/0/group");
  refused([](json& d) { d["state"]["forces"]["constraints"].push_back(d["state"]["forces"]["constraints"][0]); },
          "given twice");
  refused(
      [](json& d) {
        d["state"]["forces"]["tethers"] = json::array({{{"group", "default"}, {"multipliers", {1.0}}}});
      },
      "automatic tethers");
  refused([](json& d) { d["state"]["forces"]["pins"][0]["pin"] = "nowhere"; }, "/state/forces/pins/0/pin");
  refused([](json& d) { d["state"]["forces"]["pins"].push_back(d["state"]["forces"]["pins"][0]); }, "given twice");
  refused([](json& d) { d["state"]["forces"]["contacts"][0]["collider"] = "nowhere"; },
          "/state/forces/contacts/0/collider");
  refused([](json& d) { d["state"]["forces"]["contacts"][0]["particle"] = 16; }, "/state/forces/contacts/0/particle");
  refused([](json& d) { d["state"]["forces"]["contacts"][0]["force_h2"][1] = 1e301; },
          "/state/forces/contacts/0/force_h2/1");
  refused([](json& d) { d["state"]["forces"]["constraints"][0]["multipliers"][0] = -1e301; },
          "/state/forces/constraints/0/multipliers/0");

  // The core refuses a wrong count and changes no force.
  const std::vector<double> before = forces_read(w);
  StaticsState bad = w.statics_state();
  ASSERT_FALSE(bad.constraints.empty());
  bad.constraints[0].lambda.pop_back();
  EXPECT_THROW(w.set_statics_state(bad), Error);
  StaticsState stale = w.statics_state();
  stale.contacts[0].collider = 7;
  EXPECT_THROW(w.set_statics_state(stale), Error);
  EXPECT_TRUE(same_bits(before, forces_read(w)));
  EXPECT_EQ(save(w), text);
}

}  // namespace
}  // namespace embra
