// The projection kernels (kernels.hpp), for every lane width: scalar, vec2 and avx2.
#include "solver/kernels.hpp"
#include "solver/pin_track.hpp"

#include "common/lanes.hpp"
#include "embra/core/constraint_math.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

namespace embra {

namespace {

// --- projection kernels ------------------------------------------------------------------------
//
// One Gauss-Seidel pass of XPBD over a solver array: for each constraint C with compliance alpha,
//   dlambda = (-C - alpha~ lambda) / (sum_k w_k |grad_k C|^2 + alpha~),   alpha~ = alpha / h^2,
//   x_k += w_k dlambda grad_k C.
// Distance, tether, dihedral, quad planarity and plane offset have tight hand-written loops over the
// raw xyz array (the bulk of every cloth and panel mesh); the rarer kinds go through
// constraint_math.hpp. Constraints are stored colour by
// colour, so consecutive constraints rarely share a particle and their arithmetic overlaps.

/// Whether every lane lies in (-pi, pi] already.
template <class T>
EMBRA_ALWAYS_INLINE bool all_within_pi(T v) {
  for (int l = 0; l < lanes::Lanes<T>::count; ++l) {
    const double a = lanes::Lanes<T>::get(v, l);
    if (!(a > -std::numbers::pi && a <= std::numbers::pi)) return false;
  }
  return true;
}

// Each kernel handles one block of Lanes<T>::count constraints of one colour (they share no
// particle), reading every operand first and writing every result last.

/// One distance row's projection from its operands: d = x0 - x1, the moves x0 += s0 d and
/// x1 -= s1 d, the new multiplier; returns the lanes where it applies. Shared by the passes and the
/// islands, so both compute the same bits.
template <class T, bool kTether>
EMBRA_ALWAYS_INLINE auto distance_step(const lanes::V3<T>& p0, const lanes::V3<T>& p1, T w0, T w1, T r, T lam, T alpha,
                                       lanes::V3<T>& d, T& s0, T& s1, T& lam_new) {
  using namespace lanes;
  d = p0 - p1;
  const T len = lanes::sqrt(dot(d, d));
  const T c = len - r;
  const T denom = w0 + w1 + alpha;
  auto ok = (len > tiny<T>()) & (denom > 0.0);
  const T num = -c - alpha * lam;
  T dl = num / denom;
  T s;  // dl / len: grad C = +-(x0 - x1) / len
  if constexpr (kTether) {
    ok = ok & ((c > 0.0) | (lam != 0.0));  // a slack tether with no pull left does nothing
    const T sum = lam + dl;
    dl = select(0.0 < sum, splat<T>(0.0), sum) - lam;  // std::min(lambda + dl, 0) - lambda: pull only
    s = dl / len;
  } else {
    s = num / (denom * len);  // beside dl's division, not after it: the row's chain one division shorter
  }
  s0 = w0 * s;
  s1 = w1 * s;
  lam_new = lam + dl;
  return ok;
}

/// Distance |x0 - x1| = rest; a tether is the unilateral |x0 - x1| <= rest (it only pulls).
template <class T, bool kTether>
EMBRA_ALWAYS_INLINE void distance_block(const int32_t* ids, const double* rest, const double* compliance,
                                        double* lambda, double inv_h2, double* x, const double* w) {
  using namespace lanes;
  using L = Lanes<T>;
  const V3<T> p0 = load_point<T>(x, ids, 2), p1 = load_point<T>(x, ids + 1, 2);
  const T w0 = load_value<T>(w, ids, 2), w1 = load_value<T>(w, ids + 1, 2);
  const T r = gather<T>(rest), lam = gather<T>(lambda);
  const T alpha = gather<T>(compliance) * inv_h2;
  V3<T> d;
  T s0, s1, lam_new;
  const auto ok = distance_step<T, kTether>(p0, p1, w0, w1, r, lam, alpha, d, s0, s1, lam_new);
  for (int l = 0; l < L::count; ++l) {
    if (!L::on(ok, l)) continue;
    lambda[l] = L::get(lam_new, l);
    // An immovable end is not written: no false store-to-load chain through an anchor shared by
    // many constraints (every tether of a pin), and no write for a parallel pass to race on.
    if (L::get(w0, l) != 0.0) {
      double* q = x + 3 * static_cast<int64_t>(ids[2 * l]);
      const double k = L::get(s0, l);
      q[0] += k * L::get(d.x, l);
      q[1] += k * L::get(d.y, l);
      q[2] += k * L::get(d.z, l);
    }
    if (L::get(w1, l) != 0.0) {
      double* q = x + 3 * static_cast<int64_t>(ids[2 * l + 1]);
      const double k = L::get(s1, l);
      q[0] -= k * L::get(d.x, l);
      q[1] -= k * L::get(d.y, l);
      q[2] -= k * L::get(d.z, l);
    }
  }
}

/// The operands of a block of four-particle constraints: positions, inverse masses, rest values,
/// multipliers and alpha~ = compliance / h^2, one lane per constraint.
template <class T>
struct QuadOperands {
  lanes::V3<T> p[4];
  T wk[4];
  T r, lam, alpha;
  EMBRA_ALWAYS_INLINE QuadOperands(const int32_t* ids, const double* rest, const double* compliance,
                                   const double* lambda, double inv_h2, const double* x, const double* w) {
    for (int k = 0; k < 4; ++k) {
      p[k] = lanes::load_point<T>(x, ids + k, 4);
      wk[k] = lanes::load_value<T>(w, ids + k, 4);
    }
    r = lanes::gather<T>(rest);
    lam = lanes::gather<T>(lambda);
    alpha = lanes::gather<T>(compliance) * inv_h2;
  }
};

/// Writes back a block of four-particle constraints: each lane whose constraint is valid (ok) takes
/// its new multiplier and moves its movable particles from p_k (where the block read them) by
/// w_k dlambda grad_k C. A constraint's four particles are distinct and a colour's lanes share no
/// movable particle, so each new position is computed in registers and stored, not read again.
template <class T, class M>
EMBRA_ALWAYS_INLINE void scatter4(const int32_t* ids, M ok, T lam_new, const lanes::V3<T> p[4], const T wk[4], T dl,
                                  const lanes::V3<T> g[4], double* lambda, double* x) {
  using L = lanes::Lanes<T>;
  alignas(32) double to[4][L::count][4];  // particle k's new position in lane l
  for (int k = 0; k < 4; ++k) lanes::transpose(p[k] + (wk[k] * dl) * g[k], to[k]);
  for (int l = 0; l < L::count; ++l) {
    if (!L::on(ok, l)) continue;
    lambda[l] = L::get(lam_new, l);
    for (int k = 0; k < 4; ++k) {
      // An immovable particle is not written: colours ignore them, so lanes may share one.
      if (L::get(wk[k], l) == 0.0) continue;
      std::memcpy(x + 3 * static_cast<int64_t>(ids[4 * l + k]), to[k][l], 3 * sizeof(double));
    }
  }
}

/// The signed angle from n1 to n2 about `edge` (length le): dihedral_angle (constraint_math.hpp)
/// lane by lane, shared by the projection and the residual measurement so both see the same bits.
template <class T>
EMBRA_ALWAYS_INLINE T hinge_angle(const lanes::V3<T>& n1, const lanes::V3<T>& n2, const lanes::V3<T>& edge, T le) {
  return lanes::atan2(dot(cross(n1, n2), edge), dot(n1, n2) * le);
}

/// Dihedral angle across the edge x0-x1 of triangles (x0, x1, x2) and (x1, x0, x3) = rest: the
/// function and gradients of eval_dihedral (constraint_math.hpp), written out flat:
///   grad2 = -le / |n1|^2 n1, grad3 = -le / |n2|^2 n2, grad1 = -(s1 grad2 + s2 grad3),
///   grad0 = -(grad1 + grad2 + grad3), with s_k = (x_k - x0) . edge / le^2.
template <class T>
EMBRA_ALWAYS_INLINE void dihedral_block(const int32_t* ids, const double* rest, const double* compliance,
                                        double* lambda, double inv_h2, double* x, const double* w) {
  using namespace lanes;
  using L = Lanes<T>;
  const QuadOperands<T> o(ids, rest, compliance, lambda, inv_h2, x, w);
  const V3<T>* p = o.p;
  const T* wk = o.wk;
  const T r = o.r, lam = o.lam, alpha = o.alpha;
  const V3<T> edge = p[1] - p[0], a2 = p[2] - p[0], a3 = p[3] - p[0];
  const V3<T> n1 = cross(edge, a2), n2 = cross(a3, edge);
  const T le2 = dot(edge, edge), n1sq = dot(n1, n1), n2sq = dot(n2, n2);
  const T le = lanes::sqrt(le2);
  const auto valid = (le > 1e-300) & (n1sq > 1e-300) & (n2sq > 1e-300);
  T c = hinge_angle(n1, n2, edge, le) - r;
  if (!all_within_pi(c)) {  // wrap to (-pi, pi]: rarely needed
    double v[L::count];
    for (int l = 0; l < L::count; ++l) v[l] = wrap_angle(L::get(c, l));
    c = L::make(v);
  }
  const T k2 = -le / n1sq, k3 = -le / n2sq;
  const V3<T> g2 = k2 * n1, g3 = k3 * n2;
  const T inv_le2 = 1.0 / le2;
  const T s1 = dot(a2, edge) * inv_le2, s2 = dot(a3, edge) * inv_le2;
  const V3<T> g1 = -(s1 * g2 + s2 * g3);
  const V3<T> g0 = -(g1 + g2 + g3);
  const T denom = wk[0] * dot(g0, g0) + wk[1] * dot(g1, g1) + wk[2] * dot(g2, g2) + wk[3] * dot(g3, g3) + alpha;
  const auto ok = valid & (denom > 0.0);
  const T dl = (-c - alpha * lam) / denom;
  const V3<T> g[4] = {g0, g1, g2, g3};
  scatter4<T>(ids, ok, lam + dl, p, wk, dl, g, lambda, x);
}

/// One row of quad planarity (kPlanarity: signed distance between the diagonals of (x0, x1, x2,
/// x3)) or plane offset (signed distance of x0 from the plane of (x1, x2, x3)) = rest, from its
/// operands: the function and gradients of eval_quad_planarity / eval_plane_offset
/// (constraint_math.hpp), giving the gradients g and the multiplier's change dl; returns the lanes
/// where it applies. Shared by the passes and the islands (the same bits). Both are C = s . u with
/// u = n / |n|, n = a x b; with q = (s - C u) / |n| the gradient along a is b x q and along b is
/// q x a. a, b and q all lie across u, so both are multiples of u: b x q = beta u and q x a = gamma u
/// with (Binet-Cauchy)
///
///   beta = ((a.b)(b.s) - (a.s)(b.b)) / |n|^2,   gamma = ((a.s)(a.b) - (a.a)(b.s)) / |n|^2,
///
/// so every gradient is c_k u: dl from the four scalars c_k, the moves along u. The dot products
/// are independent of one another, and the coefficients need 1 / |n|^2 only, which comes before
/// 1 / |n| (its root): a row's chain of dependent operations runs through its value, about two
/// thirds of the vector form's. (Every term stays of the order of |n|^2 at most: in floats a panel
/// from about 1e-9 to 1e9 m a side.)
template <class T, bool kPlanarity>
EMBRA_ALWAYS_INLINE auto offset_step(const lanes::V3<T> p[4], const T wk[4], T r, T lam, T alpha, lanes::V3<T> g[4],
                                     T& dl) {
  using namespace lanes;
  const V3<T> a = kPlanarity ? p[2] - p[0] : p[2] - p[1];
  const V3<T> b = p[3] - p[1];
  const V3<T> s = kPlanarity ? p[1] - p[0] : p[0] - p[1];
  const V3<T> n = cross(a, b);
  const T nn = dot(n, n), sn = dot(s, n);
  const T ab = dot(a, b), as = dot(a, s), bs = dot(b, s), aa = dot(a, a), bb = dot(b, b);
  // 1 / |n|^2 first and 1 / |n| as its root: the coefficients and the denominator wait for the
  // division only, and the row's chain runs through its value (the root after the division).
  const auto valid = nn > tiny_square<T>();
  const T inv_nn = 1.0f / nn;
  const T inv_m = lanes::sqrt(inv_nn);
  const T beta = (ab * bs - as * bb) * inv_nn, gamma = (as * ab - aa * bs) * inv_nn;
  T c[4];
  if constexpr (kPlanarity) {  // grad = {-u - beta u, u - gamma u, beta u, gamma u}
    c[0] = -(1.0f + beta);
    c[1] = 1.0f - gamma;
  } else {  // grad = {u, -(u + beta u + gamma u), beta u, gamma u}
    c[0] = splat<T>(1.0f);
    c[1] = -((1.0f + beta) + gamma);
  }
  c[2] = beta;
  c[3] = gamma;
  const T denom =
      ((wk[0] * (c[0] * c[0]) + wk[1] * (c[1] * c[1])) + (wk[2] * (c[2] * c[2]) + wk[3] * (c[3] * c[3]))) + alpha;
  const V3<T> u = inv_m * n;
  const T value = sn * inv_m;
  for (int k = 0; k < 4; ++k) g[k] = c[k] * u;
  dl = (-(value - r) - alpha * lam) / denom;
  return valid & (denom > 0.0);
}

/// Quad planarity or plane offset (offset_step) of a block of constraints.
template <class T, bool kPlanarity>
EMBRA_ALWAYS_INLINE void offset_block(const int32_t* ids, const double* rest, const double* compliance, double* lambda,
                                      double inv_h2, double* x, const double* w) {
  const QuadOperands<T> o(ids, rest, compliance, lambda, inv_h2, x, w);
  lanes::V3<T> g[4];
  T dl;
  const auto ok = offset_step<T, kPlanarity>(o.p, o.wk, o.r, o.lam, o.alpha, g, dl);
  scatter4<T>(ids, ok, o.lam + dl, o.p, o.wk, dl, g, lambda, x);
}

/// Islands (IslandPlan) first .. first + kBlocks * lanes - 1 of one shape, one per lane: their
/// particles loaded once, every row projected in turn on the particles in registers (distance_step
/// and offset_step, as the passes project them), each row's new multiplier stored, the movable
/// particles stored once at the end. An island's rows depend each on the last (a chain of square
/// roots and divisions): kBlocks blocks of lanes go step by step side by side, so that one block's
/// latency hides behind the others' work.
template <class T, int kBlocks>
EMBRA_ALWAYS_INLINE void island_block(const IslandPlan::Shape& shape, size_t first, SolverArray* const* rows,
                                      double inv_h2, double* x, const double* w) {
  using namespace lanes;
  using L = Lanes<T>;
  const int slots = shape.slots, steps = shape.steps;
  V3<T> p[kBlocks][IslandPlan::kSlots];
  T wp[kBlocks][IslandPlan::kSlots];
  const int32_t* ids[kBlocks];
  const int32_t* row[kBlocks];
  double* lam_at[kBlocks];
  for (int b = 0; b < kBlocks; ++b) {
    const size_t at = first + static_cast<size_t>(b * L::count);
    ids[b] = &shape.particle[at * static_cast<size_t>(slots)];
    row[b] = &shape.row[at * static_cast<size_t>(steps)];
    lam_at[b] = &shape.lambda[at * static_cast<size_t>(steps)];
    for (int k = 0; k < slots; ++k) {
      p[b][k] = load_point<T>(x, ids[b] + k, slots);
      wp[b][k] = load_value<T>(w, ids[b] + k, slots);
    }
  }
  for (int step = 0; step < steps; ++step) {
    SolverArray& a = *rows[shape.kind[step]];
    const int8_t* sl = &shape.slot[4 * static_cast<size_t>(step)];
    for (int b = 0; b < kBlocks; ++b) {
      const int32_t* at = row[b] + step;  // lane l's row: at[l * steps]
      double* own = lam_at[b] + step;     // lane l's multiplier: own[l * steps]
      double lams[L::count];
      for (int l = 0; l < L::count; ++l) lams[l] = own[l * steps];
      const T r = load_value<T>(a.rest.data(), at, steps), lam = L::make(lams);
      const T alpha = load_value<T>(a.compliance.data(), at, steps) * inv_h2;
      V3<T>* q = p[b];
      const T* wq = wp[b];
      T lam_new;
      decltype(T{} > 0.0) ok;  // the lanes where the row applies
      if (shape.kind[step] == 0) {
        V3<T> d;
        T s0, s1;
        ok = distance_step<T, false>(q[sl[0]], q[sl[1]], wq[sl[0]], wq[sl[1]], r, lam, alpha, d, s0, s1, lam_new);
        q[sl[0]] = select3(ok & (wq[sl[0]] != 0.0), q[sl[0]] + s0 * d, q[sl[0]]);
        q[sl[1]] = select3(ok & (wq[sl[1]] != 0.0), q[sl[1]] - s1 * d, q[sl[1]]);
      } else {
        const V3<T> o[4] = {q[sl[0]], q[sl[1]], q[sl[2]], q[sl[3]]};
        const T wk[4] = {wq[sl[0]], wq[sl[1]], wq[sl[2]], wq[sl[3]]};
        V3<T> g[4];
        T dl;
        ok = shape.kind[step] == 1 ? offset_step<T, true>(o, wk, r, lam, alpha, g, dl)
                                   : offset_step<T, false>(o, wk, r, lam, alpha, g, dl);
        for (int k = 0; k < 4; ++k) q[sl[k]] = select3(ok & (wk[k] != 0.0), o[k] + (wk[k] * dl) * g[k], o[k]);
        lam_new = lam + dl;
      }
      for (int l = 0; l < L::count; ++l)
        if (L::on(ok, l)) own[l * steps] = L::get(lam_new, l);
    }
  }
  for (int b = 0; b < kBlocks; ++b)
    for (int k = 0; k < slots; ++k) {
      alignas(32) double to[L::count][4];
      transpose(p[b][k], to);
      for (int l = 0; l < L::count; ++l)  // an immovable particle is not written
        if (L::get(wp[b][k], l) != 0.0)
          std::memcpy(x + 3 * static_cast<int64_t>(ids[b][l * slots + k]), to[l], 3 * sizeof(double));
    }
}

/// Lanes of floats from `from`: straight where all are valid, else the first `valid` and the first
/// repeated. (Not a lambda: a lambda is a function of its own, compiled without the kernel set's
/// target attribute, and a 32-byte vector returned from it across that line is garbled by Clang.)
template <class T>
EMBRA_ALWAYS_INLINE T lane_operands(const float* from, int valid) {
  using L = lanes::Lanes<T>;
  if (valid == L::count) return L::make(from);
  float v[L::count];
  for (int l = 0; l < L::count; ++l) v[l] = from[l < valid ? l : 0];
  return L::make(v);
}

/// island_block in single precision (T: lanes of floats, Shape::single) for the islands
/// first .. first + valid - 1 of `item` (first = item.first + k; valid <= the lane count, the lanes
/// past it repeating the first island with nothing movable, written nowhere): each lane's particles
/// relative to its island's first particle, the rows projected on those, each particle's move summed
/// from zero (so a row's correction keeps its own digits, not those of the particle's place) and
/// added to its double position at the end. The rows' operands are vector loads
/// (Shape::rest_single) where every lane is valid. A lane computes the same bits in any block.
template <class T>
EMBRA_ALWAYS_INLINE void island_block_single(const IslandPlan::Shape& shape, const IslandPlan::Item& item, int k,
                                             int valid, double* x, const double* w) {
  using namespace lanes;
  using L = Lanes<T>;
  constexpr int N = L::count;
  const bool full = valid == N;
  const int slots = shape.slots, steps = shape.steps;
  const size_t first = static_cast<size_t>(item.first + k);
  const size_t ops = static_cast<size_t>(item.first) * static_cast<size_t>(steps) + static_cast<size_t>(k);
  const int32_t* ids[N];  // lane l's island's particles
  for (int l = 0; l < N; ++l)
    ids[l] = &shape.particle[(first + static_cast<size_t>(l < valid ? l : 0)) * static_cast<size_t>(slots)];
  V3<T> p[IslandPlan::kSlots], moved[IslandPlan::kSlots];  // where a particle started, how far it moved
  T wp[IslandPlan::kSlots];
  double origin[N][3];
  for (int l = 0; l < N; ++l) std::memcpy(origin[l], x + 3 * static_cast<int64_t>(ids[l][0]), sizeof origin[l]);
  for (int s = 0; s < slots; ++s) {
    moved[s] = {splat<T>(0.0f), splat<T>(0.0f), splat<T>(0.0f)};
#if EMBRA_LANES_VECTOR && __has_builtin(__builtin_shufflevector) && __has_builtin(__builtin_convertvector)
    if constexpr (std::is_same_v<T, F8>) {  // in registers: the same values, without a stall on memory
      F4 r[N];
      double wd[N];
      for (int l = 0; l < N; ++l) {
        const int32_t id = ids[l][s];
        const double* q = x + 3 * static_cast<int64_t>(id);
        const D4 d = D4{q[0], q[1], q[2], 0.0} - D4{origin[l][0], origin[l][1], origin[l][2], 0.0};
        r[l] = __builtin_convertvector(d, F4);
        wd[l] = l < valid ? w[id] : 0.0;
      }
      p[s] = transpose_in(r);
      const F4 w0 = __builtin_convertvector((D4{wd[0], wd[1], wd[2], wd[3]}), F4);
      const F4 w1 = __builtin_convertvector((D4{wd[4], wd[5], wd[6], wd[7]}), F4);
      wp[s] = __builtin_shufflevector(w0, w1, 0, 1, 2, 3, 4, 5, 6, 7);
      continue;
    }
#endif
    float a[3][N], ws[N];
    for (int l = 0; l < N; ++l) {
      const int32_t id = ids[l][s];
      const double* q = x + 3 * static_cast<int64_t>(id);
      for (int c = 0; c < 3; ++c) a[c][l] = static_cast<float>(q[c] - origin[l][c]);
      ws[l] = l < valid ? static_cast<float>(w[id]) : 0.0f;
    }
    p[s] = {L::make(a[0]), L::make(a[1]), L::make(a[2])};
    wp[s] = L::make(ws);
  }
  for (int step = 0; step < steps; ++step) {
    const int8_t* sl = &shape.slot[4 * static_cast<size_t>(step)];
    const size_t at = ops + static_cast<size_t>(step * item.count);
    float* own = shape.lambda_single.data() + at;
    const T r = lane_operands<T>(shape.rest_single.data() + at, valid), lam = lane_operands<T>(own, valid);
    const T alpha = lane_operands<T>(shape.alpha_single.data() + at, valid);
    T lam_new;
    decltype(T{} > 0.0f) ok;  // the lanes where the row applies
    if (shape.kind[step] == 0) {
      const int a = sl[0], b = sl[1];
      V3<T> d;
      T s0, s1;
      ok = distance_step<T, false>(p[a] + moved[a], p[b] + moved[b], wp[a], wp[b], r, lam, alpha, d, s0, s1, lam_new);
      moved[a] = select3(ok & (wp[a] != 0.0f), moved[a] + s0 * d, moved[a]);
      moved[b] = select3(ok & (wp[b] != 0.0f), moved[b] - s1 * d, moved[b]);
    } else {
      const V3<T> o[4] = {p[sl[0]] + moved[sl[0]], p[sl[1]] + moved[sl[1]], p[sl[2]] + moved[sl[2]],
                          p[sl[3]] + moved[sl[3]]};
      const T wk[4] = {wp[sl[0]], wp[sl[1]], wp[sl[2]], wp[sl[3]]};
      V3<T> g[4];
      T dl;
      ok = shape.kind[step] == 1 ? offset_step<T, true>(o, wk, r, lam, alpha, g, dl)
                                 : offset_step<T, false>(o, wk, r, lam, alpha, g, dl);
      for (int j = 0; j < 4; ++j)
        moved[sl[j]] = select3(ok & (wk[j] != 0.0f), moved[sl[j]] + (wk[j] * dl) * g[j], moved[sl[j]]);
      lam_new = lam + dl;
    }
    const T kept = select(ok, lam_new, lam);
    if (full) {
      std::memcpy(own, &kept, sizeof kept);
    } else {
      for (int l = 0; l < valid; ++l) own[l] = L::get(kept, l);
    }
  }
  for (int s = 0; s < slots; ++s)
    for (int l = 0; l < valid; ++l) {
      if (L::get(wp[s], l) == 0.0f) continue;  // an immovable particle is not written
      double* q = x + 3 * static_cast<int64_t>(ids[l][s]);
      q[0] += static_cast<double>(L::get(moved[s].x, l));
      q[1] += static_cast<double>(L::get(moved[s].y, l));
      q[2] += static_cast<double>(L::get(moved[s].z, l));
    }
}

/// The lanes of floats that fill the same vector register as lanes of doubles T.
template <class T>
struct SingleLanes {
  using type = float;
};
#if EMBRA_LANES_VECTOR
template <>
struct SingleLanes<lanes::D2> {
  using type = lanes::F4;
};
template <>
struct SingleLanes<lanes::D4> {
  using type = lanes::F8;
};
#endif

/// An item's rows' multipliers from the arrays into its islands' own (`take`), or back.
inline void own_lambda(const IslandPlan::Shape& shape, const IslandPlan::Item& item, SolverArray* const* rows,
                       bool take) {
  const size_t steps = static_cast<size_t>(shape.steps);
  const int32_t* row = shape.row.data() + static_cast<size_t>(item.first) * steps;
  if (shape.single) {  // item by item, step by step (Shape::lambda_single)
    const size_t n = static_cast<size_t>(item.count);
    float* single = shape.lambda_single.data() + static_cast<size_t>(item.first) * steps;
    for (size_t island = 0; island < n; ++island, row += steps)
      for (size_t step = 0; step < steps; ++step) {
        double& in_array = rows[shape.kind[step]]->lambda[static_cast<size_t>(row[step])];
        if (take)
          single[step * n + island] = static_cast<float>(in_array);
        else
          in_array = static_cast<double>(single[step * n + island]);
      }
    return;
  }
  double* own = shape.lambda.data() + static_cast<size_t>(item.first) * steps;
  for (int32_t island = 0; island < item.count; ++island, own += steps, row += steps)
    for (size_t step = 0; step < steps; ++step) {
      double& in_array = rows[shape.kind[step]]->lambda[static_cast<size_t>(row[step])];
      if (take)
        own[step] = in_array;
      else
        in_array = own[step];
    }
}

/// The islands of items [begin, end) (IslandPlan::items): in two blocks of lanes of T side by side
/// while an item has that many left, then one block, then one at a time; in single precision blocks
/// of as many floats as the register holds (8 in AVX2), the last one filled up.
template <class T>
EMBRA_ALWAYS_INLINE void island_items(const IslandPlan& plan, size_t begin, size_t end, SolverArray* const* rows,
                                      double inv_h2, double* x, const double* w, int ends) {
  constexpr int lanes_n = lanes::Lanes<T>::count;
  for (size_t i = begin; i < end; ++i) {
    const IslandPlan::Item& item = plan.items[i];
    const IslandPlan::Shape& shape = plan.shapes[static_cast<size_t>(item.shape)];
    if (ends & kIslandsTake) own_lambda(shape, item, rows, true);
    int k = 0;
    if (shape.single) {
      using F = typename SingleLanes<T>::type;
      for (; k < item.count; k += lanes::Lanes<F>::count)
        island_block_single<F>(shape, item, k, std::min(item.count - k, lanes::Lanes<F>::count), x, w);
    }
    for (; k + 2 * lanes_n <= item.count; k += 2 * lanes_n)
      island_block<T, 2>(shape, static_cast<size_t>(item.first + k), rows, inv_h2, x, w);
    for (; k + lanes_n <= item.count; k += lanes_n)
      island_block<T, 1>(shape, static_cast<size_t>(item.first + k), rows, inv_h2, x, w);
    for (; k < item.count; ++k) island_block<double, 1>(shape, static_cast<size_t>(item.first + k), rows, inv_h2, x, w);
    if (ends & kIslandsGive) own_lambda(shape, item, rows, false);
  }
}

/// Whether p lies inside the ball of radius r about c, to rounding (a tether's reach is a sum of
/// edge lengths: two tethers that just meet, as along a cloth's edge pinned at both ends at exactly
/// its length, meet at a point only to rounding).
bool within(const Vec3& p, const Vec3& c, double r) {
  return (p - c).squaredNorm() <= r * r * (1.0 + 1e-10);
}

/// The point nearest y on the circle where the spheres about c0 and c1 (radii r0, r1) meet; false
/// if they do not meet (beyond rounding) or share their centre.
bool nearest_on_circle(const Vec3& y, const Vec3& c0, double r0, const Vec3& c1, double r1, Vec3& out) {
  const Vec3 axis = c1 - c0;
  const double d = axis.norm();
  if (!(d > 0.0)) return false;
  const Vec3 u = axis / d;
  const double a = (d * d + r0 * r0 - r1 * r1) / (2.0 * d);  // the circle's centre, from c0 along u
  double rho2 = r0 * r0 - a * a;
  if (rho2 < 0.0) {
    if (rho2 < -1e-10 * r0 * r0) return false;
    rho2 = 0.0;  // the spheres touch: the circle is a point
  }
  const Vec3 m = c0 + a * u;
  Vec3 q = (y - m) - (y - m).dot(u) * u;  // y's offset from the circle's centre, in the circle's plane
  double qn = q.norm();
  if (!(qn > 0.0)) {  // y on the axis: every point of the circle is as near; take a fixed one
    q = u.unitOrthogonal();
    qn = 1.0;
  }
  out = m + (std::sqrt(rho2) / qn) * q;
  return true;
}

/// Automatic tethers (Settings::tethers), the run r of one particle: the particle goes to the point
/// nearest it inside all of its tethers at once, the intersection of the balls about its anchors,
/// rather than inside each in turn. In turn, the last tether of a particle would always have the
/// final word: along the top edge of a cloth pinned at both ends at exactly its length, where the
/// balls about the two pins only touch, the particles left of the middle (whose last tether is the
/// right pin's) were pulled right by every substep's sag and those right of it left, and the edge
/// across the middle ended squeezed by 2.5 % (the 128 x 128 acceptance cloth at 20 substeps).
///
/// The nearest point of the intersection lies on one sphere (the nearest point of that ball, if
/// inside all the others) or on the circle where two meet (the nearest such point inside all the
/// others). Where there is none (the anchors are further apart than the tethers reach, or three or
/// more tethers meet at the answer), the particle goes to the mean of its nearest points on the
/// tethers it is outside of: a compromise that favours no anchor. Anchors never move (they are the
/// immovable particles the tethers were made for); a particle that became immovable is left alone.
/// The multipliers are not kept: automatic tethers have no compliance and report no force. Runs of
/// exactly two tethers (the default) go side by side in lanes, with the same bits (tether_runs).
void project_tether_run(const SolverArray& t, size_t r, Vec3* x, const double* w) {
  constexpr int kMostPairs = 8;  // past this many tethers in play, the compromise
  const int32_t* entry = &t.run_entry[t.run_start[r]];
  const int32_t m = t.run_start[r + 1] - t.run_start[r];
  const int32_t p = t.ids[2 * entry[0]];
  if (w[p] == 0.0) return;
  const Vec3 y = x[p];
  auto anchor = [&](int32_t k) -> const Vec3& { return x[t.ids[2 * entry[k] + 1]]; };
  auto reach = [&](int32_t k) { return t.rest[entry[k]]; };
  auto inside_all = [&](const Vec3& q) {
    for (int32_t k = 0; k < m; ++k)
      if (!within(q, anchor(k), reach(k))) return false;
    return true;
  };
  auto nearest_on = [&](int32_t k, const Vec3& q) {
    const Vec3 d = q - anchor(k);
    const double len = d.norm();
    return len > reach(k) ? Vec3(anchor(k) + (reach(k) / len) * d) : q;
  };
  // In play: the tethers y is outside of, and those a nearest point on one of them is outside of.
  uint64_t outside = 0, in_play = 0;
  for (int32_t k = 0; k < m; ++k)
    if (!within(y, anchor(k), reach(k))) outside |= uint64_t{1} << k;
  if (outside == 0) return;
  for (int32_t k = 0; k < m; ++k) {
    if (!(outside >> k & 1)) continue;
    in_play |= uint64_t{1} << k;
    const Vec3 q = nearest_on(k, y);
    bool done = true;
    for (int32_t j = 0; j < m; ++j)
      if (!within(q, anchor(j), reach(j))) done = false, in_play |= uint64_t{1} << j;
    if (done) {
      x[p] = q;
      return;
    }
  }
  double best = std::numeric_limits<double>::infinity();
  Vec3 answer = y;
  if (std::popcount(in_play) <= kMostPairs)
    for (int32_t i = 0; i < m; ++i) {
      if (!(in_play >> i & 1)) continue;
      for (int32_t j = i + 1; j < m; ++j) {
        Vec3 q;
        if (!(in_play >> j & 1) || !nearest_on_circle(y, anchor(i), reach(i), anchor(j), reach(j), q)) continue;
        const double dist = (q - y).squaredNorm();
        if (dist < best && inside_all(q)) best = dist, answer = q;
      }
    }
  if (best == std::numeric_limits<double>::infinity()) {
    Vec3 sum = Vec3::Zero();
    for (int32_t k = 0; k < m; ++k)
      if (outside >> k & 1) sum += nearest_on(k, y);
    answer = sum / std::popcount(outside);
  }
  x[p] = answer;
}

/// lanes::dot(q - c, q - c) <= r^2 (1 + 1e-10): within(), lane by lane.
template <class T>
EMBRA_ALWAYS_INLINE auto within_lanes(const lanes::V3<T>& q, const lanes::V3<T>& c, T r) {
  const lanes::V3<T> d = q - c;
  return dot(d, d) <= r * r * (1.0 + 1e-10);
}

/// project_tether_run for Lanes<T>::count particles of exactly two tethers each (the default,
/// Settings::tethers = 2), side by side: the same operations in the same order, every branch taken
/// in every lane and the answer selected, so the bits are those of the one-at-a-time run. A lane
/// whose particle lies on the anchors' axis (every point of the circle equally near) is left to
/// project_tether_run.
template <class T>
EMBRA_ALWAYS_INLINE void tether_pair_block(const SolverArray& t, const int32_t* runs, double* x, const double* w) {
  using namespace lanes;
  using L = Lanes<T>;
  constexpr int N = L::count;
  int32_t pid[N], a0[N], a1[N];
  double r0d[N], r1d[N];
  for (int l = 0; l < N; ++l) {
    const int32_t* e = &t.run_entry[t.run_start[runs[l]]];
    pid[l] = t.ids[2 * e[0]], a0[l] = t.ids[2 * e[0] + 1], a1[l] = t.ids[2 * e[1] + 1];
    r0d[l] = t.rest[e[0]], r1d[l] = t.rest[e[1]];
  }
  const V3<T> y = load_point<T>(x, pid, 1), c0 = load_point<T>(x, a0, 1), c1 = load_point<T>(x, a1, 1);
  const T r0 = L::make(r0d), r1 = L::make(r1d), wp = load_value<T>(w, pid, 1);
  const auto out0 = !within_lanes(y, c0, r0), out1 = !within_lanes(y, c1, r1);
  const auto moved = (out0 | out1) & (wp != 0.0);
  if (!any(moved)) return;
  // The nearest point of each sphere (used only where y is outside it, so len > r).
  const V3<T> d0 = y - c0, d1 = y - c1;
  const V3<T> q0 = c0 + (r0 / lanes::sqrt(dot(d0, d0))) * d0;
  const V3<T> q1 = c1 + (r1 / lanes::sqrt(dot(d1, d1))) * d1;
  const auto q0_in0 = within_lanes(q0, c0, r0), q0_in1 = within_lanes(q0, c1, r1);
  const auto q1_in0 = within_lanes(q1, c0, r0), q1_in1 = within_lanes(q1, c1, r1);
  const auto done0 = out0 & q0_in0 & q0_in1;
  const auto done1 = out1 & q1_in0 & q1_in1;
  V3<T> to = select3(done0, q0, q1);       // the first sphere's answer if it has one, else the second's
  auto open = moved & (!(done0 | done1));  // lanes with no answer yet
  decltype(open) degenerate{};             // lanes left to project_tether_run (none yet)
  if (any(open)) {
    // Both tethers in play: the circle where the spheres meet (nearest_on_circle).
    const auto play0 = out0 | (out1 & (!q1_in0)), play1 = (out0 & (!q0_in1)) | out1;
    const auto circle = open & play0 & play1;
    if (any(circle)) {
      const V3<T> axis = c1 - c0;
      const T d = lanes::sqrt(dot(axis, axis));
      const V3<T> u = {axis.x / d, axis.y / d, axis.z / d};
      const T a = (d * d + r0 * r0 - r1 * r1) / (2.0 * d);
      const T rho2 = r0 * r0 - a * a;
      const auto meet = circle & (d > 0.0) & (!(rho2 < -1e-10 * r0 * r0));
      const V3<T> m = c0 + a * u;
      const V3<T> ym = y - m;
      const V3<T> q = ym - dot(ym, u) * u;
      const T qn = lanes::sqrt(dot(q, q));
      const V3<T> qc = m + (lanes::sqrt(select(rho2 < 0.0, splat<T>(0.0), rho2)) / qn) * q;
      const V3<T> dc = qc - y;
      const auto found = meet & (dot(dc, dc) < std::numeric_limits<double>::infinity()) & within_lanes(qc, c0, r0) &
                         within_lanes(qc, c1, r1);
      degenerate = meet & (!(qn > 0.0));
      to = select3(found, qc, to);
      open = open & (!found);
    }
    if (any(open)) {
      // Otherwise the mean of the nearest points of the spheres y is outside of.
      const T zero = splat<T>(0.0);
      V3<T> sum = {zero, zero, zero};
      sum = select3(out0, sum + q0, sum);
      sum = select3(out1, sum + q1, sum);
      const T count = select(out0, splat<T>(1.0), zero) + select(out1, splat<T>(1.0), zero);
      to = select3(open, V3<T>{sum.x / count, sum.y / count, sum.z / count}, to);
    }
  }
  for (int l = 0; l < N; ++l) {
    if (!L::on(moved, l)) continue;
    if (L::on(degenerate, l)) {
      project_tether_run(t, static_cast<size_t>(runs[l]), reinterpret_cast<Vec3*>(x), w);
      continue;
    }
    double* xp = x + 3 * static_cast<int64_t>(pid[l]);
    xp[0] = L::get(to.x, l), xp[1] = L::get(to.y, l), xp[2] = L::get(to.z, l);
  }
}

/// The automatic tether runs pair_runs[begin .. end) (exactly two tethers each) a block of lanes at
/// a time, the remainder one at a time; or, with `others`, the runs other_runs[begin .. end) one at a
/// time. The scalar kernel set takes them all one at a time (project_tether_run), so comparing
/// kernel sets (EMBRA_KERNELS, scenes.kernels_same_bits) checks the lanes against the one-at-a-time
/// projection.
template <class T>
EMBRA_ALWAYS_INLINE void tether_runs(const SolverArray& t, size_t i, size_t end, bool others, double* x,
                                     const double* w) {
  constexpr size_t lanes_n = static_cast<size_t>(lanes::Lanes<T>::count);
  Vec3* const points = reinterpret_cast<Vec3*>(x);
  const std::vector<int32_t>& runs = others ? t.other_runs : t.pair_runs;
  if constexpr (lanes_n > 1)
    if (!others)
      for (; i + lanes_n <= end; i += lanes_n) tether_pair_block<T>(t, &runs[i], x, w);
  for (; i < end; ++i) project_tether_run(t, static_cast<size_t>(runs[i]), points, w);
}

enum class Op { distance, tether, dihedral, planarity, plane_offset };

template <class T, Op kOp>
EMBRA_ALWAYS_INLINE void block(const SolverArray& a, size_t i, double inv_h2, double* x, const double* w,
                               double* lambda) {
  if constexpr (kOp == Op::dihedral)
    dihedral_block<T>(&a.ids[4 * i], &a.rest[i], &a.compliance[i], lambda + i, inv_h2, x, w);
  else if constexpr (kOp == Op::planarity || kOp == Op::plane_offset)
    offset_block<T, kOp == Op::planarity>(&a.ids[4 * i], &a.rest[i], &a.compliance[i], lambda + i, inv_h2, x, w);
  else
    distance_block<T, kOp == Op::tether>(&a.ids[2 * i], &a.rest[i], &a.compliance[i], lambda + i, inv_h2, x, w);
}

/// The constraints [begin, end) of one colour: blocks of T (with `in_lanes`), then one at a time.
/// Without `in_lanes` (a shared tail, whose constraints may overlap) every one is projected alone,
/// in order.
template <class T, Op kOp>
EMBRA_ALWAYS_INLINE void pass(SolverArray& a, size_t i, size_t end, bool in_lanes, double inv_h2, double* x,
                              const double* w) {
  constexpr size_t lanes_n = static_cast<size_t>(lanes::Lanes<T>::count);
  double* lambda = a.lambda.data();
  if (in_lanes)
    for (; i + lanes_n <= end; i += lanes_n) block<T, kOp>(a, i, inv_h2, x, w, lambda);
  for (; i < end; ++i) block<double, kOp>(a, i, inv_h2, x, w, lambda);
}

/// The chain pass (Settings::chain_solve): each chain of distance constraints, in turn, takes one
/// exact step of its linearised XPBD system
///   (J W J^T + alpha~) dlambda = -C - alpha~ lambda,   x += W J^T dlambda,
/// with J the chain's constraint gradients where the particles stand. Consecutive constraints share
/// one particle, so the system is tridiagonal: diagonal w_k + w_(k+1) + alpha~_k, off-diagonal
/// -w_shared n_k . n_(k+1) (n_k the unit direction of constraint k along the chain), positive
/// definite, solved by forward elimination and back substitution (Thomas). A chain of one constraint
/// is the plain projection; a hard pin (w = 0) cuts a chain into independent parts.
///
/// The step is a Newton step for the chain, exact along a straight run and quadratic in the residual
/// near one; far from the linearisation (a run folded over, a rest length cut to a fraction) it can
/// overshoot. It is therefore kept only if it lowers the chain's residual sum of (C + alpha~ lambda)^2;
/// otherwise the chain is projected one constraint at a time, as the plain pass does.
///
/// Only a group's first projection in a substep takes chain steps (project_group; not its repeats
/// under a weight above 1, nor later iterations). Newton steps repeated
/// within one substep, each linearised where the last one ended, satisfy the links to rounding but
/// add up to a correction that is not along the final gradients (the term XPBD drops, Macklin et al.
/// 2016 eq. 11): a taut chain between two pins then keeps sliding along its constraints at a speed
/// damping does not remove (64 links, 2 substeps x 40 iterations: 2 cm/s against damping 20/s, where
/// Gauss-Seidel passes come to rest). With the realignment passes, which re-derive the positions from
/// the multipliers, the chain steps did not come to rest either; those passes stay one at a time.
template <class T>
EMBRA_ALWAYS_INLINE void store(double* dst, T v) {
  std::memcpy(dst, &v, sizeof v);
}

/// One projection of the distance constraints one at a time along chain `c` (Gauss-Seidel), the
/// plain pass's arithmetic.
inline void chain_sweep(SolverArray& a, size_t c, double inv_h2, double* x, const double* w) {
  const int32_t first = a.chain_start[c], m = a.chain_start[c + 1] - first;
  const int32_t* E = &a.chain_edge[first];
  const int32_t* P = &a.chain_part[first + static_cast<int32_t>(c)];
  for (int32_t k = 0; k < m; ++k) {
    const int32_t e = E[k], i0 = P[k], i1 = P[k + 1];
    double* q0 = x + 3 * static_cast<int64_t>(i0);
    double* q1 = x + 3 * static_cast<int64_t>(i1);
    const double dx = q1[0] - q0[0], dy = q1[1] - q0[1], dz = q1[2] - q0[2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double alpha = a.compliance[e] * inv_h2, denom = w[i0] + w[i1] + alpha;
    if (!(len > 1e-300) || denom <= 0.0) continue;
    const double dl = (-(len - a.rest[e]) - alpha * a.lambda[e]) / denom;
    a.lambda[e] += dl;
    const double s = dl / len;
    q1[0] += w[i1] * s * dx, q1[1] += w[i1] * s * dy, q1[2] += w[i1] * s * dz;
    q0[0] -= w[i0] * s * dx, q0[1] -= w[i0] * s * dy, q0[2] -= w[i0] * s * dz;
  }
}

/// How many links ahead a chain step asks for a link's rest length, compliance and multiplier
/// (measured on the 256 x 256 cloth: 8 and 16 alike, about 10 % of a frame against none).
constexpr int32_t kChainAhead = 8;

/// The chain step for the chains c0 .. c0 + count - 1 of one colour, side by side, one per lane
/// (they share no particle; lanes past `count` idle). Chains are longest first within a colour, so
/// lane 0's is the longest; a lane whose chain has ended idles. `scratch`: World::kChainScratch
/// doubles per constraint of the longest chain, plus as many again (9 per constraint and lane, 4
/// per particle and lane, up to 4 lanes).
///
/// The forward sweep reads each particle, multiplier, rest length and compliance once and keeps
/// them in `scratch` for the backward sweep and the residual after the step: x is not written
/// until a lane's step is accepted, so the copies are exact.
template <class T>
EMBRA_ALWAYS_INLINE void chain_bundle(SolverArray& a, size_t c0, int count, double inv_h2, double* x, const double* w,
                                      double* scratch) {
  using namespace lanes;
  using L = Lanes<T>;
  constexpr int N = L::count;
  const int32_t* P[N];
  const int32_t* E[N];
  int32_t m[N], last[N];  // constraints this lane solves (0 when idle); its chain's last constraint
  for (int l = 0; l < N; ++l) {
    const size_t c = c0 + static_cast<size_t>(std::min(l, count - 1));
    const int32_t first = a.chain_start[c];
    last[l] = a.chain_start[c + 1] - first - 1;
    m[l] = l < count ? last[l] + 1 : 0;
    E[l] = &a.chain_edge[first];
    P[l] = &a.chain_part[first + static_cast<int32_t>(c)];
  }
  const int32_t M = m[0];
  // Per constraint k (N lanes each): direction (3), super-diagonal, 1 / eliminated diagonal,
  // eliminated right-hand side then dlambda, alpha~, rest length and multiplier before the step.
  // Per particle j (M + 1 of them): position as read, then as the step moves it (3), and inverse
  // mass.
  double* const n = scratch;
  double* const up = n + 3 * N * M;
  double* const inv = up + N * M;
  double* const rhs = inv + N * M;
  double* const alpha_k = rhs + N * M;
  double* const rest_k = alpha_k + N * M;
  double* const lambda_k = rest_k + N * M;
  double* const moved = lambda_k + N * M;
  double* const w_j = moved + 3 * N * (M + 1);
  auto point = [](const double* at) { return V3<T>{L::make(at), L::make(at + N), L::make(at + 2 * N)}; };
  auto keep = [](double* at, const V3<T>& v) { store(at, v.x), store(at + N, v.y), store(at + 2 * N, v.z); };
  // Forward: directions, the system, and elimination as it is built; the residual before.
  T merit = splat<T>(0.0), prev_inv = splat<T>(0.0), prev_rhs = splat<T>(0.0);
  T reach = splat<T>(0.0);  // the chain's longest rest length
  V3<T> prev_n{splat<T>(0.0), splat<T>(0.0), splat<T>(0.0)};
  int32_t id[N], edge[N];
  double links_d[N];  // the lane's constraint count
  for (int l = 0; l < N; ++l) id[l] = P[l][0], links_d[l] = m[l];
  const T links = L::make(links_d);
  V3<T> p0 = load_point<T>(x, id, 1);
  T w0 = load_value<T>(w, id, 1);
  keep(moved, p0);
  store(w_j, w0);
  for (int32_t k = 0; k < M; ++k) {
    for (int l = 0; l < N; ++l) {  // an idle lane repeats its last particle: a zero-length, masked link
      const int32_t kk = std::min(k, last[l]);
      id[l] = P[l][kk + 1], edge[l] = E[l][kk];
      // The link kChainAhead on: its operands asked for now. Four lanes' three operand arrays are
      // twelve streams, beside the positions and indices, more than the hardware follows on its own;
      // on the 256 x 256 cloth (4.7 MB of them) the link's own loads were most of the chain's time.
      const int32_t ahead = E[l][std::min(k + kChainAhead, last[l])];
      __builtin_prefetch(&a.compliance[ahead]);
      __builtin_prefetch(&a.rest[ahead]);
      __builtin_prefetch(&a.lambda[ahead], 1);
    }
    // Compared in registers: four scalar flags stored and read back as a vector stall the load.
    const auto on = splat<T>(static_cast<double>(k)) < links;
    const V3<T> p1 = load_point<T>(x, id, 1);
    const T w1 = load_value<T>(w, id, 1);
    keep(moved + 3 * N * (k + 1), p1);
    store(w_j + N * (k + 1), w1);
    const T alpha = load_value<T>(a.compliance.data(), edge, 1) * inv_h2;
    const T rest = load_value<T>(a.rest.data(), edge, 1);
    const T lam = load_value<T>(a.lambda.data(), edge, 1);
    store(alpha_k + N * k, alpha), store(rest_k + N * k, rest), store(lambda_k + N * k, lam);
    const V3<T> d = p1 - p0;
    const T len = lanes::sqrt(dot(d, d));
    const auto valid = on & (len > 1e-300);
    const T il = select(valid, 1.0 / len, splat<T>(0.0));
    const V3<T> nk = il * d;
    T dk = select(on, w0 + w1 + alpha, splat<T>(0.0));
    T rk = select(valid, -(len - rest) - alpha * lam, splat<T>(0.0));
    merit = merit + select(dk > 0.0, rk * rk, splat<T>(0.0));
    reach = select(on & (rest > reach), rest, reach);
    if (k > 0) {  // couple to constraint k - 1 through their shared particle
      const T upk = -w0 * dot(prev_n, nk);
      store(up + N * (k - 1), upk);
      const T f = upk * prev_inv;
      dk = dk - f * upk;
      rk = rk - f * prev_rhs;
    }
    prev_inv = select(dk > 0.0, 1.0 / dk, splat<T>(0.0));
    prev_rhs = rk;
    prev_n = nk;
    store(inv + N * k, prev_inv);
    store(rhs + N * k, rk);
    keep(n + 3 * N * k, nk);
    p0 = p1, w0 = w1;
  }
  // Backward: dlambda, and the moved positions (particle k + 1 once dlambda k and k + 1 are known).
  T next = splat<T>(0.0), farthest = splat<T>(0.0);  // the largest squared move of a particle
  V3<T> next_n{splat<T>(0.0), splat<T>(0.0), splat<T>(0.0)};
  for (int32_t k = M - 1; k >= 0; --k) {
    const T upk = k + 1 < M ? L::make(up + N * k) : splat<T>(0.0);
    const T dl = (L::make(rhs + N * k) - upk * next) * L::make(inv + N * k);
    store(rhs + N * k, dl);
    const V3<T> nk = point(n + 3 * N * k);
    double* mv = moved + 3 * N * (k + 1);
    const V3<T> step = L::make(w_j + N * (k + 1)) * (dl * nk - next * next_n);
    const T step2 = dot(step, step);
    farthest = select(step2 > farthest, step2, farthest);
    keep(mv, point(mv) + step);
    next = dl;
    next_n = nk;
  }
  {
    const V3<T> step = -(L::make(w_j) * (next * next_n));
    const T step2 = dot(step, step);
    farthest = select(step2 > farthest, step2, farthest);
    keep(moved, point(moved) + step);
  }
  // The residual after the step.
  T after = splat<T>(0.0);
  for (int32_t k = 0; k < M; ++k) {
    const auto on = splat<T>(static_cast<double>(k)) < links;
    const V3<T> d = point(moved + 3 * N * (k + 1)) - point(moved + 3 * N * k);
    const T alpha = L::make(alpha_k + N * k);
    const T dk = L::make(w_j + N * k) + L::make(w_j + N * (k + 1)) + alpha;
    const T r =
        lanes::sqrt(dot(d, d)) - L::make(rest_k + N * k) + alpha * (L::make(lambda_k + N * k) + L::make(rhs + N * k));
    after = after + select(on & (dk > 0.0), r * r, splat<T>(0.0));
  }
  // Each lane keeps its step if the step lowered its residual and moved no particle further than half
  // the chain's longest link, else takes the one-at-a-time pass. (A nearly straight chain squeezed
  // or pulled along its length has near-zero pivots: the step could carry particles several links
  // for a slight drop in the residual, and that motion becomes velocity.)
  for (int l = 0; l < count; ++l) {
    const double half_link = 0.5 * L::get(reach, l);
    if (!(L::get(after, l) <= L::get(merit, l)) || !(L::get(farthest, l) <= half_link * half_link)) {
      chain_sweep(a, c0 + static_cast<size_t>(l), inv_h2, x, w);
      continue;
    }
    for (int32_t k = 0; k < m[l]; ++k) a.lambda[E[l][k]] += rhs[N * k + l];
    for (int32_t j = 0; j <= m[l]; ++j) {
      if (w_j[N * j + l] == 0.0) continue;  // the inverse mass as the forward sweep read it
      const int32_t q = P[l][j];
      double* xq = x + 3 * static_cast<int64_t>(q);
      for (int d = 0; d < 3; ++d) xq[d] = moved[3 * N * j + d * N + l];
    }
  }
}

/// The chain pass: colour by colour, bundles of T's lanes within each colour (single chains for the
/// shared tail, whose chains may overlap).
/// The chains [begin, end) of one colour: side by side in bundles of lanes (with `in_lanes`), or
/// one after another (a shared tail).
template <class T>
EMBRA_ALWAYS_INLINE void chain_pass(SolverArray& a, size_t i, size_t end, bool in_lanes, double inv_h2, double* x,
                                    const double* w, double* scratch) {
  constexpr int lanes_n = lanes::Lanes<T>::count;
  if (in_lanes)
    for (; i < end; i += lanes_n)
      chain_bundle<T>(a, i, static_cast<int>(std::min<size_t>(lanes_n, end - i)), inv_h2, x, w, scratch);
  for (; i < end; ++i) chain_bundle<double>(a, i, 1, inv_h2, x, w, scratch);
}

/// The function values alone (no gradients, no writes) of a whole solver array, into out[0 ..
/// size): the distance |x0 - x1| or the dihedral angle, exactly as the projection kernels compute
/// them. The residual measurement's share of the lanes.
template <class T, Op kOp>
EMBRA_ALWAYS_INLINE T value_block(const int32_t* ids, const double* x) {
  using namespace lanes;
  if constexpr (kOp == Op::dihedral) {
    const V3<T> p0 = load_point<T>(x, ids, 4), p1 = load_point<T>(x, ids + 1, 4);
    const V3<T> p2 = load_point<T>(x, ids + 2, 4), p3 = load_point<T>(x, ids + 3, 4);
    const V3<T> edge = p1 - p0;
    const V3<T> n1 = cross(edge, p2 - p0), n2 = cross(p3 - p0, edge);
    return hinge_angle(n1, n2, edge, lanes::sqrt(dot(edge, edge)));
  } else {
    const V3<T> d = load_point<T>(x, ids, 2) - load_point<T>(x, ids + 1, 2);
    return lanes::sqrt(dot(d, d));
  }
}

template <class T, Op kOp>
EMBRA_ALWAYS_INLINE void values(const SolverArray& a, size_t i, size_t end, const double* x, double* out) {
  constexpr size_t lanes_n = static_cast<size_t>(lanes::Lanes<T>::count);
  constexpr size_t arity = kOp == Op::dihedral ? 4 : 2;
  for (; i + lanes_n <= end; i += lanes_n) {
    const T v = value_block<T, kOp>(&a.ids[arity * i], x);
    std::memcpy(out + i, &v, sizeof v);
  }
  for (; i < end; ++i) out[i] = value_block<double, kOp>(&a.ids[arity * i], x);
}

/// The passes for one lane type, compiled for one instruction set (ATTR).
#define EMBRA_DEFINE_PASS(NAME, T, ATTR, OP)                                                               \
  ATTR void NAME##_##OP(SolverArray& a, size_t begin, size_t end, bool in_lanes, double inv_h2, double* x, \
                        const double* w) {                                                                 \
    pass<T, Op::OP>(a, begin, end, in_lanes, inv_h2, x, w);                                                \
  }
#define EMBRA_DEFINE_PASSES(NAME, T, ATTR)                                                                            \
  EMBRA_DEFINE_PASS(NAME, T, ATTR, distance)                                                                          \
  EMBRA_DEFINE_PASS(NAME, T, ATTR, tether)                                                                            \
  EMBRA_DEFINE_PASS(NAME, T, ATTR, dihedral)                                                                          \
  EMBRA_DEFINE_PASS(NAME, T, ATTR, planarity)                                                                         \
  EMBRA_DEFINE_PASS(NAME, T, ATTR, plane_offset)                                                                      \
  ATTR void NAME##_tether_runs(const SolverArray& t, size_t begin, size_t end, bool others, double* x,                \
                               const double* w) {                                                                     \
    tether_runs<T>(t, begin, end, others, x, w);                                                                      \
  }                                                                                                                   \
  ATTR void NAME##_islands(const IslandPlan& plan, size_t begin, size_t end, SolverArray* const* rows, double inv_h2, \
                           double* x, const double* w, int ends) {                                                    \
    island_items<T>(plan, begin, end, rows, inv_h2, x, w, ends);                                                      \
  }                                                                                                                   \
  ATTR void NAME##_chain(SolverArray& a, size_t begin, size_t end, bool in_lanes, double inv_h2, double* x,           \
                         const double* w, double* scratch) {                                                          \
    chain_pass<T>(a, begin, end, in_lanes, inv_h2, x, w, scratch);                                                    \
  }                                                                                                                   \
  ATTR void NAME##_distance_values(const SolverArray& a, size_t begin, size_t end, const double* x, double* out) {    \
    values<T, Op::distance>(a, begin, end, x, out);                                                                   \
  }                                                                                                                   \
  ATTR void NAME##_dihedral_values(const SolverArray& a, size_t begin, size_t end, const double* x, double* out) {    \
    values<T, Op::dihedral>(a, begin, end, x, out);                                                                   \
  }

EMBRA_DEFINE_PASSES(scalar, double, )
#if EMBRA_LANES_VECTOR
EMBRA_DEFINE_PASSES(vec2, lanes::D2, )
#if defined(__x86_64__) && defined(__GNUC__)
#define EMBRA_HAVE_AVX2_KERNELS 1
EMBRA_DEFINE_PASSES(avx2, lanes::D4, __attribute__((target("avx2"))))
#endif
#endif

/// The kernel set for this machine, or the one EMBRA_KERNELS names.
Kernels pick_kernels() {
  const Kernels scalar{
      scalar_distance, scalar_tether,          scalar_dihedral,        scalar_planarity,   scalar_plane_offset,
      scalar_chain,    scalar_distance_values, scalar_dihedral_values, scalar_tether_runs, scalar_islands,
      "scalar"};
  const char* forced = std::getenv("EMBRA_KERNELS");
  const std::string want = forced ? forced : "";
  if (want == "scalar") return scalar;
#if EMBRA_LANES_VECTOR
  const Kernels vec2{vec2_distance, vec2_tether,          vec2_dihedral,        vec2_planarity,   vec2_plane_offset,
                     vec2_chain,    vec2_distance_values, vec2_dihedral_values, vec2_tether_runs, vec2_islands,
                     "vec2"};
  if (want == "vec2") return vec2;
#if defined(EMBRA_HAVE_AVX2_KERNELS)
  if (__builtin_cpu_supports("avx2"))
    return Kernels{avx2_distance, avx2_tether,          avx2_dihedral,        avx2_planarity,   avx2_plane_offset,
                   avx2_chain,    avx2_distance_values, avx2_dihedral_values, avx2_tether_runs, avx2_islands,
                   "avx2"};
#endif
  return vec2;
#else
  return scalar;
#endif
}

/// EMBRA_ISLANDS=rows: the pass kernels islands_by_rows projects with (distance, planarity, plane
/// offset), set once by kernels().
Kernels::Pass row_kernels[IslandPlan::kRowKinds] = {};

/// The islands of items [begin, end), their rows one at a time in the islands' order with the pass
/// kernels (EMBRA_ISLANDS=rows): what the island kernels must match bit for bit.
void islands_by_rows(const IslandPlan& plan, size_t begin, size_t end, SolverArray* const* rows, double inv_h2,
                     double* x, const double* w, int /*ends: the rows' multipliers stay in the arrays*/) {
  each_island_row(plan, begin, end,
                  [&](int kind, size_t row) { row_kernels[kind](*rows[kind], row, row + 1, false, inv_h2, x, w); });
}

}  // namespace

const Kernels& kernels() {
  static const Kernels chosen = [] {
    Kernels k = pick_kernels();
    // EMBRA_ISLANDS=off: the rows of islands in their passes instead (the same bits for welded
    // panels, to check that); =rows: the islands' rows one at a time with the pass kernels.
    const char* islands = std::getenv("EMBRA_ISLANDS");
    if (islands != nullptr && std::string(islands) == "off") k.islands = nullptr;
    if (islands != nullptr && std::string(islands) == "rows") {
      row_kernels[0] = k.distance;
      row_kernels[1] = k.planarity;
      row_kernels[2] = k.plane_offset;
      k.islands = islands_by_rows;
    }
    return k;
  }();
  return chosen;
}

namespace {

using passes::each_colour;
using passes::kAlign;
using passes::kChainGrain;
using passes::kGrain;

/// Island items (eight panels each: 100-150 rows) per thread below which the loop is not split.
constexpr size_t kIslandGrain = 4;

}  // namespace

void project_pass(ThreadPool& pool, Kernels::Pass kernel, SolverArray& a, double inv_h2, double* x, const double* w) {
  each_colour(pool, a.colour_start, a.shared_tail, kGrain,
              [&](size_t b, size_t e, bool in_lanes, int) { kernel(a, b, e, in_lanes, inv_h2, x, w); });
}

void chain_pass(ThreadPool& pool, SolverArray& a, double inv_h2, double* x, const double* w,
                std::vector<double>& scratch, ChainTrack* track) {
  const Kernels& k = kernels();
  const size_t stride = scratch.size() / static_cast<size_t>(pool.size());
  const auto run = [&](size_t b, size_t e, bool in_lanes, int part) {
    k.chain(a, b, e, in_lanes, inv_h2, x, w, scratch.data() + stride * static_cast<size_t>(part));
  };
  if (track != nullptr)
    passes::each_colour_tracked(pool, a.chain_colour_start, a.chain_shared_tail, kChainGrain, run, *track);
  else
    each_colour(pool, a.chain_colour_start, a.chain_shared_tail, kChainGrain, run);
}

void tether_runs_pass(ThreadPool& pool, const SolverArray& t, double* x, const double* w) {
  const Kernels& k = kernels();
  // Runs share no particle: the pairs and the others may go in any split, in either order.
  pool.run(0, t.pair_runs.size(), kAlign, kGrain,
           [&](size_t b, size_t e, int) { k.tether_runs(t, b, e, false, x, w); });
  pool.run(0, t.other_runs.size(), 1, kGrain, [&](size_t b, size_t e, int) { k.tether_runs(t, b, e, true, x, w); });
}

namespace {

constexpr int kFlowCalls = 32;    // islands_pass: calls between moves of its parts' items
constexpr size_t kMaxParts = 64;  // timed parts (one bit each in Flow::parts_of); past this the cut stays even

/// IslandPlan::cut for `parts` parts: even cuts when the part count changes.
void start_cut(IslandPlan& plan, size_t colours, size_t parts) {
  if (plan.cut.size() == colours * (parts + 1)) return;
  plan.cut.resize(colours * (parts + 1));
  for (size_t c = 0; c < colours; ++c)
    for (size_t p = 0; p <= parts; ++p)
      plan.cut[c * (parts + 1) + p] = static_cast<double>(p) / static_cast<double>(parts);
}

/// Part p of a colour's items [begin, end) from the first item placed at at[p] or later (the items go
/// in their places' order): every colour cut at the same places, so that a thread keeps one stretch
/// of the mesh.
size_t cut_item(const IslandPlan& plan, size_t begin, size_t end, const double* at, size_t p, size_t parts) {
  if (p == 0) return begin;
  if (p == parts) return end;
  return static_cast<size_t>(std::partition_point(plan.items.begin() + static_cast<std::ptrdiff_t>(begin),
                                                  plan.items.begin() + static_cast<std::ptrdiff_t>(end),
                                                  [&](const IslandPlan::Item& item) { return item.place < at[p]; }) -
                             plan.items.begin());
}

/// Moves a colour's cut `at` a quarter of the way to the places where its parts would have taken the
/// same time, each part's time (`seconds`) spread evenly over its stretch (a colour's time is noisy).
void move_cut(double* at, const double* seconds, size_t parts) {
  double total = 0.0;
  for (size_t p = 0; p < parts; ++p) total += seconds[p];
  if (!(total > 0.0)) return;
  double target[kMaxParts + 1] = {};
  double before = 0.0;  // time of the parts before p
  size_t p = 0;
  for (size_t q = 1; q < parts; ++q) {
    const double want = total * static_cast<double>(q) / static_cast<double>(parts);
    while (p + 1 < parts && before + seconds[p] < want) before += seconds[p++];
    const double share = seconds[p] > 0.0 ? std::clamp((want - before) / seconds[p], 0.0, 1.0) : 0.0;
    target[q] = at[p] + share * (at[p + 1] - at[p]);
  }
  for (size_t q = 1; q < parts; ++q) at[q] += 0.25 * (target[q] - at[q]);
}

/// IslandPlan::Flow's borders for its `start`: each part's first and last items that hold a
/// particle another part's items hold too (an item between two such counts as one).
void find_borders(IslandPlan& plan, size_t colours, size_t parts) {
  IslandPlan::Flow& f = plan.flow;
  size_t particles = 0;
  for (const IslandPlan::Shape& shape : plan.shapes)
    for (int32_t i : shape.particle) particles = std::max(particles, static_cast<size_t>(i) + 1);
  f.parts_of.assign(particles, 0);
  for (size_t c = 0; c < colours; ++c)
    for (size_t p = 0; p < parts; ++p)
      for (auto i = f.start[c * (parts + 1) + p]; i < f.start[c * (parts + 1) + p + 1]; ++i)
        plan.each_particle(static_cast<size_t>(i), [&](size_t k) { f.parts_of[k] |= uint64_t{1} << p; });
  f.lead.assign(colours * parts, 0);
  f.trail.assign(colours * parts, 0);
  for (size_t c = 0; c < colours; ++c)
    for (size_t p = 0; p < parts; ++p) {
      const int32_t b = f.start[c * (parts + 1) + p], e = f.start[c * (parts + 1) + p + 1];
      const int32_t middle = b + (e - b) / 2;
      int32_t lead = 0, trail = 0;
      for (int32_t i = b; i < e; ++i) {
        bool shared = false;
        plan.each_particle(static_cast<size_t>(i),
                           [&](size_t k) { shared = shared || (f.parts_of[k] & ~(uint64_t{1} << p)) != 0; });
        if (!shared) continue;
        if (i < middle)
          lead = i - b + 1;
        else if (trail == 0)
          trail = e - i;
      }
      f.lead[c * parts + p] = lead;
      f.trail[c * parts + p] = trail;
    }
}

}  // namespace

void own_multipliers(const IslandPlan& plan) {
  for (const IslandPlan::Shape& shape : plan.shapes)
    if (shape.single)
      shape.lambda_single.resize(shape.row.size());
    else
      shape.lambda.resize(shape.row.size());
}

void island_operands(const IslandPlan& plan, SolverArray* const* rows, double inv_h2) {
  for (const IslandPlan::Shape& shape : plan.shapes)
    if (shape.single) {
      shape.rest_single.resize(shape.row.size());
      shape.alpha_single.resize(shape.row.size());
    }
  for (const IslandPlan::Item& item : plan.items) {
    const IslandPlan::Shape& shape = plan.shapes[static_cast<size_t>(item.shape)];
    if (!shape.single) continue;
    const size_t steps = static_cast<size_t>(shape.steps), n = static_cast<size_t>(item.count);
    const size_t base = static_cast<size_t>(item.first) * steps;
    for (size_t island = 0; island < n; ++island)
      for (size_t step = 0; step < steps; ++step) {
        const SolverArray& a = *rows[shape.kind[step]];
        const size_t row = static_cast<size_t>(shape.row[base + island * steps + step]);
        shape.rest_single[base + step * n + island] = static_cast<float>(a.rest[row]);
        shape.alpha_single[base + step * n + island] = static_cast<float>(a.compliance[row] * inv_h2);
      }
  }
}

void islands_pass(ThreadPool& pool, IslandPlan& plan, SolverArray* const* rows, double inv_h2, double* x,
                  const double* w, int ends) {
  own_multipliers(plan);
  const size_t colours = plan.colour_start.size() - 1;
  size_t parts = static_cast<size_t>(pool.size());
  for (size_t c = 0; c < colours; ++c)
    parts = std::min(parts, static_cast<size_t>(plan.colour_start[c + 1] - plan.colour_start[c]) / kIslandGrain);
  if (colours < 2 || parts <= 1 || parts > kMaxParts) {
    for (size_t c = 0; c < colours; ++c) islands_colour(pool, plan, c, rows, inv_h2, x, w, nullptr, ends);
    return;
  }
  // One line of steps per part: a colour's border, then the rest of its items, colour after colour.
  // A border of colour c waits for the other parts' borders of colour c - 1, whose items hold the
  // particles it shares with them; the other items of a part share particles with its own items
  // only, which its line has projected before. So every particle sees the projections of the items
  // that hold it in the colours' order, as on one thread, and no step waits for a whole colour.
  start_cut(plan, colours, parts);
  IslandPlan::Flow& f = plan.flow;
  // One cut for every colour: a part that takes longer in one colour and less in another evens out
  // within the iteration, and the same cut keeps the border between the parts short (36-39 of the
  // positions' 817 cache lines written by both threads on the 32 x 32 drape, against 54-78 with a
  // cut of each colour's own). It follows the parts' times every kFlowCalls calls, and the parts'
  // items with it (finding the borders costs about a third of a pass on the 32 x 32 drape).
  const bool fresh = f.start.size() != colours * (parts + 1);
  constexpr size_t stride = 8;  // a part's time on a cache line of its own
  if (fresh || ++f.calls >= kFlowCalls) {
    f.calls = 0;
    if (!fresh) {
      double seconds[kMaxParts] = {};
      for (size_t p = 0; p < parts; ++p) seconds[p] = f.seconds[p * stride];
      move_cut(plan.cut.data(), seconds, parts);
    }
    for (size_t c = 1; c < colours; ++c)
      std::copy(plan.cut.begin(), plan.cut.begin() + static_cast<std::ptrdiff_t>(parts + 1),
                plan.cut.begin() + static_cast<std::ptrdiff_t>(c * (parts + 1)));
    f.seconds.assign(parts * stride, 0.0);
    bool moved = fresh;
    f.start.resize(colours * (parts + 1));
    for (size_t c = 0; c < colours; ++c) {
      const size_t begin = static_cast<size_t>(plan.colour_start[c]);
      const size_t end = static_cast<size_t>(plan.colour_start[c + 1]);
      for (size_t p = 0; p <= parts; ++p) {
        const auto item = static_cast<int32_t>(cut_item(plan, begin, end, plan.cut.data() + c * (parts + 1), p, parts));
        moved = moved || f.start[c * (parts + 1) + p] != item;
        f.start[c * (parts + 1) + p] = item;
      }
    }
    if (moved) find_borders(plan, colours, parts);
  }
  const Kernels& k = kernels();
  const int n = static_cast<int>(parts);
  const auto ready = [&](int line, int step, const auto& done) {
    if (step % 2 != 0 || step == 0) return true;  // a part's own items, or the first colour's border
    for (int q = 0; q < n; ++q)
      if (q != line && done(q) < step - 1) return false;  // q's border of the colour before not ended
    return true;
  };
  pool.run_lines(n, static_cast<int>(2 * colours), ready, [&](int line, int step) {
    const size_t c = static_cast<size_t>(step / 2), p = static_cast<size_t>(line);
    const size_t b = static_cast<size_t>(f.start[c * (parts + 1) + p]);
    const size_t e = static_cast<size_t>(f.start[c * (parts + 1) + p + 1]);
    const size_t lead = static_cast<size_t>(f.lead[c * parts + p]);
    const size_t trail = std::min(static_cast<size_t>(f.trail[c * parts + p]), e - b - lead);
    const auto start = std::chrono::steady_clock::now();
    if (step % 2 == 0) {
      k.islands(plan, b, b + lead, rows, inv_h2, x, w, ends);
      k.islands(plan, e - trail, e, rows, inv_h2, x, w, ends);
    } else {
      k.islands(plan, b + lead, e - trail, rows, inv_h2, x, w, ends);
    }
    f.seconds[p * stride] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
}

void islands_colour(ThreadPool& pool, IslandPlan& plan, size_t colour, SolverArray* const* rows, double inv_h2,
                    double* x, const double* w, const uint8_t* skip, int ends) {
  own_multipliers(plan);
  const Kernels& k = kernels();
  const auto project = [&](size_t b, size_t e) {
    if (skip == nullptr) return k.islands(plan, b, e, rows, inv_h2, x, w, ends);
    for (size_t i = b; i < e;) {  // the runs of items not skipped
      for (; i < e && skip[i] != 0; ++i) {
      }
      const size_t run = i;
      for (; i < e && skip[i] == 0; ++i) {
      }
      if (run < i) k.islands(plan, run, i, rows, inv_h2, x, w, ends);
    }
  };
  const size_t begin = static_cast<size_t>(plan.colour_start[colour]);
  const size_t end = static_cast<size_t>(plan.colour_start[colour + 1]);
  const size_t parts = std::min(static_cast<size_t>(pool.size()), (end - begin) / kIslandGrain);
  if (parts <= 1) return project(begin, end);
  start_cut(plan, plan.colour_start.size() - 1, parts);
  double* at = plan.cut.data() + colour * (parts + 1);  // IslandPlan::cut
  double seconds[kMaxParts] = {};
  // Each part's time from the hand-over to its end: a worker's includes its waking.
  const auto start = std::chrono::steady_clock::now();
  pool.run_parts(static_cast<int>(parts), [&](int part) {
    const size_t p = static_cast<size_t>(part);
    project(cut_item(plan, begin, end, at, p, parts), cut_item(plan, begin, end, at, p + 1, parts));
    if (p < kMaxParts) seconds[p] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  if (parts <= kMaxParts && plan.flow.start.empty()) move_cut(at, seconds, parts);  // else islands_pass's
}

void values_pass(ThreadPool& pool, Kernels::Values kernel, const SolverArray& a, const double* x, double* out) {
  pool.run(0, a.size(), kAlign, kGrain, [&](size_t b, size_t e, int) { kernel(a, b, e, x, out); });
}

const char* solver_kernels() {
  return kernels().name;
}

}  // namespace embra
