// The impulse each hard pin takes from the constraints in the last substep of a frame, tracked as
// the projections give it (World::reactions reads it; solver/statics.cpp says why).
//
// A projection of constraint C changes its multiplier by dlambda and moves each movable particle k
// by w_k grad_k C dlambda, the gradient taken where the projection starts: it hands particle k the
// impulse (times h) grad_k C dlambda. A hard-pinned particle (w = 0) does not move, but it takes
// its share all the same. PinTrack adds that share to the pin (Pin::lambda) around each run of a
// pass: the gradients before the run, the multipliers' change after it. Within one colour no two
// constraints share a movable particle, so the gradients before the run are those the projections
// start from; a shared tail is run one tracked constraint at a time (passes::each_colour_tracked).
#pragma once

#include "embra/core/shape_match.hpp"
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace embra {

template <Kind K>
class PinTrack {
 public:
  PinTrack(const SolverArray& a, const std::vector<Vec3>& x, std::vector<Pin>& pins) : a_(a), x_(x), pins_(pins) {}

  /// The first constraint at or after i that holds a hard-pinned particle (SIZE_MAX: none).
  size_t next(size_t i) const {
    const size_t j = first_entry(i);
    return j < entries() ? static_cast<size_t>(a_.pinned[3 * j]) : std::numeric_limits<size_t>::max();
  }

  /// Before the constraints [begin, end) are projected: their gradients at the pinned slots and
  /// their multipliers.
  void before(size_t begin, size_t end) {
    lo_ = first_entry(begin);
    hi_ = first_entry(end);
    grad_.resize(hi_ - lo_);
    lambda_.resize((hi_ - lo_) * kPer);
    for (size_t j = lo_; j < hi_; ++j) {
      const size_t i = static_cast<size_t>(a_.pinned[3 * j]);
      const int slot = a_.pinned[3 * j + 1];
      for (int c = 0; c < kPer; ++c) lambda_[(j - lo_) * kPer + c] = a_.lambda[kPer * i + c];
      if constexpr (K == Kind::weld) {
        grad_[j - lo_] = Vec3::Constant(slot == 0 ? 1.0 : -1.0);  // C = x0 - x1, per coordinate
      } else {
        const auto e = KindTraits<K>::evaluate(&a_.ids[i * kArity], x_);
        grad_[j - lo_] = e.valid ? Vec3(e.grad[slot]) : Vec3(Vec3::Zero());
      }
    }
  }

  /// After they were projected: each pin takes grad C dlambda.
  void after(size_t, size_t) {
    for (size_t j = lo_; j < hi_; ++j) {
      const size_t i = static_cast<size_t>(a_.pinned[3 * j]);
      Vec3& impulse = pins_[static_cast<size_t>(a_.pinned[3 * j + 2])].lambda;
      if constexpr (K == Kind::weld) {
        for (int c = 0; c < 3; ++c)
          impulse[c] += grad_[j - lo_][c] * (a_.lambda[3 * i + c] - lambda_[(j - lo_) * 3 + c]);
      } else {
        impulse += grad_[j - lo_] * (a_.lambda[i] - lambda_[j - lo_]);
      }
    }
  }

  /// Adds grad C lambda at x of every tracked constraint to its pins: what a realignment, which
  /// puts every particle where the multipliers' pulls at x take it, hands them.
  void add_all() const {
    for (size_t j = 0; j < entries(); ++j) {
      const size_t i = static_cast<size_t>(a_.pinned[3 * j]);
      const int slot = a_.pinned[3 * j + 1];
      Vec3& impulse = pins_[static_cast<size_t>(a_.pinned[3 * j + 2])].lambda;
      if constexpr (K == Kind::weld) {
        const Vec3 l(a_.lambda[3 * i], a_.lambda[3 * i + 1], a_.lambda[3 * i + 2]);
        impulse += slot == 0 ? l : Vec3(-l);
      } else {
        if (a_.lambda[i] == 0.0) continue;
        const auto e = KindTraits<K>::evaluate(&a_.ids[i * kArity], x_);
        if (e.valid) impulse += a_.lambda[i] * e.grad[slot];
      }
    }
  }

 private:
  static constexpr int kPer = multipliers(K);
  static constexpr size_t kArity = static_cast<size_t>(arity(K));
  size_t entries() const { return a_.pinned.size() / 3; }
  /// The first entry whose constraint is at or after i.
  size_t first_entry(size_t i) const {
    size_t lo = 0, hi = entries();
    while (lo < hi) {
      const size_t mid = (lo + hi) / 2;
      if (static_cast<size_t>(a_.pinned[3 * mid]) < i)
        lo = mid + 1;
      else
        hi = mid;
    }
    return lo;
  }

  const SolverArray& a_;
  const std::vector<Vec3>& x_;
  std::vector<Pin>& pins_;
  size_t lo_ = 0, hi_ = 0;
  std::vector<Vec3> grad_;
  std::vector<double> lambda_;
};

/// The chain pass's share (Settings::chain_solve), chain by chain. A chain step (one linear solve)
/// moves every particle along the gradients where the chain starts, but a chain swept one link at a
/// time projects the link before a pinned particle after the link before it moved its other end, so
/// the gradients at the start do not give that link's share. A hard-pinned particle (w = 0) cuts a
/// chain into parts that move independently; within a part each projection is momentum-neutral, so
/// the link after a part's first particle hands it grad C dlambda with the gradient at the start
/// (no link before it in the part has moved its other end, whichever way the chain was solved), and
/// the link before its last particle hands that one minus what the rest took: minus the part's
/// free particles' momentum change, less the first particle's share.
class ChainTrack {
 public:
  /// `a`: the distance array with its pinned entries (find_pinned_slots); w: the solver's inverse
  /// masses (0: hard-pinned or immovable); hard_pin_of: each particle's hard pin, or -1.
  ChainTrack(const SolverArray& a, const std::vector<Vec3>& x, const std::vector<double>& w,
             const std::vector<int32_t>& hard_pin_of, std::vector<Pin>& pins)
      : a_(a), x_(x), w_(w), hard_pin_of_(hard_pin_of), pins_(pins) {
    std::vector<uint8_t> held(a.size(), 0);
    for (size_t j = 0; j < a.pinned.size() / 3; ++j) held[static_cast<size_t>(a.pinned[3 * j])] = 1;
    for (size_t c = 0; c + 1 < a.chain_start.size(); ++c)
      for (int32_t k = a.chain_start[c]; k < a.chain_start[c + 1]; ++k)
        if (held[static_cast<size_t>(a.chain_edge[static_cast<size_t>(k)])]) {
          chains_.push_back(c);
          break;
        }
  }

  /// The first chain at or after c with a hard-pinned particle (SIZE_MAX: none).
  size_t next(size_t c) const {
    const auto it = std::lower_bound(chains_.begin(), chains_.end(), c);
    return it == chains_.end() ? std::numeric_limits<size_t>::max() : *it;
  }

  /// Before the chains [begin, end) are solved: their particles, and the gradient and multiplier of
  /// the link after each particle that cuts them.
  void before(size_t begin, size_t end) {
    lo_ = static_cast<size_t>(std::lower_bound(chains_.begin(), chains_.end(), begin) - chains_.begin());
    hi_ = static_cast<size_t>(std::lower_bound(chains_.begin(), chains_.end(), end) - chains_.begin());
    start_.clear();
    grad_.clear();
    lambda_.clear();
    for (size_t n = lo_; n < hi_; ++n) {
      const size_t c = chains_[n];
      const int32_t first = a_.chain_start[c], m = a_.chain_start[c + 1] - first;
      const int32_t* E = &a_.chain_edge[static_cast<size_t>(first)];
      const int32_t* P = &a_.chain_part[static_cast<size_t>(first) + c];
      for (int32_t j = 0; j <= m; ++j) {
        start_.push_back(x_[P[j]]);
        const bool cut = w_[P[j]] == 0.0 && j < m;
        grad_.push_back(cut ? gradient(E[j], P[j]) : Vec3(Vec3::Zero()));
        lambda_.push_back(cut ? a_.lambda[E[j]] : 0.0);
      }
    }
  }

  /// After they were solved: each pinned particle's share from the link after it and the link
  /// before it.
  void after(size_t, size_t) {
    size_t at = 0;  // index into start_, grad_, lambda_
    for (size_t n = lo_; n < hi_; ++n) {
      const size_t c = chains_[n];
      const int32_t first = a_.chain_start[c], m = a_.chain_start[c + 1] - first;
      const int32_t* E = &a_.chain_edge[static_cast<size_t>(first)];
      const int32_t* P = &a_.chain_part[static_cast<size_t>(first) + c];
      Vec3 part = Vec3::Zero();  // what the part so far took: its free particles' momentum change, and its first
                                 // particle's share
      for (int32_t j = 0; j <= m; ++j, ++at) {
        const int32_t q = P[j];
        if (w_[q] != 0.0) {
          part += (x_[q] - start_[at]) / w_[q];
          continue;
        }
        const int32_t pin = hard_pin_of_[q];
        if (j > 0 && pin >= 0) pins_[static_cast<size_t>(pin)].lambda -= part;  // the link before it
        part = Vec3::Zero();
        if (j < m) {
          const Vec3 share = grad_[at] * (a_.lambda[E[j]] - lambda_[at]);  // the link after it
          if (pin >= 0) pins_[static_cast<size_t>(pin)].lambda += share;
          part = share;
        }
      }
    }
  }

 private:
  /// grad C of distance constraint e at its particle q, where the particles stand.
  Vec3 gradient(int32_t e, int32_t q) const {
    const auto g = KindTraits<Kind::distance>::evaluate(&a_.ids[2 * static_cast<size_t>(e)], x_);
    if (!g.valid) return Vec3::Zero();
    return a_.ids[2 * static_cast<size_t>(e)] == q ? Vec3(g.grad[0]) : Vec3(g.grad[1]);
  }
  const SolverArray& a_;
  const std::vector<Vec3>& x_;
  const std::vector<double>& w_;
  const std::vector<int32_t>& hard_pin_of_;  // World::hard_pin_of_: pin slot or -1 per particle
  std::vector<Pin>& pins_;
  std::vector<size_t> chains_;  // the chains holding a hard-pinned particle, ascending
  size_t lo_ = 0, hi_ = 0;
  std::vector<Vec3> start_, grad_;
  std::vector<double> lambda_;
};

/// A shape match's share (shape_match.hpp). Its projection moves the free points by w_i dlambda_i
/// and leaves its hard-pinned points where they are; its forces, counted over every point, are
/// momentum-neutral (the goals share the points' weighted centroid and turn about it), so the pinned
/// points take back what the free points took: minus its sum, and minus its moment about the set's
/// centroid, split between them: the sum evenly, corrected by the least-norm forces that sum to zero
/// and balance the moment (all of the sum for one pinned point; between two, nothing along the
/// line through them).
/// `before`: the multipliers before the projection.
inline void pin_shape_match(const ShapeMatch& s, const std::vector<Vec3>& before, const std::vector<Vec3>& x,
                            const std::vector<int32_t>& hard_pin_of, std::vector<Pin>& pins) {
  std::vector<size_t> held;
  Vec3 sum = Vec3::Zero(), centre = Vec3::Zero();
  for (size_t i = 0; i < s.particles.size(); ++i) {
    centre += x[s.particles[i]];
    if (hard_pin_of[s.particles[i]] >= 0)
      held.push_back(i);
    else
      sum += s.lambda[i] - before[i];
  }
  if (held.empty()) return;
  if (held.size() == 1) {
    pins[static_cast<size_t>(hard_pin_of[s.particles[held[0]]])].lambda -= sum;
    return;
  }
  centre /= static_cast<double>(s.particles.size());
  Vec3 moment = Vec3::Zero();
  for (size_t i = 0; i < s.particles.size(); ++i)
    if (hard_pin_of[s.particles[i]] < 0) moment += (x[s.particles[i]] - centre).cross(s.lambda[i] - before[i]);
  // Forces f_p = -sum / k + g_p with sum_p g_p = 0 (the sum balanced exactly), g = P z (P: the
  // projection onto sum-free sets), z the least-norm least-squares solution of the moment balance
  // sum_p r_p x f_p = -moment.
  const Eigen::Index k = static_cast<Eigen::Index>(held.size());
  const Vec3 share = -sum / static_cast<double>(k);
  Eigen::MatrixXd cross(3, 3 * k), project = Eigen::MatrixXd::Identity(3 * k, 3 * k);
  Vec3 rest = -moment;  // what the g_p must turn
  for (Eigen::Index j = 0; j < k; ++j) {
    const Vec3 r = x[s.particles[held[static_cast<size_t>(j)]]] - centre;
    cross.block<3, 3>(0, 3 * j) << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;  // r x
    rest -= r.cross(share);
    for (Eigen::Index i = 0; i < k; ++i)
      project.block<3, 3>(3 * i, 3 * j) -= Eigen::Matrix3d::Identity() / static_cast<double>(k);
  }
  const Eigen::VectorXd z = (cross * project).completeOrthogonalDecomposition().solve(Eigen::Vector3d(rest));
  const Eigen::VectorXd g = project * z;
  for (Eigen::Index j = 0; j < k; ++j)
    pins[static_cast<size_t>(hard_pin_of[s.particles[held[static_cast<size_t>(j)]]])].lambda +=
        share + Vec3(g.segment<3>(3 * j));
}

}  // namespace embra
