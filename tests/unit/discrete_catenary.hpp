// The exact discrete catenary: N rigid links of length l = L / N, N - 1 free particles of equal
// weight W, both ends pinned at the same height a span S apart. Every link carries the same
// horizontal tension H and each free node's weight is the jump in vertical tension, so link k
// (k = 1..N) makes the angle phi_k with the horizontal where tan(phi_k) = (W / H) ((N + 1) / 2 - k);
// r = W / H follows from the span, sum_k l cos(phi_k) = S, by bisection (f(r) = sum_k l / sqrt(1 +
// r^2 c_k^2) - S falls from L - S > 0 at r = 0 towards -S), run to the last bit. The nodes are the
// running sums of (l cos(phi_k), -l sin(phi_k)) from the left pin. (catenary_test.cpp checks it
// against the continuous catenary.)
#pragma once

#include "embra/core/world.hpp"

#include <cmath>
#include <vector>

namespace embra::test {

struct DiscreteCatenary {
  std::vector<Vec3> nodes;      // N + 1, from the left pin to the right pin
  double w_over_h = 0.0;        // W / H
  std::vector<double> cos_phi;  // per link k = 1..N: cos(phi_k)
};

inline DiscreteCatenary discrete_catenary(int n, double span, double length, const Vec3& left) {
  const double l = length / n;
  auto c = [n](int k) { return (n + 1) / 2.0 - k; };
  auto f = [&](double r) {
    double s = 0.0;
    for (int k = 1; k <= n; ++k) s += l / std::sqrt(1.0 + r * r * c(k) * c(k));
    return s - span;
  };
  double lo = 0.0, hi = 1.0;
  while (f(hi) > 0.0) hi *= 2.0;
  for (int i = 0; i < 2000 && lo < hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (f(mid) > 0.0 ? lo : hi) = mid;
  }
  DiscreteCatenary out;
  out.w_over_h = 0.5 * (lo + hi);
  const double r = out.w_over_h;
  Vec3 x = left;
  out.nodes.push_back(x);
  for (int k = 1; k <= n; ++k) {
    const double q = 1.0 / std::sqrt(1.0 + r * r * c(k) * c(k));
    out.cos_phi.push_back(q);
    x += Vec3(l * q, 0.0, -l * r * c(k) * q);
    out.nodes.push_back(x);
  }
  return out;
}

}  // namespace embra::test
