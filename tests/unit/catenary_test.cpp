// The hanging chain: N rigid links of length l = L/N, N - 1 free particles of equal mass m (lumped
// weights W = m g), both ends hard-pinned at the same height a span S apart (S = 1, L = 1.2).
//
//   pin o--o                      o--o pin      link k (k = 1..N) makes the angle phi_k with the
//           \                    /              horizontal; every link carries the same horizontal
//            o--o            o--o               tension H, and each free node's weight W is the
//                \          /                   jump in vertical tension:
//                 o--o--o--o                        tan(phi_k) = (W / H) ((N + 1) / 2 - k).
//
// H follows from the span: sum_k l cos(phi_k) = S. The exact nodes are the running sums of
// (l cos(phi_k), -l sin(phi_k)).
//
// What the solver reaches. At a static fixed point of a substep, the positions predicted by gravity
// (x + h^2 g, h = dt / substeps) must be projected back onto x. XPBD projects along the gradients
// at the intermediate iterates rather than at the final point, so the fixed point is the true
// equilibrium plus a bias of order h^2 g (measured: 2.1e-6 of the span at h = 1/960 s, where
// h^2 g = 1.1e-5). The tests therefore settle the chain at h and h/2, check that the error falls
// by 4, and check that the Richardson extrapolation (4 x(h/2) - x(h)) / 3, and the horizontal
// tension read from the multipliers and extrapolated the same way, are the exact discrete catenary
// to 1e-9 of the span (positions) and 1e-8 relative (H).
//
// Why not 1e-9 directly: shrinking h shrinks the O(h^2) bias, but the per-substep motion h^2 g then
// becomes so small against the coordinates (|x| ~ 0.5, one ulp ~ 1e-16) that the rounding of the
// projection acts as a systematic force error of order eps / (h^2 g); it grows as 1/h^2 (moving the
// chain to x ~ 100 multiplies it by ~128, as the rounding does). The sum of the two is smallest near
// h ~ 1/46000 s (768 substeps of 1/60 s), where the direct error measured 0.6e-9 to 2e-9 of the
// span depending on h, on the path to rest and on the solver's order of operations.
//
// The bias is XPBD's, not the physics': XPBD drops the term g = M (x - x~) - grad C^T lambda
// (Macklin et al. 2016, eq. 11). With Settings::realign_passes the solver restores it, and the
// chain settles onto the exact discrete catenary directly (the last tests below).
#include "discrete_catenary.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <cstdio>

#include <cmath>
#include <vector>

namespace embra {
namespace {

constexpr double kSpan = 1.0;
constexpr double kLength = 1.2;
constexpr double kMass = 0.1;
constexpr double kG = 9.81;
const Vec3 kLeft(-0.5, 0.0, 0.0);  // centred on the origin: the coordinates' rounding is smallest there

/// The exact discrete catenary of this chain (discrete_catenary.hpp; the file comment derives it).
using test::DiscreteCatenary;
DiscreteCatenary exact_discrete(int n) {
  return test::discrete_catenary(n, kSpan, kLength, kLeft);
}

/// The continuous catenary y = a cosh(x / a) through the pins: L = 2 a sinh(b / a), b = S / 2.
double catenary_parameter() {
  const double b = kSpan / 2;
  double lo = 0.01, hi = 100.0;  // 2 a sinh(b / a) falls from +inf to 2b = S < L as a grows
  for (int i = 0; i < 200; ++i) {
    const double a = 0.5 * (lo + hi);
    (2 * a * std::sinh(b / a) > kLength ? lo : hi) = a;
  }
  return 0.5 * (lo + hi);
}

double continuous_sag() {
  const double a = catenary_parameter();
  return a * (std::cosh(kSpan / 2 / a) - 1.0);
}

/// Depth of the lowest node below the pins (even N: the middle node).
double sag(const std::vector<Vec3>& nodes) {
  return kLeft.z() - nodes[nodes.size() / 2].z();
}

struct Settled {
  std::vector<Vec3> x;
  std::vector<double> tension;  // |lambda| / h^2 per link, newtons
  double residual = 0.0;
  double max_speed = 0.0;
};

/// Hangs the chain from the continuous catenary (sampled at equal arc length, an independent start
/// about 1e-3 off the discrete answer) and steps `frames` frames of 1/60 s with damping 20/s.
Settled settle(int n, int substeps, int iterations, int frames, int realign_passes = 0, int chebyshev_rho_milli = 0,
               int chain_solve = 1) {
  Settings settings = test::settings(substeps, iterations, Vec3(0, 0, -kG), 20.0);
  settings.realign_passes = realign_passes;
  settings.chebyshev_rho_milli = chebyshev_rho_milli;
  settings.chain_solve = chain_solve;
  World w(settings);
  const double a = catenary_parameter();
  std::vector<Vec3> start;
  for (int k = 0; k <= n; ++k) {
    const double s = -kLength / 2 + kLength * k / n;
    const double x = a * std::asinh(s / a);
    start.push_back(kLeft + Vec3(x + kSpan / 2, 0.0, a * (std::cosh(x / a) - std::cosh(kSpan / 2 / a))));
  }
  const int32_t first = test::add_particles(w, start, std::vector<double>(n + 1, kMass));
  test::hard_pin(w, first, kLeft);
  test::hard_pin(w, first + n, kLeft + Vec3(kSpan, 0, 0));
  std::vector<int32_t> ids;
  for (int k = 0; k < n; ++k) ids.insert(ids.end(), {first + k, first + k + 1});
  const std::vector<double> rest(n, kLength / n);
  ConstraintDesc d;
  d.kind = Kind::distance;
  d.particles = ids;
  d.rest = rest;
  w.add_constraints(d);
  for (int f = 0; f < frames; ++f) w.step();
  Settled out;
  out.x.assign(w.positions().begin() + first, w.positions().begin() + first + n + 1);
  const double h = w.settings().dt / substeps;
  for (double lambda : w.group(w.default_group()).arrays[static_cast<int>(Kind::distance)].lambda)
    out.tension.push_back(std::abs(lambda) / (h * h));
  out.residual = w.report().residual_max;
  out.max_speed = w.report().max_speed;
  return out;
}

double max_error(const std::vector<Vec3>& x, const std::vector<Vec3>& exact) {
  double e = 0.0;
  for (size_t k = 0; k < x.size(); ++k) e = std::max(e, (x[k] - exact[k]).norm());
  return e;
}

struct Extrapolated {
  double coarse_error, fine_error, extrapolated_error, horizontal_tension_error;
  std::vector<Vec3> nodes;
};

/// Settles at substeps s and 2s, compares both with the exact discrete catenary and extrapolates.
Extrapolated settle_and_extrapolate(int n, int substeps, int iterations, int frames) {
  const DiscreteCatenary exact = exact_discrete(n);
  const Settled coarse = settle(n, substeps, iterations, frames);
  const Settled fine = settle(n, 2 * substeps, iterations, frames);
  // The projection has converged (every link within 1e-10 of its rest length): what is left is
  // the fixed-point bias, not stretch.
  EXPECT_LT(coarse.residual, 1e-10);
  EXPECT_LT(fine.residual, 1e-10);
  Extrapolated out;
  for (size_t k = 0; k < fine.x.size(); ++k) out.nodes.push_back((4.0 * fine.x[k] - coarse.x[k]) / 3.0);
  out.coarse_error = max_error(coarse.x, exact.nodes);
  out.fine_error = max_error(fine.x, exact.nodes);
  out.extrapolated_error = max_error(out.nodes, exact.nodes);
  // Equal horizontal tension H = W / r in every link, read from the multipliers (force = lambda /
  // h^2) and extrapolated the same way.
  const double h_exact = kMass * kG / exact.w_over_h;
  out.horizontal_tension_error = 0.0;
  for (int k = 0; k < n; ++k) {
    const double hc = coarse.tension[k] * exact.cos_phi[k], hf = fine.tension[k] * exact.cos_phi[k];
    out.horizontal_tension_error =
        std::max(out.horizontal_tension_error, std::abs((4.0 * hf - hc) / 3.0 - h_exact) / h_exact);
  }
  return out;
}

void check_catenary(int n, int iterations) {
  // Substeps 16 and 32 of a 1/60 s frame: h = 1/960 s and 1/1920 s.
  const Extrapolated r = settle_and_extrapolate(n, 16, iterations, 120);
  // The fixed-point bias is O(h^2): halving h divides it by 4.
  const double ratio = r.coarse_error / r.fine_error;
  EXPECT_NEAR(ratio, 4.0, 0.01) << "N = " << n;
  EXPECT_LT(r.extrapolated_error, 1e-9 * kSpan) << "N = " << n;
  EXPECT_LT(r.horizontal_tension_error, 1e-8) << "N = " << n;
  ::testing::Test::RecordProperty("error_h960", test::sci(r.coarse_error));
  ::testing::Test::RecordProperty("error_h1920", test::sci(r.fine_error));
  ::testing::Test::RecordProperty("error_ratio", test::sci(ratio));
  ::testing::Test::RecordProperty("extrapolated_error", test::sci(r.extrapolated_error));
  ::testing::Test::RecordProperty("horizontal_tension_relative_error", test::sci(r.horizontal_tension_error));
}

TEST(Catenary, TenLinksSettleOntoTheExactDiscreteCatenary) {
  check_catenary(10, 400);
}

TEST(Catenary, TwentyLinksSettleOntoTheExactDiscreteCatenary) {
  // Gauss-Seidel along a chain converges at a rate 1 - O(1/N^2) per sweep: 20 links need about
  // three times the sweeps of 10 for the same residual.
  check_catenary(20, 1200);
}

// The discrete chain against the continuous catenary: the relative sag error (sag_N - sag) / sag
// falls as c / N^2, with c about 0.52 for S = 1, L = 1.2. N = 10 comes from the simulation
// (extrapolated as above), the larger N from the exact discrete formula. For even N the lowest node
// is the middle one.
TEST(Catenary, SagErrorAgainstTheContinuousCatenaryFallsAsOneOverNSquared) {
  const double sag_c = continuous_sag();
  std::vector<int> ns;
  std::vector<double> coefficient;
  const Extrapolated sim = settle_and_extrapolate(10, 16, 400, 120);
  ns.push_back(10);
  coefficient.push_back(100.0 * (sag(sim.nodes) - sag_c) / sag_c);
  for (int n = 20; n <= 640; n *= 2) {
    ns.push_back(n);
    coefficient.push_back(static_cast<double>(n) * n * (sag(exact_discrete(n).nodes) - sag_c) / sag_c);
  }
  for (size_t i = 0; i < ns.size(); ++i) {
    EXPECT_NEAR(coefficient[i], 0.52, 0.01) << "N = " << ns[i];
    RecordProperty("c_N" + std::to_string(ns[i]), test::sci(coefficient[i]));
  }
  // c_N = c + d / N^2 + ...: each doubling of N divides the change in c_N by about 4, i.e. the
  // error is c / N^2 with a next term of order 1/N^4, not some other power.
  for (size_t i = 2; i < ns.size(); ++i) {
    const double before = coefficient[i - 2] - coefficient[i - 1];
    const double after = coefficient[i - 1] - coefficient[i];
    EXPECT_NEAR(before / after, 4.0, 0.1) << "N = " << ns[i];
  }
  // The limit, by one more Richardson step on the last two.
  const double limit = (4.0 * coefficient.back() - coefficient[coefficient.size() - 2]) / 3.0;
  RecordProperty("c_limit", test::sci(limit));
}

// The acceptance figure as stated, directly: with realignment passes (Settings::realign_passes)
// every substep is the true implicit step, not XPBD's approximation of it, so the settled chain is
// the exact discrete catenary, at an ordinary substep (h = 1/480 s), to rounding.
void check_direct(int n, int iterations) {
  const DiscreteCatenary exact = exact_discrete(n);
  const Settled s = settle(n, 8, iterations, 150, 4);
  const double e = max_error(s.x, exact.nodes);
  EXPECT_LT(s.residual, 1e-10) << "N = " << n;
  EXPECT_LT(s.max_speed, 1e-9) << "N = " << n;
  EXPECT_LT(e, 1e-9 * kSpan) << "N = " << n;
  const double h_exact = kMass * kG / exact.w_over_h;
  double tension_error = 0.0;
  for (int k = 0; k < n; ++k)
    tension_error = std::max(tension_error, std::abs(s.tension[k] * exact.cos_phi[k] - h_exact) / h_exact);
  EXPECT_LT(tension_error, 1e-8) << "N = " << n;
  ::testing::Test::RecordProperty("direct_error", test::sci(e));
  ::testing::Test::RecordProperty("horizontal_tension_relative_error", test::sci(tension_error));
}

TEST(Catenary, TenLinksSettleDirectlyWithRealignment) {
  check_direct(10, 100);
}

TEST(Catenary, TwentyLinksSettleDirectlyWithRealignment) {
  check_direct(20, 300);
}

// Chebyshev acceleration (Settings::chebyshev_rho_milli): a long chain whose Gauss-Seidel passes do
// not converge within a substep's iterations (residual left in the links) comes much closer to
// inextensible and to the exact discrete catenary with the same iterations accelerated, and still
// comes to rest.
TEST(Catenary, ChebyshevAccelerationConvergesFurtherWithTheSameIterations) {
  const int n = 64;
  const DiscreteCatenary exact = exact_discrete(n);
  // Gauss-Seidel passes, one constraint at a time (Settings::chain_solve = 0): the chain solve
  // below satisfies a chain's links far better per pass, and Chebyshev's estimate is for Gauss-Seidel.
  const Settled plain = settle(n, 2, 40, 600, 0, 0, 0);
  const Settled fast = settle(n, 2, 40, 600, 0, 900, 0);
  const Settled longer = settle(n, 2, 80, 600, 0, 0, 0);
  const double plain_error = max_error(plain.x, exact.nodes), fast_error = max_error(fast.x, exact.nodes);
  const double longer_error = max_error(longer.x, exact.nodes);
  std::printf(
      "64 links, 2 substeps: distance from the exact discrete catenary %.3e (40 iterations), %.3e (40 with rho "
      "0.9), %.3e (80); link residual %.3e, %.3e, %.3e; max speed %.1e, %.1e, %.1e m/s\n",
      plain_error, fast_error, longer_error, plain.residual, fast.residual, longer.residual, plain.max_speed,
      fast.max_speed, longer.max_speed);
  EXPECT_LT(fast_error, 0.5 * plain_error);
  EXPECT_LT(fast.residual, 0.5 * plain.residual);
  EXPECT_LT(fast_error, longer_error);  // 40 accelerated iterations beat 80 plain ones
  EXPECT_LT(fast.max_speed, 1e-3);      // and it comes to rest
}

// Chain solve (Settings::chain_solve, the default): the 64 links, end to end and nearly straight
// from one link to the next, form one chain, projected in the first iteration of every substep as
// one linearised system, a Newton step for the whole chain. At embra's default schedule (20 substeps
// of one iteration) the chain comes to rest with its links long only by what one Newton step leaves
// of each substep's gravity sag g h^2 (quadratic: (g h^2)^2 / link, about 2.5e-9 m) and on the exact
// discrete catenary up to XPBD's O(h^2 g) offset, where one Gauss-Seidel sweep per substep leaves
// the links 1e5 times longer and the shape 2,000 times further off.
TEST(Catenary, ChainSolveSettlesOnTheCatenaryWhereASweepPerSubstepDoesNot) {
  const int n = 64;
  const DiscreteCatenary exact = exact_discrete(n);
  const Settled chain = settle(n, 20, 1, 600);
  const Settled swept = settle(n, 20, 1, 600, 0, 0, 0);
  const double chain_error = max_error(chain.x, exact.nodes), swept_error = max_error(swept.x, exact.nodes);
  const double h = 1.0 / 60 / 20;
  std::printf(
      "64 links, 20 substeps x 1 iteration: distance from the exact discrete catenary %.3e (chain solve), %.3e "
      "(Gauss-Seidel); link residual %.3e, %.3e; max speed %.1e, %.1e m/s; g h^2 = %.1e m\n",
      chain_error, swept_error, chain.residual, swept.residual, chain.max_speed, swept.max_speed, kG * h * h);
  RecordProperty("error_chain", test::sci(chain_error));
  RecordProperty("error_gauss_seidel", test::sci(swept_error));
  RecordProperty("residual_chain", test::sci(chain.residual));
  RecordProperty("residual_gauss_seidel", test::sci(swept.residual));
  const double sag = kG * h * h, link = kLength / n;
  EXPECT_LT(chain.residual, 4.0 * sag * sag / link);
  EXPECT_GT(swept.residual, 1e-5);
  EXPECT_LT(chain_error, 10.0 * kG * h * h);  // XPBD's offset without realignment, O(h^2 g)
  EXPECT_LT(chain_error, swept_error / 10.0);
  EXPECT_LT(chain.max_speed, 1e-6);
}

}  // namespace
}  // namespace embra
