#include "closed_meshes.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <utility>

namespace embra::io {

namespace {

using V = Eigen::Vector3d;

void add_all_and_extremes(SurfaceMesh& m) {
  const int32_t n = static_cast<int32_t>(m.positions.size() / 3);
  int32_t top = 0, bottom = 0;
  for (int32_t i = 0; i < n; ++i) {
    m.sets["all"].push_back(i);
    if (m.positions[3 * i + 2] > m.positions[3 * top + 2]) top = i;
    if (m.positions[3 * i + 2] < m.positions[3 * bottom + 2]) bottom = i;
  }
  if (!m.sets.count("top")) m.sets["top"] = {top};
  if (!m.sets.count("bottom")) m.sets["bottom"] = {bottom};
}

}  // namespace

SurfaceMesh icosphere(double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<V> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                      {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (V& p : v) p.normalize();
  std::vector<std::array<int32_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                           {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                           {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                           {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int32_t, int32_t>, int32_t> mid;
    auto midpoint = [&](int32_t a, int32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int32_t id = static_cast<int32_t>(v.size() - 1);
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int32_t, 3>> next;
    next.reserve(f.size() * 4);
    for (const auto& tri : f) {
      const int32_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]), ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  SurfaceMesh m;
  for (const V& p : v)
    for (int k = 0; k < 3; ++k) m.positions.push_back(radius * p[k]);
  for (const auto& tri : f) m.triangles.insert(m.triangles.end(), tri.begin(), tri.end());
  add_all_and_extremes(m);
  return m;
}

SurfaceMesh rounded_box(const std::array<double, 3>& size, double radius, int resolution) {
  const int n = resolution;
  const V half(size[0] / 2, size[1] / 2, size[2] / 2);
  const V inner = half - V::Constant(radius);
  // Lattice points (i, j, k) in [0, n]^3 on the cube's surface, one vertex each.
  std::map<std::array<int, 3>, int32_t> index;
  SurfaceMesh m;
  auto vertex = [&](int i, int j, int k) {
    const std::array<int, 3> key{i, j, k};
    const auto it = index.find(key);
    if (it != index.end()) return it->second;
    // The point on the sharp box, then pulled onto the rounded one: the nearest point of the inner
    // box plus `radius` along the direction to it (sharp when radius is 0).
    const V p(half[0] * (2.0 * i / n - 1.0), half[1] * (2.0 * j / n - 1.0), half[2] * (2.0 * k / n - 1.0));
    const V q = p.cwiseMax(-inner).cwiseMin(inner);
    const V d = p - q;
    const V out = radius > 0.0 && d.norm() > 0.0 ? V(q + radius * d.normalized()) : p;
    const int32_t id = static_cast<int32_t>(m.positions.size() / 3);
    m.positions.insert(m.positions.end(), {out[0], out[1], out[2]});
    index.emplace(key, id);
    if ((i == 0 || i == n) && (j == 0 || j == n) && (k == 0 || k == n)) m.sets["corners"].push_back(id);
    if (k == n) m.sets["top"].push_back(id);
    if (k == 0) m.sets["bottom"].push_back(id);
    return id;
  };
  // Each face: axis a fixed at 0 or n, the other two (u, w) in right-handed order so that the
  // triangles face outwards.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          std::array<int32_t, 4> c;
          const int du[4] = {0, 1, 1, 0}, dw[4] = {0, 0, 1, 1};
          for (int q = 0; q < 4; ++q) {
            std::array<int, 3> ijk{};
            ijk[axis] = side * n;
            ijk[u] = a + du[q];
            ijk[w] = b + dw[q];
            c[q] = vertex(ijk[0], ijk[1], ijk[2]);
          }
          // (u, w, axis) is right-handed: counter-clockwise in (u, w) faces +axis; flip for -axis.
          if (side == 1)
            m.triangles.insert(m.triangles.end(), {c[0], c[1], c[2], c[0], c[2], c[3]});
          else
            m.triangles.insert(m.triangles.end(), {c[0], c[2], c[1], c[0], c[3], c[2]});
        }
    }
  add_all_and_extremes(m);
  return m;
}

}  // namespace embra::io
