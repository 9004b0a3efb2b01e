// Panel meshes (Planar Offset Quads): the fabrication metrics on hand-checked cases, and the builder
// on a flat grid and on a known conical mesh.
//
// The metrics are checked here against values worked out by hand from the paper's definitions
// (section 4.1), on positions written out in the test, not produced by the solver.
#include "embra/core/panels.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace embra {
namespace {

// A unit square in z = 0, counter-clockwise seen from +z:   q3 (0,1) --- q2 (1,1)
//                                                            |              |
//                                                           q0 (0,0) --- q1 (1,0)
const Vec3 kSquare[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};

TEST(PanelMetrics, FlatPanelReadsZero) {
  EXPECT_EQ(quad_planarity(kSquare[0], kSquare[1], kSquare[2], kSquare[3]), 0.0);
  EXPECT_EQ(quad_corner_distance(kSquare[0], kSquare[1], kSquare[2], kSquare[3]), 0.0);
  EXPECT_EQ(quad_diagonal_distance(kSquare[0], kSquare[1], kSquare[2], kSquare[3]), 0.0);
  // Bottom layer exactly 0.01 below: no thickness error; its side faces are vertical: no twist.
  Vec3 bottom[4];
  for (int k = 0; k < 4; ++k) bottom[k] = kSquare[k] - Vec3(0, 0, 0.01);
  EXPECT_NEAR(panel_thickness_error(kSquare, bottom, 0.01), 0.0, 1e-17);
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(miter_twist(kSquare[k], kSquare[(k + 1) % 4], bottom[k], bottom[(k + 1) % 4]), 0.0);
}

// One corner (q2) raised by d. Split along q0-q2, the triangles' normals are (0, -d, 1) and (-d, 0, 1)
// (unnormalised), so 1 - n1.n2 = 1 - 1 / (1 + d^2) = d^2 / (1 + d^2). Split along q1-q3, (q1, q3, q0)
// stays flat (0, 0, 1) and (q1, q2, q3) has normal (-d, -d, 1): 1 - 1 / sqrt(1 + 2 d^2). The metric is
// the larger. The raised corner is d off the plane of the other three (the largest of the four
// corner distances). The diagonals are d / (2 sqrt(1 + d^2 / 2)) apart; the edges are 1, 1,
// sqrt(1 + d^2), sqrt(1 + d^2).
TEST(PanelMetrics, OneCornerRaisedByD) {
  for (double d : {1e-4, 1e-3, 0.05}) {
    const Vec3 q2 = kSquare[2] + Vec3(0, 0, d);
    const double split02 = d * d / (1 + d * d);
    const double split13 = 1 - 1 / std::sqrt(1 + 2 * d * d);
    EXPECT_NEAR(quad_planarity(kSquare[0], kSquare[1], q2, kSquare[3]), std::max(split02, split13), 1e-15) << d;
    EXPECT_NEAR(quad_corner_distance(kSquare[0], kSquare[1], q2, kSquare[3]), d, 1e-15) << d;
    const double mean_edge = (2 + 2 * std::sqrt(1 + d * d)) / 4;
    EXPECT_NEAR(quad_diagonal_distance(kSquare[0], kSquare[1], q2, kSquare[3]),
                d / (2 * std::sqrt(1 + d * d / 2)) / mean_edge, 1e-15)
        << d;
  }
  // The reading of the paper's number: planarity 6e-6 is a fold of sqrt(2 * 6e-6) = 3.46e-3
  // rad, about 2.4 mm off-plane per metre of panel, not 0.006 mm.
  const double d = 0.0024;  // m, one corner of a 1 m panel
  EXPECT_NEAR(quad_planarity(kSquare[0], kSquare[1], kSquare[2] + Vec3(0, 0, d), kSquare[3]), 5.76e-6, 0.02e-6);
}

// Thickness: one bottom corner pushed down by e is e further than 0.01 from the top plane; moving a
// bottom corner along the plane changes nothing.
TEST(PanelMetrics, ThicknessError) {
  Vec3 bottom[4];
  for (int k = 0; k < 4; ++k) bottom[k] = kSquare[k] - Vec3(0, 0, 0.01);
  bottom[1] += Vec3(0.003, -0.002, 0);
  EXPECT_NEAR(panel_thickness_error(kSquare, bottom, 0.01), 0.0, 1e-17);
  bottom[3].z() -= 2e-4;
  // The top corners measured from the tilted bottom triangles are off by less; the bottom corner
  // from the flat top plane by exactly 2e-4.
  EXPECT_NEAR(panel_thickness_error(kSquare, bottom, 0.01), 2e-4, 1e-15);
}

// Miter: the joint of edge q0-q1 is the vertical face y = 0 when the bottom edge is straight below.
// Moving bottom corner 1 out of that face by e (along -y) twists the joint by e; moving it within
// the face (along x or z) does not.
TEST(PanelMetrics, MiterTwist) {
  const Vec3 b0 = kSquare[0] - Vec3(0, 0, 0.01);
  const Vec3 b1 = kSquare[1] - Vec3(0, 0, 0.01);
  EXPECT_EQ(miter_twist(kSquare[0], kSquare[1], b0, b1 + Vec3(0.004, 0, -0.002)), 0.0);
  EXPECT_NEAR(miter_twist(kSquare[0], kSquare[1], b0, b1 - Vec3(0, 0.0013, 0)), 0.0013, 1e-16);
}

// Summary against a tolerance: counts in and out, max and RMS.
TEST(PanelMetrics, SummaryCountsAgainstTolerance) {
  const std::vector<double> v = {0.0, 1e-6, 2e-6, 5e-4, 2e-3};
  const MetricSummary s = summarize(v, Tolerance{1e-6, 1e-3});
  EXPECT_EQ(s.count, 5);
  EXPECT_EQ(s.within_target, 2);
  EXPECT_EQ(s.within_max, 2);
  EXPECT_EQ(s.above_max, 1);
  EXPECT_EQ(s.max, 2e-3);
  EXPECT_NEAR(s.rms, std::sqrt((1e-12 + 4e-12 + 25e-8 + 4e-6) / 5), 1e-18);
}

// A 3 x 2 grid: 6 panels of 8 particles, 17 joints (edges of the grid: 3*3 + 4*2), 2 interior
// vertices; everything reads zero as built, the bottom layer 0.01 below the top.
TEST(PanelMesh, GridBuildsFlatAndExact) {
  World w(test::settings(10, 1));
  const Id body = test::add_panel_grid(w, 3, 2, 0.8);
  const PanelLayout* l = w.panel_layout(body);
  ASSERT_NE(l, nullptr);
  EXPECT_EQ(l->panel_count(), 6);
  EXPECT_EQ(w.particle_count(), 48);
  EXPECT_EQ(w.pin_count(), 4u);
  EXPECT_EQ(panel_joints(*l).size(), 17u);
  EXPECT_EQ(conical_vertices(*l).size(), 2u);
  for (int32_t p = 0; p < 6; ++p)
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR((w.positions()[l->top(p, k)] - w.positions()[l->bottom(p, k)] - Vec3(0, 0, 0.01)).norm(), 0.0, 1e-15);
  const PanelReport r = report_panels(measure_panels(*l, w.positions()), Tolerances{});
  EXPECT_EQ(r.planarity_top.max, 0.0);
  EXPECT_LT(r.thickness.max, 1e-15);
  EXPECT_LT(r.miter.max, 1e-15);
  EXPECT_LT(r.conical.max, 1e-15);
  EXPECT_TRUE(r.within_tolerance);
  // Per-vertex fields: one value per particle.
  EXPECT_EQ(vertex_errors(*l, measure_panels(*l, w.positions()), PanelMetric::miter).size(), 48u);
}

// measure_panels shares each corner's plane between a panel's metrics; its values are those of the
// per-quad functions above, to the bit, on panels bent every way.
TEST(PanelMetrics, MeasuredAsThePerQuadFunctions) {
  World w(test::settings(10, 1));
  const Id body = test::add_panel_grid(w, 4, 3, 0.8);
  const PanelLayout& l = *w.panel_layout(body);
  std::vector<Vec3> x = w.positions();
  for (size_t i = 0; i < x.size(); ++i)  // a fixed bend per particle, up to 3 cm
    x[i] += 0.03 * Vec3(std::sin(1.7 * static_cast<double>(i)), std::cos(2.3 * static_cast<double>(i)),
                        std::sin(0.9 * static_cast<double>(i) + 0.4));
  const PanelErrors e = measure_panels(l, x);
  ASSERT_EQ(e.thickness.size(), 12u);
  for (int32_t p = 0; p < l.panel_count(); ++p) {
    Vec3 t[4], b[4];
    for (int k = 0; k < 4; ++k) t[k] = x[l.top(p, k)], b[k] = x[l.bottom(p, k)];
    const size_t i = static_cast<size_t>(p);
    EXPECT_EQ(e.planarity_top[i], quad_planarity(t[0], t[1], t[2], t[3])) << p;
    EXPECT_EQ(e.planarity_bottom[i], quad_planarity(b[0], b[1], b[2], b[3])) << p;
    EXPECT_EQ(e.corner_distance_top[i], quad_corner_distance(t[0], t[1], t[2], t[3])) << p;
    EXPECT_EQ(e.corner_distance_bottom[i], quad_corner_distance(b[0], b[1], b[2], b[3])) << p;
    EXPECT_EQ(e.thickness[i], panel_thickness_error(t, b, l.thickness)) << p;
    EXPECT_GT(e.thickness[i], 1e-3);  // bent: the comparison is not of zeros
  }
}

// A bad description is refused and changes nothing.
TEST(PanelMesh, RefusedInputChangesNothing) {
  World w(test::settings(10, 1));
  std::vector<double> pos;
  std::vector<int32_t> quads;
  panel_grid(2, 2, 1.0, Vec3::Zero(), pos, quads);
  auto refused = [&](PanelMeshDesc d, const char* what) {
    EXPECT_THROW(build_panel_mesh(w, d), Error) << what;
    EXPECT_EQ(w.particle_count(), 0) << what;
    EXPECT_EQ(w.body_count(), 0u) << what;
    EXPECT_EQ(w.constraint_count(), 0) << what;
    EXPECT_EQ(w.pin_count(), 0u) << what;
  };
  PanelMeshDesc d;
  d.positions = pos;
  d.quads = quads;
  d.pins = PanelPins::top_corners;
  PanelMeshDesc bad = d;
  bad.thickness = 0.0;
  refused(bad, "zero thickness");
  bad = d;
  bad.thickness = std::nan("");
  refused(bad, "NaN thickness");
  std::vector<int32_t> q = quads;
  q[5] = 99;
  bad = d;
  bad.quads = q;
  refused(bad, "index out of range");
  q = quads;
  q[1] = q[0];
  bad.quads = q;
  refused(bad, "repeated vertex");
  q = quads;
  std::swap(q[4], q[6]);  // second quad turned the other way round: its shared edge runs the same way
  bad.quads = q;
  refused(bad, "inconsistent orientation");
  std::vector<double> p = pos;
  p[3 * 4 + 2] = 0.3;  // lift the middle vertex: its four quads are no longer planar
  bad = d;
  bad.positions = p;
  refused(bad, "non-planar quad");
  bad = d;
  bad.pins = static_cast<PanelPins>(7);
  refused(bad, "unknown pin mode");
}

// The conical band of the tests below: a band of a sphere of radius 3 m along its meridians and
// parallels, 24 around and 4 rows, closed round, its quads counter-clockwise seen from outside.
constexpr int kBandAround = 24, kBandRows = 4;
constexpr double kBandRadius = 3.0;
void conical_band(std::vector<double>& pos, std::vector<int32_t>& quads) {
  for (int i = 0; i <= kBandRows; ++i) {
    const double phi = -0.4 + 0.8 * i / kBandRows;
    for (int j = 0; j < kBandAround; ++j) {
      const double theta = 2 * std::numbers::pi * j / kBandAround;
      pos.insert(pos.end(), {kBandRadius * std::cos(phi) * std::cos(theta),
                             kBandRadius * std::cos(phi) * std::sin(theta), kBandRadius * std::sin(phi)});
    }
  }
  for (int i = 0; i < kBandRows; ++i)
    for (int j = 0; j < kBandAround; ++j) {
      const int32_t a = i * kBandAround + j, b = i * kBandAround + (j + 1) % kBandAround;
      quads.insert(quads.end(), {a, b, b + kBandAround, a + kBandAround});  // east, then north: outward normal
    }
}

// A known conical mesh: a band of a sphere along its meridians and parallels (a surface of
// revolution), 24 around and 4 rows, closed round. Each quad is an isosceles trapezoid (planar); at
// each vertex the mirror symmetry across the meridian plane makes opposite face angles sum equal
// (a conical vertex), so the face offset exists. Built as the top layer with its face offset, all
// three metrics read zero, and with gravity off it stays so.
// Both corner layouts: welded (the offsets meet per panel, the welds hold the copies together) and
// shared (one bottom particle a vertex at the thickness from all four of its panels' planes, which
// exists only because the mesh is conical).
TEST(PanelMesh, ConicalMeshReadsZeroAndStays) {
  constexpr int around = kBandAround, rows = kBandRows;
  constexpr double radius = kBandRadius;
  std::vector<double> pos;
  std::vector<int32_t> quads;
  conical_band(pos, quads);
  for (PanelCorners corners : {PanelCorners::welded, PanelCorners::shared}) {
    const bool shared = corners == PanelCorners::shared;
    SCOPED_TRACE(shared ? "corners shared" : "corners welded");
    World w(test::settings(20, 1));
    PanelMeshDesc d;
    d.positions = pos;
    d.quads = quads;
    d.thickness = 0.05;
    d.corners = corners;
    const Id body = build_panel_mesh(w, d);
    const PanelLayout& l = *w.panel_layout(body);
    EXPECT_EQ(w.particle_count(), shared ? 2 * around * (rows + 1) : 8 * around * rows);
    EXPECT_EQ(conical_vertices(l).size(), static_cast<size_t>(around * (rows - 1)));
    const PanelErrors before = measure_panels(l, w.positions());
    const PanelReport r0 = report_panels(before, Tolerances{});
    EXPECT_LT(r0.conical.max, 1e-13);
    EXPECT_LT(r0.planarity_top.max, 1e-14);
    EXPECT_LT(r0.planarity_bottom.max, 1e-14);
    EXPECT_LT(r0.thickness.max, 1e-12);
    EXPECT_LT(r0.miter.max, 1e-12);
    // The bottom layer lies on the sphere of radius 3 - 0.05 / cos(half the angle between rows):
    // every bottom corner is below its top corner (inside the sphere).
    for (int32_t p = 0; p < l.panel_count(); ++p)
      for (int k = 0; k < 4; ++k) EXPECT_LT(w.positions()[l.bottom(p, k)].norm(), radius - 0.049);
    for (int f = 0; f < 60; ++f) w.step();
    const PanelReport r1 = report_panels(measure_panels(l, w.positions()), Tolerances{});
    EXPECT_LT(r1.planarity_top.max, 1e-12);
    EXPECT_LT(r1.planarity_bottom.max, 1e-12);
    EXPECT_LT(r1.thickness.max, 1e-10);
    EXPECT_LT(r1.miter.max, 1e-10);
    if (shared) {
      EXPECT_EQ(r1.corner_gap.max, 0.0);
    }
    EXPECT_LT(w.report().max_speed, 1e-9);
    RecordProperty(shared ? "shared_after_60_frames_thickness" : "conical_after_60_frames_thickness",
                   test::sci(r1.thickness.max));
    RecordProperty(shared ? "shared_after_60_frames_miter" : "conical_after_60_frames_miter", test::sci(r1.miter.max));
  }
}

// Rows in single precision (PanelPrecision::single) hold a panel mesh as full precision does, to
// about the float's rounding of a panel's size, wherever the mesh lies and whatever its size: each
// panel is projected relative to its first corner, so 10 km from the origin (where a float's step is
// 1 mm) is as exact as at it, and a row's terms stay of the order of its normal's square, so panels
// of 0.7 mm and of 700 m hold as the 0.7 m ones do (the figures scale with the size). The conical
// band above with shared corners (the offset quads exist, so every metric can reach zero), every
// particle moved off it by up to 1 mm (times the scale), gravity off and damping 5/s, 120 frames of
// 20 substeps x 4 iterations: each precision, place and size ends with the panels planar, at their
// thickness and mitred, and at rest.
TEST(PanelMesh, SinglePrecisionRowsHoldThePanelsAnywhere) {
  std::vector<double> pos;
  std::vector<int32_t> quads;
  conical_band(pos, quads);
  struct Case {
    double far, scale;
    PanelPrecision precision;
    const char* name;
  };
  for (const Case& c :
       {Case{0.0, 1.0, PanelPrecision::full, "full_origin"}, Case{0.0, 1.0, PanelPrecision::single, "single_origin"},
        Case{1e4, 1.0, PanelPrecision::full, "full_10km"}, Case{1e4, 1.0, PanelPrecision::single, "single_10km"},
        Case{0.0, 1e-3, PanelPrecision::single, "single_mm"}, Case{0.0, 1e3, PanelPrecision::single, "single_km"}}) {
    const bool single = c.precision == PanelPrecision::single;
    const std::string name = c.name;
    SCOPED_TRACE(name);
    std::vector<double> placed = pos;
    for (double& x : placed) x = c.scale * x + c.far;
    World w(test::settings(20, 4, Vec3::Zero(), 5.0));
    PanelMeshDesc d;
    d.positions = placed;
    d.quads = quads;
    d.thickness = 0.05 * c.scale;
    d.corners = PanelCorners::shared;
    d.precision = c.precision;
    const Id body = build_panel_mesh(w, d);
    const PanelLayout& l = *w.panel_layout(body);
    EXPECT_EQ(l.single, single);
    std::vector<double> moved(3 * static_cast<size_t>(w.particle_count()));
    for (size_t i = 0; i < moved.size(); ++i)
      moved[i] = w.positions()[i / 3][static_cast<int>(i % 3)] +
                 1e-3 * c.scale * std::sin(12.9898 * static_cast<double>(i) + 1.0);
    w.set_positions(0, moved);
    EXPECT_GT(report_panels(measure_panels(l, w.positions()), Tolerances{}).thickness.max, 1e-4 * c.scale);
    for (int f = 0; f < 120; ++f) w.step();
    const PanelReport r = report_panels(measure_panels(l, w.positions()), Tolerances{});
    test::record_panel_report(name + "_", r);
    RecordProperty(name + "_max_speed", test::sci(w.report().max_speed));
    // Single: within a few float steps of the largest panel side (0.8 m), as far from the origin
    // as at it (measured 1.2-1.4e-7 m corner distance, 5.6-6.7e-8 thickness, 1.1-1.3e-7 miter, at
    // 1.2-1.8e-4 m/s; the mm and km bands the same times their scale); the same few steps over a
    // substep bound the speed. Full: 300 times finer (4.1e-10, 8.8e-11, 2.0e-10, still settling at
    // 3.3e-6 m/s after 120 frames). Planarity (1 - n1 . n2) has no length.
    const double step = 0.8 * c.scale * std::numeric_limits<float>::epsilon();  // 9.5e-8 m at scale 1
    const double length = single ? 4 * step : 4 * step / 100;
    EXPECT_LT(r.planarity_top.max, single ? 1e-12 : 1e-15);
    EXPECT_LT(r.corner_distance_top.max, length);
    EXPECT_LT(r.thickness.max, length);
    EXPECT_LT(r.miter.max, length);
    EXPECT_LT(w.report().max_speed, single ? 4 * step * 20 * 60 : 1e-5);
  }
}

// A 3 x 2 grid with corners shared: one top and one bottom particle per mesh vertex (12 each), the
// panels on a vertex on the same two particles; each panel's mass in eighths on its corners; the
// top's 17 edges once each with the 12 diagonals, a slide distance per vertex, no welds.
TEST(PanelMesh, SharedCornersOneParticlePerVertexAndLayer) {
  World w(test::settings(10, 1));
  std::vector<double> positions;
  std::vector<int32_t> quads;
  panel_grid(3, 2, 0.8, Vec3(0.0, 0.0, 1.0), positions, quads);
  PanelMeshDesc d;
  d.positions = positions;
  d.quads = quads;
  d.density = 2.0;
  d.corners = PanelCorners::shared;
  d.pins = PanelPins::top_corners;
  const Id body = build_panel_mesh(w, d);
  const PanelLayout& l = *w.panel_layout(body);
  EXPECT_TRUE(l.shared);
  EXPECT_EQ(w.particle_count(), 24);
  EXPECT_EQ(w.pin_count(), 4u);
  double mass = 0.0;
  for (int32_t i = 0; i < w.particle_count(); ++i) mass += 1.0 / w.inverse_masses()[i];
  EXPECT_NEAR(mass, 2.0 * 6 * 0.64, 1e-12);
  for (int32_t p = 0; p < 6; ++p)
    for (int k = 0; k < 4; ++k) {
      const int32_t v = quads[4 * static_cast<size_t>(p) + k];
      EXPECT_EQ(l.top(p, k), v);
      EXPECT_EQ(l.bottom(p, k), 12 + v);
      EXPECT_NEAR((w.positions()[l.top(p, k)] - w.positions()[l.bottom(p, k)] - Vec3(0, 0, 0.01)).norm(), 0.0, 1e-15);
    }
  const Id g = w.default_group();
  EXPECT_EQ(w.constraint_count(g, Kind::weld).first, 0);
  EXPECT_EQ(w.constraint_count(g, Kind::distance).first, 17 + 12 + 12);
  EXPECT_EQ(w.constraint_count(g, Kind::plane_offset).first, 24);
  EXPECT_EQ(w.constraint_count(g, Kind::planarity).first, 6 + 17);
  const PanelErrors e = measure_panels(l, w.positions());
  const PanelReport r = report_panels(e, Tolerances{});
  EXPECT_EQ(r.corner_gap.max, 0.0);
  EXPECT_LT(r.thickness.max, 1e-15);
  EXPECT_TRUE(r.within_tolerance);
  EXPECT_EQ(vertex_errors(l, e, PanelMetric::miter).size(), 24u);
  // A vertex on no quad has no panel to take its particles' mass: refused, nothing changed.
  positions.insert(positions.end(), {5.0, 5.0, 5.0});
  d.positions = positions;
  const int64_t constraints = w.constraint_count();
  EXPECT_THROW(build_panel_mesh(w, d), Error);
  EXPECT_EQ(w.particle_count(), 24);
  EXPECT_EQ(w.constraint_count(), constraints);
}

// An optimised PQ mesh is planar to its optimiser's tolerance, not to rounding. This one is stated
// exactly: the conical band above (a surface of revolution, 24 around, 4 rows, radius 3 m; every
// quad an isosceles trapezoid, every inner vertex conical) with each vertex v moved by
// 4e-6 m x (sin(12.9898 v + 1), sin(78.233 v + 2), sin(37.719 v + 3)): about 1e-5 of the 0.6-0.8 m
// edges off planar. The builder's old rule (diagonals at most 1e-6 of the mean edge apart) refused
// it; the tolerances in force accept it (planarity 1 - n1.n2 <= 1e-6, corner distance <= 5e-5 m),
// and the panels it builds read thickness and miter within the tolerances at frame 0. A stricter
// document (corner distance 1e-6 m) refuses it and changes nothing.
TEST(PanelMesh, PerturbedConicalMeshPlanarWithinTheTolerancesIsBuiltWithinThem) {
  constexpr int around = 24, rows = 4;
  constexpr double radius = 3.0, amplitude = 4e-6;
  std::vector<double> pos;
  for (int i = 0; i <= rows; ++i) {
    const double phi = -0.4 + 0.8 * i / rows;
    for (int j = 0; j < around; ++j) {
      const double theta = 2 * std::numbers::pi * j / around;
      const double v = static_cast<double>(i * around + j);
      pos.insert(pos.end(), {radius * std::cos(phi) * std::cos(theta) + amplitude * std::sin(12.9898 * v + 1.0),
                             radius * std::cos(phi) * std::sin(theta) + amplitude * std::sin(78.233 * v + 2.0),
                             radius * std::sin(phi) + amplitude * std::sin(37.719 * v + 3.0)});
    }
  }
  std::vector<int32_t> quads;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < around; ++j) {
      const int32_t a = i * around + j, b = i * around + (j + 1) % around;
      quads.insert(quads.end(), {a, b, b + around, a + around});
    }
  auto P = [&](int32_t v) { return Vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]); };
  double old_rule = 0.0, planarity = 0.0, corner = 0.0, corner_rel = 0.0;
  for (size_t q = 0; q < quads.size(); q += 4) {
    const Vec3 a = P(quads[q]), b = P(quads[q + 1]), c = P(quads[q + 2]), d = P(quads[q + 3]);
    old_rule = std::max(old_rule, quad_diagonal_distance(a, b, c, d));
    planarity = std::max(planarity, quad_planarity(a, b, c, d));
    corner = std::max(corner, quad_corner_distance(a, b, c, d));
    const double edge = ((b - a).norm() + (c - b).norm() + (d - c).norm() + (a - d).norm()) / 4.0;
    corner_rel = std::max(corner_rel, quad_corner_distance(a, b, c, d) / edge);
  }
  RecordProperty("old_rule_diagonal_distance_over_edge", test::sci(old_rule));
  RecordProperty("corner_distance_over_edge", test::sci(corner_rel));
  EXPECT_GT(old_rule, 1e-6) << "the old rule (diagonals 1e-6 of an edge apart) refused this mesh";
  EXPECT_GT(corner_rel, 5e-6);
  EXPECT_LT(corner_rel, 5e-5) << "about 1e-5 of an edge off planar";
  const Tolerances tol;
  EXPECT_LE(planarity, tol.planarity.target);
  EXPECT_LE(corner, tol.planarity_distance.target);

  World w(test::settings(20, 1));
  PanelMeshDesc d;
  d.positions = pos;
  d.quads = quads;
  d.thickness = 0.05;
  // A stricter document refuses it, and nothing changes.
  PanelMeshDesc strict = d;
  strict.tolerances.planarity.target = 1e-10;
  EXPECT_GT(planarity, strict.tolerances.planarity.target);
  EXPECT_THROW(build_panel_mesh(w, strict), Error);
  EXPECT_EQ(w.particle_count(), 0);
  const Id body = build_panel_mesh(w, d);
  const PanelLayout& l = *w.panel_layout(body);
  const PanelReport r0 = report_panels(measure_panels(l, w.positions()), tol);
  test::record_panel_report("frame0_", r0);
  EXPECT_LE(r0.planarity_top.max, tol.planarity.target);
  EXPECT_LE(r0.planarity_bottom.max, tol.planarity.target);
  EXPECT_LE(r0.corner_distance_top.max, tol.planarity_distance.target);
  EXPECT_LE(r0.corner_distance_bottom.max, tol.planarity_distance.target);
  EXPECT_LE(r0.thickness.max, tol.thickness.target);
  EXPECT_LE(r0.miter.max, tol.miter.target);
  EXPECT_TRUE(r0.within_tolerance);
}

}  // namespace
}  // namespace embra
