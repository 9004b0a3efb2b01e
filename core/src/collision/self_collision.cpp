// Self-collision: broad phase, narrow phase in space-time, projection and friction (see the header).
#include "collision/self_collision.hpp"

#include "common/friction.hpp"
#include "common/pool.hpp"
#include "common/triangle.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace embra::self_collision {

namespace {

/// The smallest separation kept between two primitives whose bodies have no thickness (m).
constexpr double kMinGap = 1e-6;
// A pair's gap (a lower bound of its distance less its thickness) skips its exact distance when it
// exceeds the pair's motion by this much times (1 + the largest coordinate magnitude): far more than
// the rounding of a distance and of a million shifts subtracted from it.
constexpr double kGapTolerance = 1e-9;

/// A particle's region, in which the self-collision candidate pairs stay valid: its swept bounds,
/// stretched ahead along its motion by kRegionAhead times that motion (where it will be in the next
/// substeps if it goes on as it goes) and grown all round by kRegionThickness times its half
/// thickness. Larger regions are left less often but keep more pairs, whose gaps are updated every
/// substep. On the folded-cloth benchmark (bench/self_collision_bench.cpp, n = 64, one thread,
/// cachegrind, 30 frames): 17.54 G instructions at these values; 20.13 G grown by half the half
/// thickness plus half the motion, 17.81 G by a quarter of the half thickness plus an eighth of the
/// motion, 17.52 G by a fifth of the half thickness; with a quarter of each, 18.05 G stretched 8
/// substeps ahead, 19.17 G 4 ahead, 18.44 G 12 ahead. Twice the half thickness or more cost 40 % and
/// more in wall time, a larger share of the motion too.
constexpr double kRegionAhead = 8.0;
constexpr double kRegionThickness = 0.25;
/// Items per leaf of the broad phase's hierarchy.
constexpr int32_t kLeafItems = 4;
/// Consecutive items (in leaf order) whose changed primitives share one walk of the hierarchy.
constexpr size_t kQueryGroup = 16;

/// Whether boxes a and b (lo and hi indexed 0-2) overlap: all six compared, one branch for the
/// caller, seldom mispredicted.
template <class B>
bool overlap(const B& a, const B& b) {
  return static_cast<bool>(static_cast<int>(a.lo[0] <= b.hi[0]) & static_cast<int>(b.lo[0] <= a.hi[0]) &
                           static_cast<int>(a.lo[1] <= b.hi[1]) & static_cast<int>(b.lo[1] <= a.hi[1]) &
                           static_cast<int>(a.lo[2] <= b.hi[2]) & static_cast<int>(b.lo[2] <= a.hi[2]));
}

struct Box {
  Vec3 lo, hi;
  bool overlaps(const Box& o) const { return overlap(*this, o); }
  double extent() const { return (hi - lo).maxCoeff(); }
  /// The box holding nothing: any box united with it is that box.
  static Box empty() {
    return {Vec3::Constant(std::numeric_limits<double>::infinity()),
            Vec3::Constant(-std::numeric_limits<double>::infinity())};
  }
  void unite(const Box& o) {
    lo = lo.cwiseMin(o.lo);
    hi = hi.cwiseMax(o.hi);
  }
};

/// v as a float rounded toward `dir` (-1 down, 1 up); NaN stays NaN. FloatBox::outward's values
/// (its SSE2 path gives the same bits, three coordinates at a time).
[[maybe_unused]] float to_float(double v, float dir) {
  constexpr float big = std::numeric_limits<float>::max(), inf = std::numeric_limits<float>::infinity();
  if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
  if (v > big) return dir < 0.0f ? big : inf;
  if (v < -big) return dir < 0.0f ? -inf : -big;
  const float f = static_cast<float>(v);
  if (dir < 0.0f ? !(static_cast<double>(f) > v) : !(static_cast<double>(f) < v)) return f;
  // one step toward dir: the next float's bits (f is finite here)
  if (f == 0.0f) return dir * std::numeric_limits<float>::denorm_min();
  const uint32_t bits = std::bit_cast<uint32_t>(f);
  return std::bit_cast<float>((f > 0.0f) == (dir > 0.0f) ? bits + 1 : bits - 1);
}
#if defined(__SSE2__)
/// v's three coordinates as floats rounded down (up when `up`), in lanes 0-2 (FloatBox::outward).
inline __m128 step_outward(const Vec3& v, bool up) {
  const __m128d v01 = _mm_loadu_pd(v.data()), v2 = _mm_set1_pd(v.z());
  const __m128 f = _mm_movelh_ps(_mm_cvtpd_ps(v01), _mm_cvtpd_ps(v2));
  const __m128d b01 = _mm_cvtps_pd(f), b2 = _mm_cvtps_pd(_mm_movehl_ps(f, f));
  const __m128d w01 = up ? _mm_cmplt_pd(b01, v01) : _mm_cmpgt_pd(b01, v01);
  const __m128d w2 = up ? _mm_cmplt_pd(b2, v2) : _mm_cmpgt_pd(b2, v2);
  // (an infinite v too: to_float gives the largest float toward the inside)
  const __m128 inf = _mm_set1_ps(up ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity());
  const __m128i wrong = _mm_castps_si128(
      _mm_or_ps(_mm_shuffle_ps(_mm_castpd_ps(w01), _mm_castpd_ps(w2), _MM_SHUFFLE(2, 0, 2, 0)), _mm_cmpeq_ps(f, inf)));
  const __m128i bits = _mm_castps_si128(f), sign = _mm_srai_epi32(bits, 31);  // 0 or -1
  // down: +1 where negative, -1 where not; up: the opposite
  const __m128i twice = _mm_add_epi32(sign, sign);
  const __m128i delta = up ? _mm_add_epi32(_mm_set1_epi32(1), twice) : _mm_sub_epi32(_mm_set1_epi32(-1), twice);
  return _mm_castsi128_ps(_mm_add_epi32(bits, _mm_and_si128(delta, wrong)));
}
#endif

/// A box's bounds rounded outward to floats: a filter for Box::overlaps that half the bytes feed
/// (what overlaps as Box overlaps as FloatBox).
struct FloatBox {
  float lo[3], hi[3];
  static FloatBox outward(const Box& b) {
#if defined(__SSE2__)
    // to_float's values, four lanes at a time: each coordinate rounded to the nearest float, and
    // where that lies on the wrong side, moved one step outward by its bits (a negative float's
    // bits grow away from zero, a positive one's toward it; -0 steps down to -denorm_min, +0 up to
    // +denorm_min; an infinity on the wrong side steps back to the largest float; NaN stays).
    const __m128 lo = step_outward(b.lo, false), hi = step_outward(b.hi, true);
    alignas(16) float out[8];
    _mm_store_ps(out, lo);
    _mm_store_ps(out + 4, hi);
    return {{out[0], out[1], out[2]}, {out[4], out[5], out[6]}};
#else
    return {{to_float(b.lo.x(), -1.0f), to_float(b.lo.y(), -1.0f), to_float(b.lo.z(), -1.0f)},
            {to_float(b.hi.x(), 1.0f), to_float(b.hi.y(), 1.0f), to_float(b.hi.z(), 1.0f)}};
#endif
  }
  static FloatBox empty() {
    constexpr float inf = std::numeric_limits<float>::infinity();
    return {{inf, inf, inf}, {-inf, -inf, -inf}};
  }
  bool overlaps(const FloatBox& o) const {
    return overlap(*this, o);
  }
  void unite(const FloatBox& o) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], o.lo[a]);
      hi[a] = std::max(hi[a], o.hi[a]);
    }
  }
};

/// Up to N boxes as FloatBoxes side by side, so that a box is tested against all of them in a few
/// vector instructions.
template <size_t N>
class FloatBoxes {
 public:
  static_assert(N % 4 == 0 && N <= 64);
  void add(const Box& b) {
    const FloatBox f = FloatBox::outward(b);
    for (int a = 0; a < 3; ++a) {
      lo_[a][size_] = f.lo[a];
      hi_[a][size_] = f.hi[a];
    }
    ++size_;
  }
  size_t size() const { return size_; }
  /// Bit c set where box c may overlap q: set for every box that overlaps it.
  uint64_t may_overlap(const FloatBox& q) const {
    uint64_t mask = 0;
#if defined(__SSE2__)
    const __m128 qlx = _mm_set1_ps(q.lo[0]), qly = _mm_set1_ps(q.lo[1]), qlz = _mm_set1_ps(q.lo[2]);
    const __m128 qhx = _mm_set1_ps(q.hi[0]), qhy = _mm_set1_ps(q.hi[1]), qhz = _mm_set1_ps(q.hi[2]);
    for (size_t c = 0; c < size_; c += 4) {
      __m128 hit = _mm_and_ps(_mm_cmple_ps(_mm_load_ps(&lo_[0][c]), qhx), _mm_cmple_ps(qlx, _mm_load_ps(&hi_[0][c])));
      hit = _mm_and_ps(
          hit, _mm_and_ps(_mm_cmple_ps(_mm_load_ps(&lo_[1][c]), qhy), _mm_cmple_ps(qly, _mm_load_ps(&hi_[1][c]))));
      hit = _mm_and_ps(
          hit, _mm_and_ps(_mm_cmple_ps(_mm_load_ps(&lo_[2][c]), qhz), _mm_cmple_ps(qlz, _mm_load_ps(&hi_[2][c]))));
      mask |= static_cast<uint64_t>(_mm_movemask_ps(hit)) << c;
    }
#else
    for (size_t c = 0; c < size_; ++c) {
      const FloatBox b{{lo_[0][c], lo_[1][c], lo_[2][c]}, {hi_[0][c], hi_[1][c], hi_[2][c]}};
      mask |= static_cast<uint64_t>(b.overlaps(q)) << c;
    }
#endif
    return size_ == 64 ? mask : mask & ((uint64_t{1} << size_) - 1u);
  }

 private:
  alignas(16) float lo_[3][N]{}, hi_[3][N]{};
  size_t size_ = 0;
};

/// A spatial hash of boxes: every box is listed in the buckets of the cells it overlaps, buckets
/// filled by a counting sort so each lists its boxes in increasing index. A box covering more than
/// kMaxCells cells (a very fast or very large primitive) goes to a list checked by every query.
class Grid {
 public:
  void build(std::span<const Box> boxes, double cell) {
    boxes_ = boxes;
    inv_cell_ = 1.0 / cell;
    big_.clear();
    // Each box's cells once (the six floors), its entry and its cells' buckets in the order the
    // fill reads them; then a counting sort of the entries by bucket.
    const size_t n = boxes.size();
    box_entry_.resize(n);
    box_cells_.resize(n);
    bucket_of_.clear();
    for (size_t i = 0; i < n; ++i) {
      const Span c = span_of(boxes[i]);
      box_cells_[i] = c.cells;
      if (c.cells > kMaxCells) {
        big_.push_back(static_cast<int32_t>(i));
        continue;
      }
      box_entry_[i] = entry_of(boxes[i], c, static_cast<int32_t>(i));
      for_cells(c, [&](uint32_t bucket_hash, int64_t, int64_t, int64_t) { bucket_of_.push_back(bucket_hash); });
    }
    const size_t entries = bucket_of_.size();
    size_t size = 16;
    while (size < 2 * entries) size *= 2;
    mask_ = size - 1;
    // start_[b] counts bucket b's entries, then becomes the end of its range (a running sum); the
    // fill walks the boxes backwards, placing each entry just below its bucket's end, so each bucket
    // lists its boxes in increasing index and start_[b] ends as its beginning.
    start_.assign(size + 1, 0);
    for (uint32_t& h : bucket_of_) {
      h &= static_cast<uint32_t>(mask_);
      ++start_[h];
    }
    int32_t sum = 0;
    for (size_t k = 0; k < size; ++k) start_[k] = sum += start_[k];
    start_[size] = sum;
    items_.resize(entries);
    size_t at = entries;
    for (size_t i = n; i-- > 0;) {
      if (box_cells_[i] > kMaxCells) continue;
      at -= static_cast<size_t>(box_cells_[i]);
      const Entry& entry = box_entry_[i];
      for (int64_t c = box_cells_[i]; c-- > 0;) items_[--start_[bucket_of_[at + static_cast<size_t>(c)]]] = entry.index;
    }
  }

  /// Appends the boxes overlapping `q` to `out`, each once, in a deterministic order (cell by cell,
  /// increasing index within a cell). A pair is reported only in the cell holding the low corner of
  /// the two boxes' intersection, so no sort is needed to drop the duplicates.
  void query(const Box& q, std::vector<int32_t>& out) const {
    const Span c = span_of(q);
    if (c.cells > kMaxCells) {  // a huge query: every box
      for (size_t i = 0; i < boxes_.size(); ++i)
        if (boxes_[i].overlaps(q)) out.push_back(static_cast<int32_t>(i));
      return;
    }
    const int64_t* ql = c.lo;
    const Entry qf = entry_of(q, c, -1);
    for_cells(c, [&](uint32_t hash, int64_t i, int64_t j, int64_t k) {
      const size_t bucket = hash & mask_;
      const int32_t first = start_[bucket], last = start_[bucket + 1];
      for (int32_t e = first; e < last; ++e) {
        const Entry& f = box_entry_[items_[e]];
        if (!f.box.overlaps(qf.box)) continue;  // the float boxes hold the double ones: nothing overlapping is missed
        if (f.low[0] != kFar) {                 // the low cell, when it fits in 32 bits
          if (std::max<int64_t>(f.low[0], ql[0]) != i || std::max<int64_t>(f.low[1], ql[1]) != j ||
              std::max<int64_t>(f.low[2], ql[2]) != k)
            continue;
        }
        const Box& b = boxes_[f.index];
        if (!b.overlaps(q)) continue;
        if (f.low[0] == kFar && (std::max(coord(b.lo.x()), ql[0]) != i || std::max(coord(b.lo.y()), ql[1]) != j ||
                                 std::max(coord(b.lo.z()), ql[2]) != k))
          continue;
        if (e > first && f.index == items_[e - 1]) continue;  // two of its cells share the bucket
        out.push_back(f.index);
      }
    });
    for (int32_t e : big_)
      if (boxes_[e].overlaps(q)) out.push_back(e);
  }

 private:
  static constexpr int64_t kMaxCells = 512;

  /// The cell of a coordinate, clamped to +-1e15 cells; NaN (a step about to fail) goes to -1e15.
  int64_t coord(double v) const {
    const double c = std::floor(v * inv_cell_);
    if (!(c > -1e15)) return -1000000000000000;
    if (!(c < 1e15)) return 1000000000000000;
    return static_cast<int64_t>(c);
  }
  /// The cells a box covers: its lowest and highest cell and their count, or kMaxCells + 1 for more
  /// (or for a box whose corners are not ordered, which only non-finite coordinates make).
  struct Span {
    int64_t lo[3], hi[3];
    int64_t cells;
  };
  Span span_of(const Box& b) const {
    Span s{};
    s.cells = 1;
    for (int a = 0; a < 3; ++a) {
      s.lo[a] = coord(b.lo[a]);
      s.hi[a] = coord(b.hi[a]);
      const int64_t span = s.hi[a] - s.lo[a] + 1;
      if (span < 1 || span > kMaxCells || s.cells > kMaxCells)
        s.cells = kMaxCells + 1;
      else
        s.cells = std::min(s.cells * span, kMaxCells + 1);
    }
    return s;
  }
  /// Calls f(hash, i, j, k) for each cell (i, j, k) of a span of at most kMaxCells cells, in the
  /// order k, j, i (slowest to fastest); hash & mask_ is the cell's bucket.
  template <class F>
  static void for_cells(const Span& s, F&& f) {
    for (int64_t k = s.lo[2]; k <= s.hi[2]; ++k) {
      // A block of 4 x 4 x 4 cells hashed together, its cells in consecutive buckets: a query's
      // cells, and the next primitive's, lie close in memory.
      const uint64_t hk = (static_cast<uint64_t>(k) >> 2) * 83492791u, lk = (static_cast<uint64_t>(k) & 3) << 4;
      for (int64_t j = s.lo[1]; j <= s.hi[1]; ++j) {
        const uint64_t hj = hk ^ (static_cast<uint64_t>(j) >> 2) * 19349663u, lj = lk | (static_cast<uint64_t>(j) & 3)
                                                                                            << 2;
        for (int64_t i = s.lo[0]; i <= s.hi[0]; ++i) {
          const uint64_t h = (((static_cast<uint64_t>(i) >> 2) * 73856093u ^ hj) * 0x9E3779B97F4A7C15ull) >> 20 << 6 |
                             lj | (static_cast<uint64_t>(i) & 3);
          f(static_cast<uint32_t>(h), i, j, k);
        }
      }
    }
  }

  std::span<const Box> boxes_;
  double inv_cell_ = 1.0;
  size_t mask_ = 0;
  static constexpr int32_t kFar = std::numeric_limits<int32_t>::min();
  /// A box in a bucket: its bounds rounded outward to floats (a bucket's scan reads half the bytes),
  /// its lowest cell and its index.
  struct Entry {
    FloatBox box;
    int32_t low[3];  // the box's lowest cell, or kFar in low[0] when a coordinate does not fit
    int32_t index;
  };
  Entry entry_of(const Box& b, const Span& s, int32_t index) const {
    Entry e{};
    e.box = FloatBox::outward(b);
    bool fits = true;
    for (int a = 0; a < 3; ++a) {
      const int64_t c = s.lo[a];
      fits = fits && c > kFar && c <= std::numeric_limits<int32_t>::max();
      e.low[a] = fits ? static_cast<int32_t>(c) : kFar;
    }
    if (!fits) e.low[0] = kFar;
    e.index = index;
    return e;
  }
  std::vector<int32_t> start_, big_;
  std::vector<int32_t> items_;  // the boxes of each bucket
  // The build's scratch: each box's entry and cell count, and the buckets of its cells in order.
  std::vector<Entry> box_entry_;
  std::vector<int64_t> box_cells_;
  std::vector<uint32_t> bucket_of_;
};

/// Mean of the boxes' largest extents: the cell size that keeps the cells per box bounded.
double mean_extent(std::span<const Box> boxes) {
  double sum = 0.0;
  for (const Box& b : boxes) sum += b.extent();
  const double mean = boxes.empty() ? 0.0 : sum / static_cast<double>(boxes.size());
  return mean > 0.0 && std::isfinite(mean) ? mean : 1.0;
}

Box box_of(std::initializer_list<Vec3> points, double grow) {
  Box b = Box::empty();
  for (const Vec3& p : points) {
    b.lo = b.lo.cwiseMin(p);
    b.hi = b.hi.cwiseMax(p);
  }
  b.lo.array() -= grow;
  b.hi.array() += grow;
  return b;
}

/// Roots of d3 t^3 + d2 t^2 + d1 t + d0 in [0, 1], ascending: the cubic is cut at its critical
/// points into monotone pieces, each bisected where it changes sign; a piece's end where the cubic
/// (nearly) vanishes counts too, which catches double roots.
int cubic_roots(double d0, double d1, double d2, double d3, double roots[3]) {
  const double scale = std::abs(d0) + std::abs(d1) + std::abs(d2) + std::abs(d3);
  if (!(scale > 0.0) || !std::isfinite(scale)) return 0;  // identically coplanar: no single time
  auto f = [&](double t) { return ((d3 * t + d2) * t + d1) * t + d0; };
  const double tiny = 1e-13 * scale;
  // |f| >= |d0| - |d1| - |d2| - |d3| on [0, 1]: beyond 2 tiny, every f evaluated below (Horner's
  // rounding is under 1e-15 scale) keeps d0's sign and clears tiny, so no piece yields a root. Most
  // pairs near contact stay on one side of the plane in a substep; this skips their pieces.
  if (std::abs(d0) - (std::abs(d1) + std::abs(d2) + std::abs(d3)) > 2.0 * tiny) return 0;
  double cuts[4] = {0.0, 0.0, 0.0, 1.0};
  int nc = 1;
  // critical points: 3 d3 t^2 + 2 d2 t + d1 = 0
  const double qa = 3.0 * d3, qb = 2.0 * d2, qc = d1;
  double crit[2];
  int ncrit = 0;
  if (std::abs(qa) > 1e-300) {
    const double disc = qb * qb - 4.0 * qa * qc;
    if (disc >= 0.0) {
      const double sq = std::sqrt(disc);
      const double q = -0.5 * (qb + std::copysign(sq, qb));
      if (q != 0.0) {
        crit[ncrit++] = q / qa;
        crit[ncrit++] = qc / q;
      } else {
        crit[ncrit++] = 0.0;
      }
    }
  } else if (std::abs(qb) > 1e-300) {
    crit[ncrit++] = -qc / qb;
  }
  std::sort(crit, crit + ncrit);
  for (int k = 0; k < ncrit; ++k)
    if (crit[k] > 0.0 && crit[k] < 1.0) cuts[nc++] = crit[k];
  cuts[nc++] = 1.0;
  int n = 0;
  auto add = [&](double t) {
    if (n == 0 || t > roots[n - 1] + 1e-12) roots[n++] = t;
  };
  for (int k = 0; k + 1 < nc && n < 3; ++k) {
    double lo = cuts[k], hi = cuts[k + 1];
    double flo = f(lo), fhi = f(hi);
    if (std::abs(flo) <= tiny) {
      add(lo);
      continue;
    }
    if ((flo < 0.0) == (fhi < 0.0) && std::abs(fhi) > tiny) continue;
    if (std::abs(fhi) <= tiny) {
      add(hi);
      continue;
    }
    for (int it = 0; it < 80 && hi - lo > 1e-15; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double fm = f(mid);
      if ((fm < 0.0) == (flo < 0.0)) {
        lo = mid;
        flo = fm;
      } else {
        hi = mid;
      }
    }
    add(hi);
  }
  return n;
}

/// Coefficients of det[e1(t), e2(t), e3(t)] with e_k(t) = E_k + t V_k.
void coplanarity_cubic(const Vec3& E1, const Vec3& E2, const Vec3& E3, const Vec3& V1, const Vec3& V2, const Vec3& V3,
                       double d[4]) {
  d[0] = E1.cross(E2).dot(E3);
  d[1] = V1.cross(E2).dot(E3) + E1.cross(V2).dot(E3) + E1.cross(E2).dot(V3);
  d[2] = V1.cross(V2).dot(E3) + V1.cross(E2).dot(V3) + E1.cross(V2).dot(V3);
  d[3] = V1.cross(V2).dot(V3);
}

Vec3 lerp(const Vec3& a, const Vec3& b, double t) {
  return a + t * (b - a);
}

// --- exact arithmetic (Shewchuk's expansions) ---------------------------------------------------

void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}

void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

/// e <- e + b, exactly (e nonoverlapping, increasing magnitude, no zeros).
void grow(std::vector<double>& e, double b) {
  if (b == 0.0) return;
  double q = b;
  size_t out = 0;
  for (size_t i = 0; i < e.size(); ++i) {
    double s, h;
    two_sum(q, e[i], s, h);
    q = s;
    if (h != 0.0) e[out++] = h;
  }
  e.resize(out);
  if (q != 0.0) e.push_back(q);
}

int exact_orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Exact differences u = b - a, v = c - a, w = d - a as (hi, lo) pairs, then the determinant as the
  // sum of every product of three components: 6 signed permutations x 8 products x 4 exact parts.
  double u[3][2], v[3][2], w[3][2];
  for (int k = 0; k < 3; ++k) {
    two_sum(b[k], -a[k], u[k][0], u[k][1]);
    two_sum(c[k], -a[k], v[k][0], v[k][1]);
    two_sum(d[k], -a[k], w[k][0], w[k][1]);
  }
  static constexpr int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {1, 0, 2}, {2, 1, 0}};
  static constexpr double signs[6] = {1, 1, 1, -1, -1, -1};
  std::vector<double> e;
  e.reserve(64);
  for (int p = 0; p < 6; ++p)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) {
          const double x = u[perms[p][0]][i], y = v[perms[p][1]][j], z = w[perms[p][2]][k];
          if (x == 0.0 || y == 0.0 || z == 0.0) continue;
          double p1, e1;
          two_product(x, y, p1, e1);
          double p2, e2, p3, e3;
          two_product(p1, z, p2, e2);
          two_product(e1, z, p3, e3);
          grow(e, signs[p] * p2);
          grow(e, signs[p] * e2);
          grow(e, signs[p] * p3);
          grow(e, signs[p] * e3);
        }
  if (e.empty()) return 0;
  return e.back() > 0.0 ? 1 : -1;
}

}  // namespace

}  // namespace embra::self_collision

namespace embra {

/// What the broad phase keeps from substep to substep besides the pairs (SelfCollisionCache):
/// each primitive's region box, each particle's reach, and a bounding-volume hierarchy over the
/// region boxes, built once for the primitives' topology and refitted when regions change. Its
/// leaves hold items: a triangle with the particles and edges it owns (each particle and edge owned
/// by the first triangle holding it), or, for a particle or edge in no triangle, an item of its own.
/// Items are stored in leaf order.
struct SelfCollisionIndex {
  std::vector<self_collision::Box> tri_boxes, edge_boxes, point_boxes;  // point_boxes in points order
  std::vector<double> reach;                                            // per particle: its region's diagonal
  struct Node {
    self_collision::FloatBox box;
    int32_t first = 0, count = 0;  // a leaf's items [first, first + count); count 0: internal
    int32_t right = 0;             // internal: the right child (the left is the next node)
  };
  std::vector<Node> nodes;  // pre-order: a child after its parent
  /// The walks' view of `nodes`: an internal node's children, an internal child replaced by its own
  /// two while there are fewer than four, their boxes side by side (one test for the four).
  struct Wide {
    float lo[3][4], hi[3][4];  // per coordinate, per slot (an unused slot holds the empty box)
    int32_t node[4];           // the slots' nodes (-1: unused)
    int32_t wide[4];           // an internal slot's own Wide (-1: a leaf or unused)
  };
  std::vector<Wide> wide;                          // the root's first (none when the root is a leaf)
  std::vector<int32_t> item_tri;                   // per item: its triangle, or -1
  std::vector<int32_t> point_begin, owned_points;  // per item: the particles it owns (points order)
  std::vector<int32_t> edge_begin, owned_edges;    // per item: the edges it owns
  std::vector<self_collision::FloatBox> item_box;  // per item: its primitives' region boxes
  // The owned particles' and edges' region boxes as FloatBoxes, in the order of owned_points and
  // owned_edges (a walk reads them in turn).
  std::vector<self_collision::FloatBox> owned_point_box, owned_edge_box;
  // Where a changed particle's marks go (the topology's, with the items): per point (points order)
  // the triangles and edges holding it; per triangle, edge and point the item that holds it.
  std::vector<int32_t> point_tri_begin, point_tris, point_edge_begin, point_edges;
  std::vector<int32_t> tri_item, edge_item, point_item;
  // The refit's way up: per node its parent (-1 at the root) and its Wide slot (4 w + slot, or -1),
  // per item its leaf; per node a mark while it waits to be refitted.
  std::vector<int32_t> node_parent, node_slot, item_leaf;
  std::vector<uint8_t> node_dirty;
  std::vector<Vec3> start;     // the positions at the start of the last substep
  std::vector<double> radius;  // the half thicknesses the pairs' gaps were measured with
  std::vector<Vec3> rest;      // the bodies' rest shapes (points order) near_at_rest was found in
  // The same body's pairs within their thickness in its rest shape (neighbours on the surface,
  // never kept), sorted: point p and triangle t as p nt + t, edges ea < eb as ea ne + eb.
  std::vector<uint64_t> near_at_rest_pt, near_at_rest_ee;
};

}  // namespace embra

namespace embra::self_collision {

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 u = b - a, v = c - a, w = d - a;
  const double det = u.x() * (v.y() * w.z() - v.z() * w.y()) + u.y() * (v.z() * w.x() - v.x() * w.z()) +
                     u.z() * (v.x() * w.y() - v.y() * w.x());
  const double perm = std::abs(u.x()) * (std::abs(v.y() * w.z()) + std::abs(v.z() * w.y())) +
                      std::abs(u.y()) * (std::abs(v.z() * w.x()) + std::abs(v.x() * w.z())) +
                      std::abs(u.z()) * (std::abs(v.x() * w.y()) + std::abs(v.y() * w.x()));
  // The differences themselves are rounded, so the bound is taken generously (Shewchuk's
  // o3derrboundA is about 7 eps of the permanent for exact differences; rounded ones add 3 eps per
  // product): anything closer to 0 is decided exactly.
  constexpr double eps = 0x1.0p-53;
  const double bound = 32.0 * eps * perm;
  if (det > bound) return 1;
  if (det < -bound) return -1;
  return exact_orient3d(a, b, c, d);
}

bool segment_crosses_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const int op = orient3d(a, b, c, p), oq = orient3d(a, b, c, q);
  if (op == 0 || oq == 0 || op == oq) return false;
  const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

int64_t count_edge_triangle_crossings(std::span<const Vec3> x, std::span<const int32_t> edges,
                                      std::span<const int32_t> triangles) {
  const size_t nt = triangles.size() / 3;
  std::vector<Box> boxes(nt);
  for (size_t t = 0; t < nt; ++t)
    boxes[t] = box_of({x[triangles[3 * t]], x[triangles[3 * t + 1]], x[triangles[3 * t + 2]]}, 0.0);
  Grid grid;
  grid.build(boxes, mean_extent(boxes));
  std::vector<int32_t> cand;
  int64_t count = 0;
  for (size_t e = 0; e + 1 < edges.size(); e += 2) {
    const int32_t p = edges[e], q = edges[e + 1];
    cand.clear();
    grid.query(box_of({x[p], x[q]}, 0.0), cand);
    for (int32_t t : cand) {
      const int32_t* v = &triangles[3 * static_cast<size_t>(t)];
      if (v[0] == p || v[1] == p || v[2] == p || v[0] == q || v[1] == q || v[2] == q) continue;
      if (segment_crosses_triangle(x[p], x[q], x[v[0]], x[v[1]], x[v[2]])) ++count;
    }
  }
  return count;
}

// --- narrow phase ----------------------------------------------------------------------------------

double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, double bary[3]) {
  // Ericson, Real-Time Collision Detection, 5.1.5: by Voronoi region of the triangle.
  auto set = [&](double u, double v, double w) {
    bary[0] = u;
    bary[1] = v;
    bary[2] = w;
    return (p - (u * a + v * b + w * c)).norm();
  };
  const TriangleRegion r = triangle_region(p, a, b, c);
  switch (r.feature) {
    case TriangleRegion::vertex_a:
      return set(1, 0, 0);
    case TriangleRegion::vertex_b:
      return set(0, 1, 0);
    case TriangleRegion::vertex_c:
      return set(0, 0, 1);
    case TriangleRegion::edge_ab:
      return set(1 - r.t, r.t, 0);
    case TriangleRegion::edge_ac:
      return set(1 - r.t, 0, r.t);
    case TriangleRegion::edge_bc:
      return set(0, 1 - r.t, r.t);
    default:
      break;
  }
  if (!(r.sum > 0.0)) {  // degenerate triangle: the nearest of its edges
    double best = std::numeric_limits<double>::infinity(), s, t;
    const Vec3* v[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
      const double d = edge_edge_distance(p, p, *v[k], *v[(k + 1) % 3], s, t);
      if (d < best) {
        best = d;
        double w[3] = {0, 0, 0};
        w[k] = 1 - t;
        w[(k + 1) % 3] = t;
        bary[0] = w[0];
        bary[1] = w[1];
        bary[2] = w[2];
      }
    }
    return best;
  }
  return set(1.0 - r.v - r.w, r.v, r.w);
}

double edge_edge_distance(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1, double& s, double& t) {
  // Ericson 5.1.9, with the degenerate cases.
  const Vec3 d1 = a1 - a0, d2 = b1 - b0, r = a0 - b0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double tiny = 1e-300;
  if (a <= tiny && e <= tiny) {
    s = t = 0.0;
  } else if (a <= tiny) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= tiny) {
      t = 0.0;
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((a0 + s * d1) - (b0 + t * d2)).norm();
}

bool point_triangle_toi(const Vec3& p0, const Vec3& p1, const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                        const Vec3& c0, const Vec3& c1, double tolerance, double& t) {
  double d[4];
  coplanarity_cubic(b0 - a0, c0 - a0, p0 - a0, (b1 - a1) - (b0 - a0), (c1 - a1) - (c0 - a0), (p1 - a1) - (p0 - a0), d);
  double roots[3];
  const int n = cubic_roots(d[0], d[1], d[2], d[3], roots);
  for (int k = 0; k < n; ++k) {
    double bary[3];
    const double tk = roots[k];
    if (point_triangle_distance(lerp(p0, p1, tk), lerp(a0, a1, tk), lerp(b0, b1, tk), lerp(c0, c1, tk), bary) <=
        tolerance) {
      t = tk;
      return true;
    }
  }
  return false;
}

bool edge_edge_toi(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1, const Vec3& a0e, const Vec3& a1e,
                   const Vec3& b0e, const Vec3& b1e, double tolerance, double& t) {
  double d[4];
  coplanarity_cubic(a1 - a0, b1 - b0, b0 - a0, (a1e - a0e) - (a1 - a0), (b1e - b0e) - (b1 - b0),
                    (b0e - a0e) - (b0 - a0), d);
  double roots[3];
  const int n = cubic_roots(d[0], d[1], d[2], d[3], roots);
  for (int k = 0; k < n; ++k) {
    double s, u;
    const double tk = roots[k];
    if (edge_edge_distance(lerp(a0, a0e, tk), lerp(a1, a1e, tk), lerp(b0, b0e, tk), lerp(b1, b1e, tk), s, u) <=
        tolerance) {
      t = tk;
      return true;
    }
  }
  return false;
}

// --- detection -------------------------------------------------------------------------------------

}  // namespace embra::self_collision

namespace embra {

/// find_contacts' working arrays, one set per world (SelfCollisionCache::scratch), kept from substep
/// to substep for their storage. Not thread_local: a host thread that steps a world and ends would
/// tear them down with MinGW's thread-exit destructors, which can free their storage first.
struct SelfCollisionScratch {
  using Box = self_collision::Box;
  std::vector<int32_t> tris, edges, points;  // world indices: 3, 2, 1 per primitive
  std::vector<int32_t> tri_body, edge_body;
  std::vector<int32_t> left;  // the particles that left their regions (points order)
  std::vector<uint8_t> changed, tri_changed, edge_changed, outside;
  std::vector<uint8_t> item_changed;                                // per item: holds a changed primitive
  std::vector<int32_t> changed_tris, changed_edges, changed_items;  // the marks' lists
  std::vector<int32_t> groups;  // the groups of kQueryGroup items holding a changed item
  std::vector<Box> moved;       // per particle: its start and end, not grown
  std::vector<double> motion;   // per particle: |x - x_prev| in this substep
  std::vector<double> shift;    // per particle: how far x_prev is from the last substep's (inf: unknown)
  // Per particle, triangle and edge: this substep's swept bounds and the largest motion and shift of
  // its vertices, in one cache line (a kept pair's filter reads both for each side). A particle's
  // motion and shift are also kept dense above, for the passes over the primitives' vertices.
  struct alignas(64) Swept {
    Box box;
    double motion, shift;
  };
  std::vector<Swept> swept_point, swept_tri, swept_edge;
  std::vector<double> part_scale;  // per part of the pool: the largest coordinate magnitude seen
  std::vector<int32_t> near;       // the kept pairs whose distance is measured in this substep
  // One list per thread of the pool: candidate pairs, contacts (gather).
  std::vector<std::vector<int32_t>> part_pairs, part_ee_pairs;
  std::vector<std::vector<SelfContact>> part_contacts;
  std::vector<std::pair<size_t, size_t>> part_kept;  // keep(): the kept pairs' range of each part
  // The contacts' sort: each contact's particles as one key and its place, and the sorted contacts.
  struct Order {
    uint64_t first, second;  // ids[0] ids[1], ids[2] ids[3] (particle indices, never negative)
    uint32_t at;
  };
  std::vector<Order> order;
  std::vector<SelfContact> sorted;
};

}  // namespace embra

namespace embra::self_collision {

using Scratch = SelfCollisionScratch;

namespace {

/// Calls body(k, list) for every k of [0, n), split over the pool's threads, each part appending
/// to a list of its own; the lists are then appended to `out` in part order, which is the order one
/// loop over [0, n) gives.
template <class T, class F>
void gather(ThreadPool& pool, size_t n, size_t grain, std::vector<std::vector<T>>& parts, std::vector<T>& out,
            F&& body) {
  pool.collect(0, n, grain, parts, out, [&](size_t begin, size_t end, std::vector<T>& list) {
    for (size_t k = begin; k < end; ++k) body(k, list);
  });
}

// Items per thread below which a detection loop is not split. A group's walk of the hierarchy
// costs tens of microseconds, so a few of them are worth a hand-over; the folded 64 x 64 cloth
// queries again about 200 points, 900 triangles and 1,000 edges a substep, and boxes 4,096
// particles and 7,938 triangles.
constexpr size_t kPairGrain = 4;       // groups of items queried against the hierarchy
constexpr size_t kContactGrain = 512;  // candidate pairs measured
constexpr size_t kBoxGrain = 1024;     // particles or primitives boxed
constexpr size_t kListGrain = 256;     // changed primitives or items boxed (a few regions each)

/// gather() with two lists: body(k, first, second) for every k of [0, n), split over the pool's
/// threads as the queries are (kPairGrain), each part appending to lists of its own; the lists are
/// then appended to `first_out` and `second_out` in part order.
template <class F>
void pair_lists(ThreadPool& pool, size_t n, std::vector<std::vector<int32_t>>& first_parts,
                std::vector<std::vector<int32_t>>& second_parts, std::vector<int32_t>& first_out,
                std::vector<int32_t>& second_out, F&& body) {
  const size_t parts = static_cast<size_t>(pool.size());
  first_parts.resize(parts);
  second_parts.resize(parts);
  for (size_t part = 0; part < parts; ++part) first_parts[part].clear(), second_parts[part].clear();
  pool.run(0, n, 1, kPairGrain, [&](size_t begin, size_t end, int part) {
    const size_t at = static_cast<size_t>(part);
    for (size_t k = begin; k < end; ++k) body(k, first_parts[at], second_parts[at]);
  });
  for (size_t part = 0; part < parts; ++part) {
    first_out.insert(first_out.end(), first_parts[part].begin(), first_parts[part].end());
    second_out.insert(second_out.end(), second_parts[part].begin(), second_parts[part].end());
  }
}

/// A unit normal: `primary` if it has a length, else `fallback`, turned toward `side` (the vector
/// from the second primitive to the first at the start of the substep).
bool orient_normal(Vec3 primary, const Vec3& fallback, const Vec3& side, Vec3& n) {
  const double len = primary.norm();
  if (len > 1e-300 && std::abs(primary.dot(side)) > 1e-12 * len * side.norm()) {
    n = primary / len;
    if (n.dot(side) < 0.0) n = -n;
    return true;
  }
  const double fl = fallback.norm();
  if (fl > 1e-300) {
    n = fallback / fl;
    return true;
  }
  if (len > 1e-300) {
    n = primary / len;
    return true;
  }
  return false;
}

/// Whether p is nearer than `limit` to one of `points`: then so is anything holding that point (an
/// upper bound on a distance, without the exact one). Its rounding only ever keeps a pair more.
bool near_any(const Vec3& p, std::initializer_list<Vec3> points, double limit) {
  const double l2 = limit * limit;
  for (const Vec3& q : points)
    if ((p - q).squaredNorm() < l2) return true;
  return false;
}

/// Whether the bounding boxes of two point sets are at least `gap` apart (by a margin well above
/// the rounding): then so are any two primitives spanned by them (a lower bound on a distance,
/// without the exact one).
template <size_t A, size_t B>
bool apart(const std::array<const Vec3*, A>& a, const std::array<const Vec3*, B>& b, double gap) {
  Vec3 alo = *a[0], ahi = *a[0], blo = *b[0], bhi = *b[0];
  for (size_t k = 1; k < A; ++k) alo = alo.cwiseMin(*a[k]), ahi = ahi.cwiseMax(*a[k]);
  for (size_t k = 1; k < B; ++k) blo = blo.cwiseMin(*b[k]), bhi = bhi.cwiseMax(*b[k]);
  const Vec3 sep = (blo - ahi).cwiseMax(alo - bhi).cwiseMax(0.0);
  return sep.squaredNorm() > gap * gap * (1.0 + 1e-9);
}

double mean_mu(std::span<const double> mu, const int32_t ids[4]) {
  return std::sqrt(mu[ids[0]] * mu[ids[3]]);
}

/// Rest-shape position of a world particle of body `b`.
const Vec3& rest_of(const BodyInfo& b, int32_t i) {
  return b.rest_positions[static_cast<size_t>(i - b.first_particle)];
}

/// Builds the hierarchy's items and nodes for the primitives of `s`, split at the positions `x`
/// (median splits of the items' centres along the widest axis, kLeafItems items a leaf). Any split
/// finds the same pairs; a good one finds them sooner.
void build_hierarchy(SelfCollisionIndex& ix, const Scratch& s, std::span<const Vec3> x) {
  const size_t nt = s.tris.size() / 3, ne = s.edges.size() / 2, np = s.points.size();
  // The owners: the first triangle holding a particle or an edge, else an item of its own.
  std::vector<int32_t> point_owner(x.size(), -1), edge_owner(ne, -1);
  std::vector<std::array<int32_t, 3>> by_ends(ne);  // (lower end, higher end, edge)
  for (size_t e = 0; e < ne; ++e) {
    const int32_t a = s.edges[2 * e], b = s.edges[2 * e + 1];
    by_ends[e] = {std::min(a, b), std::max(a, b), static_cast<int32_t>(e)};
  }
  std::sort(by_ends.begin(), by_ends.end());
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t a = s.tris[3 * t + k], b = s.tris[3 * t + (k + 1) % 3];
      if (point_owner[a] < 0) point_owner[a] = static_cast<int32_t>(t);
      const std::array<int32_t, 3> key = {std::min(a, b), std::max(a, b), std::numeric_limits<int32_t>::min()};
      const auto it = std::lower_bound(by_ends.begin(), by_ends.end(), key);
      if (it != by_ends.end() && (*it)[0] == key[0] && (*it)[1] == key[1] && edge_owner[(*it)[2]] < 0)
        edge_owner[(*it)[2]] = static_cast<int32_t>(t);
    }
  std::vector<int32_t> tri_of(nt);  // per item in creation order: its triangle or -1
  std::iota(tri_of.begin(), tri_of.end(), 0);
  for (size_t e = 0; e < ne; ++e)
    if (edge_owner[e] < 0) edge_owner[e] = static_cast<int32_t>(tri_of.size()), tri_of.push_back(-1);
  for (int32_t p : s.points)
    if (point_owner[p] < 0) point_owner[p] = static_cast<int32_t>(tri_of.size()), tri_of.push_back(-1);
  const size_t items = tri_of.size();
  std::vector<std::vector<int32_t>> pts(items), eds(items);
  for (size_t k = 0; k < np; ++k) pts[static_cast<size_t>(point_owner[s.points[k]])].push_back(static_cast<int32_t>(k));
  for (size_t e = 0; e < ne; ++e) eds[static_cast<size_t>(edge_owner[e])].push_back(static_cast<int32_t>(e));
  // Each item's centre (a non-finite coordinate taken as 0, so the split's order stays strict).
  std::vector<Vec3> centre(items, Vec3::Zero());
  for (size_t k = 0; k < items; ++k) {
    Vec3 sum = Vec3::Zero();
    int count = 0;
    if (tri_of[k] >= 0)
      for (int j = 0; j < 3; ++j) sum += x[s.tris[3 * static_cast<size_t>(tri_of[k]) + j]], ++count;
    for (int32_t q : pts[k]) sum += x[s.points[static_cast<size_t>(q)]], ++count;
    for (int32_t e : eds[k])
      sum += x[s.edges[2 * static_cast<size_t>(e)]] + x[s.edges[2 * static_cast<size_t>(e) + 1]], count += 2;
    for (int a = 0; a < 3; ++a) centre[k][a] = std::isfinite(sum[a]) ? sum[a] / count : 0.0;
  }
  std::vector<int32_t> order(items);
  std::iota(order.begin(), order.end(), 0);
  ix.nodes.clear();
  ix.nodes.reserve(2 * items / kLeafItems + 2);
  auto build = [&](auto&& self, int32_t lo, int32_t hi) -> int32_t {
    const int32_t at = static_cast<int32_t>(ix.nodes.size());
    ix.nodes.emplace_back();
    if (hi - lo <= kLeafItems) {
      ix.nodes[static_cast<size_t>(at)].first = lo;
      ix.nodes[static_cast<size_t>(at)].count = hi - lo;
      return at;
    }
    auto c = [&](int32_t k) -> const Vec3& { return centre[static_cast<size_t>(order[static_cast<size_t>(k)])]; };
    Vec3 lo_c = c(lo), hi_c = lo_c;
    for (int32_t k = lo; k < hi; ++k) lo_c = lo_c.cwiseMin(c(k)), hi_c = hi_c.cwiseMax(c(k));
    int axis = 0;
    (hi_c - lo_c).maxCoeff(&axis);
    const int32_t mid = lo + (hi - lo) / 2;
    std::nth_element(order.begin() + lo, order.begin() + mid, order.begin() + hi, [&](int32_t a, int32_t b) {
      const double ca = centre[static_cast<size_t>(a)][axis], cb = centre[static_cast<size_t>(b)][axis];
      return ca < cb || (ca == cb && a < b);
    });
    self(self, lo, mid);
    const int32_t right = self(self, mid, hi);
    ix.nodes[static_cast<size_t>(at)].right = right;
    return at;
  };
  build(build, 0, static_cast<int32_t>(items));
  ix.wide.clear();
  auto widen = [&](auto&& self, int32_t at) -> int32_t {
    const auto w = static_cast<int32_t>(ix.wide.size());
    ix.wide.emplace_back();
    std::array<int32_t, 4> slots{at + 1, ix.nodes[static_cast<size_t>(at)].right, -1, -1};
    size_t used = 2;
    for (size_t k = 0; k < used && used < 4;) {  // an internal slot's children take its place
      const SelfCollisionIndex::Node& node = ix.nodes[static_cast<size_t>(slots[k])];
      if (node.count > 0) {
        ++k;
        continue;
      }
      const int32_t left = slots[k] + 1, right = node.right;
      std::copy_backward(slots.begin() + static_cast<std::ptrdiff_t>(k) + 1,
                         slots.begin() + static_cast<std::ptrdiff_t>(used),
                         slots.begin() + static_cast<std::ptrdiff_t>(used) + 1);
      slots[k] = left;
      slots[k + 1] = right;
      ++used;
      k += 2;  // breadth first: a Wide spans two levels where it can
    }
    for (size_t k = 0; k < 4; ++k) {
      const int32_t child =
          slots[k] >= 0 && ix.nodes[static_cast<size_t>(slots[k])].count == 0 ? self(self, slots[k]) : -1;
      SelfCollisionIndex::Wide& wn = ix.wide[static_cast<size_t>(w)];
      wn.node[k] = slots[k];
      wn.wide[k] = child;
      for (int a = 0; a < 3; ++a) {
        wn.lo[a][k] = std::numeric_limits<float>::infinity();
        wn.hi[a][k] = -std::numeric_limits<float>::infinity();
      }
    }
    return w;
  };
  if (ix.nodes[0].count == 0) widen(widen, 0);
  ix.item_tri.resize(items);
  ix.point_begin.assign(1, 0);
  ix.edge_begin.assign(1, 0);
  ix.owned_points.clear();
  ix.owned_edges.clear();
  for (size_t k = 0; k < items; ++k) {  // in leaf order
    const size_t item = static_cast<size_t>(order[k]);
    ix.item_tri[k] = tri_of[item];
    ix.owned_points.insert(ix.owned_points.end(), pts[item].begin(), pts[item].end());
    ix.owned_edges.insert(ix.owned_edges.end(), eds[item].begin(), eds[item].end());
    ix.point_begin.push_back(static_cast<int32_t>(ix.owned_points.size()));
    ix.edge_begin.push_back(static_cast<int32_t>(ix.owned_edges.size()));
  }
  ix.item_box.resize(items);
  ix.owned_point_box.resize(ix.owned_points.size());
  ix.owned_edge_box.resize(ix.owned_edges.size());
  // The marks' ways: each primitive's item in leaf order, each point's triangles and edges.
  std::vector<int32_t> leaf_of(items);  // per item in creation order: its place in leaf order
  for (size_t k = 0; k < items; ++k) leaf_of[static_cast<size_t>(order[k])] = static_cast<int32_t>(k);
  ix.tri_item.resize(nt);
  for (size_t t = 0; t < nt; ++t) ix.tri_item[t] = leaf_of[t];
  ix.edge_item.resize(ne);
  for (size_t e = 0; e < ne; ++e) ix.edge_item[e] = leaf_of[static_cast<size_t>(edge_owner[e])];
  ix.point_item.resize(np);
  for (size_t k = 0; k < np; ++k) ix.point_item[k] = leaf_of[static_cast<size_t>(point_owner[s.points[k]])];
  std::vector<int32_t> point_of(x.size(), -1);  // per particle: its place in points order
  for (size_t k = 0; k < np; ++k) point_of[static_cast<size_t>(s.points[k])] = static_cast<int32_t>(k);
  const auto incident = [&](const std::vector<int32_t>& ids, int arity, std::vector<int32_t>& begin,
                            std::vector<int32_t>& list) {
    begin.assign(np + 1, 0);
    for (int32_t i : ids) ++begin[static_cast<size_t>(point_of[static_cast<size_t>(i)]) + 1];
    for (size_t k = 0; k < np; ++k) begin[k + 1] += begin[k];
    list.resize(ids.size());
    std::vector<int32_t> at(begin.begin(), begin.end() - 1);
    for (size_t j = 0; j < ids.size(); ++j)
      list[static_cast<size_t>(at[static_cast<size_t>(point_of[static_cast<size_t>(ids[j])])]++)] =
          static_cast<int32_t>(j / static_cast<size_t>(arity));
  };
  incident(s.tris, 3, ix.point_tri_begin, ix.point_tris);
  incident(s.edges, 2, ix.point_edge_begin, ix.point_edges);
  // The refit's way up.
  ix.node_parent.assign(ix.nodes.size(), -1);
  ix.node_slot.assign(ix.nodes.size(), -1);
  ix.item_leaf.assign(items, 0);
  for (size_t k = 0; k < ix.nodes.size(); ++k) {
    const SelfCollisionIndex::Node& node = ix.nodes[k];
    if (node.count > 0) {
      for (int32_t j = node.first; j < node.first + node.count; ++j)
        ix.item_leaf[static_cast<size_t>(j)] = static_cast<int32_t>(k);
    } else {
      ix.node_parent[k + 1] = static_cast<int32_t>(k);
      ix.node_parent[static_cast<size_t>(node.right)] = static_cast<int32_t>(k);
    }
  }
  for (size_t w = 0; w < ix.wide.size(); ++w)
    for (size_t k = 0; k < 4; ++k)
      if (ix.wide[w].node[k] >= 0)
        ix.node_slot[static_cast<size_t>(ix.wide[w].node[k])] = static_cast<int32_t>(4 * w + k);
  ix.node_dirty.assign(ix.nodes.size(), 0);
}

/// The hierarchy refitted to the primitives' region boxes where they changed: a changed item's box
/// holds its triangle's (which holds its vertices' and edges') or those of what it owns, and each
/// node above one its children's (the other nodes keep theirs: the same boxes as a refit of
/// all). `changed`: the changed items, ascending.
void refit_hierarchy(SelfCollisionIndex& ix, std::span<const int32_t> changed, ThreadPool& pool, size_t grain) {
  pool.run(0, changed.size(), 1, grain, [&](size_t begin, size_t end, int) {
    for (size_t c = begin; c < end; ++c) {
      const size_t k = static_cast<size_t>(changed[c]);
      FloatBox owned = FloatBox::empty();
      for (int32_t j = ix.point_begin[k]; j < ix.point_begin[k + 1]; ++j)
        owned.unite(ix.owned_point_box[j] = FloatBox::outward(ix.point_boxes[ix.owned_points[j]]));
      for (int32_t j = ix.edge_begin[k]; j < ix.edge_begin[k + 1]; ++j)
        owned.unite(ix.owned_edge_box[j] = FloatBox::outward(ix.edge_boxes[ix.owned_edges[j]]));
      // (a triangle's box holds its vertices' and edges')
      ix.item_box[k] =
          ix.item_tri[k] >= 0 ? FloatBox::outward(ix.tri_boxes[static_cast<size_t>(ix.item_tri[k])]) : owned;
    }
  });
  // The nodes above them, then refitted children before parents (a child comes after its parent).
  for (int32_t item : changed)
    for (int32_t n = ix.item_leaf[static_cast<size_t>(item)]; n >= 0 && !ix.node_dirty[static_cast<size_t>(n)];
         n = ix.node_parent[static_cast<size_t>(n)])
      ix.node_dirty[static_cast<size_t>(n)] = 1;
  for (int32_t n = static_cast<int32_t>(ix.nodes.size()) - 1; n >= 0; --n) {
    if (!ix.node_dirty[static_cast<size_t>(n)]) continue;
    SelfCollisionIndex::Node& node = ix.nodes[static_cast<size_t>(n)];
    ix.node_dirty[static_cast<size_t>(n)] = 0;
    if (node.count > 0) {
      node.box = ix.item_box[static_cast<size_t>(node.first)];
      for (int32_t j = node.first + 1; j < node.first + node.count; ++j) node.box.unite(ix.item_box[j]);
    } else {
      node.box = ix.nodes[static_cast<size_t>(n) + 1].box;
      node.box.unite(ix.nodes[static_cast<size_t>(node.right)].box);
    }
    const int32_t slot = ix.node_slot[static_cast<size_t>(n)];
    if (slot < 0) continue;
    SelfCollisionIndex::Wide& w = ix.wide[static_cast<size_t>(slot / 4)];
    for (int a = 0; a < 3; ++a) {
      w.lo[a][slot % 4] = node.box.lo[a];
      w.hi[a][slot % 4] = node.box.hi[a];
    }
  }
}

/// Bit k set where slot k's box of `w` overlaps q (never for an unused slot, whose box is empty).
uint32_t overlapping_slots(const SelfCollisionIndex::Wide& w, const FloatBox& q) {
#if defined(__SSE2__)
  __m128 hit = _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(w.lo[0]), _mm_set1_ps(q.hi[0])),
                          _mm_cmple_ps(_mm_set1_ps(q.lo[0]), _mm_loadu_ps(w.hi[0])));
  hit = _mm_and_ps(hit, _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(w.lo[1]), _mm_set1_ps(q.hi[1])),
                                   _mm_cmple_ps(_mm_set1_ps(q.lo[1]), _mm_loadu_ps(w.hi[1]))));
  hit = _mm_and_ps(hit, _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(w.lo[2]), _mm_set1_ps(q.hi[2])),
                                   _mm_cmple_ps(_mm_set1_ps(q.lo[2]), _mm_loadu_ps(w.hi[2]))));
  return static_cast<uint32_t>(_mm_movemask_ps(hit));
#else
  uint32_t mask = 0;
  for (int k = 0; k < 4; ++k) {
    const FloatBox b{{w.lo[0][k], w.lo[1][k], w.lo[2][k]}, {w.hi[0][k], w.hi[1][k], w.hi[2][k]}};
    mask |= static_cast<uint32_t>(b.overlaps(q)) << k;
  }
  return mask;
#endif
}

/// Calls visit(item) for every item whose box overlaps q, in leaf order (depth first). The stack is
/// on the calling thread's own stack (a shared vector's end, written at every step, would bounce
/// between the threads' caches): the median splits halve every node, so the hierarchy is at most 31
/// deep below its root, and a Wide spans two levels with at most three slots pending.
template <class F>
void query_hierarchy(const SelfCollisionIndex& ix, const FloatBox& q, F&& visit) {
  const auto leaf = [&](const SelfCollisionIndex::Node& node) {
    for (int32_t k = node.first; k < node.first + node.count; ++k)
      if (ix.item_box[static_cast<size_t>(k)].overlaps(q)) visit(k);
  };
  if (!ix.nodes[0].box.overlaps(q)) return;
  if (ix.wide.empty()) return leaf(ix.nodes[0]);
  std::array<int32_t, 64> stack;  // a Wide's index, or ~node for a leaf
  size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int32_t at = stack[--top];
    if (at < 0) {
      leaf(ix.nodes[static_cast<size_t>(~at)]);
      continue;
    }
    const SelfCollisionIndex::Wide& w = ix.wide[static_cast<size_t>(at)];
    for (uint32_t hits = overlapping_slots(w, q); hits != 0;) {
      const int k = 31 - std::countl_zero(hits);  // the last slot first, so the first is walked first
      hits &= ~(1u << k);
      stack[top++] = w.wide[k] >= 0 ? w.wide[k] : ~w.node[k];
    }
  }
}

/// Half the smallest separation kept, for a particle of half thickness r: what its boxes grow by.
double grow_of(double r) {
  return std::max(r, 0.5 * kMinGap);
}

/// A primitive's box: the union of its particles' boxes box(i), grown by their largest half
/// thickness (of r), so that two primitives within their thickness (each side's mean) overlap.
template <class F>
[[gnu::always_inline]] inline Box grown_union(std::initializer_list<int32_t> ids, std::span<const double> r, F&& box) {
  Box b = box(*ids.begin());
  double g = grow_of(r[*ids.begin()]);
  for (auto i = ids.begin() + 1; i != ids.end(); ++i) {
    b.unite(box(*i));
    g = std::max(g, grow_of(r[*i]));
  }
  b.lo.array() -= g;
  b.hi.array() += g;
  return b;
}

/// Finds ix.near_at_rest_pt and near_at_rest_ee for the primitives of `s` and the bodies' rest
/// shapes, with the half thicknesses r: the pairs of one body that share no particle and lie
/// within their thickness at rest (their rest boxes, grown by their particles' half thicknesses,
/// overlap, in a uniform grid; then the exact distance).
void find_near_at_rest(SelfCollisionIndex& ix, const Scratch& s, std::span<const BodyInfo> bodies,
                       std::span<const double> r) {
  const size_t nt = s.tris.size() / 3, ne = s.edges.size() / 2;
  ix.near_at_rest_pt.clear();
  ix.near_at_rest_ee.clear();
  std::vector<int32_t> body_of(r.size(), -1);
  for (size_t bi = 0; bi < bodies.size(); ++bi)
    if (!bodies[bi].triangles.empty())
      std::fill_n(body_of.begin() + bodies[bi].first_particle, bodies[bi].particle_count, static_cast<int32_t>(bi));
  auto rest = [&](int32_t i) -> const Vec3& { return rest_of(bodies[static_cast<size_t>(body_of[i])], i); };
  auto rest_box = [&](std::initializer_list<int32_t> ids) {
    return grown_union(ids, r, [&](int32_t i) { return Box{rest(i), rest(i)}; });
  };
  std::vector<int32_t> found;
  Grid grid;
  std::vector<Box> boxes(nt);
  for (size_t t = 0; t < nt; ++t) boxes[t] = rest_box({s.tris[3 * t], s.tris[3 * t + 1], s.tris[3 * t + 2]});
  grid.build(boxes, mean_extent(boxes));
  double bary[3];
  for (int32_t p : s.points) {
    found.clear();
    grid.query(rest_box({p}), found);
    for (int32_t t : found) {
      const int32_t* v = &s.tris[3 * static_cast<size_t>(t)];
      if (v[0] == p || v[1] == p || v[2] == p || body_of[p] != s.tri_body[t]) continue;
      const double thk = std::max(r[p] + (r[v[0]] + r[v[1]] + r[v[2]]) / 3.0, kMinGap);
      if (!apart<1, 3>({&rest(p)}, {&rest(v[0]), &rest(v[1]), &rest(v[2])}, thk) &&
          point_triangle_distance(rest(p), rest(v[0]), rest(v[1]), rest(v[2]), bary) < thk)
        ix.near_at_rest_pt.push_back(static_cast<uint64_t>(p) * nt + static_cast<uint64_t>(t));
    }
  }
  boxes.resize(ne);
  for (size_t e = 0; e < ne; ++e) boxes[e] = rest_box({s.edges[2 * e], s.edges[2 * e + 1]});
  grid.build(boxes, mean_extent(boxes));
  for (size_t ea = 0; ea < ne; ++ea) {
    found.clear();
    grid.query(boxes[ea], found);
    const int32_t a0 = s.edges[2 * ea], a1 = s.edges[2 * ea + 1];
    for (int32_t e : found) {
      const size_t eb = static_cast<size_t>(e);
      if (eb <= ea || s.edge_body[ea] != s.edge_body[eb]) continue;
      const int32_t b0 = s.edges[2 * eb], b1 = s.edges[2 * eb + 1];
      if (b0 == a0 || b0 == a1 || b1 == a0 || b1 == a1) continue;
      const double thk = std::max(0.5 * (r[a0] + r[a1] + r[b0] + r[b1]), kMinGap);
      double ps, pt;
      if (!apart<2, 2>({&rest(a0), &rest(a1)}, {&rest(b0), &rest(b1)}, thk) &&
          edge_edge_distance(rest(a0), rest(a1), rest(b0), rest(b1), ps, pt) < thk)
        ix.near_at_rest_ee.push_back(static_cast<uint64_t>(ea) * ne + static_cast<uint64_t>(eb));
    }
  }
  std::ranges::sort(ix.near_at_rest_pt);
  std::ranges::sort(ix.near_at_rest_ee);
}

/// Whether `key` is one of the sorted `keys`.
bool listed(const std::vector<uint64_t>& keys, uint64_t key) {
  return std::ranges::binary_search(keys, key);
}

}  // namespace

void find_contacts(const Input& in, std::vector<SelfContact>& out) {
  out.clear();
  SelfCollisionCache& cache = *in.cache;
  if (!cache.scratch) cache.scratch = std::make_shared<Scratch>();
  Scratch& s = *cache.scratch;
  s.tris.clear();
  s.edges.clear();
  s.tri_body.clear();
  s.edge_body.clear();
  s.points.clear();
  for (size_t bi = 0; bi < in.bodies.size(); ++bi) {
    const BodyInfo& b = in.bodies[bi];
    if (b.triangles.empty()) continue;
    s.tris.insert(s.tris.end(), b.triangles.begin(), b.triangles.end());
    s.tri_body.insert(s.tri_body.end(), b.triangles.size() / 3, static_cast<int32_t>(bi));
    s.edges.insert(s.edges.end(), b.edges.begin(), b.edges.end());
    s.edge_body.insert(s.edge_body.end(), b.edges.size() / 2, static_cast<int32_t>(bi));
    for (int32_t k = 0; k < b.particle_count; ++k) s.points.push_back(b.first_particle + k);
  }
  if (s.tris.empty()) return;
  const auto& x0 = in.x_prev;
  const auto& x1 = in.x;
  const auto& r = in.radius;
  auto grow_of = [&](int32_t i) { return self_collision::grow_of(r[i]); };
  const size_t nt = s.tris.size() / 3, ne = s.edges.size() / 2;

  // The candidate pairs hold while every particle stays inside the region it had when they were
  // found (its swept bounds stretched ahead and grown by a margin), at the start and at the end of
  // every substep.
  //  - Two primitives whose swept bounds overlap in a later substep overlapped in those regions.
  //  - A particle that stays in its region is never more than the region's diagonal D from where it
  //    was when the pairs were found, and moves at most D in a substep. A pair at distance d then is
  //    later at least d - D_a - D_b apart at the start of a substep and moves at most D_a + D_b in it
  //    (D_a, D_b: the largest D of each side's vertices), so it can only come within its thickness
  //    if d < thickness + 2 (D_a + D_b). Pairs further apart are dropped here, once, instead of
  //    being measured again in every substep.
  // So the pairs measured below are a superset of those the swept bounds would give, and the
  // contacts are the same as with a broad phase rebuilt every substep.
  // A pair's regions are those of its particles, so only the pairs with a particle that left its
  // region need finding again: that particle gets a new region and the primitives holding it are
  // queried again (against the hierarchy of region boxes, refitted); the other pairs are kept.
  if (!cache.index) cache.index = std::make_shared<SelfCollisionIndex>();
  SelfCollisionIndex& ix = *cache.index;
  const size_t np = s.points.size();
  // (the rest shapes in points order, as near_at_rest was found in)
  auto same_rest = [&] {
    size_t at = 0;
    for (const BodyInfo& b : in.bodies) {
      if (b.triangles.empty()) continue;
      if (at + b.rest_positions.size() > ix.rest.size() ||
          !std::equal(b.rest_positions.begin(), b.rest_positions.end(),
                      ix.rest.begin() + static_cast<std::ptrdiff_t>(at)))
        return false;
      at += b.rest_positions.size();
    }
    return at == ix.rest.size();
  };
  const bool cached = cache.lo.size() == x1.size() && cache.triangles == s.tris && cache.edges == s.edges &&
                      ix.point_boxes.size() == np && std::ranges::equal(ix.radius, r) && same_rest();
  auto inside = [&](const Vec3& p, int32_t i) {
    return (p.array() >= cache.lo[i].array()).all() && (p.array() <= cache.hi[i].array()).all();
  };
  s.left.clear();
  if (!cached) {
    s.left.resize(np);
    std::iota(s.left.begin(), s.left.end(), 0);
  } else {
    s.outside.assign(np, 0);
    in.pool->run(0, np, 1, kBoxGrain, [&](size_t begin, size_t end, int) {
      for (size_t k = begin; k < end; ++k) {
        const int32_t i = s.points[k];
        s.outside[k] = !inside(x0[i], i) || !inside(x1[i], i);
      }
    });
    for (size_t k = 0; k < np; ++k)
      if (s.outside[k]) s.left.push_back(static_cast<int32_t>(k));
  }
  if (!s.left.empty()) {
    if (!cached) {
      cache.lo.assign(x1.size(), Vec3::Zero());
      cache.hi.assign(x1.size(), Vec3::Zero());
      cache.triangles = s.tris;
      cache.edges = s.edges;
      ix = SelfCollisionIndex{};
      ix.radius.assign(r.begin(), r.end());
      build_hierarchy(ix, s, x1);
      for (const BodyInfo& b : in.bodies)
        if (!b.triangles.empty()) ix.rest.insert(ix.rest.end(), b.rest_positions.begin(), b.rest_positions.end());
      find_near_at_rest(ix, s, in.bodies, r);
      ix.reach.assign(x1.size(), 0.0);
      ix.tri_boxes.resize(nt);
      ix.edge_boxes.resize(ne);
      ix.point_boxes.resize(np);
    }
    // New regions for the particles that left (every particle the first time).
    s.changed.assign(x1.size(), 0);
    for (int32_t k : s.left) {
      const int32_t i = s.points[k];
      const double margin = kRegionThickness * grow_of(i);
      const Vec3 ahead = x1[i] + kRegionAhead * (x1[i] - x0[i]);
      cache.lo[i] = x0[i].cwiseMin(ahead).array() - margin;
      cache.hi[i] = x0[i].cwiseMax(ahead).array() + margin;
      ix.reach[i] = (cache.hi[i] - cache.lo[i]).norm();
      s.changed[i] = 1;
    }
    auto region = [&](std::initializer_list<int32_t> ids) {
      return grown_union(ids, r, [&](int32_t i) { return Box{cache.lo[i], cache.hi[i]}; });
    };
    auto reach = [&](std::initializer_list<int32_t> ids) {
      double d = 0.0;
      for (int32_t i : ids) d = std::max(d, ix.reach[i]);
      return d;
    };
    // The primitives holding them: new boxes (marked from the particles' lists, boxed over the
    // threads).
    s.tri_changed.assign(nt, 0);
    s.edge_changed.assign(ne, 0);
    s.changed_tris.clear();
    s.changed_edges.clear();
    for (int32_t k : s.left) {
      for (int32_t j = ix.point_tri_begin[k]; j < ix.point_tri_begin[k + 1]; ++j) {
        const int32_t t = ix.point_tris[j];
        if (!s.tri_changed[t]) s.tri_changed[t] = 1, s.changed_tris.push_back(t);
      }
      for (int32_t j = ix.point_edge_begin[k]; j < ix.point_edge_begin[k + 1]; ++j) {
        const int32_t e = ix.point_edges[j];
        if (!s.edge_changed[e]) s.edge_changed[e] = 1, s.changed_edges.push_back(e);
      }
    }
    in.pool->run(0, s.changed_tris.size(), 1, kListGrain, [&](size_t begin, size_t end, int) {
      for (size_t c = begin; c < end; ++c) {
        const int32_t* v = &s.tris[3 * static_cast<size_t>(s.changed_tris[c])];
        ix.tri_boxes[static_cast<size_t>(s.changed_tris[c])] = region({v[0], v[1], v[2]});
      }
    });
    in.pool->run(0, s.changed_edges.size(), 1, kListGrain, [&](size_t begin, size_t end, int) {
      for (size_t c = begin; c < end; ++c) {
        const int32_t* v = &s.edges[2 * static_cast<size_t>(s.changed_edges[c])];
        ix.edge_boxes[static_cast<size_t>(s.changed_edges[c])] = region({v[0], v[1]});
      }
    });
    for (int32_t k : s.left) ix.point_boxes[k] = region({s.points[k]});
    // The items holding a changed primitive, ascending.
    const size_t items = ix.item_tri.size();
    s.item_changed.assign(items, 0);
    s.changed_items.clear();
    for (int32_t t : s.changed_tris) s.item_changed[static_cast<size_t>(ix.tri_item[static_cast<size_t>(t)])] = 1;
    for (int32_t e : s.changed_edges) s.item_changed[static_cast<size_t>(ix.edge_item[static_cast<size_t>(e)])] = 1;
    for (int32_t k : s.left) s.item_changed[static_cast<size_t>(ix.point_item[static_cast<size_t>(k)])] = 1;
    for (size_t k = 0; k < items; ++k)
      if (s.item_changed[k]) s.changed_items.push_back(static_cast<int32_t>(k));
    refit_hierarchy(ix, s.changed_items, *in.pool, kListGrain);
    // The kept pairs: neither side holds a particle with a new region.
    // Each thread compacts a part of the list in place, then the parts are moved together in order:
    // the order one loop gives.
    // (begin, end: pair indices; a pair is two entries of `pairs` and one of `gaps`.)
    auto keep = [&](std::vector<int32_t>& pairs, std::vector<double>& gaps, auto&& stays) {
      s.part_kept.assign(static_cast<size_t>(in.pool->size()), {0, 0});
      in.pool->run(0, gaps.size(), 1, kContactGrain, [&](size_t begin, size_t end, int part) {
        int32_t* ids = pairs.data();
        double* gap = gaps.data();
        size_t kept = begin;
        for (size_t k = begin; k < end; ++k) {
          const int32_t a = ids[2 * k], b = ids[2 * k + 1];
          if (stays(a, b)) {
            ids[2 * kept] = a;
            ids[2 * kept + 1] = b;
            gap[kept++] = gap[k];
          }
        }
        s.part_kept[static_cast<size_t>(part)] = {begin, kept};
      });
      size_t kept = 0;
      for (const auto& [begin, end] : s.part_kept) {
        if (kept != begin) {  // forward, to an earlier place
          std::copy(pairs.begin() + static_cast<std::ptrdiff_t>(2 * begin),
                    pairs.begin() + static_cast<std::ptrdiff_t>(2 * end),
                    pairs.begin() + static_cast<std::ptrdiff_t>(2 * kept));
          std::copy(gaps.begin() + static_cast<std::ptrdiff_t>(begin), gaps.begin() + static_cast<std::ptrdiff_t>(end),
                    gaps.begin() + static_cast<std::ptrdiff_t>(kept));
        }
        kept += end - begin;
      }
      pairs.resize(2 * kept);
      gaps.resize(kept);
    };
    keep(cache.point_triangle, cache.point_triangle_gap,
         [changed = s.changed.data(), tri_changed = s.tri_changed.data()](int32_t p, int32_t t) {
           return !(changed[p] | tri_changed[t]);
         });
    keep(cache.edge_edge, cache.edge_edge_gap,
         [changed = s.edge_changed.data()](int32_t a, int32_t b) { return !(changed[a] | changed[b]); });
    // A pair is kept when the two can come within their thickness while their particles stay in
    // their regions (see above), and they are not neighbours on the surface at rest.
    auto point_triangle_pair = [&](int32_t p, int32_t t, std::vector<int32_t>& pairs) {
      const int32_t* v = &s.tris[3 * static_cast<size_t>(t)];
      if (v[0] == p || v[1] == p || v[2] == p) return;
      if (in.w[p] == 0.0 && in.w[v[0]] == 0.0 && in.w[v[1]] == 0.0 && in.w[v[2]] == 0.0) return;
      const double thk = std::max(r[p] + (r[v[0]] + r[v[1]] + r[v[2]]) / 3.0, kMinGap);
      double bary[3];
      // A vertex nearer than the limit puts the triangle nearer too (the exact distance only when
      // none is: regions that overlap seldom leave a pair beyond it).
      const double limit = thk + 2.0 * (ix.reach[p] + reach({v[0], v[1], v[2]}));
      if (!near_any(x1[p], {x1[v[0]], x1[v[1]], x1[v[2]]}, limit) &&
          point_triangle_distance(x1[p], x1[v[0]], x1[v[1]], x1[v[2]], bary) >= limit)
        return;
      if (listed(ix.near_at_rest_pt, static_cast<uint64_t>(p) * nt + static_cast<uint64_t>(t))) return;
      pairs.insert(pairs.end(), {p, t});
    };
    auto edge_edge_pair = [&](int32_t ea, int32_t eb, std::vector<int32_t>& pairs) {
      const int32_t a0 = s.edges[2 * static_cast<size_t>(ea)], a1 = s.edges[2 * static_cast<size_t>(ea) + 1];
      const int32_t b0 = s.edges[2 * static_cast<size_t>(eb)], b1 = s.edges[2 * static_cast<size_t>(eb) + 1];
      if (b0 == a0 || b0 == a1 || b1 == a0 || b1 == a1) return;
      if (in.w[a0] == 0.0 && in.w[a1] == 0.0 && in.w[b0] == 0.0 && in.w[b1] == 0.0) return;
      const double thk = std::max(0.5 * (r[a0] + r[a1] + r[b0] + r[b1]), kMinGap);
      double ps, pt;
      const double limit = thk + 2.0 * (reach({a0, a1}) + reach({b0, b1}));
      if (!near_any(x1[a0], {x1[b0], x1[b1]}, limit) && !near_any(x1[a1], {x1[b0], x1[b1]}, limit) &&
          edge_edge_distance(x1[a0], x1[a1], x1[b0], x1[b1], ps, pt) >= limit)
        return;
      if (listed(ix.near_at_rest_ee, static_cast<uint64_t>(ea) * ne + static_cast<uint64_t>(eb))) return;
      pairs.insert(pairs.end(), {ea, eb});
    };
    // The queries, a group of kQueryGroup consecutive items (neighbours in the hierarchy's leaf
    // order) at a time: the hierarchy is walked once with the union of the boxes of the group's
    // changed primitives, and each item met is tested against each of them, its box first. A pair
    // is the same box overlap test as in one walk a primitive, so the same pairs are found; only
    // their order in the lists differs (the contacts are sorted).
    // Point against triangle: each particle with a new region against every triangle, then each
    // triangle with a new region against the particles that kept theirs.
    // Edge against edge, each pair once, the lower edge first.
    const bool kept_some = s.left.size() < np;
    s.groups.clear();
    for (int32_t k : s.changed_items)
      if (s.groups.empty() || s.groups.back() != k / static_cast<int32_t>(kQueryGroup))
        s.groups.push_back(k / static_cast<int32_t>(kQueryGroup));
    // A group's items: [first, last).
    auto group_items = [&](size_t k) {
      const size_t first = static_cast<size_t>(s.groups[k]) * kQueryGroup;
      return std::pair{first, std::min(items, first + kQueryGroup)};
    };
    // One walk a group for both kinds: the union of the boxes of its changed points, triangles
    // and edges.
    pair_lists(*in.pool, s.groups.size(), s.part_pairs, s.part_ee_pairs, cache.point_triangle, cache.edge_edge,
               [&](size_t k, std::vector<int32_t>& pt_pairs, std::vector<int32_t>& ee_pairs) {
                 std::array<int32_t, 3 * kQueryGroup> left;  // points order
                 std::array<int32_t, kQueryGroup> tris;
                 std::array<int32_t, 3 * kQueryGroup> changed;  // edges
                 FloatBoxes<3 * kQueryGroup> left_boxes;
                 FloatBoxes<kQueryGroup> tri_boxes;
                 FloatBoxes<3 * kQueryGroup> edge_boxes;
                 Box q = Box::empty();
                 const auto [first, last] = group_items(k);
                 for (size_t item = first; item < last; ++item) {
                   for (int32_t j = ix.point_begin[item]; j < ix.point_begin[item + 1]; ++j) {
                     const int32_t p = ix.owned_points[j];
                     if (!s.changed[s.points[p]]) continue;
                     left[left_boxes.size()] = p;
                     left_boxes.add(ix.point_boxes[p]);
                     q.unite(ix.point_boxes[p]);
                   }
                   const int32_t t = ix.item_tri[item];
                   if (kept_some && t >= 0 && s.tri_changed[static_cast<size_t>(t)]) {
                     tris[tri_boxes.size()] = t;
                     tri_boxes.add(ix.tri_boxes[static_cast<size_t>(t)]);
                     q.unite(ix.tri_boxes[static_cast<size_t>(t)]);
                   }
                   for (int32_t j = ix.edge_begin[item]; j < ix.edge_begin[item + 1]; ++j) {
                     const int32_t e = ix.owned_edges[j];
                     if (!s.edge_changed[e]) continue;
                     changed[edge_boxes.size()] = e;
                     edge_boxes.add(ix.edge_boxes[e]);
                     q.unite(ix.edge_boxes[e]);
                   }
                 }
                 if (left_boxes.size() + tri_boxes.size() + edge_boxes.size() == 0) return;
                 query_hierarchy(ix, FloatBox::outward(q), [&](int32_t item) {
                   // Point against triangle.
                   const FloatBox& item_box = ix.item_box[static_cast<size_t>(item)];
                   const int32_t t = ix.item_tri[static_cast<size_t>(item)];
                   if (t >= 0)
                     for (uint64_t hits = left_boxes.may_overlap(item_box); hits != 0; hits &= hits - 1) {
                       const int32_t p = left[static_cast<size_t>(std::countr_zero(hits))];
                       if (ix.tri_boxes[static_cast<size_t>(t)].overlaps(ix.point_boxes[p]))
                         point_triangle_pair(s.points[p], t, pt_pairs);
                     }
                   if (tri_boxes.size() != 0)
                     for (int32_t j = ix.point_begin[item]; j < ix.point_begin[item + 1]; ++j) {
                       const int32_t p = ix.owned_points[j];
                       if (s.changed[s.points[p]]) continue;
                       for (uint64_t hits = tri_boxes.may_overlap(ix.owned_point_box[j]); hits != 0; hits &= hits - 1) {
                         const int32_t tc = tris[static_cast<size_t>(std::countr_zero(hits))];
                         if (ix.point_boxes[p].overlaps(ix.tri_boxes[static_cast<size_t>(tc)]))
                           point_triangle_pair(s.points[p], tc, pt_pairs);
                       }
                     }
                   // Edge against edge.
                   if (edge_boxes.size() != 0)
                     for (int32_t j = ix.edge_begin[item]; j < ix.edge_begin[item + 1]; ++j) {
                       const int32_t eb = ix.owned_edges[j];
                       for (uint64_t hits = edge_boxes.may_overlap(ix.owned_edge_box[j]); hits != 0; hits &= hits - 1) {
                         const int32_t ea = changed[static_cast<size_t>(std::countr_zero(hits))];
                         if (eb == ea || (s.edge_changed[eb] && eb < ea)) continue;  // found from eb's side
                         if (!ix.edge_boxes[eb].overlaps(ix.edge_boxes[ea])) continue;
                         if (ea < eb)
                           edge_edge_pair(ea, eb, ee_pairs);
                         else
                           edge_edge_pair(eb, ea, ee_pairs);
                       }
                     }
                 });
               });
    // The new pairs' gaps are measured when they are first met below.
    constexpr double unknown = -std::numeric_limits<double>::infinity();
    cache.point_triangle_gap.resize(cache.point_triangle.size() / 2, unknown);
    cache.edge_edge_gap.resize(cache.edge_edge.size() / 2, unknown);
  }

  // This substep's swept bounds, grown by the largest half thickness of each primitive's particles:
  // a pair whose bounds do not overlap stays more than its thickness apart throughout the substep.
  // Each particle's shift since the last substep's start lowers its pairs' gaps (a distance moves no
  // more than the two sides' largest shifts).
  s.swept_point.resize(x1.size());
  s.moved.resize(x1.size());
  s.motion.resize(x1.size());
  s.shift.resize(x1.size());
  const bool started = ix.start.size() == x0.size();
  s.part_scale.assign(static_cast<size_t>(in.pool->size()), 0.0);
  in.pool->run(0, np, 1, kBoxGrain, [&](size_t begin, size_t end, int part) {
    double scale = 0.0;
    for (size_t k = begin; k < end; ++k) {
      const int32_t i = s.points[k];
      s.moved[i] = box_of({x0[i], x1[i]}, 0.0);
      s.motion[i] = (x1[i] - x0[i]).norm();
      s.shift[i] = started ? (x0[i] - ix.start[i]).norm() : std::numeric_limits<double>::infinity();
      s.swept_point[i] = {
          {s.moved[i].lo.array() - grow_of(i), s.moved[i].hi.array() + grow_of(i)}, s.motion[i], s.shift[i]};
      scale = std::max({scale, x0[i].cwiseAbs().maxCoeff(), x1[i].cwiseAbs().maxCoeff()});
      if (started) scale = std::max(scale, ix.start[i].cwiseAbs().maxCoeff());
    }
    s.part_scale[static_cast<size_t>(part)] = scale;
  });
  // A gap skips the exact distance only when it clears the motion by more than the rounding of the
  // distances and shifts it was made of.
  const double tolerance = kGapTolerance * (1.0 + std::ranges::max(s.part_scale));
  const std::vector<double>& m = s.motion;
  const auto each = [&](size_t n, auto&& f) {  // independent items, split over the pool's threads
    in.pool->run(0, n, 1, kBoxGrain, [&](size_t begin, size_t end, int) {
      for (size_t k = begin; k < end; ++k) f(k);
    });
  };
  auto swept = [&](std::initializer_list<int32_t> ids) {
    return grown_union(ids, r, [&](int32_t i) -> const Box& { return s.moved[i]; });
  };
  auto swept_moves = [&](std::initializer_list<int32_t> ids) {
    Scratch::Swept sw{swept(ids), 0.0, 0.0};
    for (int32_t i : ids) sw.motion = std::max(sw.motion, m[i]), sw.shift = std::max(sw.shift, s.shift[i]);
    return sw;
  };
  s.swept_tri.resize(nt);
  each(nt, [&](size_t t) {
    const int32_t* v = &s.tris[3 * t];
    s.swept_tri[t] = swept_moves({v[0], v[1], v[2]});
  });
  s.swept_edge.resize(ne);
  each(ne, [&](size_t e) {
    const int32_t* v = &s.edges[2 * e];
    s.swept_edge[e] = swept_moves({v[0], v[1]});
  });

  // s.near: the pairs whose gap, lowered by their two sides' shifts, does not clear their motion
  // (the others have d0 >= thk + motion below) and whose swept bounds overlap; first and second:
  // the two sides' Swept arrays. Bounds that do not overlap are apart along some axis by `along`:
  // each is grown by its vertices' largest half thickness, which together are at least the pair's
  // thickness (a sum or mean of half thicknesses, or kMinGap), so the pair stays more than its
  // thickness apart through the substep and its distance less its thickness is at least `along`,
  // which raises the gap. (A range at a time, the arrays read through local pointers: a kept pair is
  // a few instructions and a cache line for each side.)
  auto near_pairs = [&](const std::vector<int32_t>& pairs, std::vector<double>& gaps,
                        const std::vector<Scratch::Swept>& first, const std::vector<Scratch::Swept>& second) {
    s.near.clear();
    in.pool->collect(0, gaps.size(), kContactGrain, s.part_pairs, s.near,
                     [&](size_t begin, size_t end, std::vector<int32_t>& near) {
                       const int32_t* ids = pairs.data();
                       double* gap = gaps.data();
                       const Scratch::Swept* sa = first.data();
                       const Scratch::Swept* sb = second.data();
                       const double tol = tolerance;
                       for (size_t pair = begin; pair < end; ++pair) {
                         const Scratch::Swept &a = sa[ids[2 * pair]], &b = sb[ids[2 * pair + 1]];
                         gap[pair] -= a.shift + b.shift;
                         if (!(gap[pair] < a.motion + b.motion + tol)) continue;
                         const double along = (b.box.lo - a.box.hi).cwiseMax(a.box.lo - b.box.hi).maxCoeff();
                         if (along > 0.0)
                           gap[pair] = std::max(gap[pair], along);
                         else
                           near.push_back(static_cast<int32_t>(pair));
                       }
                     });
  };

  // Point against triangle: the pairs near enough, then their contacts.
  near_pairs(cache.point_triangle, cache.point_triangle_gap, s.swept_point, s.swept_tri);
  gather(*in.pool, s.near.size(), kContactGrain, s.part_contacts, out, [&](size_t k, std::vector<SelfContact>& found) {
    const size_t pair = static_cast<size_t>(s.near[k]);
    const int32_t p = cache.point_triangle[2 * pair], t = cache.point_triangle[2 * pair + 1];
    const Scratch::Swept& st = s.swept_tri[static_cast<size_t>(t)];
    const double motion = m[p] + st.motion;
    double& gap = cache.point_triangle_gap[pair];
    const int32_t* v = &s.tris[3 * static_cast<size_t>(t)];
    const double thk = std::max(r[p] + (r[v[0]] + r[v[1]] + r[v[2]]) / 3.0, kMinGap);
    double bary[3];
    const double d0 = point_triangle_distance(x0[p], x0[v[0]], x0[v[1]], x0[v[2]], bary);
    gap = d0 - thk;
    if (d0 >= thk + motion) return;
    if (!s.swept_point[p].box.overlaps(st.box)) return;  // (non-finite bounds)
    double toi;
    const Vec3 tri_n = (x0[v[1]] - x0[v[0]]).cross(x0[v[2]] - x0[v[0]]);
    Vec3 side = x0[p] - (bary[0] * x0[v[0]] + bary[1] * x0[v[1]] + bary[2] * x0[v[2]]);
    Vec3 primary = side;  // closest points at the start
    if (point_triangle_toi(x0[p], x1[p], x0[v[0]], x1[v[0]], x0[v[1]], x1[v[1]], x0[v[2]], x1[v[2]], thk, toi)) {
      point_triangle_distance(lerp(x0[p], x1[p], toi), lerp(x0[v[0]], x1[v[0]], toi), lerp(x0[v[1]], x1[v[1]], toi),
                              lerp(x0[v[2]], x1[v[2]], toi), bary);
      side = x0[p] - (bary[0] * x0[v[0]] + bary[1] * x0[v[1]] + bary[2] * x0[v[2]]);
      primary = tri_n;  // touching within the substep: hold it on the triangle's side it came from
    }
    SelfContact c{};
    c.ids[0] = p;
    for (int j = 0; j < 3; ++j) c.ids[j + 1] = v[j];
    c.weight[0] = 1.0;
    for (int j = 0; j < 3; ++j) c.weight[j + 1] = -bary[j];
    if (!orient_normal(primary, side, side, c.normal) && !orient_normal(tri_n, x1[p] - x0[p], x0[p] - x1[p], c.normal))
      return;
    c.thickness = thk;
    c.mu_s = mean_mu(in.mu_s, c.ids);
    c.mu_k = mean_mu(in.mu_k, c.ids);
    found.push_back(c);
  });

  const size_t point_triangle_contacts = out.size();

  // Edge against edge, the same way.
  near_pairs(cache.edge_edge, cache.edge_edge_gap, s.swept_edge, s.swept_edge);
  gather(*in.pool, s.near.size(), kContactGrain, s.part_contacts, out, [&](size_t k, std::vector<SelfContact>& found) {
    const size_t pair = static_cast<size_t>(s.near[k]);
    const size_t ea = static_cast<size_t>(cache.edge_edge[2 * pair]);
    const size_t eb = static_cast<size_t>(cache.edge_edge[2 * pair + 1]);
    const Scratch::Swept &swa = s.swept_edge[ea], &swb = s.swept_edge[eb];
    const double motion = swa.motion + swb.motion;
    double& gap = cache.edge_edge_gap[pair];
    const int32_t a0 = s.edges[2 * ea], a1 = s.edges[2 * ea + 1], b0 = s.edges[2 * eb], b1 = s.edges[2 * eb + 1];
    const double thk = std::max(0.5 * (r[a0] + r[a1] + r[b0] + r[b1]), kMinGap);
    double sa, tb;
    const double d0 = edge_edge_distance(x0[a0], x0[a1], x0[b0], x0[b1], sa, tb);
    gap = d0 - thk;
    if (d0 >= thk + motion) return;
    if (!swa.box.overlaps(swb.box)) return;  // (non-finite bounds)
    const Vec3 cross = (x0[a1] - x0[a0]).cross(x0[b1] - x0[b0]);
    Vec3 side = lerp(x0[a0], x0[a1], sa) - lerp(x0[b0], x0[b1], tb);
    Vec3 primary = side;
    double toi;
    if (edge_edge_toi(x0[a0], x0[a1], x0[b0], x0[b1], x1[a0], x1[a1], x1[b0], x1[b1], thk, toi)) {
      edge_edge_distance(lerp(x0[a0], x1[a0], toi), lerp(x0[a1], x1[a1], toi), lerp(x0[b0], x1[b0], toi),
                         lerp(x0[b1], x1[b1], toi), sa, tb);
      side = lerp(x0[a0], x0[a1], sa) - lerp(x0[b0], x0[b1], tb);
      primary = cross;
    }
    SelfContact c{};
    c.ids[0] = a0;
    c.ids[1] = a1;
    c.ids[2] = b0;
    c.ids[3] = b1;
    c.weight[0] = 1.0 - sa;
    c.weight[1] = sa;
    c.weight[2] = -(1.0 - tb);
    c.weight[3] = -tb;
    if (!orient_normal(primary, side, side, c.normal) && !orient_normal(cross, Vec3::Zero(), side, c.normal)) return;
    c.thickness = thk;
    c.mu_s = mean_mu(in.mu_s, c.ids);
    c.mu_k = mean_mu(in.mu_k, c.ids);
    found.push_back(c);
  });

  // The contacts in an order that depends on what they join only, never on the history of the kept
  // pairs (kept ones first, then the ones found again): a world saved and loaded back, whose pairs
  // are all found afresh, projects its contacts in the same order and steps to the same bits.
  // Point-triangle contacts, then edge-edge ones, each by their particles (no two share all four).
  // (sorted as keys, then moved once: a contact is 104 bytes)
  s.order.resize(out.size());
  for (size_t k = 0; k < out.size(); ++k) {
    const auto* ids = out[k].ids;
    s.order[k] = {static_cast<uint64_t>(ids[0]) << 32 | static_cast<uint32_t>(ids[1]),
                  static_cast<uint64_t>(ids[2]) << 32 | static_cast<uint32_t>(ids[3]), static_cast<uint32_t>(k)};
  }
  const auto by_particles = [](const Scratch::Order& a, const Scratch::Order& b) {
    return a.first < b.first || (a.first == b.first && a.second < b.second);
  };
  // (the two kinds sorted side by side on the pool's threads, then moved in parallel)
  const auto split = s.order.begin() + static_cast<std::ptrdiff_t>(point_triangle_contacts);
  in.pool->run_parts(2, [&](int part) {
    if (part == 0) std::sort(s.order.begin(), split, by_particles);
    if (part == 1 || in.pool->size() == 1) std::sort(split, s.order.end(), by_particles);
  });
  s.sorted.resize(out.size());
  in.pool->run(0, out.size(), 1, kBoxGrain, [&](size_t begin, size_t end, int) {
    for (size_t k = begin; k < end; ++k) s.sorted[k] = out[s.order[k].at];
  });
  out.swap(s.sorted);
  ix.start.assign(x0.begin(), x0.end());
}

// --- resolution ------------------------------------------------------------------------------------

namespace {
double constraint(const SelfContact& c, std::span<const Vec3> x) {
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < 4; ++k) sum += c.weight[k] * x[c.ids[k]];
  return c.normal.dot(sum) - c.thickness;
}

double denominator(const SelfContact& c, std::span<const double> w) {
  double d = 0.0;
  for (int k = 0; k < 4; ++k) d += w[c.ids[k]] * c.weight[k] * c.weight[k];
  return d;
}
}  // namespace

void project(std::span<SelfContact> contacts, std::span<Vec3> x, std::span<const double> w) {
  for (SelfContact& c : contacts) {
    const double denom = denominator(c, w);
    if (denom <= 0.0) continue;
    const double C = constraint(c, x);
    const double dl = std::max(c.lambda - C / denom, 0.0) - c.lambda;
    if (dl == 0.0) continue;
    c.lambda += dl;
    for (int k = 0; k < 4; ++k) x[c.ids[k]] += (w[c.ids[k]] * c.weight[k] * dl) * c.normal;
  }
}

void add_corrections(std::span<const SelfContact> contacts, std::span<const double> w, std::span<Vec3> out) {
  for (const SelfContact& c : contacts) {
    if (c.lambda == 0.0) continue;
    for (int k = 0; k < 4; ++k) out[c.ids[k]] += (w[c.ids[k]] * c.weight[k] * c.lambda) * c.normal;
  }
}

void apply_friction(std::span<const SelfContact> contacts, std::span<Vec3> x, std::span<const Vec3> x_prev,
                    std::span<const double> w, double h) {
  for (const SelfContact& c : contacts) {
    if (c.lambda <= 0.0) continue;
    const double denom = denominator(c, w);
    if (denom <= 0.0) continue;
    Vec3 slip = Vec3::Zero();  // relative motion of the two sides over the substep
    for (int k = 0; k < 4; ++k) slip += c.weight[k] * (x[c.ids[k]] - x_prev[c.ids[k]]);
    const Vec3 tangential = slip - slip.dot(c.normal) * c.normal;
    const double len = tangential.norm();
    const double push = denom * c.lambda;  // the normal correction, a length
    const double f = friction_fraction(len, push, c.mu_s, c.mu_k, h);
    if (f == 0.0) continue;
    // Remove the fraction f of the relative tangential motion, shared by inverse mass.
    for (int k = 0; k < 4; ++k) x[c.ids[k]] -= (f * w[c.ids[k]] * c.weight[k] / denom) * tangential;
  }
}

double penetration(const SelfContact& c, std::span<const Vec3> x) {
  return std::max(-constraint(c, x), 0.0);
}

}  // namespace embra::self_collision

namespace embra {

void World::find_self_contacts() {
  if (settings_.self_collision == 0) {
    self_contacts_.clear();
    return;
  }
  self_collision::Input in{bodies_, x_prev_, x_, w_, radius_, mu_s_, mu_k_, &self_cache_, pool_.get()};
  self_collision::find_contacts(in, self_contacts_);
}

}  // namespace embra
