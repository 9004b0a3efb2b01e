// Collider geometry in the collider's own frame: signed distances, outward normals and the swept
// (space-time) first contact of a particle path, for every collider shape but the plane and the
// sphere (which solver/contacts.cpp handles in closed form).
//
//   box      |p| <= half_extents componentwise
//   capsule  points within `radius` of the segment (0, 0, -half_length) - (0, 0, half_length)
//   convex   the convex hull of a point list, built once at creation (incremental hull)
//   mesh     a triangle mesh; closed (every edge shared by exactly two triangles) meshes are solids
//            whose inside is told by the angle-weighted pseudo-normal (Baerentzen & Aanaes 2005);
//            open meshes are two-sided sheets. An AABB tree over the triangles, built once.
//
// Every query is exact up to rounding (closest points, no iteration) except the swept search,
// which advances conservatively along the path (never past the first contact).
#pragma once

#include "embra/core/world.hpp"

#include <array>
#include <memory>
#include <vector>

namespace embra {

struct ColliderGeometry {
  // convex and mesh
  std::vector<Vec3> vertices;
  std::vector<std::array<int32_t, 3>> triangles;
  std::vector<Vec3> face_normal;                 // unit, outward
  std::vector<double> face_offset;               // convex: n . x <= offset inside
  std::vector<Vec3> vertex_normal;               // mesh: angle-weighted pseudo-normals
  std::vector<std::array<Vec3, 3>> edge_normal;  // mesh: per triangle, edge k = (v_k, v_k+1)
  bool closed = false;
  struct Node {
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
    int32_t first = 0, count = 0;  // leaf: triangles [first, first + count) of `order`
    int32_t left = -1, right = -1;
  };
  std::vector<Node> nodes;
  std::vector<int32_t> order;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // local bounds of the solid
};

/// Validates the shape fields of `desc` (throws Error(invalid_argument) with a clear message) and
/// builds the geometry a box, capsule, convex or mesh collider needs (null for plane and sphere).
std::shared_ptr<const ColliderGeometry> build_collider_geometry(const ColliderDesc& desc);

/// Signed distance from local point `p` to the surface of the collider's solid (negative inside;
/// for an open mesh the unsigned distance) and the outward unit normal there.
double shape_distance(const ColliderDesc& desc, const ColliderGeometry& g, const Vec3& p, Vec3& normal);

/// Barycentric coordinates (weights of a, b, c; non-negative, summing to 1) of the point of triangle
/// (a, b, c) closest to p (Ericson, Real-Time Collision Detection 5.1.5). Used by face contacts.
Vec3 closest_barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Local bounds of the solid (without clearance).
void shape_bounds(const ColliderDesc& desc, const ColliderGeometry& g, Vec3& lo, Vec3& hi);

}  // namespace embra
