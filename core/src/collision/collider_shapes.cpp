#include "collision/collider_shapes.hpp"

#include "collision/self_collision.hpp"
#include "common/check.hpp"
#include "common/triangle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>

namespace embra {

namespace {

/// Closest point of triangle (a, b, c) to p and the feature it lies on: 0..2 vertex k, 3..5 edge
/// (k, k+1), 6 the face (TriangleRegion's numbering).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& feature) {
  const TriangleRegion r = triangle_region(p, a, b, c);
  feature = r.feature;
  switch (r.feature) {
    case TriangleRegion::vertex_a:
      return a;
    case TriangleRegion::vertex_b:
      return b;
    case TriangleRegion::vertex_c:
      return c;
    case TriangleRegion::edge_ab:
      return a + r.t * (b - a);
    case TriangleRegion::edge_ac:
      return a + r.t * (c - a);
    case TriangleRegion::edge_bc:
      return b + r.t * (c - b);
    default:
      return a + (b - a) * r.v + (c - a) * r.w;
  }
}

}  // namespace

Vec3 closest_barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  double bary[3];
  self_collision::point_triangle_distance(p, a, b, c, bary);
  return Vec3(bary[0], bary[1], bary[2]);
}

namespace {

double box_distance(const Vec3& e, const Vec3& p, Vec3& n) {
  const Vec3 q = p.cwiseAbs() - e;
  if (q.maxCoeff() > 0.0) {
    const Vec3 d = p - p.cwiseMax(-e).cwiseMin(e);
    const double len = d.norm();
    n = d / len;
    return len;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (q[k] > q[axis]) axis = k;
  n = Vec3::Zero();
  n[axis] = p[axis] < 0.0 ? -1.0 : 1.0;
  return q[axis];
}

double capsule_distance(double radius, double half_length, const Vec3& p, Vec3& n) {
  const Vec3 c(0.0, 0.0, std::clamp(p.z(), -half_length, half_length));
  const Vec3 d = p - c;
  const double len = d.norm();
  if (len > 0.0)
    n = d / len;
  else
    n = Vec3::UnitX();  // on the axis: any radial direction is closest
  return len - radius;
}

/// Below this distance a point counts as on the surface for the direction of its normal.
double on_surface(const Vec3& p) {
  return 1e-9 * (1.0 + p.cwiseAbs().maxCoeff());
}

double convex_distance(const ColliderGeometry& g, const Vec3& p, Vec3& n) {
  // Inside (or on) the hull the distance to the surface is that to the nearest face plane.
  double best = -std::numeric_limits<double>::infinity();
  size_t best_face = 0;
  for (size_t f = 0; f < g.triangles.size(); ++f) {
    const double s = g.face_normal[f].dot(p) - g.face_offset[f];
    if (s > best) {
      best = s;
      best_face = f;
    }
  }
  if (best <= 0.0) {
    n = g.face_normal[best_face];
    return best;
  }
  double d2 = std::numeric_limits<double>::infinity();
  Vec3 closest = p;
  for (const auto& t : g.triangles) {
    int feature;
    const Vec3 c = closest_on_triangle(p, g.vertices[t[0]], g.vertices[t[1]], g.vertices[t[2]], feature);
    const double e = (p - c).squaredNorm();
    if (e < d2) {
      d2 = e;
      closest = c;
    }
  }
  const double len = std::sqrt(d2);
  // On the surface to rounding, the direction to the closest point is noise: take the face's.
  n = len > on_surface(p) ? Vec3((p - closest) / len) : g.face_normal[best_face];
  return len;
}

double box_point_distance2(const Vec3& lo, const Vec3& hi, const Vec3& p) {
  const Vec3 d = (lo - p).cwiseMax(p - hi).cwiseMax(Vec3::Zero());
  return d.squaredNorm();
}

double mesh_distance(const ColliderGeometry& g, const Vec3& p, Vec3& n) {
  double best = std::numeric_limits<double>::infinity();
  int32_t best_tri = -1;
  int best_feature = 6;
  Vec3 closest = p;
  int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const ColliderGeometry::Node& node = g.nodes[stack[--top]];
    if (box_point_distance2(node.lo, node.hi, p) >= best) continue;
    if (node.left < 0) {
      for (int32_t k = node.first; k < node.first + node.count; ++k) {
        const int32_t ti = g.order[k];
        const auto& t = g.triangles[ti];
        int feature;
        const Vec3 c = closest_on_triangle(p, g.vertices[t[0]], g.vertices[t[1]], g.vertices[t[2]], feature);
        const double e = (p - c).squaredNorm();
        if (e < best || (e == best && ti < best_tri)) {
          best = e;
          best_tri = ti;
          best_feature = feature;
          closest = c;
        }
      }
      continue;
    }
    // Nearer child last, so it is searched first.
    const ColliderGeometry::Node& l = g.nodes[node.left];
    const ColliderGeometry::Node& r = g.nodes[node.right];
    const double dl = box_point_distance2(l.lo, l.hi, p), dr = box_point_distance2(r.lo, r.hi, p);
    if (dl <= dr) {
      stack[top++] = node.right;
      stack[top++] = node.left;
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
  const double len = std::sqrt(best);
  const Vec3 face = g.face_normal[best_tri];
  if (!g.closed) {
    // A two-sided sheet: the normal points from the sheet to the particle.
    if (len > on_surface(p))
      n = (p - closest) / len;
    else
      n = face;
    return len;
  }
  const auto& t = g.triangles[best_tri];
  Vec3 pseudo;
  if (best_feature < 3)
    pseudo = g.vertex_normal[t[best_feature]];
  else if (best_feature < 6)
    pseudo = g.edge_normal[best_tri][best_feature - 3];
  else
    pseudo = face;
  const double sign = (p - closest).dot(pseudo) < 0.0 ? -1.0 : 1.0;
  if (len > on_surface(p))
    n = sign * (p - closest) / len;
  else
    n = pseudo.normalized();
  return sign * len;
}

/// Builds the AABB tree over a mesh's triangles: median split on the longest axis of the centroids.
void build_tree(ColliderGeometry& g) {
  const size_t nt = g.triangles.size();
  g.order.resize(nt);
  std::vector<Vec3> centroid(nt);
  for (size_t i = 0; i < nt; ++i) {
    g.order[i] = static_cast<int32_t>(i);
    const auto& t = g.triangles[i];
    centroid[i] = (g.vertices[t[0]] + g.vertices[t[1]] + g.vertices[t[2]]) / 3.0;
  }
  g.nodes.clear();
  g.nodes.reserve(2 * nt);
  struct Task {
    int32_t node, first, count;
  };
  std::vector<Task> tasks;
  g.nodes.push_back({});
  tasks.push_back({0, 0, static_cast<int32_t>(nt)});
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    Vec3 clo = lo, chi = hi;
    for (int32_t k = task.first; k < task.first + task.count; ++k) {
      const auto& t = g.triangles[g.order[k]];
      for (int v = 0; v < 3; ++v) {
        lo = lo.cwiseMin(g.vertices[t[v]]);
        hi = hi.cwiseMax(g.vertices[t[v]]);
      }
      clo = clo.cwiseMin(centroid[g.order[k]]);
      chi = chi.cwiseMax(centroid[g.order[k]]);
    }
    g.nodes[task.node].lo = lo;
    g.nodes[task.node].hi = hi;
    if (task.count <= 4) {
      g.nodes[task.node].first = task.first;
      g.nodes[task.node].count = task.count;
      continue;
    }
    int axis = 0;
    const Vec3 ext = chi - clo;
    for (int k = 1; k < 3; ++k)
      if (ext[k] > ext[axis]) axis = k;
    const int32_t half = task.count / 2;
    auto* begin = g.order.data() + task.first;
    std::nth_element(begin, begin + half, begin + task.count, [&](int32_t a, int32_t b) {
      return centroid[a][axis] < centroid[b][axis] || (centroid[a][axis] == centroid[b][axis] && a < b);
    });
    const int32_t left = static_cast<int32_t>(g.nodes.size());
    g.nodes.push_back({});
    g.nodes.push_back({});
    g.nodes[task.node].left = left;
    g.nodes[task.node].right = left + 1;
    tasks.push_back({left, task.first, half});
    tasks.push_back({left + 1, task.first + half, task.count - half});
  }
}

std::vector<Vec3> read_points(const ColliderDesc& desc, const char* shape) {
  if (desc.vertices.size() % 3 != 0) invalid(std::string(shape) + " vertex array length is not a multiple of 3");
  std::vector<Vec3> pts(desc.vertices.size() / 3);
  for (size_t i = 0; i < pts.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      check_finite(desc.vertices[3 * i + k], std::string(shape) + " vertex " + std::to_string(i) + " coordinate");
    pts[i] = Vec3(desc.vertices[3 * i], desc.vertices[3 * i + 1], desc.vertices[3 * i + 2]);
  }
  return pts;
}

double extent_of(const std::vector<Vec3>& pts) {
  Vec3 lo = pts[0], hi = pts[0];
  for (const Vec3& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

/// The convex hull of `pts` as outward triangles (incremental: each point outside the current hull
/// replaces the faces it sees by a fan over their horizon). Points within `eps` of a face plane are
/// taken as on it.
void build_hull(ColliderGeometry& g, const std::vector<Vec3>& pts) {
  const double scale = extent_of(pts);
  const double eps = 1e-12 * std::max(scale, 1e-300);
  // Initial tetrahedron of well-separated points.
  size_t i0 = 0, i1 = 0, i2 = 0, i3 = 0;
  double best = -1.0;
  for (size_t i = 0; i < pts.size(); ++i)
    if ((pts[i] - pts[i0]).squaredNorm() > best) best = (pts[i] - pts[i0]).squaredNorm(), i1 = i;
  best = -1.0;
  const Vec3 axis = pts[i1] - pts[i0];
  for (size_t i = 0; i < pts.size(); ++i) {
    const double d = axis.cross(pts[i] - pts[i0]).squaredNorm();
    if (d > best) best = d, i2 = i;
  }
  const Vec3 pn = axis.cross(pts[i2] - pts[i0]);
  best = -1.0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const double d = std::abs(pn.dot(pts[i] - pts[i0]));
    if (d > best) best = d, i3 = i;
  }
  const double pn_len = pn.norm();
  if (scale == 0.0 || pn_len <= 1e-12 * scale * scale || best / pn_len <= 1e-9 * scale)
    invalid("convex collider points are degenerate: the hull needs at least 4 points not in one plane");

  struct Face {
    std::array<int32_t, 3> v;
    Vec3 n;
    double d;
    bool alive;
  };
  std::vector<Face> faces;
  auto add_face = [&](int32_t a, int32_t b, int32_t c) {
    const Vec3 n = (pts[b] - pts[a]).cross(pts[c] - pts[a]);
    const double len = n.norm();
    const Vec3 u = len > 0.0 ? Vec3(n / len) : Vec3::Zero();
    faces.push_back({{a, b, c}, u, u.dot(pts[a]), true});
  };
  const Vec3 inside = (pts[i0] + pts[i1] + pts[i2] + pts[i3]) / 4.0;
  const int32_t t[4] = {static_cast<int32_t>(i0), static_cast<int32_t>(i1), static_cast<int32_t>(i2),
                        static_cast<int32_t>(i3)};
  const int tri[4][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};
  for (const auto& f : tri) {
    int32_t a = t[f[0]], b = t[f[1]], c = t[f[2]];
    if ((pts[b] - pts[a]).cross(pts[c] - pts[a]).dot(inside - pts[a]) > 0.0) std::swap(b, c);
    add_face(a, b, c);
  }
  for (size_t i = 0; i < pts.size(); ++i) {
    const int32_t pi = static_cast<int32_t>(i);
    if (pi == t[0] || pi == t[1] || pi == t[2] || pi == t[3]) continue;
    std::map<std::pair<int32_t, int32_t>, int> visible_edges;
    bool any = false;
    for (Face& f : faces) {
      if (!f.alive || f.n.dot(pts[i]) - f.d <= eps) continue;
      any = true;
      f.alive = false;
      for (int k = 0; k < 3; ++k) visible_edges[{f.v[k], f.v[(k + 1) % 3]}] += 1;
    }
    if (!any) continue;
    for (const auto& [e, count] : visible_edges)
      if (!visible_edges.contains({e.second, e.first})) add_face(e.first, e.second, pi);
  }
  for (const Face& f : faces)
    if (f.alive && f.n.squaredNorm() > 0.0) {
      g.triangles.push_back(f.v);
      g.face_normal.push_back(f.n);
      g.face_offset.push_back(f.d);
    }
  g.vertices = pts;
}

void build_mesh(ColliderGeometry& g, const ColliderDesc& desc, const std::vector<Vec3>& pts) {
  if (desc.triangles.empty()) invalid("mesh collider has no triangles");
  if (desc.triangles.size() % 3 != 0) invalid("mesh collider triangle index array length is not a multiple of 3");
  const double scale = extent_of(pts);
  const size_t nt = desc.triangles.size() / 3;
  for (size_t i = 0; i < nt; ++i) {
    std::array<int32_t, 3> t;
    for (int k = 0; k < 3; ++k) {
      t[k] = desc.triangles[3 * i + k];
      if (t[k] < 0 || static_cast<size_t>(t[k]) >= pts.size())
        invalid("mesh collider triangle " + std::to_string(i) + " has vertex index " + std::to_string(t[k]) +
                " outside [0, " + std::to_string(pts.size()) + ")");
    }
    const Vec3 n = (pts[t[1]] - pts[t[0]]).cross(pts[t[2]] - pts[t[0]]);
    if (!(n.norm() > 1e-12 * scale * scale))
      invalid("mesh collider triangle " + std::to_string(i) + " is degenerate (zero area)");
    g.triangles.push_back(t);
    g.face_normal.push_back(n.normalized());
  }
  g.vertices = pts;
  // Closed: every edge is used by exactly two triangles, once in each direction.
  std::map<std::pair<int32_t, int32_t>, int> directed;
  for (const auto& t : g.triangles)
    for (int k = 0; k < 3; ++k) directed[{t[k], t[(k + 1) % 3]}] += 1;
  g.closed = true;
  for (const auto& [e, count] : directed)
    if (count != 1 || !directed.contains({e.second, e.first})) {
      g.closed = false;
      break;
    }
  if (g.closed) {
    double volume = 0.0;
    for (const auto& t : g.triangles) volume += pts[t[0]].dot(pts[t[1]].cross(pts[t[2]]));
    if (volume < 0.0) {  // triangles wound inward: turn them so normals point out
      for (size_t i = 0; i < g.triangles.size(); ++i) {
        std::swap(g.triangles[i][1], g.triangles[i][2]);
        g.face_normal[i] = -g.face_normal[i];
      }
    }
    g.vertex_normal.assign(pts.size(), Vec3::Zero());
    std::map<std::pair<int32_t, int32_t>, Vec3> edge_sum;
    for (size_t i = 0; i < g.triangles.size(); ++i) {
      const auto& t = g.triangles[i];
      for (int k = 0; k < 3; ++k) {
        const Vec3 e1 = (pts[t[(k + 1) % 3]] - pts[t[k]]).normalized();
        const Vec3 e2 = (pts[t[(k + 2) % 3]] - pts[t[k]]).normalized();
        const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
        g.vertex_normal[t[k]] += angle * g.face_normal[i];
        const auto key = std::minmax(t[k], t[(k + 1) % 3]);
        auto it = edge_sum.try_emplace({key.first, key.second}, Vec3::Zero()).first;
        it->second += g.face_normal[i];
      }
    }
    g.edge_normal.resize(g.triangles.size());
    for (size_t i = 0; i < g.triangles.size(); ++i) {
      const auto& t = g.triangles[i];
      for (int k = 0; k < 3; ++k) {
        const auto key = std::minmax(t[k], t[(k + 1) % 3]);
        g.edge_normal[i][k] = edge_sum.at({key.first, key.second});
      }
    }
  }
  build_tree(g);
}

}  // namespace

std::shared_ptr<const ColliderGeometry> build_collider_geometry(const ColliderDesc& desc) {
  switch (desc.shape) {
    case ColliderShape::plane:
    case ColliderShape::sphere:
      return nullptr;
    case ColliderShape::box:
      for (int k = 0; k < 3; ++k) check_positive(desc.half_extents[k], "box half_extents");
      return std::make_shared<ColliderGeometry>();
    case ColliderShape::capsule:
      check_positive(desc.radius, "capsule radius");
      check_non_negative(desc.half_length, "capsule half_length");
      return std::make_shared<ColliderGeometry>();
    case ColliderShape::convex: {
      if (!desc.triangles.empty()) invalid("convex collider takes points only, no triangles");
      const std::vector<Vec3> pts = read_points(desc, "convex collider");
      if (pts.size() < 4)
        invalid("convex collider needs at least 4 points (it has " + std::to_string(pts.size()) + ")");
      auto g = std::make_shared<ColliderGeometry>();
      build_hull(*g, pts);
      return g;
    }
    case ColliderShape::mesh: {
      const std::vector<Vec3> pts = read_points(desc, "mesh collider");
      if (pts.size() < 3) invalid("mesh collider needs at least 3 vertices");
      auto g = std::make_shared<ColliderGeometry>();
      build_mesh(*g, desc, pts);
      return g;
    }
  }
  invalid("unknown collider shape " + std::to_string(static_cast<int>(desc.shape)));
}

double shape_distance(const ColliderDesc& desc, const ColliderGeometry& g, const Vec3& p, Vec3& normal) {
  switch (desc.shape) {
    case ColliderShape::box:
      return box_distance(desc.half_extents, p, normal);
    case ColliderShape::capsule:
      return capsule_distance(desc.radius, desc.half_length, p, normal);
    case ColliderShape::convex:
      return convex_distance(g, p, normal);
    case ColliderShape::mesh:
      return mesh_distance(g, p, normal);
    case ColliderShape::sphere: {
      const double len = p.norm();
      normal = len > 0.0 ? Vec3(p / len) : Vec3(Vec3::UnitZ());
      return len - desc.radius;
    }
    case ColliderShape::plane:
      break;
  }
  normal = Vec3::UnitZ();
  return p.z();
}

void shape_bounds(const ColliderDesc& desc, const ColliderGeometry& g, Vec3& lo, Vec3& hi) {
  switch (desc.shape) {
    case ColliderShape::box:
      hi = desc.half_extents;
      break;
    case ColliderShape::capsule:
      hi = Vec3(desc.radius, desc.radius, desc.radius + desc.half_length);
      break;
    case ColliderShape::sphere:
      hi = Vec3::Constant(desc.radius);
      break;
    case ColliderShape::convex:
    case ColliderShape::mesh:
      lo = hi = g.vertices[0];
      for (const Vec3& v : g.vertices) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
      return;
    case ColliderShape::plane:
      hi = Vec3::Constant(std::numeric_limits<double>::infinity());
      break;
  }
  lo = -hi;
}

}  // namespace embra
