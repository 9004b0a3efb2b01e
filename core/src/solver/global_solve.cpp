// The global solve (Settings::global_solve).
//
// XPBD's substep is the implicit step: positions x and multipliers lambda with
//
//   F1 = M (x - x~) - sum_j grad C_j(x) lambda_j = 0,      F2_j = C_j(x) + alpha~_j lambda_j = 0
//
// (alpha~ = alpha / h^2). Gauss-Seidel projections approach it one constraint at a time, and a load
// carried across a large or stiff structure converges slowly: the static error grows with the
// square of its size and falls only linearly with the iterations (docs/decisions.md). Here the
// substep is first solved as one system, by Newton's method on these equations: each iteration
// solves the symmetric quasi-definite system
//
//   [ K   -J^T ] [dx]   [ -F1 ]
//   [ -J  -D   ] [dl] = [  F2 ],    K = M - sum lambda_j d2C_j,  D = alpha~ (at least 1e-10 of J W J^T)
//
// with one sparse LDL^T factorisation (Eigen's SimplicialLDLT, AMD ordering; a quasi-definite matrix
// factorises stably in any symmetric order, Vanderbei 1995), its symbolic analysis kept while the
// pattern stays the same. K holds the geometric stiffness of the lengths (distances, tethers) in
// tension, which is what makes a taut net or cable stiff across its length and what Newton steps
// without it missed (they diverged: docs/decisions.md); under compression it is dropped, and the
// other kinds contribute their first derivatives only, so K stays positive definite. Hard constraints
// (alpha = 0) are solved exactly: D's floor only regularises the factorisation, F2 keeps alpha~ = 0.
// A tether is one-sided: active while stretched or pulling (lambda < 0), otherwise its row asks for
// lambda = 0. A step is halved until it lowers the residual |W F1|^2 + |F2|^2 (lengths, radians).
//
// The multipliers stay in the solver arrays and the Gauss-Seidel iterations run on from there: they
// have the final word, so contacts, pressure volumes and fields act as they always do, and the
// groups' order and weight keep their meaning (who wins where constraints cannot all be met). One
// thread, in a fixed order: the same bits at any thread count.
#include "solver/global_solve.hpp"

#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace embra {

namespace {

/// Newton iterations per substep at most, and halvings of a step.
constexpr int kNewtonIterations = 24;
constexpr int kHalvings = 12;
/// The floor of D over a row's J W J^T: regularises hard rows without changing their solution.
constexpr double kRegularisation = 1e-10;

enum class Pass { count, setup, evaluate, clear, warm, keep };
/// A distance shorter than its rest by more than this fraction of it is slack in the global solve (a
/// cable gone loose, a net drawn in, a wrinkle): its row asks for lambda = 0 and the iterations push
/// it back. A compressed flat net or sheet is where the implicit step buckles, and Newton's steps from
/// there do not converge; slack, it falls and draws itself taut, and the solve is exact from then on.
constexpr double kSlack = 1e-3;
constexpr double kNoSlack = std::numeric_limits<double>::infinity();

using Mat3 = Eigen::Matrix3d;

/// Adds block B at (row block ua, column block ub) of the lower triangle (B^T at (ub, ua) when ua <
/// ub; on the diagonal the lower part of B + B^T when `pair`, of B alone otherwise).
void add_block(std::vector<Eigen::Triplet<double>>& out, int32_t ua, int32_t ub, const Mat3& b, bool pair) {
  if (ua == ub) {
    const Mat3 s = pair ? Mat3(b + b.transpose()) : b;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c <= r; ++c) out.emplace_back(3 * ua + r, 3 * ua + c, s(r, c));
    return;
  }
  const bool lower = ua > ub;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out.emplace_back(3 * (lower ? ua : ub) + r, 3 * (lower ? ub : ua) + c, lower ? b(r, c) : b(c, r));
}

}  // namespace

/// One sweep over the global solve's rows (every constraint and soft pin of the enabled groups, in
/// group order, kinds in table order, then welds (3 rows) and soft pins (3 rows)). The automatic
/// tethers are left to the iterations: they are there to carry a load Gauss-Seidel has not yet
/// carried across a cloth, which the global solve does itself, and one-sided rows that switch on and
/// off from one Newton step to the next keep it from converging (the 32 x 32 net never did).
/// Pass::count counts the rows only (GlobalSolve::rows), evaluating nothing. Pass::setup counts them
/// and stores each row's alpha~ and the floor of D. Pass::evaluate, at
/// positions x and multipliers lambda + t dl (dl: GlobalSolve::step's row part), adds -grad C lambda
/// into F1 (GlobalSolve::residual's particle part), writes F2 and, with `matrix`, emits K's
/// constraint blocks, -J and -D into GlobalSolve::triplets (every row emits the same entries whether
/// or not it is active, so the pattern never changes). Pass::evaluate with t and no matrix after an
/// accepted step also stores lambda + t dl when `store`. Pass::warm sets each row's multiplier from
/// GlobalSolve::warm, Pass::keep copies them there after a kept solve, Pass::clear sets them to 0.
void World::global_terms(const std::vector<Vec3>& x, double inv_h2, int pass_number, double t, bool matrix,
                         bool store) {
  GlobalSolve& gs = *global_;
  const Pass pass = static_cast<Pass>(pass_number);
  const int64_t rows0 = 3 * static_cast<int64_t>(gs.particle.size());
  if (pass == Pass::setup) gs.alpha.clear(), gs.floor.clear();
  if (pass == Pass::clear) store = true, t = 0.0;
  if (pass == Pass::keep) gs.warm.clear();
  int64_t r = 0;  // the row
  const auto dl = [&](int64_t row) { return t == 0.0 ? 0.0 : t * gs.step[rows0 + row]; };
  const auto f1 = [&](int32_t p) -> Eigen::Ref<Eigen::Vector3d> { return gs.residual.segment<3>(3 * gs.unknown[p]); };
  // A row of one function C (value c) with gradients `grad` over particles p[0..n); `lambda`: its
  // multiplier; geometric_over: 1 / |d| for a length (its geometric stiffness), else 0.
  const auto row = [&]<int N>(const int32_t* p, const std::array<Vec3, N>& grad, bool valid, double c,
                              double compliance, int side, double& lambda, double geometric_over, double slack) {
    if (pass == Pass::setup) {
      double eff = 0.0;
      for (int a = 0; a < N; ++a) eff += w_[p[a]] * grad[a].squaredNorm();
      const double alpha = compliance * inv_h2;
      gs.alpha.push_back(alpha);
      gs.floor.push_back(std::max(alpha, kRegularisation * eff));
      gs.eff.push_back(eff > 0.0 ? eff : 1.0);
      ++r;
      return;
    }
    if (pass == Pass::warm || pass == Pass::keep) {
      if (pass == Pass::warm)
        lambda = r < static_cast<int64_t>(gs.warm.size()) ? gs.warm[r] : 0.0;
      else
        gs.warm.push_back(lambda);
      ++r;
      return;
    }
    const double alpha = gs.alpha[r], eff = gs.eff[r];
    // A one-sided row (KindTraits::side) holds one side of its rest, its multiplier of one sign only
    // (side -1, value <= rest: lambda <= 0; side +1: lambda >= 0): the step's is clamped where it is
    // used, and the row is active while its side is violated or its multiplier acts.
    double l = pass == Pass::clear ? 0.0 : lambda + dl(r);
    if (side < 0) l = std::min(l, 0.0);
    if (side > 0) l = std::max(l, 0.0);
    const bool active = valid && (side == 0 || side * c < 0.0 || side * l > 0.0) && !(c < -slack);
    const int64_t at = rows0 + r;
    if (store) lambda = l;
    if (active) {
      gs.residual[at] = c + alpha * l;
      for (int a = 0; a < N; ++a)
        if (gs.unknown[p[a]] >= 0) f1(p[a]) -= l * grad[a];
    } else {
      gs.residual[at] = eff * l;  // lambda = 0, in length units
    }
    if (matrix) {
      for (int a = 0; a < N; ++a) {
        const int32_t ua = gs.unknown[p[a]];
        if (ua < 0) continue;
        for (int k = 0; k < 3; ++k) gs.triplets.emplace_back(at, 3 * ua + k, active ? -grad[a][k] : 0.0);
        // Geometric stiffness of a length in tension: -lambda / |d| (I - n n^T), + on the diagonal
        // blocks, - off them.
        if (geometric_over > 0.0) {
          const double s = active ? std::max(-l, 0.0) * geometric_over : 0.0;
          const Vec3 n = grad[0];
          const Mat3 geo = s * (Mat3::Identity() - n * n.transpose());
          for (int b = 0; b <= a; ++b) {
            const int32_t ub = gs.unknown[p[b]];
            if (ub >= 0) add_block(gs.triplets, ua, ub, a == b ? geo : Mat3(-geo), a != b);
          }
        }
      }
      gs.triplets.emplace_back(at, at, active ? -gs.floor[r] : -eff);
    }
    ++r;
  };
  const auto each_array = [&]<Kind K>(KindTag<K>, SolverArray& arr) {
    constexpr int N = arity(K);
    constexpr bool length = K == Kind::distance || K == Kind::tether;
    if (pass == Pass::count) {
      r += static_cast<int64_t>(arr.size());
      return;
    }
    for (size_t i = 0; i < arr.size(); ++i) {
      const int32_t* p = &arr.ids[i * N];
      auto e = KindTraits<K>::evaluate(p, x);
      const double c = KindTraits<K>::deviation(e.value, arr.rest[i]);
      row.template operator()<N>(p, e.grad, e.valid, c, arr.compliance[i], KindTraits<K>::side, arr.lambda[i],
                                 length && e.valid ? 1.0 / e.value : 0.0,
                                 K == Kind::distance ? kSlack * arr.rest[i] : kNoSlack);
    }
  };
  for (int32_t slot : order_) {
    Group& g = groups_[slot];
    for (const KindInfo& info : kKinds)
      visit_kind(info.kind, [&](auto kind) {
        if constexpr (kind != Kind::weld) each_array(kind, g.solve[static_cast<int>(info.kind)]);
      });
    // Welds: x0 - x1 = 0, a row per axis.
    SolverArray& weld = g.solve[static_cast<int>(Kind::weld)];
    if (pass == Pass::count) {
      r += 3 * static_cast<int64_t>(weld.size() + g.soft_pins.size());
      continue;
    }
    for (size_t i = 0; i < weld.size(); ++i) {
      const int32_t p[2] = {weld.ids[2 * i], weld.ids[2 * i + 1]};
      const Vec3 d = x[p[0]] - x[p[1]];
      for (int k = 0; k < 3; ++k) {
        const std::array<Vec3, 2> grad = {Vec3::Unit(k), -Vec3::Unit(k)};
        row.template operator()<2>(p, grad, true, d[k], weld.compliance[i], 0, weld.lambda[3 * i + k], 0.0, kNoSlack);
      }
    }
    // Soft pins and supports: held(x - target) = 0, a row per axis; held is the projection P (the
    // polyline's across its segment at the closest point, the mesh's along the face normal there,
    // either whole at a vertex or edge), its rows the gradients.
    for (int32_t pi : g.soft_pins) {
      Pin& pin = pins_[pi];
      const Vec3 d = x[pin.particle] - pin.target;
      const Vec3 held = pin.held(d);
      Mat3 proj = Mat3::Identity();
      switch (pin.support) {
        case PinSupport::plane:
          proj = pin.axis * pin.axis.transpose();
          break;
        case PinSupport::line:
          proj -= pin.axis * pin.axis.transpose();
          break;
        case PinSupport::polyline: {
          const CurvePoint cp = closest_point_on_polyline(pin.curve, pin.closed, d);
          if (cp.inside_segment) proj -= cp.tangent * cp.tangent.transpose();
          break;
        }
        case PinSupport::axes:
          proj = pin.axis.cwiseAbs().asDiagonal();  // the held coordinates' flags, 1 or 0
          break;
        case PinSupport::mesh: {
          const SurfacePoint cp = closest_point_on_mesh(pin.curve, pin.triangles, d);
          if (cp.inside_face) proj = cp.normal * cp.normal.transpose();
          break;
        }
        case PinSupport::point:
          break;
      }
      for (int k = 0; k < 3; ++k) {
        const std::array<Vec3, 1> grad = {Vec3(proj.row(k).transpose())};
        row.template operator()<1>(&pin.particle, grad, true, held[k], pin.compliance, 0, pin.lambda[k], 0.0, kNoSlack);
      }
    }
  }
  gs.rows = r;
}

void World::global_step(double h) {
  const bool automatic = settings_.global_solve == kGlobalSolveAuto;
  // Contacts are not rows of the solve: where they act it would pull into a collider what the contact
  // projections push out, substep after substep (the POQ drape at the preset never came to rest). So
  // the automatic mode leaves worlds with colliders or self-collision to the iterations; it decides
  // that, and the system's size from a count of its rows, before anything of the solve is evaluated.
  if (automatic && (settings_.self_collision != 0 ||
                    std::any_of(colliders_.begin(), colliders_.end(), [](const Collider& c) { return c.alive; })))
    return;
  if (!global_) global_ = std::make_unique<GlobalSolve>();
  GlobalSolve& gs = *global_;
  const size_t n = x_.size();
  gs.unknown.assign(n, -1);
  gs.particle.clear();
  for (size_t i = 0; i < n; ++i)
    if (w_[i] > 0.0) {
      gs.unknown[i] = static_cast<int32_t>(gs.particle.size());
      gs.particle.push_back(static_cast<int32_t>(i));
    }
  const int64_t blocks = static_cast<int64_t>(gs.particle.size());
  if (blocks == 0) return;
  const double inv_h2 = 1.0 / (h * h);
  global_terms(x_, inv_h2, static_cast<int>(Pass::count), 0.0, false, false);
  const int64_t counted = gs.rows;
  if (automatic && 3 * blocks + counted > kGlobalSolveAutoLimit) return;
  gs.inertial = x_;  // x~: where the particles go with no constraint
  gs.eff.clear();
  global_terms(x_, inv_h2, static_cast<int>(Pass::setup), 0.0, false, false);
  if (gs.rows != counted) throw Error(ErrorCode::internal, "the global solve's row count disagrees with its rows");
  // Newton starts from the last kept solve's multipliers (0 for rows it did not have): the lengths in
  // tension then give their geometric stiffness from the first step.
  if (static_cast<int64_t>(gs.warm.size()) != gs.rows) gs.warm.assign(static_cast<size_t>(gs.rows), 0.0);
  global_terms(x_, inv_h2, static_cast<int>(Pass::warm), 0.0, false, false);
  const int64_t size = 3 * blocks + gs.rows;
  gs.step.setZero(size);
  // F at x and lambda + t dl into gs.residual; returns |W F1|^2 + |F2|^2.
  const auto evaluate = [&](const std::vector<Vec3>& x, double t, bool matrix) {
    gs.residual.setZero(size);
    for (int64_t u = 0; u < blocks; ++u) {
      const int32_t p = gs.particle[u];
      gs.residual.segment<3>(3 * u) = (x[p] - gs.inertial[p]) / w_[p];
    }
    global_terms(x, inv_h2, static_cast<int>(Pass::evaluate), t, matrix, false);
    double merit = 0.0;
    for (int64_t u = 0; u < blocks; ++u) merit += (w_[gs.particle[u]] * gs.residual.segment<3>(3 * u)).squaredNorm();
    return merit + gs.residual.tail(gs.rows).squaredNorm();
  };
  gs.trial = x_;
  double scale = 1.0;  // the largest coordinate of a movable particle, at least 1 (model units)
  for (int32_t p : gs.particle) scale = std::max(scale, x_[p].cwiseAbs().maxCoeff());
  double start = -1.0, merit = 0.0;
  for (int it = 0; it < kNewtonIterations; ++it) {
    gs.triplets.clear();
    for (int64_t u = 0; u < blocks; ++u)
      add_block(gs.triplets, static_cast<int32_t>(u), static_cast<int32_t>(u), Mat3::Identity() / w_[gs.particle[u]],
                false);
    merit = evaluate(x_, 0.0, true);
    if (start < 0.0) start = merit;
    if (!(merit > 0.0)) break;
    gs.matrix.resize(size, size);
    gs.matrix.setFromTriplets(gs.triplets.begin(), gs.triplets.end());
    const auto& A = gs.matrix;
    const bool same = gs.pattern_outer.size() == static_cast<size_t>(A.outerSize() + 1) &&
                      std::equal(gs.pattern_outer.begin(), gs.pattern_outer.end(), A.outerIndexPtr()) &&
                      gs.pattern_inner.size() == static_cast<size_t>(A.nonZeros()) &&
                      std::equal(gs.pattern_inner.begin(), gs.pattern_inner.end(), A.innerIndexPtr());
    if (!same) {
      gs.ldlt.analyzePattern(A);
      gs.pattern_outer.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
      gs.pattern_inner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    }
    gs.ldlt.factorize(A);
    ++gs.factorisations;
    if (gs.ldlt.info() != Eigen::Success) break;
    gs.rhs = gs.residual;
    gs.rhs.head(3 * blocks) = -gs.rhs.head(3 * blocks);
    gs.step = gs.ldlt.solve(gs.rhs);
    if (!gs.step.allFinite()) break;
    double t = 1.0, tried = merit;
    for (int k = 0; k < kHalvings; ++k, t *= 0.5) {
      for (int64_t u = 0; u < blocks; ++u) {
        const int32_t p = gs.particle[u];
        gs.trial[p] = x_[p] + t * gs.step.segment<3>(3 * u);
      }
      tried = evaluate(gs.trial, t, false);
      if (tried < merit) break;
    }
    if (!(tried < merit)) break;
    merit = tried;
    const double moved = t * gs.step.head(3 * blocks).cwiseAbs().maxCoeff();
    for (int32_t p : gs.particle) x_[p] = gs.trial[p];
    global_terms(x_, inv_h2, static_cast<int>(Pass::evaluate), t, false, true);  // lambda += t dl
    if (moved <= 1e-12 * scale) break;                                           // converged far below any tolerance
  }
  // A residual that is not a number (a factorisation gone wrong) undoes the solve: the substep's
  // iterations then start from x~ and lambda = 0, as without it.
  if (!(merit <= start)) {
    for (int32_t p : gs.particle) x_[p] = gs.inertial[p];
    global_terms(x_, inv_h2, static_cast<int>(Pass::clear), 0.0, false, true);
    gs.warm.assign(gs.warm.size(), 0.0);
    ++gs.undone;
  } else {
    global_terms(x_, inv_h2, static_cast<int>(Pass::keep), 0.0, false, false);
  }
}

}  // namespace embra
