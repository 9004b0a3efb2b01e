// The world as Wavefront OBJ text (obj.hpp).
#include "embra/io/obj.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <vector>

namespace embra::io {

namespace {

void append(std::string& out, const char* format, auto... values) {
  char line[128];
  const int n = std::snprintf(line, sizeof line, format, values...);
  out.append(line, static_cast<size_t>(std::min<int>(n, static_cast<int>(sizeof line) - 1)));
}

/// The edges of a body without triangles: its own, and the distance constraints added between two
/// of its particles; each pair once, sorted.
std::vector<std::pair<int32_t, int32_t>> body_lines(const World& world, const BodyInfo& b) {
  std::vector<std::pair<int32_t, int32_t>> lines;
  for (size_t e = 0; e + 1 < b.edges.size(); e += 2) lines.emplace_back(b.edges[e], b.edges[e + 1]);
  const int32_t lo = b.first_particle, hi = b.first_particle + b.particle_count;
  for (const Group& g : world.groups()) {
    if (!g.alive) continue;
    const ConstraintArray& a = g.arrays[static_cast<int>(Kind::distance)];
    for (size_t i = a.generated; i < a.size(); ++i) {
      const int32_t p = a.ids[2 * i], q = a.ids[2 * i + 1];
      if (p >= lo && p < hi && q >= lo && q < hi) lines.emplace_back(std::min(p, q), std::max(p, q));
    }
  }
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

}  // namespace

std::string export_obj(const World& world, std::string_view header) {
  std::string out = "# ";
  out.append(header);
  out += '\n';
  const std::vector<Vec3>& x = world.positions();
  out.reserve(out.size() + x.size() * 64);
  for (const Vec3& p : x) append(out, "v %.17g %.17g %.17g\n", p.x(), p.y(), p.z());
  for (size_t i = 0; i < world.body_count(); ++i) {
    const BodyInfo& b = world.body(Id{static_cast<uint32_t>(i), 1});  // bodies are never destroyed
    const std::vector<int32_t>& t = b.triangles;
    const auto lines = t.empty() ? body_lines(world, b) : std::vector<std::pair<int32_t, int32_t>>{};
    if (t.empty() && lines.empty()) continue;  // loose particles: vertices only
    append(out, "g body_%u\n", static_cast<unsigned>(i));
    for (size_t k = 0; k + 2 < t.size(); k += 3) append(out, "f %d %d %d\n", t[k] + 1, t[k + 1] + 1, t[k + 2] + 1);
    for (auto [p, q] : lines) append(out, "l %d %d\n", p + 1, q + 1);
  }
  return out;
}

}  // namespace embra::io
