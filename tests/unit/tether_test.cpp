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

}  // namespace
}  // namespace embra
