// Conservation laws and free flight.
#include "test_support.hpp"

#include <gtest/gtest.h>

namespace embra {
namespace {

using test::Rng;

// With no gravity, pins, colliders or damping, every force is internal: each projection moves its
// operands by w_i grad_i C dlambda, and the gradients of a shape function sum to zero
// (translation invariance), so sum m_i dx_i = 0 and the total momentum sum m v is unchanged. The
// centre of mass then moves in a straight line at P / M.
//
// Scene: a jittered 6 x 6 cloth (stretch, shear, bend; mixed compliances) and a cube of five
// tetrahedra (hard stretch and volume), random velocities about a common drift, 100 frames of 4
// substeps and 4 iterations. What remains is rounding: every position update rounds to an ulp of
// |x| (~1e-16 here, the scene sits near the origin) and the velocity is (x - x_prev) / h, so the
// momentum takes a random walk of about m ulp / h per operation; measured ~3e-13 of sum m |v|.
TEST(Conservation, MomentumIsConservedWithoutExternalForces) {
  Rng rng(11);
  World w(test::settings(4, 4));
  test::Grid g = test::make_grid(6, 6, 0.1, Vec3(-0.25, -0.25, -0.2));
  for (size_t i = 0; i < g.positions.size(); ++i) g.positions[i] += rng.uniform(-0.02, 0.02);
  BodyDesc cloth;
  cloth.positions = g.positions;
  cloth.triangles = g.triangles;
  cloth.material.density = 0.3;
  cloth.material.stretch_compliance = 1e-6;
  cloth.material.shear_compliance = 1e-3;
  cloth.material.bend_compliance = 1e-2;
  cloth.generate = generate_stretch | generate_shear | generate_bend;
  w.create_body(cloth);
  // Cube corners 0..7 (bit 0: x, bit 1: y, bit 2: z) cut into five tetrahedra: the four corner
  // tets at 0, 3, 5, 6 and the central one (1, 2, 4, 7).
  std::vector<double> cube;
  for (int i = 0; i < 8; ++i) {
    const Vec3 c =
        Vec3(0.3 * (i & 1) - 0.15, 0.3 * ((i >> 1) & 1) - 0.15, 0.3 * ((i >> 2) & 1) + 0.05) + rng.vec(-0.02, 0.02);
    cube.insert(cube.end(), {c.x(), c.y(), c.z()});
  }
  const std::vector<int32_t> tets{0, 1, 2, 4, 1, 3, 2, 7, 1, 2, 4, 7, 1, 4, 5, 7, 2, 6, 4, 7};
  BodyDesc block;
  block.positions = cube;
  block.tets = tets;
  block.material.density = 20.0;
  block.generate = generate_stretch | generate_volume;
  w.create_body(block);

  std::vector<Vec3> v(w.particle_count());
  for (Vec3& vi : v) vi = Vec3(0.3, -0.2, 0.1) + rng.vec(-1.0, 1.0);
  w.set_velocities(0, test::flatten(v));

  double mass = 0.0, scale = 0.0;
  Vec3 com0 = Vec3::Zero();
  for (int32_t i = 0; i < w.particle_count(); ++i) {
    const double m = 1.0 / w.inverse_masses()[i];
    mass += m;
    scale += m * v[i].norm();
    com0 += m * w.positions()[i];
  }
  com0 /= mass;
  const Vec3 p0 = test::total_momentum(w);
  double worst = 0.0;
  for (int f = 1; f <= 100; ++f) {
    w.step();
    const Vec3 p = test::total_momentum(w);
    worst = std::max(worst, (p - p0).norm() / scale);
  }
  Vec3 com = Vec3::Zero();
  for (int32_t i = 0; i < w.particle_count(); ++i) com += w.positions()[i] / w.inverse_masses()[i];
  com /= mass;
  const double t = w.report().time;
  EXPECT_LT((com - (com0 + p0 / mass * t)).norm(), 1e-12 * (com0.norm() + scale / mass * t));
  // The bodies really deformed: the constraints were busy all along.
  EXPECT_GT(w.report().residual_max, 0.0);
  EXPECT_LT(worst, 1e-12);
  RecordProperty("momentum_drift_relative", test::sci(worst));
}

// Free flight under gravity. The integrator is symplectic Euler per substep (v += h g, then
// x += h v), so after n substeps of h (t = n h):
//   v_n = v0 + g t                                exactly (the analytic velocity), and
//   x_n = x0 + v0 t + g h^2 n (n + 1) / 2 = x0 + v0 t + g t^2 / 2 + g h t / 2,
// i.e. the position runs ahead of the analytic x0 + v0 t + g t^2 / 2 by g h t / 2, a first-order
// error (here 9.81 / 480 / 2 = 0.0102 m after 1 s). The world must match the discrete answer to
// rounding; the offset from the analytic one is measured and must be exactly g h t / 2.
TEST(Conservation, FreeFallFollowsSymplecticEuler) {
  const Vec3 g(0.3, -0.2, -9.81);
  const Vec3 x0(0.1, -0.2, 3.0), v0(0.5, -0.25, 2.0);
  const int substeps = 8, frames = 60;
  World w(test::settings(substeps, 1, g));
  const int32_t p = test::add_particles(w, {x0}, {2.0});
  const std::vector<double> vel{v0.x(), v0.y(), v0.z()};
  w.set_velocities(p, vel);
  for (int f = 0; f < frames; ++f) w.step();
  const double h = w.settings().dt / substeps;
  const double n = static_cast<double>(substeps * frames);
  const double t = n * h;
  const Vec3 analytic = x0 + v0 * t + 0.5 * g * t * t;
  const Vec3 discrete = x0 + v0 * t + g * (h * h * n * (n + 1) / 2);
  const Vec3 x = w.positions()[p];
  const double scale = x0.norm() + v0.norm() * t + g.norm() * t * t;
  EXPECT_LT((x - discrete).norm(), 1e-12 * scale);
  EXPECT_LT(((x - analytic) - 0.5 * g * h * t).norm(), 1e-12 * scale);
  EXPECT_LT((w.velocities()[p] - (v0 + g * t)).norm(), 1e-12 * (v0.norm() + g.norm() * t));
  RecordProperty("offset_from_analytic", test::sci((x - analytic).norm()));
  RecordProperty("error_against_discrete", test::sci((x - discrete).norm()));
}

}  // namespace
}  // namespace embra
