// Sliding supports (PinSupport::plane, PinSupport::line): a pin that holds its particle on a plane
// or a line through its target, frictionless, checked against motion and statics worked out here.
//
//   - a particle released on an inclined frictionless plane slides down it at g sin(theta): with
//     the plane projected exactly each substep, the symplectic Euler path along the slope is
//     s_n = g sin(theta) h^2 n (n + 1) / 2 to rounding, and the support's reaction is the normal
//     force m g cos(theta);
//   - tied to a pin on the plane by a rope of length L it comes to rest at the lowest point it can
//     reach, L straight down the slope from the pin, and the two reactions sum to minus its weight;
//   - a bead on an inclined line slides at g times the sine of the line's slope;
//   - a simply supported Pratt truss, hard pin at one end and a roller (a plane support) at the
//     other: member forces and both reactions equal the method of joints.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <vector>

namespace embra {
namespace {

constexpr double kG = 9.81;

Id support(World& w, int32_t particle, const Vec3& target, PinSupport kind, const Vec3& axis, double compliance = 0.0) {
  PinDesc d;
  d.particle = particle;
  d.target = target;
  d.compliance = compliance;
  d.support = kind;
  d.axis = axis;
  return w.create_pin(d);
}

TEST(Supports, ParticleSlidesDownAnInclinedPlaneAtGSinTheta) {
  const double theta = std::numbers::pi / 6.0;
  const Vec3 n(-std::sin(theta), 0.0, std::cos(theta));      // the plane rises towards +x
  const Vec3 down(-std::cos(theta), 0.0, -std::sin(theta));  // straight down the slope
  World w(test::settings(10, 1, Vec3(0.0, 0.0, -kG)));
  const double m = 3.0;
  const int32_t p = test::add_particles(w, {Vec3(0.5, 0.0, 0.5 * std::tan(theta))}, {m});
  const Vec3 start = w.positions()[p];
  const Id s = support(w, p, Vec3::Zero(), PinSupport::plane, 2.0 * n);  // any length: the unit normal is kept
  constexpr int frames = 60;
  for (int f = 0; f < frames; ++f) w.step();
  const double h = w.settings().dt / w.settings().substeps;
  const int steps = frames * w.settings().substeps;
  const double a = kG * std::sin(theta);
  const Vec3 moved = w.positions()[p] - start;
  const double along = moved.dot(down);
  const double exact = a * h * h * steps * (steps + 1) / 2.0;
  RecordProperty("slide_relative_error", test::sci(std::abs(along - exact) / exact));
  EXPECT_LT(std::abs(along - exact), 1e-12 * exact) << "the discrete path down the slope";
  EXPECT_LT(std::abs(moved.dot(n)), 1e-12) << "on the plane";
  EXPECT_LT(std::abs(moved.y()), 1e-15);
  // The continuous answer, a t^2 / 2, to the integrator's first-order term a t h / 2.
  const double t = frames * w.settings().dt;
  EXPECT_NEAR(along, 0.5 * a * t * t, 0.5 * a * t * h * 1.000001);
  // The support pushes along its normal with the weight's normal part.
  const std::vector<Reaction> r = w.reactions();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].pin, s);
  EXPECT_LT((r[0].force - m * kG * std::cos(theta) * n).norm(), 1e-9 * m * kG);
}

TEST(Supports, TiedParticleRestsAtThePlanesLowestReachablePoint) {
  const double theta = 0.4;
  const Vec3 n(-std::sin(theta), 0.0, std::cos(theta));
  const Vec3 down(-std::cos(theta), 0.0, -std::sin(theta));
  const Vec3 across(0.0, 1.0, 0.0);
  constexpr double L = 1.5;
  Settings settings = test::settings(8, 20, Vec3(0.0, 0.0, -kG), 3.0);
  settings.realign_passes = 2;
  settings.tethers = 0;
  World w(settings);
  const Vec3 anchor(0.3, 0.2, 0.3 * std::tan(theta));  // on the plane through the origin
  // Released off to the side, up the slope: it swings down and across to rest below the anchor.
  const Vec3 released = anchor + L * (0.6 * across - 0.8 * down);
  const int32_t first = test::add_particles(w, {anchor, released}, {2.0, 1.25});
  test::hard_pin(w, first, anchor);
  support(w, first + 1, Vec3::Zero(), PinSupport::plane, n);
  const int32_t rope[2] = {first, first + 1};
  ConstraintDesc d;
  d.particles = rope;
  w.add_constraints(d);
  for (int f = 0; f < 1200; ++f) w.step();
  const Vec3 lowest = anchor + L * down;
  const double off = (w.positions()[first + 1] - lowest).norm();
  RecordProperty("offset_from_lowest_point_m", test::sci(off));
  EXPECT_LT(off, 1e-9 * L);
  // The rope holds the slope's pull, m g sin(theta); the reactions sum to minus both weights.
  const double tension = w.constraint_forces(w.default_group(), Kind::distance)[0];
  EXPECT_NEAR(tension, 1.25 * kG * std::sin(theta), 1e-9 * kG);
  Vec3 sum = Vec3::Zero();
  for (const Reaction& r : w.reactions()) sum += r.force;
  const Vec3 weight(0.0, 0.0, -(2.0 + 1.25) * kG);
  RecordProperty("reaction_imbalance", test::sci((sum + weight).norm() / weight.norm()));
  EXPECT_LT((sum + weight).norm(), 1e-9 * weight.norm());
}

TEST(Supports, BeadSlidesAlongAnInclinedLine) {
  const Vec3 d = Vec3(1.0, 2.0, -2.0) / 3.0;  // unit, falling 2/3 per unit of length
  World w(test::settings(10, 1, Vec3(0.0, 0.0, -kG)));
  const int32_t p = test::add_particles(w, {Vec3(1.0, 1.0, 1.0)}, {0.5});
  support(w, p, Vec3(1.0, 1.0, 1.0) - 4.0 * d, PinSupport::line, -d);
  constexpr int frames = 30;
  for (int f = 0; f < frames; ++f) w.step();
  const double h = w.settings().dt / w.settings().substeps;
  const int steps = frames * w.settings().substeps;
  const double a = kG * 2.0 / 3.0;
  const Vec3 moved = w.positions()[p] - Vec3(1.0, 1.0, 1.0);
  const double exact = a * h * h * steps * (steps + 1) / 2.0;
  // Rounding: each substep rounds x (|x| ~ 2, eps 2.2e-16) and v = (x - x_prev) / h, an error the
  // next substeps carry on: it grows as steps^2 eps |x| (4e-11 m here).
  EXPECT_LT(std::abs(moved.dot(d) - exact), steps * steps * 2.2e-16 * 2.0);
  EXPECT_LT((moved - moved.dot(d) * d).norm(), 1e-12) << "on the line";
  const std::vector<Reaction> r = w.reactions();
  ASSERT_EQ(r.size(), 1u);
  const Vec3 gravity_across = 0.5 * (Vec3(0.0, 0.0, -kG) - Vec3(0.0, 0.0, -kG).dot(d) * d);
  EXPECT_LT((r[0].force + gravity_across).norm(), 1e-9 * kG) << "the line holds the weight's part across it";
}

// A Pratt truss of four bays a by b, simply supported: a hard pin at B0, a roller at B4 (a plane
// support of normal z: free to slide along x).
//
//        T1 ---- T2 ---- T3
//      / |     / | \     | \          diagonals T1-B2 and T3-B2 (Pratt: tension under
//    /   |   /   |   \   |   \        gravity loads)
//  B0 -- B1 ---- B2 ---- B3 -- B4
//  pin                         roller
TEST(Supports, PrattTrussOnAPinAndARollerIsTheMethodOfJoints) {
  constexpr double a = 2.0, b = 1.75;
  std::vector<Vec3> x;
  for (int k = 0; k <= 4; ++k) x.emplace_back(k * a, 0.0, 0.0);  // B0..B4: 0..4
  for (int k = 1; k <= 3; ++k) x.emplace_back(k * a, 0.0, b);    // T1..T3: 5..7
  const std::vector<std::pair<int, int>> members = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {5, 6}, {6, 7}, {1, 5},
                                                    {2, 6}, {3, 7}, {0, 5}, {5, 2}, {7, 2}, {7, 4}};
  std::vector<Vec3> loads(x.size(), Vec3::Zero());
  loads[1] = Vec3(0.0, 0.0, -12000.0);
  loads[2] = Vec3(0.0, 0.0, -18000.0);
  loads[3] = Vec3(2500.0, 0.0, -6000.0);
  loads[6] = Vec3(-4000.0, 0.0, -3000.0);
  constexpr double mass = 1e4;  // the loads move a joint by h^2 F / m in a substep

  // The method of joints: unknowns the 13 tensions and the roller's vertical reaction; equations
  // the x and z equilibrium of the seven joints other than the pin.
  const int m = static_cast<int>(members.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(14, m + 1);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(14);
  const auto row = [](int joint) { return 2 * (joint - 1); };  // joints 1..7
  for (int c = 0; c < m; ++c) {
    const auto [i, j] = members[c];
    const Vec3 u = (x[j] - x[i]).normalized();
    if (i != 0) A(row(i), c) += u.x(), A(row(i) + 1, c) += u.z();
    if (j != 0) A(row(j), c) -= u.x(), A(row(j) + 1, c) -= u.z();
  }
  A(row(4) + 1, m) = 1.0;  // the roller pushes B4 along z
  for (int j = 1; j < 8; ++j) {
    const Vec3 f = loads[j] + Vec3(0.0, 0.0, -mass * kG);
    rhs(row(j)) = -f.x();
    rhs(row(j) + 1) = -f.z();
  }
  const Eigen::VectorXd exact = A.fullPivLu().solve(rhs);
  ASSERT_LT((A * exact - rhs).norm(), 1e-9 * rhs.norm());
  Vec3 pin_exact = -(loads[0] + Vec3(0.0, 0.0, -mass * kG));
  for (int c = 0; c < m; ++c)
    if (members[c].first == 0) pin_exact -= exact(c) * (x[members[c].second] - x[0]).normalized();

  Settings settings = test::settings(4, 600, Vec3(0.0, 0.0, -kG), 4.0);
  settings.realign_passes = 4;
  settings.tethers = 0;
  World w(settings);
  const int32_t first = test::add_particles(w, x, std::vector<double>(x.size(), mass));
  std::vector<int32_t> ids;
  for (const auto& [i, j] : members) ids.insert(ids.end(), {first + i, first + j});
  ConstraintDesc d;
  d.particles = ids;
  w.add_constraints(d);
  for (size_t j = 0; j < x.size(); ++j)
    w.set_loads(first + static_cast<int32_t>(j), std::span<const double>(loads[j].data(), 3));
  const Id pin = test::hard_pin(w, first, x[0]);
  const Id roller = support(w, first + 4, x[4], PinSupport::plane, Vec3(0.0, 0.0, 1.0));
  for (int f = 0; f < 100; ++f) w.step();

  const std::vector<double> forces = w.constraint_forces(w.default_group(), Kind::distance);
  double err = 0.0, scale = 0.0;
  for (int c = 0; c < m; ++c) {
    err = std::max(err, std::abs(forces[c] - exact(c)));
    scale = std::max(scale, std::abs(exact(c)));
  }
  RecordProperty("member_error", test::sci(err / scale));
  EXPECT_LT(err, 1e-6 * scale);
  // Pratt: the bottom chord in tension, the top chord in compression.
  EXPECT_GT(forces[1], 0.0);
  EXPECT_LT(forces[4], 0.0);
  const std::vector<Reaction> r = w.reactions();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].pin, pin);
  EXPECT_EQ(r[1].pin, roller);
  EXPECT_LT((r[0].force - pin_exact).norm(), 1e-6 * scale);
  EXPECT_LT((r[1].force - Vec3(0.0, 0.0, exact(m))).norm(), 1e-6 * scale) << "the roller pushes only along z";
  EXPECT_EQ(r[1].force.x(), 0.0);
}

TEST(Supports, ProjectionLowersTheResidualAndAPlaneIsRefusedWithoutANormal) {
  World w(test::settings(1, 1));
  const int32_t p = test::add_particles(w, {Vec3(0.3, -0.2, 0.9)}, {1.0});
  EXPECT_THROW(support(w, p, Vec3::Zero(), PinSupport::plane, Vec3::Zero()), Error);
  EXPECT_THROW(support(w, p, Vec3::Zero(), PinSupport::line, Vec3(0.0, 1e-320, 0.0)), Error);
  EXPECT_THROW(support(w, p, Vec3::Zero(), PinSupport::plane, Vec3(0.0, std::nan(""), 1.0)), Error);
  EXPECT_THROW(support(w, p, Vec3::Zero(), static_cast<PinSupport>(7), Vec3::UnitZ()), Error);
  EXPECT_EQ(w.pin_count(), 0u) << "a refused call changes nothing";
  // Compliant: each projection brings the particle closer to the plane z = 0 (gravity off).
  support(w, p, Vec3::Zero(), PinSupport::plane, Vec3::UnitZ(), 1e-6);
  double before = std::abs(w.positions()[p].z());
  for (int f = 0; f < 5; ++f) {
    w.step();
    const double now = std::abs(w.positions()[p].z());
    EXPECT_LT(now, before);
    before = now;
  }
  EXPECT_NEAR(w.positions()[p].x(), 0.3, 1e-15) << "free along the plane";
}

}  // namespace
}  // namespace embra
