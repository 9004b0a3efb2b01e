// Determinism: the same scene built and stepped twice gives bit-identical positions and velocities.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>

namespace embra {
namespace {

/// A scene that exercises every stage: a cloth with stretch, shear and bend in three groups (one with
/// weight 2), hard and soft pins, a moving pin target, a plane and a sphere collider, random initial
/// velocities, damping and gravity.
struct Scene {
  std::unique_ptr<World> world;
  Id pin;
};

Scene build() {
  auto w = std::make_unique<World>(test::settings(6, 3, Vec3(0, 0, -9.81), 0.1));
  test::Rng rng(31);
  GroupDesc gs, gb;
  gs.order = 1;
  gb.order = 2;
  gb.weight = 2;
  const Id shear = w->create_group(gs), bend = w->create_group(gb);
  const test::Grid g = test::make_grid(12, 12, 0.05, Vec3(-0.3, -0.3, 0.5));
  BodyDesc d;
  d.positions = g.positions;
  d.triangles = g.triangles;
  d.material.stretch_compliance = 1e-6;
  d.material.shear_compliance = 1e-4;
  d.material.bend_compliance = 1e-2;
  d.material.thickness = 0.01;
  d.generate = generate_stretch | generate_shear | generate_bend;
  d.shear_group = shear;
  d.bend_group = bend;
  w->create_body(d);
  const Id pin = test::hard_pin(*w, g.index(0, 0), Vec3(-0.3, -0.3, 0.5));
  PinDesc soft;
  soft.particle = g.index(11, 11);
  soft.target = Vec3(0.25, 0.25, 0.35);
  soft.compliance = 1e-4;
  soft.group = shear;
  w->create_pin(soft);
  ColliderDesc plane;
  plane.position = Vec3(0, 0, -0.2);
  w->create_collider(plane);
  ColliderDesc sphere;
  sphere.shape = ColliderShape::sphere;
  sphere.position = Vec3(0.02, 0.01, 0.3);  // below the cloth, which sags onto it
  sphere.radius = 0.15;
  w->create_collider(sphere);
  std::vector<Vec3> v(w->particle_count());
  for (Vec3& vi : v) vi = rng.vec(-0.5, 0.5);
  w->set_velocities(0, test::flatten(v));
  return Scene{std::move(w), pin};
}

TEST(Determinism, SameSceneTwiceIsBitIdentical) {
  Scene sa = build(), sb = build();
  World* a = sa.world.get();
  World* b = sb.world.get();
  int64_t contacts = 0;
  for (int f = 0; f < 90; ++f) {
    if (f == 30) {
      // Move the hard pin mid-run (it glides over the next frame).
      a->set_pin_target(sa.pin, Vec3(-0.2, -0.3, 0.55));
      b->set_pin_target(sb.pin, Vec3(-0.2, -0.3, 0.55));
    }
    a->step();
    b->step();
    contacts = std::max(contacts, a->report().contact_count);
  }
  ASSERT_EQ(a->particle_count(), b->particle_count());
  const size_t bytes = sizeof(Vec3) * a->positions().size();
  EXPECT_EQ(std::memcmp(a->positions().data(), b->positions().data(), bytes), 0);
  EXPECT_EQ(std::memcmp(a->velocities().data(), b->velocities().data(), bytes), 0);
  // And the run was not trivial: the cloth moved and touched the colliders.
  EXPECT_GT(contacts, 0);
  EXPECT_GT(a->report().kinetic_energy, 0.0);
}

}  // namespace
}  // namespace embra
