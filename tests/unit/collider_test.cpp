// Colliders: non-penetration of planes and spheres, and Coulomb friction on a plane.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace embra {
namespace {

constexpr double kG = 9.81;

int32_t add_particle(World& w, const Vec3& x, double thickness, double mu_s, double mu_k) {
  const std::vector<double> xyz{x.x(), x.y(), x.z()}, m{1.0};
  BodyDesc d;
  d.positions = xyz;
  d.masses = m;
  d.generate = 0;
  d.material.thickness = thickness;
  d.material.friction_static = mu_s;
  d.material.friction_dynamic = mu_k;
  return w.body(w.create_body(d)).first_particle;
}

// A particle dropped onto a plane (horizontal, then tilted by 0.3 rad with static friction 1 >
// tan 0.3 so it sticks where it lands) never ends a frame more than 1e-9 inside its clearance
// (half the particle's thickness plus the collider's thickness), and comes to rest on it.
//
//        o   drop from 0.5 m above the surface
//        |
//   _____v______  plane (normal = rotation * +z)
TEST(Colliders, ParticleRestsOnAPlaneWithoutPenetrating) {
  for (double tilt : {0.0, 0.3}) {
    World w(test::settings(8, 2, Vec3(0, 0, -kG)));
    ColliderDesc c;
    c.shape = ColliderShape::plane;
    c.position = Vec3(0.2, -0.1, 0.05);
    c.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Vec3::UnitX()));
    c.thickness = 0.004;
    c.friction_static = 1.0;
    c.friction_dynamic = 1.0;
    w.create_collider(c);
    const Vec3 normal = c.rotation * Vec3::UnitZ();
    const double clearance = 0.5 * 0.02 + c.thickness;
    const int32_t p = add_particle(w, c.position + Vec3(0.1, 0.1, 0.0) + 0.5 * normal, 0.02, 1.0, 1.0);
    double worst = 0.0;
    for (int f = 0; f < 120; ++f) {
      w.step();
      const double gap = normal.dot(w.positions()[p] - c.position) - clearance;
      worst = std::min(worst, gap);
      ASSERT_GT(gap, -1e-9) << "tilt " << tilt << " frame " << f;
    }
    EXPECT_NEAR(normal.dot(w.positions()[p] - c.position), clearance, 1e-9) << "tilt " << tilt;
    EXPECT_LT(w.velocities()[p].norm(), 1e-9) << "tilt " << tilt;
    EXPECT_GT(w.report().contact_count, 0);
    RecordProperty(tilt == 0.0 ? "worst_gap_flat" : "worst_gap_tilted", test::sci(worst));
  }
}

// Sliding to a stop: a particle resting on a horizontal plane, launched along it at v0 with
// dynamic (and static) friction mu, stops after the analytic distance v0^2 / (2 mu g) of constant
// deceleration mu g.
//
// Discretisation: each substep of h the contact pushes the particle back up by the depth gravity
// moved it, g h^2 (the normal impulse), and friction removes mu g h^2 of tangential slip, i.e. mu g h
// of speed: v_n = v0 - n a with a = mu g h. The particle moves h v_n in substep n while
// v_(n-1) >= a and stops in the substep after (the remaining slip is below the static limit), so
//   d = h (K v0 - a K (K + 1) / 2),  K = floor(v0 / a),
// which lies in [v0^2 / (2 mu g) - h v0 / 2, v0^2 / (2 mu g)]: the stated tolerance is h v0 / 2
// (here 2.1 mm on 0.51 m), below the analytic distance. The world must match d to rounding.
TEST(Colliders, FrictionStopsASlidingParticleWithinTheAnalyticDistance) {
  const double mu = 0.4, v0 = 2.0;
  const int substeps = 8;
  World w(test::settings(substeps, 1, Vec3(0, 0, -kG)));
  ColliderDesc c;
  c.friction_static = mu;
  c.friction_dynamic = mu;
  w.create_collider(c);
  const int32_t p = add_particle(w, Vec3::Zero(), 0.0, mu, mu);  // the pair's coefficient: sqrt(mu * mu)
  const std::vector<double> v{v0, 0.0, 0.0};
  w.set_velocities(p, v);
  for (int f = 0; f < 60; ++f) w.step();  // stops after v0 / (mu g) = 0.51 s
  const double h = w.settings().dt / substeps;
  const double a = mu * kG * h;
  const double k = std::floor(v0 / a);
  const double discrete = h * (k * v0 - a * k * (k + 1) / 2);
  const double analytic = v0 * v0 / (2 * mu * kG);
  const Vec3 x = w.positions()[p];
  EXPECT_EQ(w.velocities()[p].norm(), 0.0);
  EXPECT_NEAR(x.x(), discrete, 1e-12);
  EXPECT_LE(x.x(), analytic);
  EXPECT_GE(x.x(), analytic - h * v0 / 2);
  EXPECT_EQ(x.y(), 0.0);
  EXPECT_EQ(x.z(), 0.0);
  RecordProperty("distance", test::sci(x.x()));
  RecordProperty("analytic_distance", test::sci(analytic));
}

// A cloth dropped on a sphere (radius R, centre c): every particle keeps half the cloth's thickness
// t off the surface, so at the end of every frame |x - c| >= R + t/2 - 1e-9.
//
//      ==============  cloth, 19 x 19, 1.44 m square, 0.3 m above the top of the sphere
//           .--.
//          (    )      sphere, R = 0.4
//           '--'
TEST(Colliders, ClothDrapedOnASphereStaysOutside) {
  const double radius = 0.4, thickness = 0.02;
  World w(test::settings(8, 4, Vec3(0, 0, -kG)));
  ColliderDesc c;
  c.shape = ColliderShape::sphere;
  c.radius = radius;
  w.create_collider(c);
  const test::Grid g = test::make_grid(19, 19, 0.08, Vec3(-0.72, -0.72, radius + 0.3));
  BodyDesc d;
  d.positions = g.positions;
  d.triangles = g.triangles;
  d.material.density = 0.2;
  d.material.stretch_compliance = 1e-7;
  d.material.bend_compliance = 10.0;  // a limp cloth: it drapes rather than resting on top like a plate
  d.material.thickness = thickness;
  d.material.damping = 0.5;
  w.create_body(d);
  double worst = 1.0;
  for (int f = 0; f < 180; ++f) {
    w.step();
    for (const Vec3& x : w.positions()) worst = std::min(worst, x.norm() - (radius + thickness / 2));
    ASSERT_GT(worst, -1e-9) << "frame " << f;
  }
  // The cloth really is draped: its rim hangs below the sphere's equator (the half-width, 0.72 m,
  // exceeds the quarter circumference, 0.63 m) and it touches.
  double lowest = 1.0;
  for (const Vec3& x : w.positions()) lowest = std::min(lowest, x.z());
  EXPECT_LT(lowest, 0.0);
  EXPECT_GT(w.report().contact_count, 0);
  RecordProperty("worst_clearance", test::sci(worst));
}

}  // namespace
}  // namespace embra
