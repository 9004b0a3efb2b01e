// Statics read from the solver: member forces (World::constraint_forces), pin reactions
// (World::reactions) and point loads (World::set_loads), checked against equilibrium worked out
// here, independently of the solver.
//
// The cantilever truss: four bays of a by b in the x-z plane, the two joints at the wall (x = 0)
// hard-pinned, rectangular bays with one diagonal each. j = 10 joints, 8 of them free (16
// equations), m = 16 members: statically determinate, so the member forces follow from joint
// equilibrium alone, whatever the members' stiffness.
//
//   T0 ---- T1 ---- T2 ---- T3 ---- T4        T: top chord, z = b
//   |pin  /  |    /  |    /  |    /  |
//   |   /    |  /    |  /    |  /    |        diagonals from B(k) up to T(k+1)
//   B0 ---- B1 ---- B2 ---- B3 ---- B4        B: bottom chord, z = 0
//   pin                               P
//
// The method of joints: at every free joint, sum over its members of T_m u_m + F = 0, with u_m
// the unit vector from the joint along the member and T_m the tension; 16 equations in the 16
// tensions, solved here by LU on the rest geometry. The solver's members are hard (compliance 0),
// so the settled geometry is the rest geometry to the constraints' residual (below 1e-12 m here).
#include "embra/core/panels.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>
#include <vector>

namespace embra {
namespace {

constexpr double kBay = 2.0;    // a, m
constexpr double kDepth = 1.5;  // b, m
constexpr int kBays = 4;
constexpr double kMass = 1e4;  // kg per joint: the loads move a joint by h^2 F / m in a substep
constexpr double kG = 9.81;

struct Truss {
  std::vector<Vec3> joints;                  // B0..B4, then T0..T4
  std::vector<std::pair<int, int>> members;  // joint pairs
  std::vector<Vec3> loads;                   // point load per joint (N)
  std::vector<bool> pinned;
};

int bottom(int k) {
  return k;
}
int top(int k) {
  return kBays + 1 + k;
}

Truss cantilever() {
  Truss t;
  for (int k = 0; k <= kBays; ++k) t.joints.emplace_back(k * kBay, 0.0, 0.0);
  for (int k = 0; k <= kBays; ++k) t.joints.emplace_back(k * kBay, 0.0, kDepth);
  for (int k = 0; k < kBays; ++k) {
    t.members.emplace_back(bottom(k), bottom(k + 1));
    t.members.emplace_back(top(k), top(k + 1));
    t.members.emplace_back(bottom(k + 1), top(k + 1));
    t.members.emplace_back(bottom(k), top(k + 1));
  }
  t.loads.assign(t.joints.size(), Vec3::Zero());
  t.loads[bottom(kBays)] = Vec3(0.0, 0.0, -20000.0);  // the tip load P
  t.loads[bottom(2)] = Vec3(3000.0, 0.0, -5000.0);    // and two more, one of them slanted
  t.loads[top(3)] = Vec3(-1500.0, 0.0, -8000.0);
  t.pinned.assign(t.joints.size(), false);
  t.pinned[bottom(0)] = t.pinned[top(0)] = true;
  return t;
}

/// The method of joints on the joints' positions `at`: member tensions (N) for loads plus joint
/// weights m g (gravity along -z when `gravity`).
std::vector<double> method_of_joints(const Truss& t, const std::vector<Vec3>& at, bool gravity) {
  std::vector<int> row(t.joints.size(), -1);
  int free = 0;
  for (size_t j = 0; j < t.joints.size(); ++j)
    if (!t.pinned[j]) row[j] = free++;
  const int m = static_cast<int>(t.members.size());
  EXPECT_EQ(2 * free, m) << "statically determinate";
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * free, m);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * free);
  for (int c = 0; c < m; ++c) {
    const auto [i, j] = t.members[c];
    const Vec3 u = (at[j] - at[i]).normalized();  // from i towards j
    // A tension pulls i towards j and j towards i.
    if (row[i] >= 0) a(2 * row[i], c) += u.x(), a(2 * row[i] + 1, c) += u.z();
    if (row[j] >= 0) a(2 * row[j], c) -= u.x(), a(2 * row[j] + 1, c) -= u.z();
  }
  for (size_t j = 0; j < t.joints.size(); ++j)
    if (row[j] >= 0) {
      const Vec3 f = t.loads[j] + (gravity ? Vec3(0.0, 0.0, -kMass * kG) : Vec3::Zero());
      rhs(2 * row[j]) = -f.x();
      rhs(2 * row[j] + 1) = -f.z();
    }
  const Eigen::VectorXd tension = a.fullPivLu().solve(rhs);
  EXPECT_LT((a * tension - rhs).norm(), 1e-9 * rhs.norm());
  return std::vector<double>(tension.data(), tension.data() + m);
}

/// The truss in a world: loose particles, hard distance members, the wall joints hard-pinned, the
/// loads set.
void build(World& w, const Truss& t, std::vector<Id>& pins) {
  const int32_t first = test::add_particles(w, t.joints, std::vector<double>(t.joints.size(), kMass));
  std::vector<int32_t> ids;
  for (const auto& [i, j] : t.members) ids.insert(ids.end(), {first + i, first + j});
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = ids;
  w.add_constraints(d);
  for (size_t j = 0; j < t.joints.size(); ++j) {
    if (t.pinned[j]) pins.push_back(test::hard_pin(w, first + static_cast<int32_t>(j), t.joints[j]));
    w.set_loads(first + static_cast<int32_t>(j), std::span<const double>(t.loads[j].data(), 3));
  }
}

Settings statics_settings(const Vec3& gravity, int realign_passes = 4) {
  Settings s = test::settings(4, 600, gravity, 4.0);
  s.realign_passes = realign_passes;
  s.tethers = 0;
  return s;
}

/// max |F - F_exact| over max |F_exact|.
double relative_error(const std::vector<double>& f, const std::vector<double>& exact) {
  double err = 0.0, scale = 0.0;
  for (size_t i = 0; i < f.size(); ++i) {
    err = std::max(err, std::abs(f[i] - exact[i]));
    scale = std::max(scale, std::abs(exact[i]));
  }
  return err / scale;
}

TEST(Statics, CantileverTrussMemberForcesAreTheMethodOfJoints) {
  const Truss t = cantilever();
  for (const bool gravity : {false, true}) {
    World w(statics_settings(gravity ? Vec3(0.0, 0.0, -kG) : Vec3::Zero()));
    std::vector<Id> pins;
    build(w, t, pins);
    for (int f = 0; f < 100; ++f) w.step();
    // The geometry is the rest geometry: hard members.
    double off = 0.0;
    for (size_t j = 0; j < t.joints.size(); ++j) off = std::max(off, (w.positions()[j] - t.joints[j]).norm());
    // Equilibrium on the settled geometry (what the forces must balance) and on the rest geometry
    // (the textbook answer; the members are hard, so the two differ by the joints' offset).
    const std::vector<double> exact = method_of_joints(t, w.positions(), gravity);
    const std::vector<double> exact_rest = method_of_joints(t, t.joints, gravity);
    const std::vector<double> forces = w.constraint_forces(w.default_group(), Kind::distance);
    ASSERT_EQ(forces.size(), exact.size());
    const double err = relative_error(forces, exact), err_rest = relative_error(forces, exact_rest);
    const std::string tag = gravity ? "_gravity" : "";
    RecordProperty("member_error" + tag, test::sci(err));
    RecordProperty("member_error_rest_geometry" + tag, test::sci(err_rest));
    RecordProperty("joint_offset_m" + tag, test::sci(off));
    EXPECT_LT(err, 1e-6) << "member forces against the method of joints, relative to the largest";
    EXPECT_LT(err_rest, 1e-6) << "and on the rest geometry";
    // Spot checks by hand, tip load only would give the root chords P L / b; here: the first bay's
    // bottom chord is in compression and its top chord in tension (the cantilever hogs).
    EXPECT_LT(forces[0], 0.0);
    EXPECT_GT(forces[1], 0.0);
    // The wall reactions: each pinned joint's equilibrium with the exact member forces.
    Vec3 exact_reaction[2] = {Vec3::Zero(), Vec3::Zero()};
    const int wall[2] = {bottom(0), top(0)};
    for (int k = 0; k < 2; ++k) {
      Vec3 f = t.loads[wall[k]] + (gravity ? Vec3(0.0, 0.0, -kMass * kG) : Vec3::Zero());
      for (size_t c = 0; c < t.members.size(); ++c) {
        const auto [i, j] = t.members[c];
        if (i == wall[k]) f += exact[c] * (t.joints[j] - t.joints[i]).normalized();
        if (j == wall[k]) f += exact[c] * (t.joints[i] - t.joints[j]).normalized();
      }
      exact_reaction[k] = -f;
    }
    const std::vector<Reaction> r = w.reactions();
    ASSERT_EQ(r.size(), 2u);
    double scale = 0.0;
    for (const Vec3& e : exact_reaction) scale = std::max(scale, e.norm());
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(r[k].pin, pins[k]);
      EXPECT_EQ(r[k].particle, wall[k]);
      EXPECT_LT((r[k].force - exact_reaction[k]).norm(), 1e-6 * scale) << "reaction at the wall joint " << k;
    }
  }
}

double reaction_imbalance(const World& w) {
  Vec3 sum = Vec3::Zero();
  for (const Reaction& r : w.reactions()) sum += r.force;
  const Vec3 load = test::applied_load(w);
  return (sum + load).norm() / load.norm();
}

TEST(Statics, TrussReactionsSumToTheAppliedLoad) {
  const Truss t = cantilever();
  World w(statics_settings(Vec3(0.0, 0.0, -kG)));
  std::vector<Id> pins;
  build(w, t, pins);
  for (int f = 0; f < 100; ++f) w.step();
  const double imbalance = reaction_imbalance(w);
  RecordProperty("imbalance", test::sci(imbalance));
  EXPECT_LT(imbalance, 1e-9);
}

/// A compliant cable net: a 6 x 6 grid of particles joined by stretchy distance constraints
/// (compliance 1e-4 m/N), its four corners hard-pinned, one edge's midpoint on a soft pin, under
/// gravity and point loads at three nodes. The reactions (hard and soft pins) sum to the weights
/// plus the loads.
TEST(Statics, CableNetReactionsSumToTheAppliedLoad) {
  constexpr int n = 6;
  constexpr double dx = 0.5;
  for (const int realign : {4, 0}) {
    World w(statics_settings(Vec3(0.0, 0.0, -kG), realign));
    std::vector<Vec3> x;
    const int32_t first = test::add_net(w, n, dx, 0.0, 0.5, 1e-4, x);
    for (const int32_t c : {0, n - 1, n * (n - 1), n * n - 1}) test::hard_pin(w, first + c, x[c]);
    PinDesc soft;
    soft.particle = first + n / 2;
    soft.target = x[n / 2] + Vec3(0.0, -0.2, 0.1);
    soft.compliance = 1e-3;
    w.create_pin(soft);
    const double loads[] = {0.0, 0.0, -40.0, 15.0, 0.0, -10.0, 0.0, 5.0, -25.0};
    const int32_t at[] = {first + 2 * n + 2, first + 3 * n + 4, first + 4 * n + 1};
    for (int k = 0; k < 3; ++k) w.set_loads(at[k], std::span<const double>(&loads[3 * k], 3));
    for (int f = 0; f < 1500; ++f) w.step();
    const double imbalance = reaction_imbalance(w);
    RecordProperty(realign > 0 ? "imbalance_realigned" : "imbalance_textbook", test::sci(imbalance));
    RecordProperty(realign > 0 ? "max_speed_realigned" : "max_speed_textbook", test::sci(w.report().max_speed));
    // The hard pins' reactions are what they took, so they balance with or without realignment
    // (design.md, "Statics"); the member forces need it.
    EXPECT_LT(imbalance, 1e-9) << "realign_passes " << realign;
  }
}

/// A panel mesh (3 x 3 panels of 0.8 m, 1 cm thick, hard-pinned at its four top corners) hangs under
/// gravity. Its hard constraints are redundant (bracing, planarity, plane offsets, joints and welds
/// meeting at every corner), so their multipliers are not fixed by the statics and Gauss-Seidel
/// lets them grow against each other: the pins pull several times the weight against each other.
/// The reactions are what the pinned particles took, projection by projection, so they still sum
/// to minus the weight once the mesh is at rest, with realignment passes and without (textbook XPBD,
/// whose chain pass sweeps chains one link at a time).
TEST(Statics, PanelMeshReactionsSumToTheWeight) {
  for (const int realign : {4, 0}) {
    Settings s = test::settings(4, 50, Vec3(0.0, 0.0, -kG), 4.0);
    s.realign_passes = realign;
    World w(s);
    test::add_panel_grid(w, 3, 3, 0.8);
    for (int f = 0; f < 600; ++f) w.step();
    double largest = 0.0;
    for (const Reaction& r : w.reactions()) largest = std::max(largest, r.force.norm());
    const double weight = test::applied_load(w).norm();
    const double imbalance = reaction_imbalance(w);
    const std::string tag = realign > 0 ? "_realigned" : "_textbook";
    RecordProperty("imbalance" + tag, test::sci(imbalance));
    RecordProperty("max_speed" + tag, test::sci(w.report().max_speed));
    RecordProperty("largest_pin_over_weight" + tag, test::sci(largest / weight));
    EXPECT_LT(w.report().max_speed, 1e-9) << "at rest";
    EXPECT_GT(largest, weight) << "the redundant constraints' multipliers pull the pins against each other";
    EXPECT_LT(imbalance, 1e-9) << "realign_passes " << realign;
  }
}

/// A point load moves a particle as gravity would: a free particle of mass m under load F
/// accelerates at F / m (x = F t^2 / 2m after t, to the integrator's O(h) error).
TEST(Statics, PointLoadAcceleratesAFreeParticleAtForceOverMass) {
  World w(test::settings(20, 1));
  const int32_t p = test::add_particles(w, {Vec3::Zero()}, {2.0});
  const double f[3] = {4.0, -2.0, 1.0};
  w.set_loads(p, f);
  constexpr int frames = 60;
  for (int k = 0; k < frames; ++k) w.step();
  const double t = frames * w.settings().dt;
  const Vec3 expected = 0.5 * Vec3(f[0], f[1], f[2]) / 2.0 * t * t;
  const double h = w.settings().dt / w.settings().substeps;
  // Symplectic Euler: x_n = a h^2 n (n + 1) / 2 = a t^2 / 2 + a t h / 2.
  EXPECT_LT((w.positions()[p] - expected).norm(), 0.5 * Vec3(f[0], f[1], f[2]).norm() / 2.0 * t * h * 1.000001);
  EXPECT_GT(w.positions()[p].x(), 0.0);
}

TEST(Statics, LoadsAndForcesRefuseBadArguments) {
  World w(test::settings(4, 4));
  test::add_particles(w, {Vec3::Zero(), Vec3(1.0, 0.0, 0.0)}, {1.0, 1.0});
  const double nan3[3] = {0.0, std::nan(""), 0.0};
  const double big3[3] = {0.0, 2e300, 0.0};
  const double ok3[3] = {1.0, 2.0, 3.0};
  EXPECT_THROW(w.set_loads(0, nan3), Error);
  EXPECT_THROW(w.set_loads(0, big3), Error);
  EXPECT_THROW(w.set_loads(2, ok3), Error);
  EXPECT_THROW(w.set_loads(-1, ok3), Error);
  EXPECT_THROW(w.set_loads(0, std::span<const double>(ok3, 2)), Error);
  EXPECT_TRUE(w.loads()[0].isZero()) << "a refused call changes nothing";
  EXPECT_TRUE(w.loads()[1].isZero());
  w.set_loads(1, ok3);
  EXPECT_EQ(w.loads()[1], Vec3(1.0, 2.0, 3.0));
  EXPECT_THROW(w.constraint_forces(w.default_group(), Kind::weld), Error);
  EXPECT_THROW(w.constraint_forces(Id{999, 1}, Kind::distance), Error);
}

}  // namespace
}  // namespace embra
