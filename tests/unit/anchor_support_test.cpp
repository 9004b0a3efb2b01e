// Per-axis anchors (PinSupport::axes, Kangaroo's AnchorXYZ, a roller): a pin that holds chosen world
// coordinates of its particle at the target's and leaves the others free, checked against motion and
// statics worked out here.
//
//   - under gravity and a point load the held coordinates stay at the target's to 1e-12 at every
//     frame, and each free coordinate follows the symplectic Euler path of a constant acceleration
//     a = g + F / m, s_n = a h^2 n (n + 1) / 2, to rounding; the reaction has the held components of
//     minus (weight + load) and exactly 0 in the free ones (z held; x and z held; y held);
//   - a particle on a roller (z held) tied by two members sloping in plan to two hard pins, loaded
//     by gravity and a horizontal point load, settles with the roller's reaction equal to minus the
//     load's held (z) component and the members' tensions equal to the joint's equilibrium (a 2 x 2
//     system solved here); the reactions sum to minus the total load;
//   - one compliant projection leaves alpha / (w + alpha) of the held offset, the free part untouched;
//   - bad axes are refused and change nothing; the same bits run after run.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstring>
#include <vector>

namespace embra {
namespace {

Id anchor(World& w, int32_t particle, const Vec3& target, const Vec3& held, double compliance = 0.0) {
  PinDesc d;
  d.particle = particle;
  d.target = target;
  d.support = PinSupport::axes;
  d.axis = held;
  d.compliance = compliance;
  return w.create_pin(d);
}

TEST(AnchorSupport, HeldCoordinatesStayAndFreeOnesFallAtGPlusFOverM) {
  const Vec3 gravity(0.0, -2.0, -9.81);
  const Vec3 force(1.5, 0.5, 0.0);  // N: a horizontal point load
  const double m = 2.0;
  const Vec3 start(0.3, -0.4, 1.2);
  const Vec3 target(0.3, -0.4, 1.2);
  double worst_held = 0.0, worst_path = 0.0;
  for (const Vec3& held : {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 0)}) {
    World w(test::settings(10, 1, gravity));
    const int32_t p = test::add_particles(w, {start}, {m});
    const Id pin = anchor(w, p, target, held);
    w.set_loads(p, std::span<const double>(force.data(), 3));
    constexpr int frames = 60;
    const double h = w.settings().dt / w.settings().substeps;
    const Vec3 a = gravity + force / m;
    for (int f = 1; f <= frames; ++f) {
      w.step();
      const Vec3 x = w.positions()[p];
      const int n = f * w.settings().substeps;
      for (int k = 0; k < 3; ++k) {
        if (held[k] == 1.0) {
          worst_held = std::max(worst_held, std::abs(x[k] - target[k]));
          EXPECT_LT(std::abs(x[k] - target[k]), 1e-12) << "held coordinate " << k << " at frame " << f;
        } else {
          // The discrete path of a constant acceleration; rounding of x (|x| <= 4) and of the
          // velocity (x - x_prev) / h grows as n^2 eps |x| (the bound used for the line support).
          const double exact = start[k] + a[k] * h * h * n * (n + 1) / 2.0;
          worst_path = std::max(worst_path, std::abs(x[k] - exact));
          EXPECT_LT(std::abs(x[k] - exact), n * n * 2.2e-16 * 4.0) << "free coordinate " << k << " at frame " << f;
        }
      }
    }
    // The continuous free fall a t^2 / 2, to the integrator's first-order term a t h / 2.
    const double t = frames * w.settings().dt;
    for (int k = 0; k < 3; ++k) {
      if (held[k] == 0.0) {
        EXPECT_NEAR(w.positions()[p][k] - start[k], 0.5 * a[k] * t * t, 0.5 * std::abs(a[k]) * t * h * 1.000001);
      }
    }
    // The reaction holds the held components of weight + load and nothing else.
    const std::vector<Reaction> r = w.reactions();
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].pin, pin);
    const Vec3 total = m * gravity + force;
    for (int k = 0; k < 3; ++k) {
      if (held[k] == 1.0)
        EXPECT_NEAR(r[0].force[k], -total[k], 1e-9 * total.norm()) << "held component " << k;
      else
        EXPECT_EQ(r[0].force[k], 0.0) << "free component " << k;
    }
  }
  RecordProperty("held_offset_max_m", test::sci(worst_held));
  RecordProperty("free_path_error_max_m", test::sci(worst_path));
}

TEST(AnchorSupport, RollerTiedByTwoSlopingMembersCarriesTheLoadsHeldComponent) {
  // The joint J on a roller holding z; two members, horizontal but sloping in plan, tie it to hard
  // pins A and B. The members carry the load's x and y, the roller its z.
  const Vec3 J(0.2, 0.5, 1.0), A(-1.0, -0.6, 1.0), B(1.3, -0.9, 1.0);
  const double m = 1.5;
  const Vec3 gravity(0.0, 0.0, -9.81);
  const Vec3 force(0.7, 2.3, -0.4);  // N
  Settings s = test::settings(4, 600, gravity, 4.0);
  s.realign_passes = 4;
  s.tethers = 0;
  World w(s);
  const int32_t first = test::add_particles(w, {A, B, J}, {1.0, 1.0, m});
  const int32_t j = first + 2;
  test::hard_pin(w, first, A);
  test::hard_pin(w, first + 1, B);
  const Id roller = anchor(w, j, J, Vec3(0, 0, 1));
  const int32_t members[4] = {first, j, first + 1, j};
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = members;
  w.add_constraints(d);
  w.set_loads(j, std::span<const double>(force.data(), 3));
  for (int f = 0; f < 300; ++f) w.step();
  EXPECT_LT((w.positions()[j] - J).norm(), 1e-9) << "the members fix the joint where it was";
  // Joint equilibrium in plan: t_A u_A + t_B u_B + F_xy = 0, u pointing from J to each pin
  // (a tension pulls the joint towards the pin).
  const Vec3 uA = (A - J).normalized(), uB = (B - J).normalized();
  Eigen::Matrix2d M;
  M << uA.x(), uB.x(), uA.y(), uB.y();
  const Eigen::Vector2d t = M.colPivHouseholderQr().solve(Eigen::Vector2d(-force.x(), -force.y()));
  const std::vector<double> tension = w.constraint_forces(w.default_group(), Kind::distance);
  ASSERT_EQ(tension.size(), 2u);
  const double member_error =
      std::max(std::abs(tension[0] - t[0]), std::abs(tension[1] - t[1])) / t.cwiseAbs().maxCoeff();
  RecordProperty("member_force_relative_error", test::sci(member_error));
  EXPECT_LT(member_error, 1e-9);
  Reaction at_roller;
  Vec3 sum = Vec3::Zero();
  for (const Reaction& r : w.reactions()) {
    sum += r.force;
    if (r.pin == roller) at_roller = r;
  }
  EXPECT_EQ(at_roller.pin, roller);
  const Vec3 total = 2.0 * gravity + m * gravity + force;  // the pins' own weights too
  const double held_load = m * gravity.z() + force.z();
  const double roller_error = std::abs(at_roller.force.z() + held_load) / std::abs(held_load);
  RecordProperty("roller_reaction_relative_error", test::sci(roller_error));
  EXPECT_LT(roller_error, 1e-9) << "the roller holds the load's z";
  EXPECT_EQ(at_roller.force.x(), 0.0);
  EXPECT_EQ(at_roller.force.y(), 0.0);
  const double imbalance = (sum + total).norm() / total.norm();
  RecordProperty("reaction_imbalance", test::sci(imbalance));
  EXPECT_LT(imbalance, 1e-9);
}

TEST(AnchorSupport, CompliantProjectionLeavesAlphaOverWPlusAlphaOfTheHeldOffset) {
  const Vec3 target(0.1, 0.2, 0.3);
  const Vec3 start = target + Vec3(0.05, -0.02, 0.04);
  for (const double compliance : {0.0, 1e-6, 1e-4}) {
    World w(test::settings(1, 1));
    const int32_t p = test::add_particles(w, {start}, {2.0});
    anchor(w, p, target, Vec3(1, 0, 1), compliance);
    w.step();
    const double h = w.settings().dt;
    const double alpha = compliance / (h * h);
    const Vec3 x = w.positions()[p];
    for (const int k : {0, 2})
      EXPECT_NEAR(x[k] - target[k], alpha / (0.5 + alpha) * (start[k] - target[k]), 1e-15) << "held " << k;
    EXPECT_EQ(x.y(), start.y()) << "free";
  }
}

TEST(AnchorSupport, SameBitsRunAfterRun) {
  std::vector<Vec3> runs;
  for (int run = 0; run < 2; ++run) {
    World w(test::settings(4, 3, Vec3(0.3, 0.0, -9.81)));
    const int32_t p = test::add_particles(w, {Vec3(0.7, 0.0, 0.1)}, {1.0});
    anchor(w, p, Vec3(0.0, 0.0, 0.1), Vec3(0, 1, 1), 1e-5);
    for (int f = 0; f < 100; ++f) w.step();
    runs.push_back(w.positions()[p]);
  }
  EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[1].data(), sizeof(Vec3)));
}

TEST(AnchorSupport, BadAxesAreRefusedAndChangeNothing) {
  World w;
  const int32_t p = test::add_particles(w, {Vec3::Zero()}, {1.0});
  EXPECT_THROW(anchor(w, p, Vec3::Zero(), Vec3(0, 0, 0)), Error) << "nothing held";
  EXPECT_THROW(anchor(w, p, Vec3::Zero(), Vec3(0, 0.5, 1)), Error) << "not a flag";
  EXPECT_THROW(anchor(w, p, Vec3::Zero(), Vec3(0, 0, 2)), Error) << "not a flag";
  EXPECT_THROW(anchor(w, p, Vec3::Zero(), Vec3(-1, 0, 0)), Error) << "not a flag";
  EXPECT_THROW(anchor(w, p, Vec3::Zero(), Vec3(NAN, 0, 1)), Error);
  EXPECT_THROW(anchor(w, p, Vec3(INFINITY, 0, 0), Vec3(0, 0, 1)), Error);
  EXPECT_THROW(anchor(w, p + 1, Vec3::Zero(), Vec3(0, 0, 1)), Error);
  EXPECT_THROW(anchor(w, p, Vec3::Zero(), Vec3(0, 0, 1), -1.0), Error);
  EXPECT_EQ(w.pin_count(), 0u);
  const Id id = anchor(w, p, Vec3::Zero(), Vec3(-0.0, 1, 1));
  EXPECT_EQ(w.pin_count(), 1u);
  EXPECT_FALSE(std::signbit(w.pin(id).axis.x())) << "-0 kept as 0";
}

}  // namespace
}  // namespace embra
