// Automatic tethers (Settings::tethers): each particle of an inextensible body may be at most its
// path length over the body from each of its nearest anchors. A particle's tethers are projected
// together, to the nearest point inside all of them, not one after another.
//
// What anyone can check from positions alone: an inextensible chain pinned at both ends exactly its
// length apart cannot sag (the only shape of that length between the pins is the straight line), so
// under gravity every link must stay at its rest length and every particle on the line. The balls
// of a particle's two tethers there only touch, at its rest position. Projected one after the other,
// the second tether had the final word: a particle left of the middle was pulled towards the right
// pin by every substep's sag and one right of it towards the left pin, and the link across the
// middle ended squeezed (2.5 % on the top edge of the 128 x 128 acceptance cloth).
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace embra {
namespace {

struct Taut {
  double link_strain = 0.0;  // largest |length / rest - 1| over the links
  double off_line = 0.0;     // largest distance of a particle from the line between the pins, m
};

/// A straight chain of `links` links, 1 m in all along x, its two ends pinned where they are,
/// stepped `frames` frames under gravity with embra's default settings (tethers on).
Taut taut_chain(int32_t links, int frames, int32_t tethers) {
  Settings s;
  s.tethers = tethers;
  World w(s);
  std::vector<Vec3> shape;
  for (int32_t k = 0; k <= links; ++k) shape.emplace_back(static_cast<double>(k) / links, 0.0, 0.0);
  const std::vector<double> xyz = test::flatten(shape);
  std::vector<int32_t> edges;
  for (int32_t k = 0; k < links; ++k) edges.insert(edges.end(), {k, k + 1});
  BodyDesc d;
  d.positions = xyz;
  d.edges = edges;
  d.material.mass = 1.0;
  d.generate = generate_stretch;
  const int32_t first = w.body(w.create_body(d)).first_particle;
  test::hard_pin(w, first, shape.front());
  test::hard_pin(w, first + links, shape.back());
  for (int f = 0; f < frames; ++f) w.step();
  Taut t;
  const auto& x = w.positions();
  for (int32_t k = 0; k < links; ++k)
    t.link_strain = std::max(t.link_strain, std::abs((x[first + k + 1] - x[first + k]).norm() * links - 1.0));
  for (int32_t k = 0; k <= links; ++k)
    t.off_line = std::max(t.off_line, Vec3(0.0, x[first + k].y(), x[first + k].z()).norm());
  return t;
}

TEST(Tethers, AChainPinnedAtExactlyItsLengthHangsStraightWithEveryLinkAtRest) {
  for (int32_t links : {16, 63, 64}) {
    const Taut t = taut_chain(links, 60, 2);
    RecordProperty("link_strain_" + std::to_string(links), test::sci(t.link_strain));
    RecordProperty("off_line_" + std::to_string(links), test::sci(t.off_line));
    std::printf("%d links, 1 s under gravity: largest link strain %.3g, farthest off the line %.3g m\n", links,
                t.link_strain, t.off_line);
    // The balls of a particle's tethers meet at its rest position to rounding: their circle's radius
    // is the square root of a difference of squares, about 1e-8 of the tether.
    EXPECT_LT(t.link_strain, 1e-9) << links << " links";
    EXPECT_LT(t.off_line, 1e-7) << links << " links";
  }
}

// With one tether a particle (to its nearest pin) nothing holds the chain up but the links: it sags
// and its links stretch. The tethers' pull is what keeps it straight, not the links alone.
TEST(Tethers, WithOneTetherAParticleTheTautChainSags) {
  const Taut one = taut_chain(64, 60, 1), two = taut_chain(64, 60, 2);
  std::printf("64 links: off the line by %.3g m with one tether a particle, %.3g m with two\n", one.off_line,
              two.off_line);
  EXPECT_GT(one.off_line, 1e3 * two.off_line);
}

/// A sheet's body (no constraints generated): `positions` 3 per vertex, `triangles` 3 per triangle.
const BodyInfo& sheet(World& w, const std::vector<double>& positions, const std::vector<int32_t>& triangles) {
  BodyDesc d;
  d.positions = positions;
  d.triangles = triangles;
  return w.body(w.create_body(d));
}

/// The grid `g` turned about (1, 2, 3) by 0.7 rad and moved by (0.3, -0.2, 0.5): a flat sheet in a
/// tilted plane whose coordinates are rounded.
std::vector<double> tilted(const test::Grid& g) {
  const Eigen::AngleAxisd turn(0.7, Vec3(1, 2, 3).normalized());
  std::vector<double> out;
  for (size_t i = 0; i < g.positions.size(); i += 3) {
    const Vec3 p = turn * Vec3(g.positions[i], g.positions[i + 1], g.positions[i + 2]) + Vec3(0.3, -0.2, 0.5);
    out.insert(out.end(), {p.x(), p.y(), p.z()});
  }
  return out;
}

// On a flat sheet that covers its convex hull (a cloth grid, flat or in a tilted plane) the shortest
// path over the surface between two points is the straight line: every tether's rest length is the
// distance between its ends, and the attachments skip the straight links' walks over the triangles
// with the same result to the bit as the walks give.
TEST(Tethers, OnAFlatConvexSheetEveryRestLengthIsTheStraightDistance) {
  Settings s;
  s.tethers = 0;
  World w(s);
  const test::Grid g = test::make_grid(33, 21, 0.03, Vec3(-0.5, -0.3, 0.2));
  std::vector<int32_t> one_diagonal;  // each quad split along the same diagonal (the benchmark's cloth)
  for (int j = 0; j + 1 < g.ny; ++j)
    for (int i = 0; i + 1 < g.nx; ++i)
      one_diagonal.insert(one_diagonal.end(), {g.index(i, j), g.index(i + 1, j), g.index(i + 1, j + 1), g.index(i, j),
                                               g.index(i + 1, j + 1), g.index(i, j + 1)});
  const std::vector<std::pair<std::vector<double>, std::vector<int32_t>>> sheets{
      {g.positions, g.triangles}, {g.positions, one_diagonal}, {tilted(g), g.triangles}};
  for (size_t k = 0; k < sheets.size(); ++k) {
    const BodyInfo& b = sheet(w, sheets[k].first, sheets[k].second);
    const int32_t f = b.first_particle;
    const std::vector<int32_t> anchors{f + g.index(0, 0), f + g.index(g.nx - 1, 0), f + g.index(12, 9)};
    const std::vector<Attachment> skipped = long_range_attachments(b, anchors, 2);
    const std::vector<Attachment> walked = long_range_attachments(b, anchors, 2, true);
    ASSERT_EQ(skipped.size(), walked.size()) << "sheet " << k;
    ASSERT_EQ(skipped.size(), 2 * (b.rest_positions.size() - anchors.size()) + anchors.size()) << "sheet " << k;
    double worst = 0.0;
    for (size_t i = 0; i < skipped.size(); ++i) {
      EXPECT_EQ(skipped[i].particle, walked[i].particle) << "sheet " << k << ", attachment " << i;
      EXPECT_EQ(skipped[i].anchor, walked[i].anchor) << "sheet " << k << ", attachment " << i;
      EXPECT_EQ(skipped[i].rest, walked[i].rest) << "sheet " << k << ", attachment " << i;
      const double straight =
          (b.rest_positions[skipped[i].particle - f] - b.rest_positions[skipped[i].anchor - f]).norm();
      worst = std::max(worst, std::abs(skipped[i].rest - straight) / straight);
    }
    EXPECT_LT(worst, 1e-12) << "sheet " << k;  // a sum of straight links along one line
  }
}

// A flat L-shaped sheet is not convex: from the tip of one arm to the tip of the other the straight
// line leaves the sheet, and the shortest path over it bends at the inner corner: |anchor - corner| +
// |corner - point| (1 m here, against 0.71 m straight). The tether is no shorter than that.
TEST(Tethers, AroundTheInnerCornerOfAnLShapedSheetTheRestLengthGoesAroundIt) {
  Settings s;
  s.tethers = 0;
  World w(s);
  const int n = 21;
  const test::Grid g = test::make_grid(n, n, 0.05, Vec3::Zero());
  // The grid without its upper right quarter, its vertices renumbered (none left off the sheet).
  const auto kept = [&](int32_t v) { return v % n <= n / 2 || v / n <= n / 2; };
  std::vector<int32_t> index(g.positions.size() / 3, -1), tris;
  std::vector<double> xyz;
  for (int32_t v = 0; v < static_cast<int32_t>(index.size()); ++v)
    if (kept(v)) {
      index[v] = static_cast<int32_t>(xyz.size() / 3);
      xyz.insert(xyz.end(), g.positions.begin() + 3 * v, g.positions.begin() + 3 * v + 3);
    }
  for (size_t t = 0; t < g.triangles.size(); t += 3)
    if (kept(g.triangles[t]) && kept(g.triangles[t + 1]) && kept(g.triangles[t + 2]))
      for (int c = 0; c < 3; ++c) tris.push_back(index[g.triangles[t + c]]);
  const BodyInfo& b = sheet(w, xyz, tris);
  const int32_t f = b.first_particle, anchor = index[g.index(n - 1, n / 2)], point = index[g.index(n / 2, n - 1)],
                corner = index[g.index(n / 2, n / 2)];
  const std::vector<int32_t> anchors{f + anchor};
  const std::vector<Attachment> links = long_range_attachments(b, anchors, 1);
  EXPECT_EQ(links.size(), b.rest_positions.size() - 1);
  const auto at = [&](int32_t v) { return b.rest_positions[v]; };
  const double around = (at(anchor) - at(corner)).norm() + (at(corner) - at(point)).norm();
  const double straight = (at(anchor) - at(point)).norm();
  for (const Attachment& l : links)
    if (l.particle == f + point) {
      std::printf("L-shaped sheet: the far arm's tip held at %.6f m; around the corner %.6f, straight %.6f\n", l.rest,
                  around, straight);
      EXPECT_GE(l.rest, around * (1.0 - 1e-12));
      EXPECT_LT(l.rest, 1.01 * around);
      EXPECT_GT(l.rest, 1.1 * straight);
    }
}

}  // namespace
}  // namespace embra
