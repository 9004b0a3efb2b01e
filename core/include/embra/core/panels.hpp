// Planar Offset Quad (POQ) panel meshes: the paper's section 4, fabrication constraints that live
// inside the simulation, and the fabrication metrics of its section 4.1.
//
// A panel mesh is built from a quad mesh (the top layer). Every quad becomes a panel of its own, 8
// particles (PanelLayout in world.hpp):
//   (a) the top quad braced rigid: its 4 edges and 2 diagonals as hard distances, and a hard
//       planarity constraint (the distance between its diagonals is 0);
//   (b) corners of adjacent panels on one mesh vertex welded, so panels pivot about their borders;
//   (c) a bottom quad, offset by the thickness opposite the top's normal,
//   (d) each bottom corner held at the thickness from the plane of its top corner's triangle by a
//       hard point-to-plane constraint (plane_offset) that lets it slide along that plane;
// and, so that a bottom corner's sliding is decided by the joints: every edge's joint (the miter
// face: the edge's two top corners and two bottom corners) held planar, and a soft distance from
// each bottom corner to its top corner that only matters where nothing else decides it (a flat
// region, where the offset planes coincide).
//
// The metrics are computed from positions alone (measure_panels): nothing here reads the solver.
#pragma once

#include "embra/core/world.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace embra {

enum class PanelPins : int32_t { none = 0, top_corners = 1, top_and_bottom_corners = 2 };
/// How the panels on one mesh vertex hold together: each panel with corners of its own, welded to
/// the others' (8 particles a panel), or one top and one bottom particle a vertex that its panels
/// share (2 a vertex, no welds: the offset quads of the panels round a vertex meet in one point, the
/// paper's POQ condition, which asks the top mesh to stay conical).
enum class PanelCorners : int32_t { welded = 0, shared = 1 };
/// The arithmetic of the mesh's own rows (its panels' distances, planarity and plane offsets) where
/// they are projected panel by panel (IslandPlan): full (double) or single precision
/// (embra_panel_mesh_def.precision says what single costs in accuracy and gains in time).
enum class PanelPrecision : int32_t { full = 0, single = 1 };

/// A metric's tolerance: its target and the end of its colour scale.
struct Tolerance {
  double target = 0.0;  // within it: fine (drawn grey)
  double max = 0.0;     // the colour scale's end
};

/// The tolerance settings document (schemas/tolerances.schema.json). Defaults: the paper's thickness
/// (0.00005, max 0.001) and miter (0.001) tolerances, planarity 1e-6 (the bar), corner
/// distance as thickness; unit_scale converts model units to millimetres per metre of panel.
struct Tolerances {
  double unit_scale = 1000.0;
  Tolerance planarity{1e-6, 1e-4};
  Tolerance planarity_distance{5e-5, 1e-3};
  Tolerance thickness{5e-5, 1e-3};
  Tolerance miter{1e-3, 1e-2};
};

struct PanelMeshDesc {
  std::span<const double> positions;  // top mesh vertices, 3 each (model units)
  std::span<const int32_t> quads;     // 4 vertex indices per panel, counter-clockwise seen from the
                                      // side the top's normal points to (the bottom is on the other)
  double thickness = 0.01;            // > 0, model units
  double mass = 0.0;                  // kg for the whole mesh when > 0, else density
  double density = 1.0;               // kg per unit area of the top layer (when mass is 0)
  double damping = 0.0;               // 1/s per particle
  double friction_static = 0.5, friction_dynamic = 0.3;
  double slide_compliance = 1e-3;    // m/N of the soft distance from each bottom corner to its top corner
  PanelPins pins = PanelPins::none;  // hard pins at the mesh's corners (vertices on one panel only)
  PanelCorners corners = PanelCorners::welded;
  PanelPrecision precision = PanelPrecision::full;
  Id group;  // group of every constraint; null = the default group
  // The tolerances in force (the world's tolerance document; through the C ABI the one set with
  // embra_world_set_tolerances, in a scene its "tolerances"): a top quad is accepted when its
  // planarity (quad_planarity) is within its target. The corner distance (quad_corner_distance) is
  // reported, not a gate (docs/design.md, "Panel meshes").
  Tolerances tolerances{};
};

/// Builds a panel mesh: one body (8 particles per panel welded, 2 per vertex shared; top and bottom
/// triangles for drawing and face contact), its constraints, its pins and its layout. Every
/// argument is checked first (a quad with a repeated or out-of-range vertex, a degenerate quad, a
/// non-manifold edge, a non-positive thickness, a quad whose planarity is beyond the target of
/// desc.tolerances, with shared corners a vertex on no quad, are refused) and nothing changes on a
/// refusal. Returns the body.
Id build_panel_mesh(World& world, const PanelMeshDesc& desc);

/// The vertices (3 each) and quads (4 each) of an n x m grid of square panels of side `size` in the
/// plane z = origin.z, from `origin` along +x (n panels) and +y (m panels); normal +z.
void panel_grid(int32_t n, int32_t m, double size, const Vec3& origin, std::vector<double>& out_positions,
                std::vector<int32_t>& out_quads);

// --- metrics --------------------------------------------------------------------------------------

/// Planarity as the paper defines it: 1 - n1 . n2 for the unit normals of the quad's two triangles,
/// the larger of the two ways of splitting it along a diagonal. Dimensionless; quadratic in the fold
/// angle (1 - cos angle).
double quad_planarity(const Vec3& q0, const Vec3& q1, const Vec3& q2, const Vec3& q3);
/// The largest distance of a corner from the plane through the other three (model units).
double quad_corner_distance(const Vec3& q0, const Vec3& q1, const Vec3& q2, const Vec3& q3);
/// Distance between the diagonals over the mean edge length (dimensionless).
double quad_diagonal_distance(const Vec3& q0, const Vec3& q1, const Vec3& q2, const Vec3& q3);
/// Thickness error of a panel: the largest | distance - thickness | of a corner of one layer from
/// the plane of the corresponding corner triangle (k-1, k, k+1) of the other layer, over the four
/// corner triangles of both layers (model units).
double panel_thickness_error(const Vec3 top[4], const Vec3 bottom[4], double thickness);
/// Miter twist of a joint: distance of the fourth point (bottom_j) from the plane through the edge's
/// top corners and bottom_i (model units).
double miter_twist(const Vec3& top_i, const Vec3& top_j, const Vec3& bottom_i, const Vec3& bottom_j);

/// One joint per edge of the top mesh: the panel holding it first and the edge's corners in it
/// (corner k to k+1 mod 4).
struct PanelJoint {
  int32_t panel = 0;
  int32_t corner = 0;
  int32_t other_panel = -1;  // the panel across the edge, -1 on the boundary
  int32_t other_corner = -1;
};
std::vector<PanelJoint> panel_joints(const PanelLayout& layout);

/// Interior vertices of valence 4 with their four panels in cyclic order (the corner index of the
/// vertex in each): the vertices where the conical defect is defined.
struct ConicalVertex {
  int32_t vertex = 0;
  int32_t panel[4] = {0, 0, 0, 0};
  int32_t corner[4] = {0, 0, 0, 0};
};
std::vector<ConicalVertex> conical_vertices(const PanelLayout& layout);

/// What the metrics read of a layout's connectivity, derived from its quads once.
struct PanelTopology {
  std::vector<PanelJoint> joints;                                // panel_joints
  std::vector<ConicalVertex> conical;                            // conical_vertices
  std::vector<std::vector<std::pair<int32_t, int32_t>>> around;  // per mesh vertex: its (panel, corner)s
};
PanelTopology panel_topology(const PanelLayout& layout);

/// Every metric of a panel mesh at positions `x` (world particle positions).
struct PanelErrors {
  std::vector<double> planarity_top, planarity_bottom;              // per panel, paper's definition
  std::vector<double> corner_distance_top, corner_distance_bottom;  // per panel, model units
  std::vector<double> diagonal_top, diagonal_bottom;                // per panel, relative
  std::vector<double> thickness;                                    // per panel, model units
  std::vector<double> miter;                                        // per joint (panel_joints order)
  std::vector<double> conical;     // per conical vertex: |(a1 + a3) - (a2 + a4)| in radians
  std::vector<double> corner_gap;  // per mesh vertex of two or more panels: the largest distance
                                   // between two of its corner copies in one layer (the welds' error)
};
PanelErrors measure_panels(const PanelLayout& layout, std::span<const Vec3> x);

/// Max, RMS and counts of one metric against its tolerance.
struct MetricSummary {
  double max = 0.0;
  double rms = 0.0;
  int64_t count = 0;
  int64_t within_target = 0;  // <= target
  int64_t within_max = 0;     // > target and <= max
  int64_t above_max = 0;      // > max
};
MetricSummary summarize(std::span<const double> values, const Tolerance& tolerance);

struct PanelReport {
  MetricSummary planarity_top, planarity_bottom, corner_distance_top, corner_distance_bottom, diagonal_top,
      diagonal_bottom, thickness, miter, conical, corner_gap;
  bool within_tolerance = false;  // planarity (both layers), corner distance, thickness and miter within target
};
PanelReport report_panels(const PanelErrors& errors, const Tolerances& tolerances);

/// Which per-vertex field (vertex_errors) to colour by.
enum class PanelMetric : int32_t { planarity = 0, thickness = 1, miter = 2, corner_distance = 3, conical = 4 };
constexpr int kPanelMetricCount = 5;

/// One value per particle of the panel mesh (8 per panel): the largest error of `metric` over the
/// elements the particle belongs to (its panel's layer for planarity and corner distance, its panel
/// for thickness, the joints it is a corner of for miter, its mesh vertex for the conical defect).
std::vector<double> vertex_errors(const PanelLayout& layout, const PanelErrors& errors, PanelMetric metric);

/// What a cutter takes, per panel: the top and bottom outlines in the panel's own plane coordinates
/// (origin at top corner 0, x along its first edge, y in the top plane, z along the top normal), its
/// thickness, and the miter angle of each edge (the angle between the joint face and the top
/// plane's normal, in degrees; 0 = a square cut).
struct PanelCut {
  double top[4][2];
  double bottom[4][2];
  double bottom_z;  // height of the bottom plane in the panel's frame (-thickness when exact)
  double thickness;
  double miter_deg[4];
};
std::vector<PanelCut> panel_cuts(const PanelLayout& layout, std::span<const Vec3> x);
/// The cuts as a JSON document and as CSV (one row per panel).
std::string panel_cuts_json(const std::vector<PanelCut>& cuts);
std::string panel_cuts_csv(const std::vector<PanelCut>& cuts);

}  // namespace embra
