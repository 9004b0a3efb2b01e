// Panel meshes (Planar Offset Quads): the builder, the metrics and the cut list. See panels.hpp.
#include "embra/core/panels.hpp"

#include "common/check.hpp"

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

namespace embra {

namespace {

// (not inlined: inlined into CornerPlanes, measure_panels took 0.39 ms on the 32 x 32 drape's mesh
// instead of 0.30, GCC 12)
[[gnu::noinline]] Vec3 unit_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double len = n.norm();
  return len > 1e-300 ? Vec3(n / len) : Vec3(Vec3::Zero());
}

/// |distance of p from the plane through a, b, c| (0 for a collapsed triangle).
double plane_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return std::abs((p - a).dot(unit_normal(a, b, c)));
}

/// A quad's corner planes, normal[k] = unit_normal(q[k - 1], q[k], q[k + 1]) (indices mod 4), and
/// the metrics made of them: measure_panels computes them once for a panel's planarity, corner
/// distance and thickness.
struct CornerPlanes {
  Vec3 normal[4];

  explicit CornerPlanes(const Vec3 q[4]) {
    for (int k = 0; k < 4; ++k) normal[k] = unit_normal(q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
  }
  /// plane_distance(p, q[k - 1], q[k], q[k + 1]).
  double distance(const Vec3& p, const Vec3 q[4], int k) const { return std::abs((p - q[(k + 3) % 4]).dot(normal[k])); }
  /// quad_planarity(q[0], q[1], q[2], q[3]).
  double planarity(const Vec3 q[4]) const {
    const double split02 = 1.0 - normal[1].dot(unit_normal(q[0], q[2], q[3]));
    const double split13 = 1.0 - normal[2].dot(unit_normal(q[1], q[3], q[0]));
    return std::max({split02, split13, 0.0});
  }
  /// quad_corner_distance(q[0], q[1], q[2], q[3]).
  double corner_distance(const Vec3 q[4]) const {
    return std::max({distance(q[3], q, 1), distance(q[0], q, 2), distance(q[1], q, 3), distance(q[2], q, 0)});
  }
};

/// panel_thickness_error of a panel whose layers' corner planes are top_planes and bottom_planes.
double thickness_error(const CornerPlanes& top_planes, const Vec3 top[4], const CornerPlanes& bottom_planes,
                       const Vec3 bottom[4], double thickness) {
  double worst = 0.0;
  for (int k = 0; k < 4; ++k) {
    const int a = (k + 3) % 4, b = (k + 1) % 4;
    for (int j : {a, k, b}) {
      worst = std::max(worst, std::abs(top_planes.distance(bottom[j], top, k) - thickness));
      worst = std::max(worst, std::abs(bottom_planes.distance(top[j], bottom, k) - thickness));
    }
  }
  return worst;
}

/// The corners on each mesh vertex, (panel, corner k) in panel order, from quads of 4 indices.
std::vector<std::vector<std::pair<int32_t, int32_t>>> corners_around(std::span<const int32_t> quads,
                                                                     int64_t vertex_count) {
  std::vector<std::vector<std::pair<int32_t, int32_t>>> around(static_cast<size_t>(vertex_count));
  for (size_t q = 0; q < quads.size() / 4; ++q)
    for (int k = 0; k < 4; ++k) around[static_cast<size_t>(quads[4 * q + k])].emplace_back(static_cast<int32_t>(q), k);
  return around;
}

/// v with 3 significant digits (for messages).
std::string g3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// Undirected edge key.
std::pair<int32_t, int32_t> edge_key(int32_t a, int32_t b) {
  return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
}

}  // namespace

// --- metrics -----------------------------------------------------------------------------------------

double quad_planarity(const Vec3& q0, const Vec3& q1, const Vec3& q2, const Vec3& q3) {
  const Vec3 q[4] = {q0, q1, q2, q3};
  return CornerPlanes(q).planarity(q);
}

double quad_corner_distance(const Vec3& q0, const Vec3& q1, const Vec3& q2, const Vec3& q3) {
  const Vec3 q[4] = {q0, q1, q2, q3};
  return CornerPlanes(q).corner_distance(q);
}

double quad_diagonal_distance(const Vec3& q0, const Vec3& q1, const Vec3& q2, const Vec3& q3) {
  const double mean_edge = ((q1 - q0).norm() + (q2 - q1).norm() + (q3 - q2).norm() + (q0 - q3).norm()) / 4.0;
  const Vec3 n = (q2 - q0).cross(q3 - q1);
  const double len = n.norm();
  if (!(len > 1e-300) || !(mean_edge > 0.0)) return 0.0;
  return std::abs((q1 - q0).dot(n / len)) / mean_edge;
}

double panel_thickness_error(const Vec3 top[4], const Vec3 bottom[4], double thickness) {
  return thickness_error(CornerPlanes(top), top, CornerPlanes(bottom), bottom, thickness);
}

double miter_twist(const Vec3& top_i, const Vec3& top_j, const Vec3& bottom_i, const Vec3& bottom_j) {
  return plane_distance(bottom_j, top_i, top_j, bottom_i);
}

std::vector<PanelJoint> panel_joints(const PanelLayout& layout) {
  std::map<std::pair<int32_t, int32_t>, size_t> seen;
  std::vector<PanelJoint> joints;
  for (int32_t p = 0; p < layout.panel_count(); ++p)
    for (int k = 0; k < 4; ++k) {
      const auto key = edge_key(layout.quads[4 * p + k], layout.quads[4 * p + (k + 1) % 4]);
      auto it = seen.find(key);
      if (it == seen.end()) {
        seen.emplace(key, joints.size());
        joints.push_back(PanelJoint{p, k, -1, -1});
      } else {
        joints[it->second].other_panel = p;
        joints[it->second].other_corner = k;
      }
    }
  return joints;
}

std::vector<ConicalVertex> conical_vertices(const PanelLayout& layout) {
  const auto around = corners_around(layout.quads, layout.vertex_count);
  std::map<std::pair<int32_t, int32_t>, int> edge_uses;
  for (int32_t p = 0; p < layout.panel_count(); ++p)
    for (int k = 0; k < 4; ++k) ++edge_uses[edge_key(layout.quads[4 * p + k], layout.quads[4 * p + (k + 1) % 4])];
  std::vector<ConicalVertex> out;
  for (int32_t v = 0; v < layout.vertex_count; ++v) {
    const auto& faces = around[v];
    if (faces.size() != 4) continue;
    bool interior = true;
    for (const auto& [p, k] : faces) {
      interior = interior && edge_uses[edge_key(v, layout.quads[4 * p + (k + 1) % 4])] == 2 &&
                 edge_uses[edge_key(v, layout.quads[4 * p + (k + 3) % 4])] == 2;
    }
    if (!interior) continue;
    // Walk round v: the face after (p, k) is the one in which v's previous corner is p's next corner.
    ConicalVertex c;
    c.vertex = v;
    auto cur = faces[0];
    bool closed = true;
    for (int i = 0; i < 4; ++i) {
      c.panel[i] = cur.first;
      c.corner[i] = cur.second;
      const int32_t next = layout.quads[4 * cur.first + (cur.second + 1) % 4];
      bool found = false;
      for (const auto& f : faces)
        if (layout.quads[4 * f.first + (f.second + 3) % 4] == next) {
          cur = f;
          found = true;
          break;
        }
      closed = closed && found;
    }
    if (closed && cur == faces[0]) out.push_back(c);
  }
  return out;
}

PanelTopology panel_topology(const PanelLayout& layout) {
  return PanelTopology{panel_joints(layout), conical_vertices(layout),
                       corners_around(layout.quads, layout.vertex_count)};
}

namespace {

/// The layout's topology: the one World::set_panel_layout derived, else derived now into `own`.
const PanelTopology& topology_of(const PanelLayout& layout, std::optional<PanelTopology>& own) {
  return layout.topology ? *layout.topology : own.emplace(panel_topology(layout));
}

}  // namespace

PanelErrors measure_panels(const PanelLayout& layout, std::span<const Vec3> x) {
  std::optional<PanelTopology> own;
  const PanelTopology& topology = topology_of(layout, own);
  PanelErrors e;
  const int32_t n = layout.panel_count();
  for (auto* v : {&e.planarity_top, &e.planarity_bottom, &e.corner_distance_top, &e.corner_distance_bottom,
                  &e.diagonal_top, &e.diagonal_bottom, &e.thickness})
    v->resize(static_cast<size_t>(n));
  for (int32_t p = 0; p < n; ++p) {
    Vec3 t[4], b[4];
    for (int k = 0; k < 4; ++k) {
      t[k] = x[layout.top(p, k)];
      b[k] = x[layout.bottom(p, k)];
    }
    // (each corner's plane, through it and its two neighbours, computed once for the three metrics)
    const CornerPlanes top(t), bottom(b);
    const size_t i = static_cast<size_t>(p);
    e.planarity_top[i] = top.planarity(t);
    e.planarity_bottom[i] = bottom.planarity(b);
    e.corner_distance_top[i] = top.corner_distance(t);
    e.corner_distance_bottom[i] = bottom.corner_distance(b);
    e.diagonal_top[i] = quad_diagonal_distance(t[0], t[1], t[2], t[3]);
    e.diagonal_bottom[i] = quad_diagonal_distance(b[0], b[1], b[2], b[3]);
    e.thickness[i] = thickness_error(top, t, bottom, b, layout.thickness);
  }
  for (const PanelJoint& j : topology.joints) {
    const int k = j.corner, k1 = (j.corner + 1) % 4;
    e.miter.push_back(miter_twist(x[layout.top(j.panel, k)], x[layout.top(j.panel, k1)], x[layout.bottom(j.panel, k)],
                                  x[layout.bottom(j.panel, k1)]));
  }
  for (const ConicalVertex& c : topology.conical) {
    double a[4];
    for (int i = 0; i < 4; ++i) {
      const int32_t p = c.panel[i];
      const int k = c.corner[i];
      const Vec3 v = x[layout.top(p, k)];
      const Vec3 u = x[layout.top(p, (k + 1) % 4)] - v, w = x[layout.top(p, (k + 3) % 4)] - v;
      a[i] = std::atan2(u.cross(w).norm(), u.dot(w));
    }
    e.conical.push_back(std::abs((a[0] + a[2]) - (a[1] + a[3])));
  }
  for (const auto& copies : topology.around) {
    if (copies.size() < 2) continue;
    double gap = 0.0;
    for (size_t i = 0; i < copies.size(); ++i)
      for (size_t j = i + 1; j < copies.size(); ++j) {
        const auto [pi, ki] = copies[i];
        const auto [pj, kj] = copies[j];
        gap = std::max(gap, (x[layout.top(pi, ki)] - x[layout.top(pj, kj)]).norm());
        gap = std::max(gap, (x[layout.bottom(pi, ki)] - x[layout.bottom(pj, kj)]).norm());
      }
    e.corner_gap.push_back(gap);
  }
  return e;
}

MetricSummary summarize(std::span<const double> values, const Tolerance& tolerance) {
  MetricSummary s;
  double sq = 0.0;
  for (double v : values) {
    s.max = std::max(s.max, v);
    sq += v * v;
    ++s.count;
    if (v <= tolerance.target)
      ++s.within_target;
    else if (v <= tolerance.max)
      ++s.within_max;
    else
      ++s.above_max;
  }
  s.rms = s.count > 0 ? std::sqrt(sq / static_cast<double>(s.count)) : 0.0;
  return s;
}

PanelReport report_panels(const PanelErrors& e, const Tolerances& t) {
  PanelReport r;
  const Tolerance none{0.0, 0.0};
  r.planarity_top = summarize(e.planarity_top, t.planarity);
  r.planarity_bottom = summarize(e.planarity_bottom, t.planarity);
  r.corner_distance_top = summarize(e.corner_distance_top, t.planarity_distance);
  r.corner_distance_bottom = summarize(e.corner_distance_bottom, t.planarity_distance);
  r.diagonal_top = summarize(e.diagonal_top, none);
  r.diagonal_bottom = summarize(e.diagonal_bottom, none);
  r.thickness = summarize(e.thickness, t.thickness);
  r.miter = summarize(e.miter, t.miter);
  r.conical = summarize(e.conical, none);
  r.corner_gap = summarize(e.corner_gap, none);
  r.within_tolerance = r.planarity_top.max <= t.planarity.target && r.planarity_bottom.max <= t.planarity.target &&
                       r.corner_distance_top.max <= t.planarity_distance.target &&
                       r.corner_distance_bottom.max <= t.planarity_distance.target &&
                       r.thickness.max <= t.thickness.target && r.miter.max <= t.miter.target;
  return r;
}

std::vector<double> vertex_errors(const PanelLayout& layout, const PanelErrors& e, PanelMetric metric) {
  std::optional<PanelTopology> own;
  const PanelTopology& topology = topology_of(layout, own);
  const int32_t n = layout.panel_count();
  std::vector<double> out(static_cast<size_t>(layout.particle_count()), 0.0);
  auto raise = [&](int32_t particle, double v) {
    double& slot = out[particle - layout.first_particle];
    slot = std::max(slot, v);
  };
  switch (metric) {
    case PanelMetric::planarity:
    case PanelMetric::corner_distance: {
      const bool pl = metric == PanelMetric::planarity;
      for (int32_t p = 0; p < n; ++p)
        for (int k = 0; k < 4; ++k) {
          raise(layout.top(p, k), pl ? e.planarity_top[p] : e.corner_distance_top[p]);
          raise(layout.bottom(p, k), pl ? e.planarity_bottom[p] : e.corner_distance_bottom[p]);
        }
      break;
    }
    case PanelMetric::thickness:
      for (int32_t p = 0; p < n; ++p)
        for (int k = 0; k < 4; ++k) {
          raise(layout.top(p, k), e.thickness[p]);
          raise(layout.bottom(p, k), e.thickness[p]);
        }
      break;
    case PanelMetric::miter: {
      const std::vector<PanelJoint>& joints = topology.joints;
      for (size_t j = 0; j < joints.size(); ++j) {
        const PanelJoint& jt = joints[j];
        for (int side = 0; side < (jt.other_panel >= 0 ? 2 : 1); ++side) {
          const int32_t p = side == 0 ? jt.panel : jt.other_panel;
          const int32_t k = side == 0 ? jt.corner : jt.other_corner;
          for (int c : {k, (k + 1) % 4}) {
            raise(layout.top(p, c), e.miter[j]);
            raise(layout.bottom(p, c), e.miter[j]);
          }
        }
      }
      break;
    }
    case PanelMetric::conical: {
      const std::vector<ConicalVertex>& cv = topology.conical;
      for (size_t i = 0; i < cv.size(); ++i)
        for (int f = 0; f < 4; ++f) {
          raise(layout.top(cv[i].panel[f], cv[i].corner[f]), e.conical[i]);
          raise(layout.bottom(cv[i].panel[f], cv[i].corner[f]), e.conical[i]);
        }
      break;
    }
  }
  return out;
}

// --- cut list ------------------------------------------------------------------------------------------

std::vector<PanelCut> panel_cuts(const PanelLayout& layout, std::span<const Vec3> x) {
  std::vector<PanelCut> cuts;
  for (int32_t p = 0; p < layout.panel_count(); ++p) {
    Vec3 t[4], b[4];
    for (int k = 0; k < 4; ++k) {
      t[k] = x[layout.top(p, k)];
      b[k] = x[layout.bottom(p, k)];
    }
    const Vec3 ex = (t[1] - t[0]).normalized();
    const Vec3 ez = (t[2] - t[0]).cross(t[3] - t[1]).normalized();
    const Vec3 ey = ez.cross(ex);
    PanelCut c{};
    double z = 0.0;
    for (int k = 0; k < 4; ++k) {
      c.top[k][0] = (t[k] - t[0]).dot(ex);
      c.top[k][1] = (t[k] - t[0]).dot(ey);
      c.bottom[k][0] = (b[k] - t[0]).dot(ex);
      c.bottom[k][1] = (b[k] - t[0]).dot(ey);
      z += (b[k] - t[0]).dot(ez) / 4.0;
    }
    c.bottom_z = z;
    c.thickness = layout.thickness;
    for (int k = 0; k < 4; ++k) {
      const int k1 = (k + 1) % 4;
      const Vec3 e = (t[k1] - t[k]).normalized();
      Vec3 u = ((b[k] - t[k]) + (b[k1] - t[k1])) / 2.0;
      u -= u.dot(e) * e;
      const Vec3 outward = e.cross(ez);
      c.miter_deg[k] = std::atan2(u.dot(outward), -u.dot(ez)) * 180.0 / std::numbers::pi;
    }
    cuts.push_back(c);
  }
  return cuts;
}

namespace {
std::string fmt(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.9g", v);
  return s;
}
}  // namespace

std::string panel_cuts_json(const std::vector<PanelCut>& cuts) {
  std::string s = "{\"format\": \"embra-panel-cuts\", \"version\": 1, \"panels\": [";
  for (size_t p = 0; p < cuts.size(); ++p) {
    const PanelCut& c = cuts[p];
    s += p ? ",\n  " : "\n  ";
    s += "{\"panel\": " + std::to_string(p) + ", \"thickness\": " + fmt(c.thickness) +
         ", \"bottom_z\": " + fmt(c.bottom_z) + ", \"top\": [";
    for (int k = 0; k < 4; ++k)
      s += std::string(k ? ", " : "") + "[" + fmt(c.top[k][0]) + ", " + fmt(c.top[k][1]) + "]";
    s += "], \"bottom\": [";
    for (int k = 0; k < 4; ++k)
      s += std::string(k ? ", " : "") + "[" + fmt(c.bottom[k][0]) + ", " + fmt(c.bottom[k][1]) + "]";
    s += "], \"miter_deg\": [";
    for (int k = 0; k < 4; ++k) s += std::string(k ? ", " : "") + fmt(c.miter_deg[k]);
    s += "]}";
  }
  s += "\n]}\n";
  return s;
}

std::string panel_cuts_csv(const std::vector<PanelCut>& cuts) {
  std::string s = "panel,thickness,bottom_z";
  for (const char* layer : {"top", "bottom"})
    for (int k = 0; k < 4; ++k)
      s += std::string(",") + layer + std::to_string(k) + "_x," + layer + std::to_string(k) + "_y";
  for (int k = 0; k < 4; ++k) s += ",miter" + std::to_string(k) + "_deg";
  s += "\n";
  for (size_t p = 0; p < cuts.size(); ++p) {
    const PanelCut& c = cuts[p];
    s += std::to_string(p) + "," + fmt(c.thickness) + "," + fmt(c.bottom_z);
    for (int k = 0; k < 4; ++k) s += "," + fmt(c.top[k][0]) + "," + fmt(c.top[k][1]);
    for (int k = 0; k < 4; ++k) s += "," + fmt(c.bottom[k][0]) + "," + fmt(c.bottom[k][1]);
    for (int k = 0; k < 4; ++k) s += "," + fmt(c.miter_deg[k]);
    s += "\n";
  }
  return s;
}

// --- builder -------------------------------------------------------------------------------------------

void panel_grid(int32_t n, int32_t m, double size, const Vec3& origin, std::vector<double>& out_positions,
                std::vector<int32_t>& out_quads) {
  if (n < 1 || m < 1 || n > 4096 || m > 4096) invalid("panel grid must have 1 to 4096 panels each way");
  if (8 * int64_t{n} * m > limits::kMaxParticles)
    invalid("a panel grid of " + std::to_string(n) + " x " + std::to_string(m) +
            " panels needs more than the 2097152 particles a world holds (8 per panel)");
  check_positive(size, "panel size");
  for (int c = 0; c < 3; ++c) check_finite(origin[c], "panel grid origin");
  out_positions.clear();
  out_quads.clear();
  for (int32_t j = 0; j <= m; ++j)
    for (int32_t i = 0; i <= n; ++i)
      out_positions.insert(out_positions.end(), {origin.x() + i * size, origin.y() + j * size, origin.z()});
  for (int32_t j = 0; j < m; ++j)
    for (int32_t i = 0; i < n; ++i) {
      const int32_t v = j * (n + 1) + i;
      out_quads.insert(out_quads.end(), {v, v + 1, v + n + 2, v + n + 1});
    }
}

Id build_panel_mesh(World& world, const PanelMeshDesc& d) {
  // --- check everything first ---
  if (d.positions.empty() || d.positions.size() % 3 != 0)
    invalid("panel mesh positions must be a non-empty array of 3 numbers per vertex");
  if (d.quads.empty() || d.quads.size() % 4 != 0)
    invalid("panel mesh quads must be a non-empty array of 4 indices per quad");
  const int64_t nv = static_cast<int64_t>(d.positions.size() / 3);
  const int64_t np = static_cast<int64_t>(d.quads.size() / 4);
  const int32_t corners = static_cast<int32_t>(d.corners);
  if (corners < 0 || corners > 1) invalid("panel mesh corners must be 0 (welded) or 1 (shared)");
  const int32_t precision = static_cast<int32_t>(d.precision);
  if (precision < 0 || precision > 1) invalid("panel mesh precision must be 0 (full) or 1 (single)");
  const bool shared = d.corners == PanelCorners::shared;
  if (nv > std::numeric_limits<int32_t>::max()) invalid("panel mesh has more vertices than an int32 counts");
  // The layout first (body-local: first_particle 0 until the body exists): it places the particles
  // and triangles, and says how many particles there are.
  PanelLayout layout;
  layout.vertex_count = static_cast<int32_t>(nv);
  layout.quads.assign(d.quads.begin(), d.quads.end());
  layout.thickness = d.thickness;
  layout.shared = shared;
  layout.single = d.precision == PanelPrecision::single;
  const int64_t particles = layout.particle_count();
  if (particles + world.particle_count() > limits::kMaxParticles)
    invalid("a world holds at most 2097152 particles; " + std::to_string(np) + " panels on " + std::to_string(nv) +
            " vertices (" + (shared ? "2 particles a vertex" : "8 particles a panel") + ") would make " +
            std::to_string(particles + world.particle_count()));
  for (double c : d.positions) check_finite(c, "panel mesh vertex coordinate");
  check_positive(d.thickness, "panel thickness");
  check_zero_or_positive(d.mass, "panel mesh mass");
  check_zero_or_positive(d.density, "panel mesh density");
  if (d.mass == 0.0 && d.density == 0.0) invalid("panel mesh needs a mass or a density > 0");
  check_non_negative(d.damping, "panel mesh damping");
  check_non_negative(d.friction_static, "panel mesh friction_static");
  check_non_negative(d.friction_dynamic, "panel mesh friction_dynamic");
  check_non_negative(d.slide_compliance, "panel mesh slide_compliance");
  const int32_t pins = static_cast<int32_t>(d.pins);
  if (pins < 0 || pins > 2) invalid("panel mesh pins must be 0 (none), 1 (top corners) or 2 (top and bottom corners)");
  if (!d.group.is_null()) world.group(d.group);  // throws for a stale group
  auto P = [&](int32_t v) { return Vec3(d.positions[3 * v], d.positions[3 * v + 1], d.positions[3 * v + 2]); };
  std::map<std::pair<int32_t, int32_t>, int> directed;
  std::map<std::pair<int32_t, int32_t>, int> undirected;
  for (int64_t q = 0; q < np; ++q) {
    const int32_t* v = &d.quads[4 * q];
    const std::string name = "quad " + std::to_string(q);
    for (int k = 0; k < 4; ++k) {
      if (v[k] < 0 || v[k] >= nv)
        invalid(name + " vertex " + std::to_string(v[k]) + " is outside [0, " + std::to_string(nv) + ")");
      for (int j = 0; j < k; ++j)
        if (v[j] == v[k]) invalid(name + " is degenerate: vertex " + std::to_string(v[k]) + " appears twice");
    }
    for (int k = 0; k < 4; ++k) {
      const int32_t a = v[k], b = v[(k + 1) % 4];
      if (++directed[{a, b}] > 1)
        invalid(name + ": edge " + std::to_string(a) + "-" + std::to_string(b) +
                " is used twice in the same direction (quads must be oriented consistently)");
      if (++undirected[edge_key(a, b)] > 2)
        invalid(name + ": edge " + std::to_string(a) + "-" + std::to_string(b) + " is shared by more than two quads");
    }
    const Vec3 q0 = P(v[0]), q1 = P(v[1]), q2 = P(v[2]), q3 = P(v[3]);
    const double mean_edge = ((q1 - q0).norm() + (q2 - q1).norm() + (q3 - q2).norm() + (q0 - q3).norm()) / 4.0;
    const Vec3 n = (q2 - q0).cross(q3 - q1);
    if (!(mean_edge > 0.0) || !(n.norm() > 1e-12 * mean_edge * mean_edge))
      invalid(name + " is degenerate: its diagonals are parallel (zero area)");
    for (int k = 0; k < 4; ++k)
      if (!((P(v[(k + 1) % 4]) - P(v[k])).norm() > 1e-9 * mean_edge))
        invalid(name + " is degenerate: an edge has zero length");
    // Planar within the tolerances in force: the paper's planarity (1 - n1.n2, free of the mesh's
    // scale) at most its target; a real PQ mesh is planar to its optimiser's tolerance, not to
    // rounding. The corner distance is measured and reported at every frame but does not decide:
    // a length in model units, its target (5e-5 m by default) is on a 1 m square with one corner
    // raised a planarity of 2.5e-9 (1 - n1.n2 = d^2 / (1 + d^2)), 400 times below the planarity
    // target, and so refused published PQ meshes well within the planarity target (see
    // docs/design.md, "Panel meshes"). The hard planarity of each top quad takes it down as the
    // world steps.
    const double planarity = quad_planarity(q0, q1, q2, q3);
    if (!(planarity <= d.tolerances.planarity.target))
      invalid(name + " is not planar within the tolerances: planarity " + g3(planarity) + " (target " +
              g3(d.tolerances.planarity.target) + "), corner distance " + g3(quad_corner_distance(q0, q1, q2, q3)));
  }

  // --- bottom layer: each vertex offset to where its faces' offset planes meet ---
  const auto around = corners_around(d.quads, nv);
  if (shared)
    for (int64_t v = 0; v < nv; ++v)
      if (around[v].empty())
        invalid("vertex " + std::to_string(v) +
                " is on no quad (a panel mesh with shared corners makes a particle of every vertex)");
  std::vector<Vec3> face_normal(np);
  std::vector<double> area(np);
  for (int64_t q = 0; q < np; ++q) {
    const int32_t* v = &d.quads[4 * q];
    const Vec3 n = (P(v[2]) - P(v[0])).cross(P(v[3]) - P(v[1]));
    area[q] = 0.5 * n.norm();
    face_normal[q] = n.normalized();
  }
  std::vector<Vec3> offset(nv, Vec3::Zero());    // bottom - top per mesh vertex
  std::vector<std::vector<Vec3>> free_dirs(nv);  // the directions its faces leave an offset free in
  for (int64_t v = 0; v < nv; ++v) {
    if (around[v].empty()) continue;
    // n_f . y = -thickness for every face f, in the least-squares sense; where the faces do not
    // decide y (a flat vertex, a boundary) the point nearest -thickness * (mean normal) is taken:
    // y = y0 + N^+ (r - N y0), with the pseudo-inverse of the stacked normals N.
    const Eigen::Index m = static_cast<Eigen::Index>(around[v].size());
    Eigen::MatrixXd normals(m, 3);
    Vec3 mean = Vec3::Zero();
    for (Eigen::Index f = 0; f < m; ++f) {
      normals.row(f) = face_normal[around[v][f].first].transpose();
      mean += face_normal[around[v][f].first];
    }
    const Vec3 y0 = -d.thickness * mean.normalized();
    const Eigen::VectorXd r = Eigen::VectorXd::Constant(m, -d.thickness) - normals * y0;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(normals, Eigen::ComputeThinU | Eigen::ComputeFullV);
    svd.setThreshold(1e-9);
    offset[v] = y0 + svd.solve(r);
    for (Eigen::Index k = svd.rank(); k < 3; ++k) free_dirs[v].push_back(svd.matrixV().col(k));
  }

  // --- boundary joints planar: the offsets moved along what their faces leave free ---
  // A boundary edge (a, b) of face f, top edge e = b - a, offsets y_a, y_b (bottom - top): its joint
  // face (a, b and their bottom corners) is planar exactly when g = e . (y_a x y_b) / (t |e|) = 0.
  // Each offset may move along its free directions (a line for a vertex on two faces, a plane for
  // one on one face; moves that keep it on every offset plane of its faces). Where a and b lie on
  // a plane parallel to f's offset plane (a planar quad), g = (y_b - y_a) . (n_f x e / |e|) is
  // linear in the moves and one least-norm solve makes every boundary joint planar when no boundary
  // vertex is on three faces or more; a quad planar only to a tolerance has top edges that leave
  // that plane, and g has a small bilinear part: Newton steps (each the least-norm solution of the
  // linearised equations) take it to rounding. Inner joints are planar wherever the faces round
  // each vertex decide its offset: a planar quad mesh conical at its inner vertices.
  {
    std::vector<std::array<int32_t, 2>> edges;  // (a, b) of each boundary edge
    for (int64_t q = 0; q < np; ++q) {
      const int32_t* v = &d.quads[4 * q];
      for (int k = 0; k < 4; ++k)
        if (undirected[edge_key(v[k], v[(k + 1) % 4])] == 1) edges.push_back({v[k], v[(k + 1) % 4]});
    }
    std::vector<int32_t> column(nv, -1);  // the first unknown of each vertex's moves
    Eigen::Index unknowns = 0;
    for (const auto& e : edges)
      for (int32_t v : {e[0], e[1]})
        if (column[v] < 0 && !free_dirs[v].empty()) {
          column[v] = static_cast<int32_t>(unknowns);
          unknowns += static_cast<Eigen::Index>(free_dirs[v].size());
        }
    const auto rows = static_cast<Eigen::Index>(edges.size());
    // g of every boundary edge at the current offsets; returns its largest magnitude.
    auto residual = [&](Eigen::VectorXd& g) {
      double worst = 0.0;
      for (size_t i = 0; i < edges.size(); ++i) {
        const auto& [va, vb] = edges[i];
        const Vec3 e = P(vb) - P(va);
        g(static_cast<Eigen::Index>(i)) = e.dot(offset[va].cross(offset[vb])) / (d.thickness * e.norm());
        worst = std::max(worst, std::abs(g(static_cast<Eigen::Index>(i))));
      }
      return worst;
    };
    Eigen::VectorXd g(rows);
    double worst = unknowns > 0 ? residual(g) : 0.0;
    // At most 8 steps; a step that does not lower the largest |g| is undone and ends the loop.
    for (int iteration = 0; iteration < 8 && unknowns > 0 && worst > 1e-14 * d.thickness; ++iteration) {
      // Least norm: step = A^T (A A^T + eps I)^-1 (-g), A sparse (a row per edge: dg over its two
      // vertices' directions); eps (1e-12 of A A^T's largest diagonal) keeps it defined where the
      // equations cannot all hold, and then gives their least-squares solution to that order.
      std::vector<Eigen::Triplet<double>> entries;
      for (size_t i = 0; i < edges.size(); ++i) {
        const auto& [va, vb] = edges[i];
        const Vec3 e = P(vb) - P(va);
        const double scale = 1.0 / (d.thickness * e.norm());
        const Vec3 db = e.cross(offset[va]) * scale;  // dg/dy_b
        const Vec3 da = offset[vb].cross(e) * scale;  // dg/dy_a
        const auto row = static_cast<Eigen::Index>(i);
        for (size_t k = 0; k < free_dirs[vb].size(); ++k)
          entries.emplace_back(row, column[vb] + static_cast<Eigen::Index>(k), free_dirs[vb][k].dot(db));
        for (size_t k = 0; k < free_dirs[va].size(); ++k)
          entries.emplace_back(row, column[va] + static_cast<Eigen::Index>(k), free_dirs[va][k].dot(da));
      }
      Eigen::SparseMatrix<double> a(rows, unknowns);
      a.setFromTriplets(entries.begin(), entries.end());
      Eigen::SparseMatrix<double> aat = a * a.transpose();
      double largest = 0.0;
      for (Eigen::Index i = 0; i < rows; ++i) largest = std::max(largest, aat.coeff(i, i));
      Eigen::SparseMatrix<double> eps(rows, rows);
      eps.setIdentity();
      aat += (1e-12 * largest) * eps;
      const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(aat);
      if (!(largest > 0.0) || ldlt.info() != Eigen::Success) break;
      const Eigen::VectorXd step = a.transpose() * ldlt.solve(-g);
      if (!step.allFinite()) break;
      auto move = [&](double sign) {
        for (int64_t v = 0; v < nv; ++v)
          for (size_t k = 0; column[v] >= 0 && k < free_dirs[v].size(); ++k)
            offset[v] += sign * step(column[v] + static_cast<Eigen::Index>(k)) * free_dirs[v][k];
      };
      move(1.0);
      const double next = residual(g);
      if (!(next < worst)) {
        move(-1.0);
        break;
      }
      worst = next;
    }
  }

  // --- particles ---
  std::vector<double> xyz;
  xyz.reserve(static_cast<size_t>(24 * np));
  double total_area = 0.0;
  for (double s : area) total_area += s;
  std::vector<double> masses;
  std::vector<int32_t> triangles;
  xyz.assign(static_cast<size_t>(3 * particles), 0.0);
  masses.assign(static_cast<size_t>(particles), 0.0);
  for (int32_t q = 0; q < np; ++q) {
    const int32_t* v = &d.quads[4 * static_cast<int64_t>(q)];
    // Each panel's mass in eighths on its corners (summed where corners are shared).
    const double m = d.mass > 0.0 ? d.mass * area[q] / total_area : d.density * area[q];
    for (int k = 0; k < 4; ++k) {
      const Vec3 t = P(v[k]), b = P(v[k]) + offset[v[k]];
      const int32_t it = layout.top(q, k), ib = layout.bottom(q, k);
      for (int c = 0; c < 3; ++c) {
        xyz[3 * static_cast<size_t>(it) + c] = t[c];
        xyz[3 * static_cast<size_t>(ib) + c] = b[c];
      }
      masses[static_cast<size_t>(it)] += m / 8.0;
      masses[static_cast<size_t>(ib)] += m / 8.0;
    }
    auto T = [&](int k) { return layout.top(q, k); };
    auto B = [&](int k) { return layout.bottom(q, k); };
    triangles.insert(triangles.end(), {T(0), T(1), T(2), T(0), T(2), T(3)});
    triangles.insert(triangles.end(), {B(0), B(2), B(1), B(0), B(3), B(2)});
  }
  BodyDesc body;
  body.positions = xyz;
  body.masses = masses;
  body.triangles = triangles;
  body.generate = 0;
  body.material.damping = d.damping;
  body.material.friction_static = d.friction_static;
  body.material.friction_dynamic = d.friction_dynamic;
  body.material.bend_compliance = 0.0;
  const Id id = world.create_body(body);
  layout.body = id;
  layout.first_particle = world.body(id).first_particle;

  // --- constraints ---
  auto add = [&](Kind kind, const std::vector<int32_t>& ids, const std::vector<double>& rest, double compliance) {
    if (ids.empty()) return;
    ConstraintDesc c;
    c.kind = kind;
    c.group = d.group;
    c.particles = ids;
    c.rest = rest;
    c.uniform_compliance = compliance;
    world.add_constraints(c);
  };
  const std::vector<Vec3>& x = world.positions();
  std::vector<int32_t> ids;
  std::vector<double> rest;
  // (a) the top quad braced: 4 edges and 2 diagonals (an edge two panels share, once).
  for (int32_t p = 0; p < np; ++p)
    for (auto [i, j] : {std::pair{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}, {1, 3}}) {
      const int32_t vi = d.quads[4 * static_cast<size_t>(p) + i], vj = d.quads[4 * static_cast<size_t>(p) + j];
      const bool edge =
          (i + 1) % 4 == j;  // else a diagonal; an inner edge is (vi, vj) in one panel, (vj, vi) in the other
      if (shared && edge && vi > vj && undirected[edge_key(vi, vj)] == 2) continue;
      ids.insert(ids.end(), {layout.top(p, i), layout.top(p, j)});
      rest.push_back((x[layout.top(p, i)] - x[layout.top(p, j)]).norm());
    }
  add(Kind::distance, ids, rest, 0.0);
  // (b) welded: the corners on one vertex welded, top and bottom.
  ids.clear();
  for (int64_t v = 0; v < (shared ? 0 : nv); ++v)
    for (size_t f = 1; f < around[v].size(); ++f) {
      const auto [p0, k0] = around[v][0];
      const auto [p, k] = around[v][f];
      ids.insert(ids.end(), {layout.top(p0, k0), layout.top(p, k)});
      ids.insert(ids.end(), {layout.bottom(p0, k0), layout.bottom(p, k)});
    }
  add(Kind::weld, ids, std::vector<double>(ids.size() / 2, 0.0), 0.0);
  // Planarity: the top quad, and every joint (miter face).
  ids.clear();
  for (int32_t p = 0; p < np; ++p)
    ids.insert(ids.end(), {layout.top(p, 0), layout.top(p, 1), layout.top(p, 2), layout.top(p, 3)});
  for (const PanelJoint& j : panel_joints(layout)) {
    const int k = j.corner, k1 = (j.corner + 1) % 4;
    ids.insert(ids.end(), {layout.top(j.panel, k), layout.top(j.panel, k1), layout.bottom(j.panel, k1),
                           layout.bottom(j.panel, k)});
  }
  add(Kind::planarity, ids, std::vector<double>(ids.size() / 4, 0.0), 0.0);
  // (d) each bottom corner at -thickness from the plane of its top corner's triangle.
  ids.clear();
  for (int32_t p = 0; p < np; ++p)
    for (int k = 0; k < 4; ++k)
      ids.insert(ids.end(),
                 {layout.bottom(p, k), layout.top(p, k), layout.top(p, (k + 1) % 4), layout.top(p, (k + 3) % 4)});
  add(Kind::plane_offset, ids, std::vector<double>(ids.size() / 4, -d.thickness), 0.0);
  // The soft hold of each bottom corner near its top corner.
  if (d.slide_compliance > 0.0) {
    ids.clear();
    rest.clear();
    for (int32_t p = 0; p < np; ++p)
      for (int k = 0; k < 4; ++k) {
        if (shared && around[d.quads[4 * static_cast<size_t>(p) + k]][0] != std::pair{p, k}) continue;  // once a vertex
        ids.insert(ids.end(), {layout.bottom(p, k), layout.top(p, k)});
        rest.push_back((x[layout.bottom(p, k)] - x[layout.top(p, k)]).norm());
      }
    add(Kind::distance, ids, rest, d.slide_compliance);
  }
  // Pins at the mesh's corners (vertices of one panel).
  if (d.pins != PanelPins::none)
    for (int64_t v = 0; v < nv; ++v) {
      if (around[v].size() != 1) continue;
      const auto [p, k] = around[v][0];
      PinDesc pin;
      pin.particle = layout.top(p, k);
      pin.target = x[pin.particle];
      world.create_pin(pin);
      if (d.pins == PanelPins::top_and_bottom_corners) {
        pin.particle = layout.bottom(p, k);
        pin.target = x[pin.particle];
        world.create_pin(pin);
      }
    }
  world.set_panel_layout(layout);
  return id;
}

}  // namespace embra
