// Box, capsule, convex hull and triangle mesh colliders: space-time contact (no tunnelling at any
// speed, against thin and moving colliders), agreement between the same solid given as a box, a
// hull and a closed mesh, resting without penetration, friction, and refused input.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace embra {
namespace {

constexpr double kG = 9.81;

std::vector<double> box_corners(const Vec3& e) {
  std::vector<double> v;
  for (int i = 0; i < 8; ++i) {
    v.push_back((i & 1) ? e.x() : -e.x());
    v.push_back((i & 2) ? e.y() : -e.y());
    v.push_back((i & 4) ? e.z() : -e.z());
  }
  return v;
}

/// The 12 outward triangles of box_corners.
std::vector<int32_t> box_triangles() {
  return {0, 2, 1, 1, 2, 3,   // -z
          4, 5, 6, 5, 7, 6,   // +z
          0, 1, 4, 1, 5, 4,   // -y
          2, 6, 3, 3, 6, 7,   // +y
          0, 4, 2, 2, 4, 6,   // -x
          1, 3, 5, 3, 7, 5};  // +x
}

ColliderDesc shape_desc(ColliderShape shape, const Vec3& e) {
  ColliderDesc c;
  c.shape = shape;
  c.half_extents = e;
  if (shape == ColliderShape::convex || shape == ColliderShape::mesh) c.vertices = box_corners(e);
  if (shape == ColliderShape::mesh) c.triangles = box_triangles();
  return c;
}

// Tunnelling: particles fired at 10x, 100x and 1000x the collider's thickness per substep, head on
// and at angles, at a thin box (2 mm thick, still or moving towards them) and at a moving plane,
// never end a frame on the far side.
TEST(ColliderShapes, NothingTunnelsThroughAThinBoxOrAMovingPlane) {
  const double thickness = 0.002;
  const int substeps = 10;
  const double h = 1.0 / 60.0 / substeps;
  for (double factor : {10.0, 100.0, 1000.0}) {
    const double speed = factor * thickness / h;
    for (int moving = 0; moving < 2; ++moving) {
      // (sphere stands for an open mesh sheet below; the capsule is a thin rod along x)
      for (ColliderShape shape : {ColliderShape::box, ColliderShape::convex, ColliderShape::mesh, ColliderShape::plane,
                                  ColliderShape::capsule, ColliderShape::sphere}) {
        if (shape == ColliderShape::plane && moving == 0) continue;
        World w(test::settings(substeps, 1));
        ColliderDesc c = shape_desc(shape, Vec3(5.0, 5.0, 0.5 * thickness));
        if (shape == ColliderShape::plane) c.thickness = thickness;
        if (shape == ColliderShape::capsule) {  // a thin rod along x, long enough for every particle
          c.radius = 0.5 * thickness;
          c.half_length = 5.0;
          c.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * std::numbers::pi, Vec3::UnitY()));
        }
        if (shape == ColliderShape::sphere) {  // an open mesh: a two-sided sheet kept `thickness` clear
          c.shape = ColliderShape::mesh;
          c.vertices = {-5, -5, 0, 5, -5, 0, 5, 5, 0, -5, 5, 0};
          c.triangles = {0, 1, 2, 0, 2, 3};
          c.thickness = 0.5 * thickness;
        }
        const Id id = w.create_collider(c);
        std::vector<Vec3> x;
        std::vector<Vec3> v;
        for (int k = 0; k < 25; ++k) {
          const double ax = 0.3 * (k % 5 - 2), ay = 0.3 * (k / 5 - 2);
          x.emplace_back(0.2 * ax, 0.2 * ay, 0.01 + 0.001 * k);
          v.push_back(speed * Vec3(ax, ay, -1.0).normalized());
        }
        const int32_t first = test::add_particles(w, x, std::vector<double>(x.size(), 1.0));
        w.set_velocities(first, test::flatten(v));
        int far_side = 0;
        double worst = 0.0;
        for (int f = 0; f < 3; ++f) {
          Vec3 pos = w.collider(id).desc.position;
          if (moving) {  // the collider rushes up at the particles at the same speed per substep
            pos.z() += speed / 60.0;
            w.set_collider_transform(id, pos, c.rotation);
          }
          w.step();
          const double top = pos.z() + (shape == ColliderShape::plane ? thickness : 0.5 * thickness);
          for (size_t i = 0; i < x.size(); ++i) {
            if (shape == ColliderShape::capsule && i / 5 != 2) continue;  // only those fired in y = 0 hit the rod
            const double gap = w.positions()[first + i].z() - top;
            worst = std::min(worst, gap);
            if (gap < -1e-9) ++far_side;
          }
        }
        EXPECT_EQ(far_side, 0) << "factor " << factor << " shape " << static_cast<int>(shape) << " moving " << moving;
        RecordProperty("worst_gap_" + std::to_string(static_cast<int>(factor)) + "_" +
                           std::to_string(static_cast<int>(shape)) + "_" + std::to_string(moving),
                       test::sci(worst));
      }
    }
  }
}

/// Positions after one frame of `n` random particles fired in random directions at a collider.
std::vector<Vec3> fire_at(const ColliderDesc& c, int n, double clearance) {
  World w(test::settings(4, 1));
  w.create_collider(c);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> x, v;
  for (int i = 0; i < n; ++i) {
    x.push_back(c.position + Vec3(1.5 * u(rng), 1.5 * u(rng), 1.5 * u(rng)));
    v.push_back(Vec3(u(rng), u(rng), u(rng)) * 60.0);
  }
  std::vector<double> xyz = test::flatten(x), m(x.size(), 1.0);
  BodyDesc d;
  d.positions = xyz;
  d.masses = m;
  d.generate = 0;
  d.material.thickness = 2.0 * clearance;
  const int32_t first = w.body(w.create_body(d)).first_particle;
  w.set_velocities(first, test::flatten(v));
  w.step();
  return std::vector<Vec3>(w.positions().begin() + first, w.positions().end());
}

// A box given as a convex hull of its corners, and as a closed triangle mesh, gives the contacts of
// the box itself: the same resolved positions for 2000 random particles fired at it from all sides
// (some start inside, some cross it), within 1e-6.
TEST(ColliderShapes, HullAndMeshOfABoxMatchTheBox) {
  const Vec3 e(0.7, 0.4, 0.25);
  double worst_hull = 0.0, worst_mesh = 0.0;
  for (double clearance : {0.0, 0.05}) {
    ColliderDesc box = shape_desc(ColliderShape::box, e), hull = shape_desc(ColliderShape::convex, e),
                 mesh = shape_desc(ColliderShape::mesh, e);
    for (ColliderDesc* c : {&box, &hull, &mesh}) {
      c->position = Vec3(0.3, -0.2, 1.0);
      c->rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()));
    }
    const std::vector<Vec3> a = fire_at(box, 2000, clearance), b = fire_at(hull, 2000, clearance),
                            c = fire_at(mesh, 2000, clearance);
    for (size_t i = 0; i < a.size(); ++i) {
      worst_hull = std::max(worst_hull, (a[i] - b[i]).norm());
      worst_mesh = std::max(worst_mesh, (a[i] - c[i]).norm());
    }
  }
  EXPECT_LT(worst_hull, 1e-6);
  EXPECT_LT(worst_mesh, 1e-6);
  RecordProperty("hull_vs_box_max", test::sci(worst_hull));
  RecordProperty("mesh_vs_box_max", test::sci(worst_mesh));
}

// A particle dropped on each shape comes to rest on top without ever ending a frame more than 1e-9
// inside its clearance; on a tilted top with static friction 1 > tan 0.3 it sticks, with friction
// 0.1 it slides down.
TEST(ColliderShapes, ParticlesRestOnEveryShapeAndFrictionHolds) {
  for (ColliderShape shape : {ColliderShape::box, ColliderShape::capsule, ColliderShape::convex, ColliderShape::mesh}) {
    for (double tilt : {0.0, 0.3}) {
      for (double mu : {1.0, 0.1}) {
        if (tilt == 0.0 && mu != 1.0) continue;
        if (shape == ColliderShape::capsule && tilt != 0.0) continue;  // a capsule's top is a line
        World w(test::settings(8, 1, Vec3(0, 0, -kG)));
        const Vec3 e(1.0, 1.0, 0.3);
        ColliderDesc c = shape_desc(shape, e);
        c.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Vec3::UnitX()));
        if (shape == ColliderShape::capsule) {
          c.radius = 0.3;
          c.half_length = 1.0;
          c.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * std::numbers::pi, Vec3::UnitY()));
        }
        c.position = Vec3(0.1, 0.2, 0.5);
        c.thickness = 0.004;
        c.friction_static = c.friction_dynamic = mu;
        w.create_collider(c);
        const Vec3 normal = shape == ColliderShape::capsule ? Vec3::UnitZ() : Vec3(c.rotation * Vec3::UnitZ());
        const Vec3 top = c.position + 0.3 * normal;
        const double clearance = 0.01 + c.thickness;
        std::vector<double> xyz = test::flatten({top + 0.4 * normal}), m{1.0};
        BodyDesc d;
        d.positions = xyz;
        d.masses = m;
        d.generate = 0;
        d.material.thickness = 0.02;
        d.material.friction_static = d.material.friction_dynamic = mu;
        const int32_t p = w.body(w.create_body(d)).first_particle;
        double worst = 0.0;
        for (int f = 0; f < (mu == 1.0 ? 60 : 20); ++f) {  // the slider stays on the top for 20 frames
          w.step();
          const double gap = normal.dot(w.positions()[p] - top) - clearance;
          worst = std::min(worst, gap);
          ASSERT_GT(gap, -1e-9) << "shape " << static_cast<int>(shape) << " tilt " << tilt << " frame " << f;
        }
        const std::string tag = std::to_string(static_cast<int>(shape)) + " tilt " + std::to_string(tilt);
        if (mu == 1.0) {
          EXPECT_NEAR(normal.dot(w.positions()[p] - top), clearance, 1e-9) << tag;
          EXPECT_LT(w.velocities()[p].norm(), 1e-9) << tag;
        } else {
          EXPECT_GT(w.velocities()[p].norm(), 0.5) << tag;  // sliding off the tilted top
        }
        RecordProperty("worst_gap_" + std::to_string(static_cast<int>(shape)) + "_" + std::to_string(tilt) + "_" +
                           std::to_string(mu),
                       test::sci(worst));
      }
    }
  }
}

// A collider's geometry moves with it: a particle resting on a box that moves sideways is carried
// along by static friction.
TEST(ColliderShapes, FrictionCarriesAParticleOnAMovingMesh) {
  World w(test::settings(8, 1, Vec3(0, 0, -kG)));
  ColliderDesc c = shape_desc(ColliderShape::mesh, Vec3(1.0, 1.0, 0.1));
  c.friction_static = c.friction_dynamic = 1.0;
  const Id id = w.create_collider(c);
  const int32_t p = test::add_particles(w, {Vec3(0, 0, 0.1)}, {1.0});
  for (int f = 0; f < 30; ++f) w.step();
  // 6 cm/s, reached in one substep: static friction (mu g = 9.81 m/s^2) takes the particle to that
  // speed within 6 ms, slipping v^2 / (2 mu g) = 0.2 mm on the way.
  for (int f = 1; f <= 300; ++f) {
    w.set_collider_transform(id, Vec3(0.001 * f, 0, 0), Eigen::Quaterniond::Identity());
    w.step();
  }
  EXPECT_NEAR(w.positions()[p].x(), 0.3, 1e-3);
  EXPECT_GT(w.positions()[p].z(), 0.1 - 1e-9);
}

// Refused input leaves the world unchanged.
TEST(ColliderShapes, BadShapesAreRefused) {
  World w;
  auto refused = [&](const ColliderDesc& c) {
    try {
      w.create_collider(c);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
      return std::string(e.what());
    }
    return std::string();
  };
  ColliderDesc c = shape_desc(ColliderShape::box, Vec3(1, 1, 0));
  EXPECT_NE(refused(c).find("half_extents"), std::string::npos);
  c = shape_desc(ColliderShape::capsule, Vec3(1, 1, 1));
  c.half_length = -1.0;
  EXPECT_NE(refused(c).find("half_length"), std::string::npos);
  c = shape_desc(ColliderShape::convex, Vec3(1, 1, 1));
  c.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 2, 0};  // coplanar
  EXPECT_NE(refused(c).find("degenerate"), std::string::npos);
  c.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  EXPECT_NE(refused(c).find("at least 4"), std::string::npos);
  c = shape_desc(ColliderShape::mesh, Vec3(1, 1, 1));
  c.triangles[5] = 8;
  EXPECT_NE(refused(c).find("outside"), std::string::npos);
  c = shape_desc(ColliderShape::mesh, Vec3(1, 1, 1));
  c.triangles[2] = c.triangles[1];
  EXPECT_NE(refused(c).find("degenerate"), std::string::npos);
  c = shape_desc(ColliderShape::mesh, Vec3(1, 1, 1));
  c.vertices[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(refused(c).find("finite"), std::string::npos);
  EXPECT_EQ(w.collider_count(), 0u);
}

}  // namespace
}  // namespace embra
