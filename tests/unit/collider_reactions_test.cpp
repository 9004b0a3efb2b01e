// The force each collider exerts on the world (World::collider_reactions), checked against the
// loads worked out here, independently of the solver: at a static rest the colliders' forces and
// the pins' reactions together balance every weight and point load, and the colliders' moments
// balance the loads' moments.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace embra {
namespace {

constexpr double kG = 9.81;

Settings resting_settings() {
  Settings s = test::settings(4, 100, Vec3(0.0, 0.0, -kG), 4.0);
  s.realign_passes = 4;
  s.tethers = 0;
  return s;
}

/// Moment of the applied loads about `about` (N m), each acting at its particle.
Vec3 applied_moment(const World& w, const Vec3& about) {
  Vec3 total = Vec3::Zero();
  const auto x = w.positions();
  for (int32_t i = 0; i < w.particle_count(); ++i) {
    Vec3 f = w.loads()[i];
    if (w.inverse_masses()[i] > 0.0) f += w.settings().gravity / w.inverse_masses()[i];
    total += (x[i] - about).cross(f);
  }
  return total;
}

/// A 6 x 6 net lying on a ground plane under gravity and three point loads, one of them with a
/// horizontal part that friction holds. Nothing is pinned, so the plane carries everything: its
/// force is minus the total weight and load, and its moment about its origin minus the loads'.
TEST(ColliderReactions, GroundPlaneCarriesTheWeightAndLoads) {
  World w(resting_settings());
  ColliderDesc ground;  // the plane z = 0, normal +z
  const Id plane = w.create_collider(ground);
  std::vector<Vec3> x;
  const int32_t first = test::add_net(w, 6, 0.25, 0.0, 0.5, 1e-4, x);
  const double loads[] = {0.0, 0.0, -40.0, 1.5, -0.5, -10.0, 0.0, 0.0, -25.0};
  const int32_t at[] = {first + 14, first + 22, first + 31};
  for (int k = 0; k < 3; ++k) w.set_loads(at[k], std::span<const double>(&loads[3 * k], 3));
  for (int f = 0; f < 300; ++f) w.step();
  ASSERT_TRUE(w.reactions().empty());
  const std::vector<ColliderReaction> r = w.collider_reactions();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].collider.index, plane.index);
  EXPECT_EQ(r[0].contacts, 36);
  const Vec3 load = test::applied_load(w);
  const double imbalance = (r[0].force + load).norm() / load.norm();
  const Vec3 moment = applied_moment(w, ground.position);
  const double moment_imbalance = (r[0].moment + moment).norm() / moment.norm();
  RecordProperty("imbalance", test::sci(imbalance));
  RecordProperty("moment_imbalance", test::sci(moment_imbalance));
  RecordProperty("max_speed", test::sci(w.report().max_speed));
  EXPECT_LT(imbalance, 1e-9);
  EXPECT_LT(moment_imbalance, 1e-9);
}

/// A 9 x 9 stretchy net hard-pinned at two corners, the rest of it draped over a sphere: the pins'
/// reactions and the sphere's force (normal push and friction, the contacts around the top of the
/// sphere slanted) sum to minus the total weight and load.
TEST(ColliderReactions, NetOnSphereAndPinsSumToTheLoad) {
  World w(resting_settings());
  ColliderDesc ball;
  ball.shape = ColliderShape::sphere;
  ball.radius = 0.6;
  ball.position = Vec3(1.0, 1.1, -0.3);
  const Id sphere = w.create_collider(ball);
  constexpr int n = 9;
  std::vector<Vec3> x;
  const int32_t first = test::add_net(w, n, 0.25, 0.5, 0.2, 1e-3, x);
  test::hard_pin(w, first, x[0]);
  test::hard_pin(w, first + n - 1, x[n - 1]);
  const double load[] = {0.0, 0.0, -3.0};
  w.set_loads(first + 4 * n + 4, std::span<const double>(load, 3));
  for (int f = 0; f < 800; ++f) w.step();
  const std::vector<ColliderReaction> r = w.collider_reactions();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].collider.index, sphere.index);
  Vec3 pins = Vec3::Zero();
  for (const Reaction& p : w.reactions()) pins += p.force;
  const Vec3 total = test::applied_load(w);
  const double imbalance = (pins + r[0].force + total).norm() / total.norm();
  // The sphere carries a real share, and not straight up only (slanted contacts, friction).
  const double share = r[0].force.z() / -total.z();
  const Vec3 horizontal(r[0].force.x(), r[0].force.y(), 0.0);
  RecordProperty("imbalance", test::sci(imbalance));
  RecordProperty("sphere_share", test::sci(share));
  RecordProperty("sphere_horizontal", test::sci(horizontal.norm()));
  RecordProperty("contacts", std::to_string(r[0].contacts));
  RecordProperty("max_speed", test::sci(w.report().max_speed));
  EXPECT_GT(r[0].contacts, 4);
  EXPECT_GT(share, 0.2);
  EXPECT_LT(share, 0.95);
  EXPECT_LT(imbalance, 1e-9);
}

/// The same net on the sphere, run twice on one thread and once on three: the same bits.
TEST(ColliderReactions, SameBitsRunAfterRunAndOnThreeThreads) {
  std::vector<std::vector<double>> runs;
  for (const int threads : {1, 1, 3}) {
    Settings s = resting_settings();
    s.threads = threads;
    World w(s);
    ColliderDesc ball;
    ball.shape = ColliderShape::sphere;
    ball.radius = 0.6;
    ball.position = Vec3(1.0, 1.1, -0.3);
    w.create_collider(ball);
    w.create_collider(ColliderDesc{});  // and the ground plane z = 0 the net's free corners reach
    std::vector<Vec3> x;
    const int32_t first = test::add_net(w, 9, 0.25, 0.5, 0.2, 1e-3, x);
    test::hard_pin(w, first, x[0]);
    for (int f = 0; f < 60; ++f) w.step();
    std::vector<double> out;
    for (const ColliderReaction& r : w.collider_reactions())
      out.insert(out.end(), {r.force.x(), r.force.y(), r.force.z(), r.moment.x(), r.moment.y(), r.moment.z(),
                             static_cast<double>(r.contacts)});
    runs.push_back(out);
  }
  ASSERT_EQ(runs[0].size(), 14u);
  EXPECT_GT(runs[0][6], 0.0);
  EXPECT_EQ(runs[0], runs[1]);
  EXPECT_EQ(runs[0], runs[2]);
}

/// A destroyed collider is not listed; one without contacts reads zero.
TEST(ColliderReactions, ListsLiveCollidersInSlotOrder) {
  World w(resting_settings());
  ColliderDesc far;
  far.shape = ColliderShape::sphere;
  far.position = Vec3(0.0, 0.0, -50.0);
  const Id a = w.create_collider(far);
  const Id b = w.create_collider(far);
  const Id c = w.create_collider(far);
  w.destroy_collider(b);
  std::vector<Vec3> x;
  test::add_net(w, 3, 0.25, 0.0, 0.5, 0.0, x);
  w.step();
  const std::vector<ColliderReaction> r = w.collider_reactions();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].collider.index, a.index);
  EXPECT_EQ(r[1].collider.index, c.index);
  for (const ColliderReaction& k : r) {
    EXPECT_EQ(k.contacts, 0);
    EXPECT_EQ(k.force, Vec3::Zero());
    EXPECT_EQ(k.moment, Vec3::Zero());
  }
}

}  // namespace
}  // namespace embra
