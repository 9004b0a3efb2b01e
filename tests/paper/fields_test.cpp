// Field forces against answers derived outside the code: the surface-tension force is minus the
// tension times the finite-difference gradient of the area; the vortex's strength varies along its
// axis as 1 + twist * s and decays as exp(-decay * t).
#include "embra/core/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace embra {
namespace {

double area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

Settings one_substep(double dt) {
  Settings s;
  s.dt = dt;
  s.substeps = 1;
  s.iterations = 1;
  s.gravity = Vec3::Zero();
  s.tethers = 0;
  return s;
}

// One free triangle of 1 kg corners with tension 2 N/m and no regularisation: after one step of h,
// each corner's velocity is -h * 2 * dA/dx_k, with dA/dx_k taken by central differences.
TEST(Fields, SurfaceTensionIsMinusTensionTimesTheAreaGradient) {
  const double h = 1e-3, gamma = 2.0;
  const std::vector<double> xyz = {0.1, -0.2, 0.3, 1.1, 0.2, -0.1, 0.3, 0.9, 0.4};
  const std::vector<double> masses = {1.0, 1.0, 1.0};
  const std::vector<int32_t> tri = {0, 1, 2};
  World w(one_substep(h));
  BodyDesc d;
  d.positions = xyz;
  d.masses = masses;
  d.triangles = tri;
  d.generate = 0;
  const Id body = w.create_body(d);
  FieldDesc f;
  f.kind = FieldKind::surface_tension;
  f.body = static_cast<int32_t>(body.index);
  f.surface_tension.tension = gamma;
  f.surface_tension.regularisation = 0.0;
  w.create_field(f);
  const std::vector<Vec3> x0 = w.positions();
  w.step();
  double worst = 0.0;
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) {
      const double e = 1e-6;
      std::vector<Vec3> p = x0, m = x0;
      p[k][c] += e;
      m[k][c] -= e;
      const double grad = (area(p[0], p[1], p[2]) - area(m[0], m[1], m[2])) / (2.0 * e);
      worst = std::max(worst, std::abs(w.velocities()[k][c] - (-h * gamma * grad)));
    }
  EXPECT_LT(worst, 1e-11);
}

// Two particles on the vortex's falloff radius, at heights 0 and 0.5 m along its axis, with twist
// 2 /m: the upper one is pushed twice as hard as the one at the centre's height; after the field
// has decayed for 1 s at 1.5 /s both are pushed exp(-1.5) as hard as at the start.
TEST(Fields, VortexVariesAlongItsAxisAndDecays) {
  const double h = 0.01;
  World w(one_substep(h));
  const std::vector<double> xyz = {1.0, 0.0, 0.0, 1.0, 0.0, 0.5};
  const std::vector<double> masses = {1.0, 3.0};  // the acceleration does not depend on the mass
  BodyDesc d;
  d.positions = xyz;
  d.masses = masses;
  d.generate = 0;
  w.create_body(d);
  FieldDesc f;
  f.kind = FieldKind::vortex;
  f.vortex.strength = 4.0;
  f.vortex.radius = 1.0;
  f.vortex.twist = 2.0;
  f.vortex.decay = 1.5;
  w.create_field(f);
  w.step();
  const double a0 = 4.0 * std::exp(-1.0);  // at r = radius
  EXPECT_NEAR(w.velocities()[0].y(), h * a0, 1e-14);
  EXPECT_NEAR(w.velocities()[1].y(), 2.0 * h * a0, 1e-14);
  // From rest again at t = 1 s.
  w.set_clock(100, 1.0);
  const std::vector<double> zero(6, 0.0);
  w.set_positions(0, xyz);
  w.set_velocities(0, zero);
  w.step();
  EXPECT_NEAR(w.velocities()[0].y(), h * a0 * std::exp(-1.5), 1e-14);
}

}  // namespace
}  // namespace embra
