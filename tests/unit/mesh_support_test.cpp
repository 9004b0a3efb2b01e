// Mesh supports (PinSupport::mesh, Kangaroo's OnMesh): a pin that holds its particle on the closest
// point of a triangle mesh, checked against geometry worked out here, independently of the solver.
//
//   - the distance to the mesh, |q - closest point|, has the gradient (q - c) / |q - c|: checked by
//     central differences against the test's own distance (each triangle's plane where q projects
//     inside it, else its three edges);
//   - one compliant projection inside a face leaves alpha / (w + alpha) of the distance (0 hard);
//   - a particle released on a flat two-triangle mesh inclined at theta slides down it on the
//     symplectic Euler path of g sin(theta) and the reaction is m g cos(theta) along the normal;
//   - a bead on a closed triangulated sphere (an icosphere, 320 triangles) pulled by gravity and a
//     point load slides over it and stays on it to 1e-9 m at every frame; damped, it comes to rest at
//     the vertex farthest along weight + load (the mesh's lowest point for that pull) with a reaction
//     that balances weight and load;
//   - moving the target moves the mesh; the same bits run after run; bad meshes are refused.
#include "closed_meshes.hpp"  // io::icosphere, the scenes' sphere (core/io/src)
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

namespace embra {
namespace {

constexpr double kG = 9.81;
using Tri = std::array<int32_t, 3>;

/// Distance from q to the segment ab.
double segment_distance(const Vec3& q, const Vec3& a, const Vec3& b) {
  const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (q - (a + t * (b - a))).norm();
}

/// Distance from q to the mesh, the test's own way: per triangle, the plane distance when q's
/// projection on the plane is inside the triangle (all three edge tests by cross products), else
/// the nearest of its edges.
double distance_to_mesh(const std::vector<Vec3>& v, const std::vector<Tri>& tris, const Vec3& q) {
  double best = INFINITY;
  for (const Tri& t : tris) {
    const Vec3 a = v[t[0]], b = v[t[1]], c = v[t[2]];
    const Vec3 n = (b - a).cross(c - a).normalized();
    const Vec3 p = q - n.dot(q - a) * n;
    const bool inside =
        (b - a).cross(p - a).dot(n) >= 0 && (c - b).cross(p - b).dot(n) >= 0 && (a - c).cross(p - c).dot(n) >= 0;
    const double d = inside
                         ? std::abs(n.dot(q - a))
                         : std::min({segment_distance(q, a, b), segment_distance(q, b, c), segment_distance(q, c, a)});
    best = std::min(best, d);
  }
  return best;
}

/// The scenes' icosphere of `radius` (io::icosphere: the icosahedron with each triangle split in
/// four `levels` times, the new vertices pushed out to the sphere; counter-clockwise seen from
/// outside), as vertices and triangles.
void icosphere(int levels, double radius, std::vector<Vec3>& v, std::vector<Tri>& tris) {
  const io::SurfaceMesh m = io::icosphere(radius, levels);
  v.clear();
  tris.clear();
  for (size_t i = 0; i + 2 < m.positions.size(); i += 3)
    v.emplace_back(m.positions[i], m.positions[i + 1], m.positions[i + 2]);
  for (size_t i = 0; i + 2 < m.triangles.size(); i += 3)
    tris.push_back({m.triangles[i], m.triangles[i + 1], m.triangles[i + 2]});
}

Id mesh_support(World& w, int32_t particle, const Vec3& target, const std::vector<Vec3>& v,
                const std::vector<Tri>& tris, double compliance = 0.0) {
  return test::shape_support(w, PinSupport::mesh, particle, target, v, false, tris, compliance);
}

TEST(MeshSupport, DistanceGradientMatchesFiniteDifferences) {
  std::vector<Vec3> v;
  std::vector<Tri> tris;
  icosphere(1, 0.7, v, tris);
  v[3] += Vec3(0.05, -0.1, 0.02);  // not a sphere any more: faces of every shape
  const Vec3 qs[] = {Vec3(0.9, 0.1, 0.2), Vec3(-0.3, 0.2, 0.1), Vec3(0.1, -1.2, 0.4), Vec3(0.2, 0.3, -0.95),
                     Vec3(-0.8, -0.7, 0.5)};
  double worst = 0.0, worst_value = 0.0;
  int inside = 0;
  for (const Vec3& q : qs) {
    const SurfacePoint c = closest_point_on_mesh(v, tris, q);
    worst_value = std::max(worst_value, std::abs((q - c.point).norm() - distance_to_mesh(v, tris, q)));
    const Vec3 grad = (q - c.point).normalized();
    worst = std::max(worst, test::gradient_error([&](const Vec3& y) { return distance_to_mesh(v, tris, y); }, q, grad));
    if (c.inside_face) {
      ++inside;
      EXPECT_LT((q - c.point).cross(c.normal).norm(), 1e-14) << "along its face's normal";
    }
  }
  EXPECT_GT(inside, 0);
  RecordProperty("gradient_error", test::sci(worst));
  EXPECT_LT(worst_value, 1e-15);
  EXPECT_LT(worst, 1e-8);
}

TEST(MeshSupport, ProjectionPutsTheParticleOnTheMesh) {
  // One substep, one iteration, no gravity, at rest, above the middle of a face: the projection moves
  // the particle along the face's normal (so its closest point stays), leaving alpha / (1 / m + alpha)
  // of its distance (alpha = compliance / h^2): 0 for a hard support.
  const std::vector<Vec3> v = {Vec3(0, 0, 0), Vec3(1, 0, 0.2), Vec3(0, 1, -0.1), Vec3(1.2, 1.1, 0.3)};
  const std::vector<Tri> tris = {{0, 1, 2}, {1, 3, 2}};
  const Vec3 target(0.2, 0.1, 0.3);
  const Vec3 start = target + Vec3(0.3, 0.25, 0.4);
  const double d0 = distance_to_mesh(v, tris, start - target);
  ASSERT_TRUE(closest_point_on_mesh(v, tris, start - target).inside_face);
  for (const double compliance : {0.0, 1e-6, 1e-4, 1e-3}) {
    World w(test::settings(1, 1));
    const int32_t p = test::add_particles(w, {start}, {2.0});
    mesh_support(w, p, target, v, tris, compliance);
    w.step();
    const double h = w.settings().dt;
    const double alpha = compliance / (h * h);
    const double d1 = distance_to_mesh(v, tris, w.positions()[p] - target);
    EXPECT_NEAR(d1, alpha / (0.5 + alpha) * d0, 1e-15 + 1e-12 * d0) << "compliance " << compliance;
  }
}

TEST(MeshSupport, ParticleSlidesDownAnInclinedFaceAtGSinTheta) {
  const double theta = 0.35;
  const Vec3 n(-std::sin(theta), 0.0, std::cos(theta));      // the face rises towards +x
  const Vec3 down(-std::cos(theta), 0.0, -std::sin(theta));  // straight down the slope
  const Vec3 across(0.0, 1.0, 0.0);
  // A square of side 20 on the inclined plane through the origin, two triangles.
  const std::vector<Vec3> v = {10.0 * (down + across), 10.0 * (-down + across), 10.0 * (-down - across),
                               10.0 * (down - across)};
  const std::vector<Tri> tris = {{0, 3, 2}, {0, 2, 1}};
  World w(test::settings(10, 1, Vec3(0.0, 0.0, -kG)));
  const double m = 1.5;
  const Vec3 start = 0.3 * across - 0.7 * down;  // off the diagonal
  const int32_t p = test::add_particles(w, {start}, {m});
  const Id s = mesh_support(w, p, Vec3::Zero(), v, tris);
  constexpr int frames = 60;
  for (int f = 0; f < frames; ++f) w.step();
  const double h = w.settings().dt / w.settings().substeps;
  const int steps = frames * w.settings().substeps;
  const double a = kG * std::sin(theta);
  const Vec3 moved = w.positions()[p] - start;
  const double exact = a * h * h * steps * (steps + 1) / 2.0;
  RecordProperty("slide_relative_error", test::sci(std::abs(moved.dot(down) - exact) / exact));
  EXPECT_LT(std::abs(moved.dot(down) - exact), 1e-12 * exact) << "the discrete path down the slope";
  EXPECT_LT(std::abs(moved.dot(n)), 1e-12) << "on the face";
  // Rounding: the closest point is computed from vertices of size 10 (eps 2.2e-16 each), an error the
  // velocity (x - x_prev) / h carries on: it grows as steps^2 eps 10 (as for the line support).
  EXPECT_LT(std::abs(moved.dot(across)), steps * steps * 2.2e-16 * 10.0) << "straight down";
  const std::vector<Reaction> r = w.reactions();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].pin, s);
  EXPECT_LT((r[0].force - m * kG * std::cos(theta) * n).norm(), 1e-9 * m * kG) << "normal to the face";
}

TEST(MeshSupport, BeadOnASphereMeshStaysOnItAndRestsAtItsLowestVertex) {
  constexpr double R = 0.8;
  std::vector<Vec3> v;
  std::vector<Tri> tris;
  icosphere(2, R, v, tris);
  ASSERT_EQ(tris.size(), 320u);
  const double m = 0.4;
  const Vec3 centre(1.0, 2.0, 3.0);
  // Released on the equator's side, 1 cm off the mesh: the first projection puts it on.
  const Vec3 start_dir = Vec3(0.9, 0.3, 0.1).normalized();
  const Vec3 load(0.5, -0.3, -1.0);  // N
  test::Bead bead(PinSupport::mesh, centre, v, false, tris, centre + (R + 0.01) * start_dir, m, load, kG);
  double off = 0.0, lowest = INFINITY;
  for (int f = 0; f < 240; ++f) {
    bead.world.step();
    const Vec3 x = bead.offset();
    off = std::max(off, distance_to_mesh(v, tris, x));
    lowest = std::min(lowest, x.z());
  }
  RecordProperty("max_distance_sliding", test::sci(off));
  EXPECT_LT(off, 1e-9) << "on the mesh at every frame while it slides";
  EXPECT_LT(lowest, -0.5 * R) << "it slid down round the sphere";
  // Damped, it settles where the pull (weight + load) is in the mesh's normal cone: at the vertex
  // farthest along the pull (a linear function over a convex polyhedron is largest at a vertex).
  bead.settle(3.0, 1500);
  const Vec3 pull = bead.pull();
  size_t far = 0;
  for (size_t i = 1; i < v.size(); ++i)
    if (v[i].dot(pull) > v[far].dot(pull)) far = i;
  const Vec3 x = bead.offset();
  RecordProperty("rest_offset_from_vertex_m", test::sci((x - v[far]).norm()));
  EXPECT_LT((x - v[far]).norm(), 1e-9) << "at vertex " << far;
  EXPECT_LT(v[far].z(), -0.8 * R) << "in the sphere's lowest region";
  const std::vector<Reaction> reactions = bead.world.reactions();
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_EQ(reactions[0].pin, bead.pin);
  const double imbalance = (reactions[0].force + pull).norm() / pull.norm();
  RecordProperty("reaction_imbalance", test::sci(imbalance));
  EXPECT_LT(imbalance, 1e-9) << "the reaction balances weight and load";
}

TEST(MeshSupport, MovingTheTargetMovesTheMesh) {
  std::vector<Vec3> v;
  std::vector<Tri> tris;
  icosphere(1, 0.5, v, tris);
  Settings s = test::settings(8, 2, Vec3(0.0, 0.0, -kG), 2.0);
  s.tethers = 0;
  World w(s);
  const int32_t p = test::add_particles(w, {Vec3(0.1, 0.0, 0.6)}, {1.0});
  const Id pin = mesh_support(w, p, Vec3::Zero(), v, tris);
  const Vec3 shift(0.3, -0.2, 1.5);
  w.set_pin_target(pin, shift);
  double off = 0.0;
  for (int f = 0; f < 120; ++f) {
    w.step();
    off = std::max(off, distance_to_mesh(v, tris, w.positions()[p] - shift));
  }
  EXPECT_LT(off, 1e-9) << "on the moved mesh at every frame";
}

TEST(MeshSupport, SameBitsRunAfterRun) {
  std::vector<Vec3> v;
  std::vector<Tri> tris;
  icosphere(2, 0.75, v, tris);
  const std::array<Vec3, 2> runs = test::support_run_twice(PinSupport::mesh, v, false, tris, kG);
  EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[1].data(), sizeof(Vec3)));
}

TEST(MeshSupport, BadMeshesAreRefusedAndChangeNothing) {
  World w;
  const int32_t p = test::add_particles(w, {Vec3::Zero()}, {1.0});
  const std::vector<Vec3> v = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(2, 0, 0)};
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), {v[0], v[1]}, {{0, 1, 1}}), Error) << "two vertices";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), v, {}), Error) << "no triangle";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), v, {{0, 1, 4}}), Error) << "index out of range";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), v, {{0, -1, 2}}), Error) << "negative index";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), v, {{0, 1, 1}}), Error) << "repeated vertex: zero area";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), v, {{0, 1, 3}}), Error) << "collinear: zero area";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), {v[0], v[1], Vec3(0.5, 1e-13, 0)}, {{0, 1, 2}}), Error) << "a sliver";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), {v[0], Vec3(1e-170, 0, 0), Vec3(0, 1e-170, 0)}, {{0, 1, 2}}), Error)
      << "too small";
  EXPECT_THROW(mesh_support(w, p, Vec3::Zero(), {v[0], v[1], Vec3(0, NAN, 0)}, {{0, 1, 2}}), Error);
  EXPECT_THROW(mesh_support(w, p + 1, Vec3::Zero(), v, {{0, 1, 2}}), Error);
  PinDesc plane;
  plane.particle = p;
  plane.support = PinSupport::plane;
  plane.triangles = {{0, 1, 2}};
  EXPECT_THROW(w.create_pin(plane), Error) << "triangles for a plane";
  EXPECT_EQ(w.pin_count(), 0u);
  mesh_support(w, p, Vec3::Zero(), v, {{0, 1, 2}});  // one triangle, a vertex unused: fine
  EXPECT_EQ(w.pin_count(), 1u);
}

}  // namespace
}  // namespace embra
