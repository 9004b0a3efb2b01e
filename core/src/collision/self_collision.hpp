// Self-collision of cloth and shells (issue 4): point-triangle and edge-edge contacts between the
// triangles and edges of every body that has triangles, same body or different bodies (pairs
// sharing a vertex excluded), kept `thickness` apart (the two sides' half thicknesses added).
//
//   broad phase   regions around the particles (their swept bounds stretched ahead along their
//                 motion, where they go on to in the next substeps, and grown by a margin), and the
//                 candidate pairs they give, kept from substep to substep while their particles stay
//                 inside their regions. A particle that leaves its region gets a new one, and only
//                 the pairs of the primitives holding it are dropped and found again (each such
//                 primitive queried against the others). The queries walk a bounding-volume
//                 hierarchy over the primitives' region boxes (rounded outward to floats), built once
//                 for their topology (median splits of the items' centres along the widest axis, four
//                 items a leaf) and refitted where regions changed, and walked four boxes at a time
//                 (a node's children, or grandchildren, side by side); the changed primitives of a
//                 group of neighbouring items (kQueryGroup, in leaf order) share a walk, made with
//                 their united box (points, triangles and edges in one walk), each primitive an
//                 item met owns then tested against each of them. An item is a triangle with the
//                 particles and edges it owns (each particle and edge owned by the first triangle
//                 holding it), or a particle or edge held by no triangle, so a query meets each
//                 primitive once. Pairs that cannot come within their thickness while the regions
//                 hold (their distance, less what the regions let them move) are dropped when the
//                 pairs are found, as are
//                 the same body's pairs within their thickness in its rest shape (neighbours on the
//                 surface, listed once for the topology from a grid over the rest shape). The
//                 loops over particles, primitives, items and pairs are split over the pool's
//                 threads and their lists appended in part order; the contacts are sorted by their
//                 particles, so they do not depend on the hierarchy's splits or on history.
//   narrow phase  a kept pair becomes a contact when its swept bounds in this substep, each grown by
//                 the largest half thickness of its particles, overlap and it could come within the
//                 thickness during the substep: its distance at the start is below thickness + how
//                 far its vertices move.
//                 The contacts are the same as a broad phase rebuilt every substep would give.
//                 Each kept pair carries a gap, a lower bound of its distance less its thickness:
//                 set where its distance is measured, lowered in every later substep by the largest
//                 shift of each side's vertices since the last (a distance moves no more than that).
//                 A pair whose gap still clears its motion cannot be a contact, and is not measured;
//                 the others are measured: the swept bounds first (bounds apart raise the gap to
//                 their separation, less the thickness and plus the two growths), then the exact
//                 distance.
//                 Space-time: the first time in the substep at which the four points become coplanar
//                 with the point inside the triangle (or the two edges crossing) is found from the
//                 roots of the cubic coplanarity condition; the contact then acts at the barycentric
//                 coordinates of that first touch, else at the closest points at the start. Its normal
//                 is the side the pair was on at the start of the substep, so fast motion never passes
//                 through.
//   resolution    a hard unilateral XPBD constraint C = n . sum_k c_k x_k - thickness >= 0 (c_k the
//                 barycentric weights, negative on the triangle's or second edge's side), projected in
//                 the contact group after the collider contacts, with the accumulated multiplier
//                 clamped at 0 like every contact; friction (static/dynamic, the two sides' geometric
//                 mean) on the relative tangential motion when the velocities are updated.
#pragma once

#include "embra/core/world.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace embra::self_collision {

/// The state the detection reads: positions at the start of the substep and predicted.
struct Input {
  std::span<const BodyInfo> bodies;
  std::span<const Vec3> x_prev, x;
  std::span<const double> w;       // inverse masses (0 = immovable or hard-pinned)
  std::span<const double> radius;  // half thickness per particle
  std::span<const double> mu_s, mu_k;
  SelfCollisionCache* cache;  // the candidate pairs, kept from substep to substep while they hold
  ThreadPool* pool;           // the detection's loops are split over its threads (same result)
};

/// Finds the contacts of one substep (replaces `out`), in a deterministic order.
void find_contacts(const Input& in, std::vector<SelfContact>& out);

/// One Gauss-Seidel pass over the contacts (hard, unilateral, accumulated multiplier >= 0).
void project(std::span<SelfContact> contacts, std::span<Vec3> x, std::span<const double> w);

/// Adds each contact's w_k c_k lambda n to `out` (the realignment of Settings::realign_passes).
void add_corrections(std::span<const SelfContact> contacts, std::span<const double> w, std::span<Vec3> out);

/// Friction (friction_fraction) on the relative tangential motion of the pushing contacts over a
/// substep of h seconds.
void apply_friction(std::span<const SelfContact> contacts, std::span<Vec3> x, std::span<const Vec3> x_prev,
                    std::span<const double> w, double h);

/// max(-C, 0): how far a contact is inside its thickness.
double penetration(const SelfContact& c, std::span<const Vec3> x);

// --- narrow phase, exposed for the tests ----------------------------------------------------------

/// Distance from p to triangle (a, b, c); `bary` gets the closest point's barycentric coordinates.
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, double bary[3]);

/// Distance between segments (a0, a1) and (b0, b1); s and t are the closest points' parameters.
double edge_edge_distance(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1, double& s, double& t);

/// First time t in [0, 1] at which the point, moving linearly from p0 to p1, touches the triangle
/// moving linearly from (a0, b0, c0) to (a1, b1, c1): the first root of the coplanarity cubic at which
/// the point is within `tolerance` of the triangle. Returns false when it never touches.
bool point_triangle_toi(const Vec3& p0, const Vec3& p1, const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                        const Vec3& c0, const Vec3& c1, double tolerance, double& t);

/// The same for two moving segments (a0, a1) -> (a0e, a1e) and (b0, b1) -> (b0e, b1e).
bool edge_edge_toi(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1, const Vec3& a0e, const Vec3& a1e,
                   const Vec3& b0e, const Vec3& b1e, double tolerance, double& t);

// --- exact checks ---------------------------------------------------------------------------------

/// Sign of det[b - a, c - a, d - a] (positive when d is on the side of (a, b, c)'s normal by the
/// right hand rule), exact for any finite doubles: a filtered floating-point evaluation, then exact
/// expansion arithmetic when the filter cannot decide.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Whether the segment (p, q) crosses the closed triangle (a, b, c): its ends strictly on opposite
/// sides of the triangle's plane and the line through it meeting the triangle (boundary included).
/// Exact (orient3d only).
bool segment_crosses_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c);

/// How many (edge, triangle) pairs that share no vertex cross (segment_crosses_triangle), over the
/// given edges (2 indices each) and triangles (3 each) of positions x. Exact; a uniform grid finds the
/// candidate pairs.
int64_t count_edge_triangle_crossings(std::span<const Vec3> x, std::span<const int32_t> edges,
                                      std::span<const int32_t> triangles);

}  // namespace embra::self_collision
