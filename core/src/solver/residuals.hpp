// Residuals of the constraints at the end of a step, shared by the step report (World::measure) and
// the diagnostics (solver/diagnose.cpp).
#pragma once

#include "common/pool.hpp"
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"
#include "solver/kernels.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace embra {

/// XPBD residual |C + alpha~ lambda| of every constraint of `a` (for a one-sided kind, KindTraits::side,
/// only while it acts or is violated): the largest into `max`, the sum of squares added to `sum_sq`,
/// and each into `*each` and its |C| (how far from its rest: for a one-sided kind, how far on the
/// wrong side, e.g. how far a tether is overstretched) into `*violation`
/// (solver-array order) when given. Distances and dihedral angles are evaluated by the
/// kernels' value passes into `values`.
template <Kind K>
void residuals(ThreadPool& pool, const SolverArray& a, double inv_h2, const std::vector<Vec3>& x, double& max,
               double& sum_sq, std::vector<double>& values, std::vector<double>* each = nullptr,
               std::vector<double>* violation = nullptr) {
  constexpr int N = arity(K);
  constexpr bool kLanes = K == Kind::distance || K == Kind::tether || K == Kind::dihedral;
  if constexpr (kLanes) {
    values.resize(a.size());
    const Kernels& k = kernels();
    values_pass(pool, K == Kind::dihedral ? k.dihedral_values : k.distance_values, a, coords(x), values.data());
  }
  if (each != nullptr) each->resize(a.size());
  if (violation != nullptr) violation->resize(a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    double value;
    if constexpr (kLanes)
      value = values[i];
    else
      value = KindTraits<K>::evaluate(&a.ids[i * N], x).value;
    const double c = KindTraits<K>::deviation(value, a.rest[i]);
    double r = c + a.compliance[i] * inv_h2 * a.lambda[i];
    constexpr int side = KindTraits<K>::side;  // one-sided: no residual while it holds with no multiplier
    if constexpr (side != 0)
      if (a.lambda[i] == 0.0) r = std::max(-side * c, 0.0);
    r = std::abs(r);
    max = std::max(max, r);
    sum_sq += r * r;
    if (each != nullptr) (*each)[i] = r;
    if (violation != nullptr) (*violation)[i] = side != 0 ? std::max(-side * c, 0.0) : std::abs(c);
  }
}

}  // namespace embra
