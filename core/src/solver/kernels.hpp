// The projection kernels: tight loops over the raw xyz array for the bulk of every cloth and panel
// mesh (distance, tether, dihedral, quad planarity, plane offset), the automatic tethers' runs, the
// chain pass (Settings::chain_solve) and the value passes of the residual measurement. Each is
// compiled for every lane width this machine may run (lanes.hpp): all give the same bits.
#pragma once

#include "embra/core/world.hpp"

#include <vector>

namespace embra {

/// The coordinates of a position array as one array of doubles (x0 y0 z0 x1 ...); null when empty.
inline double* coords(std::vector<Vec3>& x) {
  return x.empty() ? nullptr : x.front().data();
}
inline const double* coords(const std::vector<Vec3>& x) {
  return x.empty() ? nullptr : x.front().data();
}

static_assert(sizeof(Vec3) == 3 * sizeof(double), "positions are packed xyz triples");

/// One instruction set's kernels. Each projection kernel takes one Gauss-Seidel pass of XPBD over a
/// solver array (alpha~ = compliance * inv_h2), writing positions x (xyz) of particles with inverse
/// mass w != 0.
struct Kernels {
  void (*distance)(SolverArray&, double, double*, const double*);
  void (*tether)(SolverArray&, double, double*, const double*);
  void (*dihedral)(SolverArray&, double, double*, const double*);
  void (*planarity)(SolverArray&, double, double*, const double*);
  void (*plane_offset)(SolverArray&, double, double*, const double*);
  void (*chain)(SolverArray&, double, double*, const double*, double*);
  void (*distance_values)(const SolverArray&, const double*, double*);
  void (*dihedral_values)(const SolverArray&, const double*, double*);
  void (*tether_runs)(const SolverArray&, double*, const double*);
  const char* name;
};

/// The kernels for this machine. Every set computes the same bits (lanes.hpp); EMBRA_KERNELS=scalar,
/// vec2 or avx2 forces one, to check exactly that.
const Kernels& kernels();

}  // namespace embra
