// XPBD compliance is a physical material constant: a vertical chain of N particles of mass m below
// a hard-pinned top, every link a spring of compliance alpha (m/N), stretches by
//
//   link j (j = 1 at the top) carries the weight of the N - j + 1 particles below it:
//     stretch_j = alpha (N - j + 1) m g,      total = alpha m g N (N + 1) / 2,
//
// and the top link's force lambda_1 / h^2 (h = dt / substeps) is N m g, whatever the iteration and
// substep counts. (Plain PBD, with a stiffness factor per projection, would give a stretch that
// depends on both.)
//
//      o  pin
//      |  link 1: N m g
//      o
//      |  link 2: (N - 1) m g
//      o
//      :
//      o  particle N
//
// Two parameter sets, N = 10, m = 0.1 kg, rest 0.1 m:
//
// * Compliance comparable to the inverse mass: alpha = 3e-3 m/N, dt = 1/240 s, one substep, so
//   alpha / h^2 = 173 against 1/m = 10 (alpha m / h^2 = 17). Each iteration matters here (plain PBD
//   would come out stiffer with every extra iteration); Gauss-Seidel contracts the error by about
//   (2 / (2 + 17))^2 ~ 0.01 per sweep, and iterations 5, 20 and 100 must agree.
// * Substeps instead of iterations: alpha = 4e-3 m/N, dt = 1/6000 s, so alpha m / h^2 = 1.4e4 with
//   one substep and 5.8e6 with 20 substeps of one iteration. A single Gauss-Seidel sweep per
//   substep leaves the settled state off by about 0.8 h^2 / (alpha m) relative, because the sweep
//   from lambda = 0 does not solve the substep's (coupled) system exactly: with the first parameter
//   set, 20 substeps of one iteration settle 1.2e-4 too long. alpha m / h^2 must therefore exceed
//   ~1e6 for "20 substeps, 1 iteration" to agree to 1e-6, which this set gives (measured ~1e-7).
#include "test_support.hpp"

#include <gtest/gtest.h>

namespace embra {
namespace {

constexpr int kN = 10;
constexpr double kMass = 0.1;
constexpr double kRest = 0.1;
constexpr double kG = 9.81;

struct Stretch {
  std::vector<double> links;  // stretch of each link, top first
  double top_force = 0.0;     // |lambda_1| / h^2
};

struct Schedule {
  int substeps, iterations;
};

/// Hangs the chain unstretched, lets it settle for `seconds` with damping 15/s (about critical for
/// the lowest mode, omega_1 = 2 sqrt(1 / (alpha m)) sin(pi / 42) = 7.5 to 8.6 rad/s here) and
/// measures the links.
Stretch hang(double alpha, double dt, double seconds, Schedule run) {
  World w(test::settings(run.substeps, run.iterations, Vec3(0, 0, -kG), 15.0, dt));
  std::vector<Vec3> x;
  for (int k = 0; k <= kN; ++k) x.emplace_back(0.0, 0.0, -kRest * k);
  const int32_t first = test::add_particles(w, x, std::vector<double>(kN + 1, kMass));
  test::hard_pin(w, first, Vec3::Zero());
  std::vector<int32_t> ids;
  for (int k = 0; k < kN; ++k) ids.insert(ids.end(), {first + k, first + k + 1});
  const std::vector<double> rest(kN, kRest);
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = ids;
  d.rest = rest;
  d.uniform_compliance = alpha;
  w.add_constraints(d);
  const int frames = static_cast<int>(std::lround(seconds / dt));
  for (int f = 0; f < frames; ++f) w.step();
  Stretch s;
  for (int k = 0; k < kN; ++k)
    s.links.push_back((w.positions()[first + k] - w.positions()[first + k + 1]).norm() - kRest);
  const double h = dt / run.substeps;
  s.top_force = std::abs(w.group(w.default_group()).arrays[static_cast<int>(Kind::distance)].lambda[0]) / (h * h);
  return s;
}

void check_runs(double alpha, double dt, double seconds, std::initializer_list<Schedule> runs) {
  const double total_expected = alpha * kMass * kG * kN * (kN + 1) / 2.0;
  double worst_total = 0.0, worst_link = 0.0, worst_force = 0.0;
  for (const Schedule r : runs) {
    const Stretch s = hang(alpha, dt, seconds, r);
    double total = 0.0;
    for (int j = 0; j < kN; ++j) {
      const double expected = alpha * (kN - j) * kMass * kG;
      const double rel = std::abs(s.links[j] - expected) / expected;
      EXPECT_LT(rel, 1e-6) << "substeps " << r.substeps << " iterations " << r.iterations << " link " << j + 1;
      worst_link = std::max(worst_link, rel);
      total += s.links[j];
    }
    const double rel_total = std::abs(total - total_expected) / total_expected;
    EXPECT_LT(rel_total, 1e-6) << "substeps " << r.substeps << " iterations " << r.iterations;
    worst_total = std::max(worst_total, rel_total);
    const double rel_force = std::abs(s.top_force - kN * kMass * kG) / (kN * kMass * kG);
    EXPECT_LT(rel_force, 1e-6) << "substeps " << r.substeps << " iterations " << r.iterations;
    worst_force = std::max(worst_force, rel_force);
  }
  ::testing::Test::RecordProperty("worst_total_stretch_relative_error", test::sci(worst_total));
  ::testing::Test::RecordProperty("worst_link_stretch_relative_error", test::sci(worst_link));
  ::testing::Test::RecordProperty("worst_top_force_relative_error", test::sci(worst_force));
}

TEST(Compliance, VerticalChainStretchIsIndependentOfIterations) {
  check_runs(3e-3, 1.0 / 240.0, 3.0, {Schedule{1, 5}, Schedule{1, 20}, Schedule{1, 100}});
}

TEST(Compliance, VerticalChainStretchIsTheSameWithSubstepsInsteadOfIterations) {
  check_runs(4e-3, 1.0 / 6000.0, 4.0,
             {Schedule{1, 5}, Schedule{1, 20}, Schedule{1, 100}, Schedule{20, 1}, Schedule{5, 4}});
}

}  // namespace
}  // namespace embra
