// Shape matching (Mueller et al. 2005; ShapeOp's Rigid goal, Kangaroo2's RigidPointSet, Vellum's
// Shape Match): a point set pulled toward the best-fit rigid placement of its rest shape.
//
// The fit: with weights m_i (the particles' masses), the current points x_i and the rest points r_i,
// the weighted centroids c = sum m_i x_i / M and r_c = sum m_i r_i / M, and the covariance
// A = sum m_i (x_i - c)(r_i - r_c)^T, the rotation R is the proper rotation (det +1) nearest to A,
// its polar factor: with A = U S V^T (singular values in decreasing order), R = U D V^T where
// D = diag(1, 1, det(U V^T)). R and c minimise sum m_i |x_i - g_i|^2 over every rigid placement,
// whose goals are g_i = c + R (r_i - r_c).
//
// The energy, for a compliance alpha (m/N) and the mean weight m_bar = M / n:
//   E(x) = 1 / (2 alpha) sum_i (m_i / m_bar) |x_i - g_i(x)|^2,
// whose gradient is dE/dx_k = (m_k / (m_bar alpha)) (x_k - g_k): the fit's own minimisation makes
// the goals' dependence on x drop out (the envelope theorem). Each point is pulled toward its goal as
// by a soft pin of compliance alpha m_bar / m_k (m/N; alpha itself for equal masses).
#pragma once

#include "embra/core/constraint_math.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace embra {

/// A point set kept near the best-fit rigid placement of its rest shape (World::add_shape_match).
struct ShapeMatch {
  std::vector<int32_t> particles;  // world particle indices, distinct, at least 3
  std::vector<Vec3> rest;          // the rest shape (m), one point per particle, not all on one line
  double compliance = 0.0;         // alpha, m/N (0 = hard)
  std::vector<Vec3> lambda;        // state: the accumulated multiplier of each point (kg m)
};

/// The best-fit rigid placement of a rest shape onto current points.
struct RigidFit {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // R, a proper rotation
  Vec3 centre = Vec3::Zero();                              // c, the weighted centroid of the points
  Vec3 rest_centre = Vec3::Zero();                         // r_c, the weighted centroid of the rest shape
  double weight = 0.0;                                     // M, the sum of the weights
  /// The goal of the rest point r: c + R (r - r_c).
  Vec3 goal(const Vec3& r) const { return centre + rotation * (r - rest_centre); }
};

/// The proper rotation nearest to a (its polar factor, turned to det +1 by flipping the direction of
/// its smallest singular value, as Kabsch does): deterministic (a 3x3 Jacobi SVD).
inline Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& a) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0.0) u.col(2) = -u.col(2);
  return u * v.transpose();
}

/// The fit of the rest points `rest` onto the points x[particles[i]], weights `weights` (> 0, one per
/// point), summed in point order.
inline RigidFit fit_rigid(std::span<const int32_t> particles, std::span<const Vec3> rest,
                          std::span<const double> weights, const std::vector<Vec3>& x) {
  RigidFit f;
  for (size_t i = 0; i < particles.size(); ++i) {
    f.weight += weights[i];
    f.centre += weights[i] * x[particles[i]];
    f.rest_centre += weights[i] * rest[i];
  }
  f.centre /= f.weight;
  f.rest_centre /= f.weight;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < particles.size(); ++i)
    a += weights[i] * (x[particles[i]] - f.centre) * (rest[i] - f.rest_centre).transpose();
  f.rotation = nearest_rotation(a);
  return f;
}

/// The weight each point of `s` takes in the fit: its particle's mass 1 / inv_mass; an immovable
/// particle (inverse mass 0) takes the largest mass of the set's others (1 kg when every one is
/// immovable), so that it counts as a heavy point without swamping the fit.
inline void shape_match_weights(const ShapeMatch& s, const std::vector<double>& inv_mass, std::vector<double>& out) {
  double heaviest = 0.0;
  for (int32_t p : s.particles)
    if (inv_mass[p] > 0.0) heaviest = std::max(heaviest, 1.0 / inv_mass[p]);
  if (heaviest == 0.0) heaviest = 1.0;
  out.resize(s.particles.size());
  for (size_t i = 0; i < s.particles.size(); ++i)
    out[i] = inv_mass[s.particles[i]] > 0.0 ? 1.0 / inv_mass[s.particles[i]] : heaviest;
}

/// E(x) of the header comment (J), the fit made at x.
inline double shape_match_energy(const ShapeMatch& s, const std::vector<double>& inv_mass, const std::vector<Vec3>& x) {
  std::vector<double> m;
  shape_match_weights(s, inv_mass, m);
  const RigidFit f = fit_rigid(s.particles, s.rest, m, x);
  const double m_bar = f.weight / static_cast<double>(s.particles.size());
  double e = 0.0;
  for (size_t i = 0; i < s.particles.size(); ++i)
    e += (m[i] / m_bar) * (x[s.particles[i]] - f.goal(s.rest[i])).squaredNorm();
  return e / (2.0 * s.compliance);
}

/// One XPBD projection of the set: the fit made once at the current points, then each point whose
/// solver inverse mass w is nonzero moved toward its goal g_i (held fixed) by the constraint
/// C_i = x_i - g_i of compliance alpha m_bar / m_i: dlambda = (-C_i - a_i lambda_i) / (w_i + a_i),
/// a_i = alpha m_bar w_i / h^2, x_i += w_i dlambda. Points are taken in order; `weights` is scratch.
inline void project_shape_match(ShapeMatch& s, double inv_h2, const std::vector<double>& inv_mass,
                                const std::vector<double>& w, std::vector<Vec3>& x, std::vector<double>& weights) {
  shape_match_weights(s, inv_mass, weights);
  const RigidFit f = fit_rigid(s.particles, s.rest, weights, x);
  const double m_bar = f.weight / static_cast<double>(s.particles.size());
  for (size_t i = 0; i < s.particles.size(); ++i) {
    const int32_t p = s.particles[i];
    if (w[p] == 0.0) continue;
    const double a = s.compliance * m_bar * w[p] * inv_h2;
    const Vec3 dl = (f.goal(s.rest[i]) - x[p] - a * s.lambda[i]) / (w[p] + a);
    s.lambda[i] += dl;
    x[p] += w[p] * dl;
  }
}

}  // namespace embra
