// Shape matching (World::add_shape_match, shape_match.hpp), checked against answers derived here:
//
//   - the fit: points moved by a known rotation and translation give back that rotation (to 1e-12)
//     and translation; with noise, the fit's weighted residual is no larger than the true
//     placement's; a mirrored input still gives a proper rotation (det +1), no worse than any of
//     2000 random rotations;
//   - the energy E = 1 / (2 alpha) sum (m_i / m_bar) |x_i - g_i|^2 has the gradient
//     (m_k / (m_bar alpha)) (x_k - g_k) (envelope theorem of the fit): central differences;
//   - one projection lowers the residual sum |x_i - g_i|; a hard set, one point pinned, converges
//     below 1e-6 of its size;
//   - a hard set of 8 points of unequal masses thrown spinning under gravity keeps every pairwise
//     distance to 1e-9 of its size, and its centre of mass follows the integrator's free fall
//     (a loose particle's path) to 1e-9 relative;
//   - a soft set hung from one pinned point comes to rest with each free point alpha m_bar g below
//     its goal (the static balance of its weight and the goal's pull): twice the compliance, twice
//     the sag;
//   - hung from one hard-pinned point, then two, at rest: the pins' reactions sum to minus the weight;
//   - the same bits at 1 and 4 threads; bad input refused, changing nothing;
//   - the point-set checks every adder shares (point_set.hpp): the base of a set with known
//     distances, the one-line limit, a repeated particle.
#include "embra/core/point_set.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace embra {
namespace {

using test::Rng;
using test::sci;

constexpr double kG = 9.81;

Eigen::Matrix3d random_rotation(Rng& rng) {
  return Eigen::AngleAxisd(rng.uniform(0.3, 3.0), rng.unit()).toRotationMatrix();
}

std::vector<int32_t> iota(int32_t first, int32_t n) {
  std::vector<int32_t> ids(n);
  for (int32_t i = 0; i < n; ++i) ids[i] = first + i;
  return ids;
}

/// sum m_i |x_i - (R r_i + t)|^2 with the best t for R (weighted centroids matched).
double placement_residual(const std::vector<Vec3>& x, const std::vector<Vec3>& r, const std::vector<double>& m,
                          const Eigen::Matrix3d& rot) {
  Vec3 cx = Vec3::Zero(), cr = Vec3::Zero();
  double total = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    cx += m[i] * x[i];
    cr += m[i] * r[i];
    total += m[i];
  }
  cx /= total;
  cr /= total;
  double e = 0.0;
  for (size_t i = 0; i < x.size(); ++i) e += m[i] * (x[i] - cx - rot * (r[i] - cr)).squaredNorm();
  return e;
}

TEST(ShapeMatch, FitRecoversAKnownRotation) {
  Rng rng(20);
  double worst_rotation = 0.0, worst_centre = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 3 + trial % 8;
    std::vector<Vec3> r(n), x(n);
    std::vector<double> m(n);
    for (int i = 0; i < n; ++i) {
      r[i] = rng.vec(-1.0, 1.0);
      m[i] = rng.uniform(0.2, 3.0);
    }
    const Eigen::Matrix3d rot = random_rotation(rng);
    const Vec3 t = rng.vec(-5.0, 5.0);
    for (int i = 0; i < n; ++i) x[i] = rot * r[i] + t;
    const std::vector<int32_t> ids = iota(0, n);
    const RigidFit f = fit_rigid(ids, r, m, x);
    worst_rotation = std::max(worst_rotation, (f.rotation - rot).cwiseAbs().maxCoeff());
    EXPECT_NEAR(f.rotation.determinant(), 1.0, 1e-14);
    for (int i = 0; i < n; ++i) worst_centre = std::max(worst_centre, (f.goal(r[i]) - x[i]).norm());
  }
  ::testing::Test::RecordProperty("rotation_error", sci(worst_rotation));
  ::testing::Test::RecordProperty("goal_error_m", sci(worst_centre));
  EXPECT_LT(worst_rotation, 1e-12);
  EXPECT_LT(worst_centre, 1e-12);
}

TEST(ShapeMatch, FitWithNoiseIsNoWorseThanTheTruePlacement) {
  Rng rng(21);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 6;
    std::vector<Vec3> r(n), x(n);
    std::vector<double> m(n);
    for (int i = 0; i < n; ++i) {
      r[i] = rng.vec(-1.0, 1.0);
      m[i] = rng.uniform(0.2, 3.0);
    }
    const Eigen::Matrix3d rot = random_rotation(rng);
    for (int i = 0; i < n; ++i) x[i] = rot * r[i] + Vec3(1.0, 2.0, 3.0) + rng.vec(-0.01, 0.01);
    const RigidFit f = fit_rigid(iota(0, n), r, m, x);
    EXPECT_NEAR(f.rotation.determinant(), 1.0, 1e-14);
    EXPECT_LE(placement_residual(x, r, m, f.rotation), placement_residual(x, r, m, rot) * (1.0 + 1e-12));
    // Noise of 1e-2 on points about 1 apart turns the fit by about that much.
    EXPECT_LT((f.rotation - rot).norm(), 0.05);
  }
}

TEST(ShapeMatch, MirroredInputGivesAProperRotation) {
  Rng rng(22);
  const int n = 7;
  std::vector<Vec3> r(n), x(n);
  std::vector<double> m(n, 1.0);
  for (int i = 0; i < n; ++i) r[i] = rng.vec(-1.0, 1.0);
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  const Eigen::Matrix3d rot = random_rotation(rng);
  for (int i = 0; i < n; ++i) x[i] = rot * mirror * r[i];
  const RigidFit f = fit_rigid(iota(0, n), r, m, x);
  EXPECT_NEAR(f.rotation.determinant(), 1.0, 1e-14);
  EXPECT_LT((f.rotation.transpose() * f.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  const double best = placement_residual(x, r, m, f.rotation);
  for (int k = 0; k < 2000; ++k) EXPECT_LE(best, placement_residual(x, r, m, random_rotation(rng)) * (1.0 + 1e-12));
}

TEST(ShapeMatch, EnergyGradientMatchesDifferences) {
  Rng rng(23);
  const int n = 6;
  ShapeMatch s;
  std::vector<Vec3> x(n);
  std::vector<double> inv_mass(n);
  for (int i = 0; i < n; ++i) {
    s.particles.push_back(i);
    s.rest.push_back(rng.vec(-1.0, 1.0));
    x[i] = 0.9 * s.rest[i] + rng.vec(-0.2, 0.2);
    inv_mass[i] = 1.0 / rng.uniform(0.5, 2.0);
  }
  inv_mass[2] = 0.0;  // immovable: weighted as the heaviest of the others
  s.compliance = 1e-3;
  std::vector<double> m;
  shape_match_weights(s, inv_mass, m);
  const RigidFit f = fit_rigid(s.particles, s.rest, m, x);
  const double m_bar = f.weight / n;
  double worst = 0.0;
  const double step = 1e-6;
  for (int k = 0; k < n; ++k) {
    const Vec3 grad = (m[k] / (m_bar * s.compliance)) * (x[k] - f.goal(s.rest[k]));
    for (int c = 0; c < 3; ++c) {
      std::vector<Vec3> xp = x, xm = x;
      xp[k][c] += step;
      xm[k][c] -= step;
      const double fd = (shape_match_energy(s, inv_mass, xp) - shape_match_energy(s, inv_mass, xm)) / (2.0 * step);
      worst = std::max(worst, std::abs(fd - grad[c]) / std::max(1.0, std::abs(grad[c])));
    }
  }
  ::testing::Test::RecordProperty("gradient_relative_error", sci(worst));
  EXPECT_LT(worst, 1e-6);
}

/// sum |x_i - g_i| at the fit of x.
double residual(const ShapeMatch& s, const std::vector<double>& inv_mass, const std::vector<Vec3>& x) {
  std::vector<double> m;
  shape_match_weights(s, inv_mass, m);
  const RigidFit f = fit_rigid(s.particles, s.rest, m, x);
  double sum = 0.0;
  for (size_t i = 0; i < s.particles.size(); ++i) sum += (x[s.particles[i]] - f.goal(s.rest[i])).norm();
  return sum;
}

TEST(ShapeMatch, ProjectionLowersTheResidualAndAHardSetConverges) {
  Rng rng(24);
  const int n = 8;
  ShapeMatch s;
  std::vector<Vec3> x(n);
  std::vector<double> inv_mass(n);
  for (int i = 0; i < n; ++i) {
    s.particles.push_back(i);
    s.rest.push_back(rng.vec(-0.5, 0.5));
    x[i] = s.rest[i] + rng.vec(-0.1, 0.1);
    inv_mass[i] = 1.0 / rng.uniform(0.5, 2.0);
  }
  s.lambda.assign(n, Vec3::Zero());
  std::vector<double> scratch;
  const double h = 1.0 / 960.0, inv_h2 = 1.0 / (h * h);
  // Soft: every projection that starts a substep (multipliers 0) lowers the residual, by the factor
  // 1 / (1 + alpha m_bar / h^2) of each point's move toward its goal.
  s.compliance = 1e-6;
  std::vector<Vec3> y = x;
  double before = residual(s, inv_mass, y);
  for (int it = 0; it < 20; ++it) {
    std::fill(s.lambda.begin(), s.lambda.end(), Vec3::Zero());
    project_shape_match(s, inv_h2, inv_mass, inv_mass, y, scratch);
    const double after = residual(s, inv_mass, y);
    EXPECT_LT(after, before) << "projection " << it;
    before = after;
  }
  // Within a substep the multipliers accumulate: the XPBD residual |C_i + alpha_i~ lambda_i| goes
  // to 0 (the compliant balance), the goals' own residual stays where that balance holds it.
  y = x;
  std::fill(s.lambda.begin(), s.lambda.end(), Vec3::Zero());
  for (int it = 0; it < 50; ++it) project_shape_match(s, inv_h2, inv_mass, inv_mass, y, scratch);
  {
    std::vector<double> m;
    shape_match_weights(s, inv_mass, m);
    const RigidFit f = fit_rigid(s.particles, s.rest, m, y);
    const double m_bar = f.weight / n;
    double worst = 0.0;
    for (int i = 0; i < n; ++i)
      worst = std::max(worst,
                       (y[i] - f.goal(s.rest[i]) + s.compliance * m_bar * inv_mass[i] * inv_h2 * s.lambda[i]).norm());
    ::testing::Test::RecordProperty("soft_xpbd_residual_after_50_m", sci(worst));
    EXPECT_LT(worst, 1e-12);
  }
  // Hard, all free: one projection puts every point on its goal.
  s.compliance = 0.0;
  std::fill(s.lambda.begin(), s.lambda.end(), Vec3::Zero());
  y = x;
  project_shape_match(s, inv_h2, inv_mass, inv_mass, y, scratch);
  const double scale = 1.0;  // the rest points span about 1 m
  ::testing::Test::RecordProperty("hard_free_residual_m", sci(residual(s, inv_mass, y)));
  EXPECT_LT(residual(s, inv_mass, y), 1e-12 * scale);
  // Hard, point 0 pinned (solver inverse mass 0): it takes part in the fit but stays; the others
  // converge onto the placement through it.
  std::vector<double> w = inv_mass;
  w[0] = 0.0;
  y = x;
  std::fill(s.lambda.begin(), s.lambda.end(), Vec3::Zero());
  before = residual(s, inv_mass, y);
  int iterations = 0;
  while (residual(s, inv_mass, y) > 1e-6 * scale && iterations < 1000) {
    project_shape_match(s, inv_h2, inv_mass, w, y, scratch);
    const double after = residual(s, inv_mass, y);
    EXPECT_LT(after, before);
    before = after;
    ++iterations;
  }
  EXPECT_EQ(y[0], x[0]);
  ::testing::Test::RecordProperty("pinned_hard_projections_to_1e-6", std::to_string(iterations));
  EXPECT_LT(residual(s, inv_mass, y), 1e-6 * scale);
}

TEST(ShapeMatch, HardSetFallsAndSpinsRigidly) {
  Rng rng(25);
  World w(test::settings(16, 1, Vec3(0.0, 0.0, -kG)));
  const int n = 8;
  std::vector<Vec3> x(n);
  std::vector<double> masses(n);
  for (int i = 0; i < n; ++i) {
    x[i] = Vec3(0.0, 0.0, 10.0) + rng.vec(-0.5, 0.5);
    masses[i] = rng.uniform(0.5, 2.0);
  }
  const int32_t first = test::add_particles(w, x, masses);
  const int32_t loose = test::add_particles(w, {Vec3::Zero()}, {1.0});
  w.add_shape_match(Id{}, iota(first, n), {}, 0.0);
  // Thrown: the centre of mass at 1 m/s along x and 3 m/s up, spinning at 6 rad/s about a tilted
  // axis; the loose particle thrown with the same velocity from the centre of mass.
  double total = 0.0;
  Vec3 c0 = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    total += masses[i];
    c0 += masses[i] * x[i];
  }
  c0 /= total;
  const Vec3 v0(1.0, 0.0, 3.0), omega = 6.0 * Vec3(0.3, -0.5, 0.8).normalized();
  std::vector<double> vel;
  for (int i = 0; i < n; ++i) {
    const Vec3 v = v0 + omega.cross(x[i] - c0);
    vel.insert(vel.end(), {v.x(), v.y(), v.z()});
  }
  w.set_velocities(first, vel);
  w.set_positions(loose, std::vector<double>{c0.x(), c0.y(), c0.z()});
  w.set_velocities(loose, std::vector<double>{v0.x(), v0.y(), v0.z()});
  double size = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) size = std::max(size, (x[i] - x[j]).norm());
  double worst_distance = 0.0, worst_centre = 0.0, worst_loose = 0.0, worst_formula = 0.0, continuous = 0.0;
  const double h = w.settings().dt / w.settings().substeps;
  int64_t substeps = 0;
  for (int frame = 0; frame < 120; ++frame) {
    w.step();
    substeps += w.settings().substeps;
    const std::vector<Vec3>& p = w.positions();
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < i; ++j)
        worst_distance =
            std::max(worst_distance, std::abs((p[first + i] - p[first + j]).norm() - (x[i] - x[j]).norm()) / size);
    Vec3 c = Vec3::Zero();
    for (int i = 0; i < n; ++i) c += masses[i] * p[first + i];
    c /= total;
    // Symplectic Euler's free fall: after k substeps z = z0 + vz k h - g h^2 k (k + 1) / 2.
    const double k = static_cast<double>(substeps);
    const Vec3 expected = c0 + v0 * (k * h) + Vec3(0.0, 0.0, -kG * h * h * k * (k + 1.0) / 2.0);
    worst_centre = std::max(worst_centre, (c - expected).norm() / expected.norm());
    worst_loose = std::max(worst_loose, (c - p[loose]).norm() / expected.norm());
    worst_formula = std::max(worst_formula, (p[loose] - expected).norm() / expected.norm());
    const double t = k * h;
    continuous = std::max(continuous, std::abs(c.z() - (c0.z() + v0.z() * t - kG * t * t / 2.0)));
  }
  ::testing::Test::RecordProperty("pairwise_distance_change_over_size", sci(worst_distance));
  ::testing::Test::RecordProperty("centre_vs_discrete_free_fall_relative", sci(worst_centre));
  ::testing::Test::RecordProperty("centre_vs_loose_particle_relative", sci(worst_loose));
  ::testing::Test::RecordProperty("loose_particle_vs_discrete_free_fall_relative", sci(worst_formula));
  ::testing::Test::RecordProperty("centre_vs_continuous_free_fall_m", sci(continuous));
  EXPECT_LT(worst_distance, 1e-9);
  EXPECT_LT(worst_centre, 1e-9);
}

/// The relative change of a hard set's angular momentum about its centre of mass after 2 s of free
/// spin at `substeps` per frame.
double spin_loss(int32_t substeps) {
  Rng rng(25);
  World w(test::settings(substeps, 1));
  const int n = 8;
  std::vector<Vec3> x(n);
  std::vector<double> masses(n);
  for (int i = 0; i < n; ++i) {
    x[i] = rng.vec(-0.5, 0.5);
    masses[i] = rng.uniform(0.5, 2.0);
  }
  const int32_t first = test::add_particles(w, x, masses);
  w.add_shape_match(Id{}, iota(first, n), {}, 0.0);
  double total = 0.0;
  Vec3 c0 = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    total += masses[i];
    c0 += masses[i] * x[i];
  }
  c0 /= total;
  const Vec3 omega = 6.0 * Vec3(0.3, -0.5, 0.8).normalized();
  std::vector<double> vel;
  Vec3 ang0 = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    const Vec3 v = omega.cross(x[i] - c0);
    vel.insert(vel.end(), {v.x(), v.y(), v.z()});
    ang0 += masses[i] * (x[i] - c0).cross(v);
  }
  w.set_velocities(first, vel);
  for (int frame = 0; frame < 120; ++frame) w.step();
  const std::vector<Vec3>& p = w.positions();
  const std::vector<Vec3>& v = w.velocities();
  Vec3 c = Vec3::Zero(), vc = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    c += masses[i] * p[first + i];
    vc += masses[i] * v[first + i];
  }
  c /= total;
  vc /= total;
  Vec3 ang = Vec3::Zero();
  for (int i = 0; i < n; ++i) ang += masses[i] * (p[first + i] - c).cross(v[first + i] - vc);
  return (ang - ang0).norm() / ang0.norm();
}

// Position-based projection of a spinning set onto its rigid placements takes a little of the spin
// each substep (the straight-line prediction leaves the circle by O(h^2)): the loss over a fixed time
// is first order in h, halved with twice the substeps.
TEST(ShapeMatch, SpinLossIsFirstOrderInTheSubstep) {
  const double l16 = spin_loss(16), l32 = spin_loss(32), l64 = spin_loss(64);
  ::testing::Test::RecordProperty("angular_momentum_change_16", sci(l16));
  ::testing::Test::RecordProperty("angular_momentum_change_32", sci(l32));
  ::testing::Test::RecordProperty("angular_momentum_change_64", sci(l64));
  EXPECT_NEAR(l16 / l32, 2.0, 0.1);
  EXPECT_NEAR(l32 / l64, 2.0, 0.1);
}

/// Rests a soft set of 6 points hung from point 0 (hard-pinned); returns, per free point, its
/// offset from its goal x_i - g_i divided by alpha m_bar g (the static balance: (0, 0, -1)).
std::vector<Vec3> hung_offsets(double compliance, double* sag) {
  Settings s = test::settings(8, 30, Vec3(0.0, 0.0, -kG), 4.0);
  World w(s);
  const std::vector<Vec3> x = {Vec3(0.0, 0.0, 1.0),  Vec3(0.3, 0.0, 1.0),  Vec3(0.0, 0.3, 1.0),
                               Vec3(0.3, 0.3, 1.05), Vec3(0.15, 0.1, 0.8), Vec3(0.2, 0.25, 0.9)};
  const std::vector<double> masses = {1.0, 0.5, 0.8, 1.2, 0.7, 1.1};
  const int32_t first = test::add_particles(w, x, masses);
  test::hard_pin(w, first, x[0]);
  const std::vector<int32_t> ids = iota(first, 6);
  w.add_shape_match(Id{}, ids, {}, compliance);
  for (int frame = 0; frame < 1500; ++frame) w.step();
  const ShapeMatch& sm = w.shape_matches(Id{})[0];
  std::vector<double> m;
  shape_match_weights(sm, w.inverse_masses(), m);
  const RigidFit f = fit_rigid(sm.particles, sm.rest, m, w.positions());
  const double m_bar = f.weight / 6.0;
  std::vector<Vec3> out;
  *sag = 0.0;
  for (int i = 1; i < 6; ++i) {
    const Vec3 d = w.positions()[first + i] - f.goal(sm.rest[i]);
    out.push_back(d / (compliance * m_bar * kG));
    *sag = std::max(*sag, d.norm());
  }
  return out;
}

TEST(ShapeMatch, SoftSetHungFromAPinSagsByItsCompliance) {
  double worst = 0.0, sag1 = 0.0, sag2 = 0.0;
  for (const double compliance : {1e-4, 2e-4}) {
    double sag = 0.0;
    for (const Vec3& o : hung_offsets(compliance, &sag)) worst = std::max(worst, (o - Vec3(0.0, 0.0, -1.0)).norm());
    (compliance == 1e-4 ? sag1 : sag2) = sag;
  }
  ::testing::Test::RecordProperty("offset_vs_alpha_mbar_g_relative", sci(worst));
  ::testing::Test::RecordProperty("sag_1e-4_m", sci(sag1));
  ::testing::Test::RecordProperty("sag_2e-4_m", sci(sag2));
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(sag2, sag1);
  EXPECT_NEAR(sag2 / sag1, 2.0, 1e-5);
}

/// The same set hung from one hard-pinned point, then from two: at rest the pins' reactions sum to
/// minus the set's weight. A pinned point does not move, but it takes back what the free points
/// took from the set's pull (the set's forces, over all its points, are momentum-neutral); between
/// two pins the split is the least-norm one that balances force and moment.
TEST(ShapeMatch, HardPinnedPointsCarryTheSetsWeight) {
  for (const int pinned : {1, 2}) {
    Settings s = test::settings(8, 30, Vec3(0.0, 0.0, -kG), 4.0);
    World w(s);
    const std::vector<Vec3> x = {Vec3(0.0, 0.0, 1.0),  Vec3(0.3, 0.0, 1.0),  Vec3(0.0, 0.3, 1.0),
                                 Vec3(0.3, 0.3, 1.05), Vec3(0.15, 0.1, 0.8), Vec3(0.2, 0.25, 0.9)};
    const int32_t first = test::add_particles(w, x, {1.0, 0.5, 0.8, 1.2, 0.7, 1.1});
    for (int k = 0; k < pinned; ++k) test::hard_pin(w, first + k, x[static_cast<size_t>(k)]);
    w.add_shape_match(Id{}, iota(first, 6), {}, 1e-4);
    for (int frame = 0; frame < 1500; ++frame) w.step();
    Vec3 sum = Vec3::Zero();
    for (const Reaction& r : w.reactions()) sum += r.force;
    const Vec3 weight = test::applied_load(w);
    const double imbalance = (sum + weight).norm() / weight.norm();
    ::testing::Test::RecordProperty("imbalance_" + std::to_string(pinned) + "_pins", sci(imbalance));
    EXPECT_LT(w.report().max_speed, 1e-9) << pinned << " pins: at rest";
    EXPECT_LT(imbalance, 1e-9) << pinned << " pins";
  }
}

std::vector<Vec3> run_with_threads(int32_t threads) {
  Settings s = test::settings(8, 4, Vec3(0.0, 0.0, -kG));
  s.threads = threads;
  World w(s);
  std::vector<Vec3> x;
  const int32_t first = test::add_net(w, 24, 0.05, 1.0, 0.01, 0.0, x);
  test::hard_pin(w, first, x[0]);
  test::hard_pin(w, first + 23, x[23]);
  // Two shape matches over the middle of the net, overlapping, in two groups.
  const Id g = w.create_group(GroupDesc{});
  std::vector<int32_t> a, b;
  for (int j = 8; j < 14; ++j)
    for (int i = 8; i < 14; ++i) {
      a.push_back(first + 24 * j + i);
      b.push_back(first + 24 * (j + 3) + i + 3);
    }
  w.add_shape_match(Id{}, a, {}, 1e-5);
  w.add_shape_match(g, b, {}, 0.0);
  for (int frame = 0; frame < 30; ++frame) w.step();
  return w.positions();
}

TEST(ShapeMatch, SameBitsAtAnyThreadCount) {
  const std::vector<Vec3> one = run_with_threads(1), again = run_with_threads(1), four = run_with_threads(4);
  ASSERT_EQ(one.size(), four.size());
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i], again[i]) << i;
    EXPECT_EQ(one[i], four[i]) << i;
  }
}

TEST(ShapeMatch, BadInputIsRefusedAndChangesNothing) {
  World w;
  const int32_t first =
      test::add_particles(w, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 0), Vec3(0, 1, 0)},
                          {1, 1, 1, 1, 1, 1});
  auto refused = [&](std::vector<int32_t> ids, std::vector<Vec3> rest, double compliance, const char* what) {
    try {
      w.add_shape_match(Id{}, ids, rest, compliance);
      ADD_FAILURE() << what << ": accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument) << what;
    }
    EXPECT_TRUE(w.shape_matches(Id{}).empty()) << what;
  };
  refused({first, first + 1}, {}, 0.0, "two points");
  refused({first, first + 1, first + 2}, {}, 0.0, "collinear");
  refused({first + 3, first + 4, first + 5}, {}, 0.0, "one place");
  refused({first, first + 1, first + 1}, {}, 0.0, "repeated");
  refused({first, first + 1, 99}, {}, 0.0, "out of range");
  refused({first, first + 1, first + 3}, {}, -1.0, "negative compliance");
  refused({first, first + 1, first + 3}, {}, NAN, "NaN compliance");
  refused({first, first + 1, first + 3}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, 0.0, "rest count");
  refused({first, first + 1, first + 3}, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(INFINITY, 0, 0)}, 0.0, "rest inf");
  EXPECT_EQ(w.add_shape_match(Id{}, std::vector<int32_t>{first, first + 1, first + 3}, {}, 0.0), 0);
  EXPECT_THROW(w.remove_shape_match(Id{}, 1), Error);
  w.remove_shape_match(Id{}, 0);
  EXPECT_TRUE(w.shape_matches(Id{}).empty());
}

TEST(PointSet, BaseHasTheKnownFarthestPoints) {
  // From (0,0,0): (3,4,0) is 5 away, the farthest; (4,-3,0) is 5 from the line through those two
  // (perpendicular to it), the farthest; (1,1,2) is 2 from their plane z = 0, the farthest.
  const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 1, 2), Vec3(3, 4, 0), Vec3(4, -3, 0), Vec3(1, 1, 0)};
  const PointSetBase b = point_set_base(p.size(), [&](size_t i) { return p[i]; });
  EXPECT_EQ(b.far, 2u);
  EXPECT_DOUBLE_EQ(b.reach, 5.0);
  EXPECT_EQ(b.off, 3u);
  EXPECT_NEAR(b.off_line, 5.0, 1e-15);
  EXPECT_EQ(b.off_plane, 1u);
  EXPECT_NEAR(b.plane_distance, 2.0, 1e-15);
  EXPECT_TRUE(b.spans_plane());
  // A third point 1e-7 of the reach off the line does not span a plane; 1e-5 does.
  for (const double off : {1e-7, 1e-5}) {
    const std::vector<Vec3> q{Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(5, 10 * off, 0)};
    EXPECT_EQ(point_set_base(q.size(), [&](size_t i) { return q[i]; }).spans_plane(), off > 1e-6) << off;
  }
  const std::vector<Vec3> one_place(3, Vec3(1, 2, 3));
  const PointSetBase c = point_set_base(3, [&](size_t i) { return one_place[i]; });
  EXPECT_EQ(c.reach, 0.0);
  EXPECT_FALSE(c.spans_plane());
  EXPECT_EQ(repeated_particle(std::vector<int32_t>{4, 2, 9, 2, 4}), 2);
  EXPECT_EQ(repeated_particle(std::vector<int32_t>{4, 2, 9}), -1);
}

}  // namespace
}  // namespace embra
