// The global solve (Settings::global_solve): each substep's implicit XPBD problem over every
// constraint of the enabled groups, solved together by Newton's method on its energy before the
// Gauss-Seidel iterations (global_solve.cpp says how).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cstdint>
#include <vector>

namespace embra {

/// What the global solve keeps between substeps: the unknowns, the matrix's pattern and its
/// symbolic factorisation (reused while the pattern stays the same), and scratch.
struct GlobalSolve {
  std::vector<int32_t> unknown;   // per particle: its block of unknowns, or -1 (immovable)
  std::vector<int32_t> particle;  // per block: its particle
  int64_t rows = 0;               // constraint rows (a weld and a soft pin have 3)
  std::vector<double> alpha;      // per row: alpha~ = compliance / h^2
  std::vector<double> floor;      // per row: D, alpha~ or at least 1e-10 of J W J^T
  std::vector<double> eff;        // per row: J W J^T (1 where it is 0)
  std::vector<double> warm;       // per row: the multiplier the last kept solve ended with
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::SparseMatrix<double> matrix;  // the lower triangle of [K -J^T; -J -D]
  std::vector<int64_t> pattern_outer;  // the pattern the symbolic factorisation was made for
  std::vector<int32_t> pattern_inner;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
  Eigen::VectorXd residual, rhs, step;    // [F1 per block; F2 per row], [-F1; F2], [dx; dl]
  std::vector<Eigen::Vector3d> inertial;  // per particle: x~, where it goes with no constraint
  std::vector<Eigen::Vector3d> trial;     // per particle: a step's trial position
  int64_t factorisations = 0;             // numeric factorisations so far
  int64_t undone = 0;                     // substeps whose global solve was undone
};

}  // namespace embra
