// Polyline supports (PinSupport::polyline): a pin that holds its particle on the closest point of a
// polyline, checked against geometry worked out here, independently of the solver.
//
//   - the distance to the polyline, |q - closest point|, has the gradient (q - c) / |q - c|: checked
//     by central differences against a brute-force distance (every segment, here);
//   - one hard projection puts a particle on the curve (distance 0 to rounding); a compliant one
//     brings it closer every step;
//   - a bead on a circle-shaped polyline (64 segments, a vertical wire) pulled by gravity and a
//     point load swings and stays on the polyline to 1e-9 m at every frame; damped, it comes to rest
//     on the lowest segment with a reaction normal to it that balances its weight and load;
//   - a bead on a 48-gon sliding across its vertices stays on it to 1e-9 m with its reaction normal
//     to the segment it is inside; damped, it rests at the vertex farthest along its pull (the
//     closed polyline's seam, point 0, or an interior vertex), there to 1e-9 m, with a reaction that
//     balances weight and load (a particle held at a vertex, its closest point inside a segment by
//     rounding only, keeps its whole multiplier);
//   - an open polyline holds its particle at its end; moving the target moves the curve;
//   - the same bits run after run; bad curves are refused and change nothing.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace embra {
namespace {

constexpr double kG = 9.81;

/// Distance from q to the polyline, every segment tried (the test's own closest point).
double distance_to_polyline(const std::vector<Vec3>& pts, bool closed, const Vec3& q) {
  double best = INFINITY;
  const size_t n = pts.size();
  for (size_t s = 0; s < (closed ? n : n - 1); ++s) {
    const Vec3 a = pts[s], b = pts[(s + 1) % n];
    const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (q - (a + t * (b - a))).norm());
  }
  return best;
}

/// A circle of radius r about the origin in the x-z plane, n points, point k at the angle
/// first + 2 pi k / n from +x (counter-clockwise seen from -y).
std::vector<Vec3> circle(double r, int n, double first) {
  std::vector<Vec3> pts;
  for (int k = 0; k < n; ++k) {
    const double a = first + 2.0 * std::numbers::pi * k / n;
    pts.emplace_back(r * std::cos(a), 0.0, r * std::sin(a));
  }
  return pts;
}

/// The same circle with its lowest segment horizontal: the closing one, from point n - 1 to point 0.
std::vector<Vec3> circle(double r, int n) {
  return circle(r, n, -std::numbers::pi / 2 + std::numbers::pi / n);
}

Id polyline_support(World& w, int32_t particle, const Vec3& target, const std::vector<Vec3>& pts, bool closed,
                    double compliance = 0.0) {
  return test::shape_support(w, PinSupport::polyline, particle, target, pts, closed, {}, compliance);
}

TEST(PolylineSupport, DistanceGradientMatchesFiniteDifferences) {
  const std::vector<Vec3> pts = {Vec3(0, 0, 0), Vec3(1, 0.2, 0), Vec3(1.5, 1, 0.3), Vec3(0.8, 1.6, -0.2)};
  const Vec3 qs[] = {Vec3(0.5, -0.4, 0.2), Vec3(1.6, 0.4, 0.1), Vec3(0.9, 1.9, 0.4), Vec3(-0.3, -0.2, 0.1)};
  double worst = 0.0;
  for (const bool closed : {false, true})
    for (const Vec3& q : qs) {
      const CurvePoint c = closest_point_on_polyline(pts, closed, q);
      EXPECT_NEAR((q - c.point).norm(), distance_to_polyline(pts, closed, q), 1e-15);
      const Vec3 grad = (q - c.point).normalized();
      worst = std::max(
          worst, test::gradient_error([&](const Vec3& y) { return distance_to_polyline(pts, closed, y); }, q, grad));
      if (c.inside_segment) {
        EXPECT_LT(std::abs(c.tangent.dot(q - c.point)), 1e-14) << "normal to its segment";
      }
    }
  RecordProperty("gradient_error", test::sci(worst));
  EXPECT_LT(worst, 1e-8);
}

TEST(PolylineSupport, ProjectionPutsTheParticleOnTheCurve) {
  // One substep, one iteration, no gravity, at rest: the one projection moves the particle along
  // the normal to its closest segment (so the closest point stays), leaving alpha / (1 / m + alpha)
  // of its distance (alpha = compliance / h^2): 0 for a hard support.
  const std::vector<Vec3> pts = circle(0.5, 16);
  const Vec3 target(0.2, 0.1, 0.3);
  const Vec3 start = target + Vec3(0.2, 0.35, -0.1);
  const double d0 = distance_to_polyline(pts, true, start - target);
  for (const double compliance : {0.0, 1e-6, 1e-4, 1e-3}) {
    World w(test::settings(1, 1));
    const int32_t p = test::add_particles(w, {start}, {2.0});
    polyline_support(w, p, target, pts, true, compliance);
    w.step();
    const double h = w.settings().dt;
    const double alpha = compliance / (h * h);
    const double d1 = distance_to_polyline(pts, true, w.positions()[p] - target);
    EXPECT_LT(d1, d0);
    EXPECT_NEAR(d1, alpha / (0.5 + alpha) * d0, 1e-15 + 1e-12 * d0) << "compliance " << compliance;
  }
}

TEST(PolylineSupport, BeadOnACircleStaysOnItAndRestsOnTheLowestSegment) {
  constexpr double r = 0.8;
  const std::vector<Vec3> pts = circle(r, 64);
  const double m = 0.4;
  // Released at 60 degrees from the bottom, off the wire by 1 cm: the first projection puts it on.
  const double a0 = -std::numbers::pi / 2 + std::numbers::pi / 3;
  const Vec3 centre(1.0, 2.0, 3.0);
  test::Bead bead(PinSupport::polyline, centre, pts, true, {},
                  centre + (r + 0.01) * Vec3(std::cos(a0), 0.0, std::sin(a0)), m, Vec3(0.5, 0.0, -1.0), kG);
  double off = 0.0, lowest = INFINITY, highest = -INFINITY;
  for (int f = 0; f < 240; ++f) {
    bead.world.step();
    const Vec3 x = bead.offset();
    off = std::max(off, distance_to_polyline(pts, true, x));
    lowest = std::min(lowest, x.x());
    highest = std::max(highest, x.x());
  }
  RecordProperty("max_distance_swinging", test::sci(off));
  EXPECT_LT(off, 1e-9) << "on the polyline at every frame while it swings";
  EXPECT_LT(lowest, -0.3) << "it swung across the bottom";
  EXPECT_GT(highest, 0.3);
  // Damped, it settles where the wire's normal balances weight and load: on the lowest segment
  // (horizontal) when the load's pull along it is 0 there. Take the side load off and damp.
  bead.set_load(Vec3(0.0, 0.0, -1.0));
  bead.settle(3.0, 1200);
  const Vec3 x = bead.offset();
  EXPECT_LT(distance_to_polyline(pts, true, x), 1e-9);
  EXPECT_NEAR(x.z(), pts[0].z(), 1e-9) << "on the lowest segment, z = " << pts[0].z();
  EXPECT_LT(std::abs(x.x()), std::abs(pts[0].x())) << "between its ends";
  const std::vector<Reaction> reactions = bead.world.reactions();
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_EQ(reactions[0].pin, bead.pin);
  const Vec3 total = bead.pull();
  const double imbalance = (reactions[0].force + total).norm() / total.norm();
  RecordProperty("reaction_imbalance", test::sci(imbalance));
  EXPECT_LT(imbalance, 1e-9) << "the reaction balances weight and load";
  EXPECT_LT(std::abs(reactions[0].force.x()), 1e-9 * total.norm()) << "normal to the (horizontal) segment";
}

/// Where q's closest point on the polyline lies, the test's own way: the segment s and the
/// parameter t along it of the nearest of every segment's clamped projection.
std::pair<size_t, double> closest_segment(const std::vector<Vec3>& pts, bool closed, const Vec3& q) {
  double best = INFINITY, best_t = 0.0;
  size_t best_s = 0;
  const size_t n = pts.size();
  for (size_t s = 0; s < (closed ? n : n - 1); ++s) {
    const Vec3 a = pts[s], b = pts[(s + 1) % n];
    const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    const double d = (q - (a + t * (b - a))).norm();
    if (d < best) best = d, best_t = t, best_s = s;
  }
  return {best_s, best_t};
}

TEST(PolylineSupport, BeadSlidesAcrossVerticesAndRestsAtOneWithItsWholeLoad) {
  // A bead on a 48-gon of radius 0.8 m pulled by weight and a point load slides across its vertices
  // and, damped, comes to rest at the vertex farthest along the pull: a linear function over the
  // polygon is largest at a vertex, where the wire's normal cone holds any pull between its two
  // segments' normals. There the whole multiplier must be kept, so the reaction balances weight and
  // load. The polygon is turned so that this vertex is (a) its seam, point 0, where the closing
  // segment meets the first, and (b) an interior vertex, with a sideways load.
  constexpr double r = 0.8, m = 0.4;
  constexpr int n = 48;
  const Vec3 centre(1.0, 2.0, 3.0);
  struct Case {
    const char* name;
    double first;  // the angle of point 0
    Vec3 load;     // N
  };
  const Case cases[] = {{"seam", -std::numbers::pi / 2, Vec3(0.0, 0.0, -1.0)},
                        {"interior", -std::numbers::pi / 2 + 0.05, Vec3(1.2, 0.0, -1.0)}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::vector<Vec3> pts = circle(r, n, c.first);
    const Vec3 pull = Vec3(0.0, 0.0, -m * kG) + c.load;
    size_t far = 0;
    for (size_t i = 1; i < pts.size(); ++i)
      if (pts[i].dot(pull) > pts[far].dot(pull)) far = i;
    if (std::string(c.name) == "seam") {
      ASSERT_EQ(far, 0u) << "the seam is the lowest point";
    } else {
      ASSERT_GT(far, 0u);
      ASSERT_LT(far, pts.size() - 1) << "an interior vertex";
    }
    // Released 70 degrees round from the resting vertex, 1 cm off the wire.
    const double a0 = std::atan2(pts[far].z(), pts[far].x()) + 70.0 * std::numbers::pi / 180.0;
    test::Bead bead(PinSupport::polyline, centre, pts, true, {},
                    centre + (r + 0.01) * Vec3(std::cos(a0), 0.0, std::sin(a0)), m, c.load, kG);
    double off = 0.0, along = 0.0;
    std::set<size_t> visited;
    for (int f = 0; f < 240; ++f) {
      bead.world.step();
      const Vec3 x = bead.offset();
      off = std::max(off, distance_to_polyline(pts, true, x));
      // Strictly inside a segment the reaction is normal to it (the particle slides freely).
      const auto [seg, t] = closest_segment(pts, true, x);
      visited.insert(seg);
      if (t > 1e-6 && t < 1.0 - 1e-6) {
        const Vec3 e = (pts[(seg + 1) % n] - pts[seg]).normalized();
        along = std::max(along, std::abs(bead.world.reactions()[0].force.dot(e)) / pull.norm());
      }
    }
    RecordProperty(std::string(c.name) + "_max_distance_sliding", test::sci(off));
    RecordProperty(std::string(c.name) + "_max_reaction_along_segment", test::sci(along));
    EXPECT_LT(off, 1e-9) << "on the polyline at every frame while it slides";
    EXPECT_GT(visited.size(), 10u) << "it slid across many vertices";
    EXPECT_LT(along, 1e-9) << "inside a segment the reaction is normal to it";
    bead.settle(3.0, 1500);
    const Vec3 x = bead.offset();
    RecordProperty(std::string(c.name) + "_rest_offset_from_vertex_m", test::sci((x - pts[far]).norm()));
    EXPECT_LT((x - pts[far]).norm(), 1e-9) << "at vertex " << far;
    const std::vector<Reaction> reactions = bead.world.reactions();
    ASSERT_EQ(reactions.size(), 1u);
    EXPECT_EQ(reactions[0].pin, bead.pin);
    const double imbalance = (reactions[0].force + pull).norm() / pull.norm();
    RecordProperty(std::string(c.name) + "_reaction_imbalance", test::sci(imbalance));
    EXPECT_LT(imbalance, 1e-9) << "the reaction balances weight and load";
  }
}

TEST(PolylineSupport, OpenEndHoldsAndMovingTheTargetMovesTheCurve) {
  // An open polyline sloping down to its end at (0, 0, 0): a particle slides down and stops there.
  const std::vector<Vec3> pts = {Vec3(-1.0, 0.0, 1.0), Vec3(-0.5, 0.0, 0.4), Vec3(0.0, 0.0, 0.0)};
  Settings s = test::settings(8, 2, Vec3(0.0, 0.0, -kG), 2.0);
  s.tethers = 0;
  World w(s);
  const int32_t p = test::add_particles(w, {Vec3(-0.9, 0.0, 0.88)}, {1.0});
  const Id pin = polyline_support(w, p, Vec3::Zero(), pts, false);
  for (int f = 0; f < 600; ++f) w.step();
  EXPECT_LT(w.positions()[p].norm(), 1e-9) << "held at the curve's end";
  const Vec3 shift(0.3, -0.2, 0.5);
  w.set_pin_target(pin, shift);
  for (int f = 0; f < 600; ++f) w.step();
  EXPECT_LT((w.positions()[p] - shift).norm(), 1e-9) << "the curve moved with its target";
}

TEST(PolylineSupport, SameBitsRunAfterRun) {
  const std::array<Vec3, 2> runs = test::support_run_twice(PinSupport::polyline, circle(0.75, 40), true, {}, kG);
  EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[1].data(), sizeof(Vec3)));
}

TEST(PolylineSupport, BadCurvesAreRefusedAndChangeNothing) {
  World w;
  const int32_t p = test::add_particles(w, {Vec3::Zero()}, {1.0});
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0);
  EXPECT_THROW(polyline_support(w, p, Vec3::Zero(), {a}, false), Error) << "one point";
  EXPECT_THROW(polyline_support(w, p, Vec3::Zero(), {a, b}, true), Error) << "closed needs 3";
  EXPECT_THROW(polyline_support(w, p, Vec3::Zero(), {a, b, b, c}, false), Error) << "a zero-length segment";
  EXPECT_THROW(polyline_support(w, p, Vec3::Zero(), {a, b, c, a}, true), Error) << "last = first, closed";
  EXPECT_THROW(polyline_support(w, p, Vec3::Zero(), {a, Vec3(1e-170, 0, 0)}, false), Error) << "too short";
  EXPECT_THROW(polyline_support(w, p, Vec3::Zero(), {a, Vec3(NAN, 0, 0)}, false), Error);
  EXPECT_THROW(polyline_support(w, p + 1, Vec3::Zero(), {a, b}, false), Error);
  PinDesc plane;
  plane.particle = p;
  plane.support = PinSupport::plane;
  plane.curve = {a, b};
  EXPECT_THROW(w.create_pin(plane), Error) << "points for a plane";
  EXPECT_EQ(w.pin_count(), 0u);
  polyline_support(w, p, Vec3::Zero(), {a, b, c, a}, false);  // open: last = first is a loop, fine
  EXPECT_EQ(w.pin_count(), 1u);
}

}  // namespace
}  // namespace embra
