// Loading and stepping an example scene as `embra run` does, and geometric checks on the result.
#pragma once

#include "embra/core/world.hpp"
#include "embra/io/scene.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace embra::paper {

struct Scene {
  std::unique_ptr<World> world;
  io::SceneMeta meta;
  /// Steps one frame, the scene's actions first (as embra_world_step does).
  void step() {
    if (!meta.actions.empty()) io::apply_actions(*world, meta, world->report().frame + 1);
    world->step();
  }
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline Scene load_example(const std::string& name) {
  Scene s;
  s.world = io::load_scene(read_text(std::string(EMBRA_EXAMPLES_DIR) + "/" + name), EMBRA_EXAMPLES_DIR, s.meta);
  return s;
}

/// The id of a body named in the scene.
inline Id body_named(const Scene& s, const std::string& name) {
  for (const auto& [slot, n] : s.meta.body_names)
    if (n == name) return Id{slot, 1};
  return Id{};
}

inline double triangle_area_sum(const std::vector<Vec3>& x, const std::vector<int32_t>& tri) {
  double a = 0.0;
  for (size_t t = 0; t + 2 < tri.size(); t += 3)
    a += 0.5 * (x[tri[t + 1]] - x[tri[t]]).cross(x[tri[t + 2]] - x[tri[t]]).norm();
  return a;
}

/// Whether segment p-q crosses triangle (a, b, c) (Moller-Trumbore, strictly inside both).
inline bool segment_crosses_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 d = q - p, e1 = b - a, e2 = c - a;
  const Vec3 h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return false;
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = inv * s.dot(h);
  if (u <= 0.0 || u >= 1.0) return false;
  const Vec3 qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v <= 0.0 || u + v >= 1.0) return false;
  const double t = inv * e2.dot(qv);
  return t > 0.0 && t < 1.0;
}

/// Number of pairs of triangles (sharing no vertex) that intersect: an edge of one passes through
/// the other. A uniform grid over the triangles' bounds keeps it near linear.
inline int64_t count_self_intersections(const std::vector<Vec3>& x, const std::vector<int32_t>& tri) {
  const size_t n = tri.size() / 3;
  if (n == 0) return 0;
  std::vector<Vec3> lo(n), hi(n);
  double mean = 0.0;
  for (size_t t = 0; t < n; ++t) {
    lo[t] = x[tri[3 * t]].cwiseMin(x[tri[3 * t + 1]]).cwiseMin(x[tri[3 * t + 2]]);
    hi[t] = x[tri[3 * t]].cwiseMax(x[tri[3 * t + 1]]).cwiseMax(x[tri[3 * t + 2]]);
    mean += (hi[t] - lo[t]).maxCoeff();
  }
  const double cell = std::max(2.0 * mean / static_cast<double>(n), 1e-9);
  std::unordered_map<int64_t, std::vector<int32_t>> grid;
  auto key = [](int64_t i, int64_t j, int64_t k) { return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791); };
  for (size_t t = 0; t < n; ++t) {
    const Eigen::Vector3i a = (lo[t] / cell).array().floor().cast<int>(),
                          b = (hi[t] / cell).array().floor().cast<int>();
    for (int i = a.x(); i <= b.x(); ++i)
      for (int j = a.y(); j <= b.y(); ++j)
        for (int k = a.z(); k <= b.z(); ++k) grid[key(i, j, k)].push_back(static_cast<int32_t>(t));
  }
  std::set<std::pair<int32_t, int32_t>> seen;
  int64_t count = 0;
  for (const auto& [k, list] : grid)
    for (size_t p = 0; p < list.size(); ++p)
      for (size_t q = p + 1; q < list.size(); ++q) {
        const int32_t s = std::min(list[p], list[q]), t = std::max(list[p], list[q]);
        if (((lo[s] - hi[t]).array() > 0.0).any() || ((lo[t] - hi[s]).array() > 0.0).any()) continue;
        bool shared = false;
        for (int u = 0; u < 3; ++u)
          for (int v = 0; v < 3; ++v) shared |= tri[3 * s + u] == tri[3 * t + v];
        if (shared || !seen.insert({s, t}).second) continue;
        bool hit = false;
        for (int e = 0; e < 3 && !hit; ++e) {
          hit |= segment_crosses_triangle(x[tri[3 * s + e]], x[tri[3 * s + (e + 1) % 3]], x[tri[3 * t]],
                                          x[tri[3 * t + 1]], x[tri[3 * t + 2]]);
          hit |= segment_crosses_triangle(x[tri[3 * t + e]], x[tri[3 * t + (e + 1) % 3]], x[tri[3 * s]],
                                          x[tri[3 * s + 1]], x[tri[3 * s + 2]]);
        }
        count += hit ? 1 : 0;
      }
  return count;
}

}  // namespace embra::paper
