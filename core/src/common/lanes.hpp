// Lane-generic arithmetic for the projection kernels (private to core/src).
//
// A kernel is written once as a template over T: `double` (one constraint) or a vector of doubles
// (2 or 4 independent constraints of one colour at a time, GCC/Clang vector extensions). Every lane
// performs exactly the operations the scalar instance performs, in the same order, with IEEE +, -,
// *, / and sqrt only, so the vector kernels give the same bits as the scalar one on every machine:
// the instruction set chosen at run time never changes a result.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <type_traits>

#if defined(__GNUC__) || defined(__clang__)
// The vector types only ever live inside always-inlined code of one function; no ABI is involved.
#pragma GCC diagnostic ignored "-Wpsabi"
#define EMBRA_LANES_VECTOR 1
#define EMBRA_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define EMBRA_LANES_VECTOR 0
#define EMBRA_ALWAYS_INLINE inline
#endif

namespace embra::lanes {

template <class T>
struct Lanes;

template <class E>
struct ScalarLanes {
  using Elem = E;
  static constexpr int count = 1;
  static EMBRA_ALWAYS_INLINE E get(E v, int) { return v; }
  static EMBRA_ALWAYS_INLINE E make(const E* a) { return a[0]; }
  template <class M>
  static EMBRA_ALWAYS_INLINE bool on(M m, int) {
    return static_cast<bool>(m);
  }
};
template <>
struct Lanes<double> : ScalarLanes<double> {};
template <>
struct Lanes<float> : ScalarLanes<float> {};

#if EMBRA_LANES_VECTOR
using D2 = double __attribute__((vector_size(16)));
using D4 = double __attribute__((vector_size(32)));
using F4 = float __attribute__((vector_size(16)));
using F8 = float __attribute__((vector_size(32)));

template <class V, int N>
struct VectorLanes {
  using Elem = std::remove_cvref_t<decltype(V{}[0])>;
  static constexpr int count = N;
  static EMBRA_ALWAYS_INLINE Elem get(V v, int l) { return v[l]; }
  static EMBRA_ALWAYS_INLINE V make(const Elem* a) {
    V v;
    std::memcpy(&v, a, sizeof v);
    return v;
  }
  template <class M>
  static EMBRA_ALWAYS_INLINE bool on(M m, int l) {
    return m[l] != 0;
  }
};
template <>
struct Lanes<D2> : VectorLanes<D2, 2> {};
template <>
struct Lanes<D4> : VectorLanes<D4, 4> {};
template <>
struct Lanes<F4> : VectorLanes<F4, 4> {};
template <>
struct Lanes<F8> : VectorLanes<F8, 8> {};
#endif

/// The element type of lanes T (double or float).
template <class T>
using Elem = typename Lanes<T>::Elem;

/// The smallest length a row divides by: 1e-300 in doubles, 1e-30 in floats.
template <class T>
constexpr Elem<T> tiny() {
  if constexpr (std::is_same_v<Elem<T>, double>)
    return 1e-300;
  else
    return 1e-30f;
}

/// The smallest squared length a row divides by: 1e-300 in doubles, 1e-37 in floats (its reciprocal
/// finite: a float reaches 3.4e38).
template <class T>
constexpr Elem<T> tiny_square() {
  if constexpr (std::is_same_v<Elem<T>, double>)
    return 1e-300;
  else
    return 1e-37f;
}

template <class T>
EMBRA_ALWAYS_INLINE T splat(Elem<T> s) {
  Elem<T> a[Lanes<T>::count];
  for (Elem<T>& v : a) v = s;
  return Lanes<T>::make(a);
}

/// Lane-wise gather: lane l takes src[l * stride].
template <class T>
EMBRA_ALWAYS_INLINE T gather(const double* src, int stride = 1) {
  double a[Lanes<T>::count];
  for (int l = 0; l < Lanes<T>::count; ++l) a[l] = src[l * stride];
  return Lanes<T>::make(a);
}

/// Lane-wise select: m ? a : b (m a comparison result of the same width).
template <class M, class T>
EMBRA_ALWAYS_INLINE T select(M m, T a, T b) {
  return m ? a : b;
}

template <class T>
EMBRA_ALWAYS_INLINE T sqrt(T v) {
  Elem<T> a[Lanes<T>::count];
  for (int l = 0; l < Lanes<T>::count; ++l) a[l] = std::sqrt(Lanes<T>::get(v, l));
  return Lanes<T>::make(a);
}

template <class T>
struct V3 {
  T x, y, z;
};

template <class T>
EMBRA_ALWAYS_INLINE V3<T> operator-(const V3<T>& a, const V3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
EMBRA_ALWAYS_INLINE V3<T> operator+(const V3<T>& a, const V3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
EMBRA_ALWAYS_INLINE V3<T> operator-(const V3<T>& a) {
  return {-a.x, -a.y, -a.z};
}
template <class T>
EMBRA_ALWAYS_INLINE V3<T> operator*(T s, const V3<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
/// The same expressions as Eigen's Vector3d cross and dot, so lane results match eval_* to the bit.
template <class T>
EMBRA_ALWAYS_INLINE V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
EMBRA_ALWAYS_INLINE T dot(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

/// Whether any lane of mask m is set.
template <class M>
EMBRA_ALWAYS_INLINE bool any(M m) {
  if constexpr (std::is_arithmetic_v<M>) {
    return m != 0;
  } else {
    for (int l = 0; l < static_cast<int>(sizeof m / sizeof m[0]); ++l)
      if (m[l]) return true;
    return false;
  }
}

/// Lane-wise m ? a : b of points.
template <class M, class T>
EMBRA_ALWAYS_INLINE V3<T> select3(M m, const V3<T>& a, const V3<T>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

/// Lane l takes the point x + 3 ids[l * stride] (packed xyz triples).
template <class T>
EMBRA_ALWAYS_INLINE V3<T> load_point(const double* x, const int32_t* ids, int stride) {
  double a[3][Lanes<T>::count];
  for (int l = 0; l < Lanes<T>::count; ++l) {
    const double* q = x + 3 * static_cast<int64_t>(ids[l * stride]);
    a[0][l] = q[0];
    a[1][l] = q[1];
    a[2][l] = q[2];
  }
  return {Lanes<T>::make(a[0]), Lanes<T>::make(a[1]), Lanes<T>::make(a[2])};
}

/// Lane l takes w[ids[l * stride]].
template <class T>
EMBRA_ALWAYS_INLINE T load_value(const double* w, const int32_t* ids, int stride) {
  double a[Lanes<T>::count];
  for (int l = 0; l < Lanes<T>::count; ++l) a[l] = w[ids[l * stride]];
  return Lanes<T>::make(a);
}

/// Lane l's (v.x, v.y, v.z) as the triple out[l][0..2] (out[l][3] is padding): a block's per-lane
/// corrections laid out for writing back particle by particle. Four lanes transpose in registers.
template <class T>
EMBRA_ALWAYS_INLINE void transpose(const V3<T>& v, double (*out)[4]) {
  for (int l = 0; l < Lanes<T>::count; ++l) {
    out[l][0] = Lanes<T>::get(v.x, l);
    out[l][1] = Lanes<T>::get(v.y, l);
    out[l][2] = Lanes<T>::get(v.z, l);
    out[l][3] = 0.0;
  }
}
#if EMBRA_LANES_VECTOR && __has_builtin(__builtin_shufflevector)
template <>
EMBRA_ALWAYS_INLINE void transpose(const V3<D4>& v, double (*out)[4]) {
  const D4 zero = {0.0, 0.0, 0.0, 0.0};
  const D4 xy02 = __builtin_shufflevector(v.x, v.y, 0, 4, 2, 6), xy13 = __builtin_shufflevector(v.x, v.y, 1, 5, 3, 7);
  const D4 z02 = __builtin_shufflevector(v.z, zero, 0, 4, 2, 6), z13 = __builtin_shufflevector(v.z, zero, 1, 5, 3, 7);
  const D4 lanes[4] = {__builtin_shufflevector(xy02, z02, 0, 1, 4, 5), __builtin_shufflevector(xy13, z13, 0, 1, 4, 5),
                       __builtin_shufflevector(xy02, z02, 2, 3, 6, 7), __builtin_shufflevector(xy13, z13, 2, 3, 6, 7)};
  std::memcpy(out, lanes, sizeof lanes);
}
#endif

#if EMBRA_LANES_VECTOR && __has_builtin(__builtin_shufflevector)
/// The transpose of eight lanes' points r[l] = (x, y, z, unused) into lanes of floats, in
/// registers (a block filled lane by lane through memory stalls on the store it reads back).
EMBRA_ALWAYS_INLINE V3<F8> transpose_in(const F4 (&r)[8]) {
  const F8 v0 = __builtin_shufflevector(r[0], r[4], 0, 1, 2, 3, 4, 5, 6, 7);
  const F8 v1 = __builtin_shufflevector(r[1], r[5], 0, 1, 2, 3, 4, 5, 6, 7);
  const F8 v2 = __builtin_shufflevector(r[2], r[6], 0, 1, 2, 3, 4, 5, 6, 7);
  const F8 v3 = __builtin_shufflevector(r[3], r[7], 0, 1, 2, 3, 4, 5, 6, 7);
  const F8 t0 = __builtin_shufflevector(v0, v1, 0, 8, 1, 9, 4, 12, 5, 13);
  const F8 t1 = __builtin_shufflevector(v0, v1, 2, 10, 3, 11, 6, 14, 7, 15);
  const F8 t2 = __builtin_shufflevector(v2, v3, 0, 8, 1, 9, 4, 12, 5, 13);
  const F8 t3 = __builtin_shufflevector(v2, v3, 2, 10, 3, 11, 6, 14, 7, 15);
  return {__builtin_shufflevector(t0, t2, 0, 1, 8, 9, 4, 5, 12, 13),
          __builtin_shufflevector(t0, t2, 2, 3, 10, 11, 6, 7, 14, 15),
          __builtin_shufflevector(t1, t3, 0, 1, 8, 9, 4, 5, 12, 13)};
}
#endif

/// atan2_det (constraint_math.hpp) lane by lane, its branches turned into selects: one division for
/// the range reduction and one for the rational approximation.
template <class T>
EMBRA_ALWAYS_INLINE T atan2(T y, T x) {
  constexpr double p0 = -8.750608600031904122785e-1, p1 = -1.615753718733365076637e1, p2 = -7.500855792314704667340e1,
                   p3 = -1.228866684490136173410e2, p4 = -6.485021904942025371773e1;
  constexpr double q0 = 2.485846490142306297962e1, q1 = 1.650270098316988542046e2, q2 = 4.328810604912902668951e2,
                   q3 = 4.853903996359136964868e2, q4 = 1.945506571482613964425e2;
  constexpr double tan_3pi_8 = 2.41421356237309504880, more_bits = 6.123233995736765886130e-17;
  constexpr double pi = std::numbers::pi;
  const T ay = select(y < 0.0, -y, y), ax = select(x < 0.0, -x, x);
  const auto big = ay > tan_3pi_8 * ax;
  const auto mid = ay > 0.66 * ax;
  const T num = select(big, -ax, select(mid, ay - ax, ay));
  const T den = select(big, ay, select(mid, ay + ax, ax));
  const T r = num / den;
  const T base = select(big, splat<T>(pi / 2), select(mid, splat<T>(pi / 4), splat<T>(0.0)));
  const T extra = select(big, splat<T>(more_bits), select(mid, splat<T>(0.5 * more_bits), splat<T>(0.0)));
  const T z = r * r;
  const T p = (((p0 * z + p1) * z + p2) * z + p3) * z + p4;
  const T q = ((((z + q0) * z + q1) * z + q2) * z + q3) * z + q4;
  const T u = base + ((r * (z * p / q) + r) + extra);
  const T right = select(y < 0.0, -u, u);
  const T left = select(y >= 0.0, pi - u, u - pi);
  const T axis = select(y > 0.0, splat<T>(pi / 2), select(y < 0.0, splat<T>(-pi / 2), splat<T>(0.0)));
  return select(x == 0.0, axis, select(x > 0.0, right, left));
}

}  // namespace embra::lanes
