// The convex hull collider against libccd (Debian's libccd-dev, the client's convex-contact
// package): for particles inside a hull, the engine's push-out (to the nearest face plane of the
// hull it builds) equals the penetration libccd's GJK/EPA finds between the hull's points and the
// particle, within 1e-6.
#include "test_support.hpp"

#include <ccd/ccd.h>
#include <gtest/gtest.h>

#include <random>

namespace embra {
namespace {

struct Cloud {
  std::vector<Vec3> points;  // world frame
};

void cloud_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const Cloud& c = *static_cast<const Cloud*>(obj);
  const Vec3 d(ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir));
  size_t best = 0;
  for (size_t i = 1; i < c.points.size(); ++i)
    if (c.points[i].dot(d) > c.points[best].dot(d)) best = i;
  ccdVec3Set(out, c.points[best].x(), c.points[best].y(), c.points[best].z());
}

void point_support(const void* obj, const ccd_vec3_t*, ccd_vec3_t* out) {
  const Vec3& p = *static_cast<const Vec3*>(obj);
  ccdVec3Set(out, p.x(), p.y(), p.z());
}

TEST(ColliderCcd, HullPushOutMatchesLibccdPenetration) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> nd;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ColliderDesc c;
  c.shape = ColliderShape::convex;
  c.position = Vec3(0.2, 0.1, -0.3);
  c.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(1, -1, 2).normalized()));
  Cloud cloud;
  for (int i = 0; i < 24; ++i) {
    const Vec3 p = Vec3(nd(rng), nd(rng), nd(rng)).normalized().cwiseProduct(Vec3(1.0, 0.6, 0.4));
    for (int k = 0; k < 3; ++k) c.vertices.push_back(p[k]);
    cloud.points.push_back(c.position + c.rotation * p);
  }
  // Particles inside: convex combinations of the hull's points, at rest, no gravity.
  std::vector<Vec3> x;
  for (int i = 0; i < 300; ++i) {
    Vec3 p = Vec3::Zero();
    double total = 0.0;
    for (const Vec3& v : cloud.points) {
      const double wgt = std::pow(u(rng), 8.0);
      p += wgt * v;
      total += wgt;
    }
    x.push_back(p / total);
  }
  World w(test::settings(1, 1));
  w.create_collider(c);
  const int32_t first = test::add_particles(w, x, std::vector<double>(x.size(), 1.0));
  w.step();
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = cloud_support;
  ccd.support2 = point_support;
  ccd.max_iterations = 1000;
  ccd.epa_tolerance = 1e-12;
  double worst = 0.0;
  int compared = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    ccd_real_t depth;
    ccd_vec3_t dir, pos;
    if (ccdGJKPenetration(&cloud, &x[i], &ccd, &depth, &dir, &pos) != 0) continue;
    const Vec3 expected = x[i] + depth * Vec3(ccdVec3X(&dir), ccdVec3Y(&dir), ccdVec3Z(&dir));
    worst = std::max(worst, (w.positions()[first + i] - expected).norm());
    ++compared;
  }
  EXPECT_GT(compared, 290);
  EXPECT_LT(worst, 1e-6);
  RecordProperty("hull_vs_libccd_max", test::sci(worst));
  RecordProperty("compared", compared);
}

}  // namespace
}  // namespace embra
