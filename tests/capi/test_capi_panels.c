/* The paper's section 4.1 experiment through the C ABI: examples/poq_drape.json (4 x 4 panels of 0.8,
 * thickness 0.01, top corners pinned, gravity, a sphere of radius 1 below, moved between frames 120
 * and 180), with the thresholds the issue sets:
 *   - settled (no particle faster than 1 mm/s) from frame 100 on until the sphere moves (120), with
 *     max thickness error <= 0.00005, max planarity <= 1e-6 on top and bottom, max miter twist
 *     <= 0.001 at frame 100;
 *   - every metric within tolerance again within 30 frames of the sphere stopping (frame 210) and
 *     to the end;
 *   - no panel face inside the sphere at any frame, measured here per triangle from positions alone
 *     (closest point of each top and bottom triangle to the centre), with a rounding allowance of
 *     1e-6.
 * The metrics embra reports are also recomputed here from the positions (planarity of each panel's
 * top and bottom quads, both diagonal splits) so the numbers do not rest on the library's own code.
 *
 * With --large SCENE PANELS it runs one of the larger versions instead (examples/large/: 16 x 16 and
 * 32 x 32 panels over the same area, the same sphere and path, their corners shared; the panels'
 * corners are read with embra_panel_mesh_get_corner_particles, so either layout is checked) for the
 * scene's 300 frames: settled
 * at the end with max thickness error <= 0.00005, max planarity <= 1e-6 top and bottom and max miter
 * twist <= 0.001, and within every target of the scene's tolerance document (corner off plane
 * too); our own planarity equal to the reported one every frame; no panel face inside the sphere at
 * any frame (the same per-triangle check); the corner gap equal to our own from positions.
 *
 * usage: test_capi_panels EXAMPLES_DIR
 *        test_capi_panels --large SCENE PANELS */
#include "capi_test.h"

#include <stdlib.h>

typedef struct vec {
  double x, y, z;
} vec;
static vec at(const double* p, int32_t i) {
  vec v = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
  return v;
}
static vec sub(vec a, vec b) {
  vec v = {a.x - b.x, a.y - b.y, a.z - b.z};
  return v;
}
static vec add(vec a, vec b) {
  vec v = {a.x + b.x, a.y + b.y, a.z + b.z};
  return v;
}
static vec mul(double s, vec a) {
  vec v = {s * a.x, s * a.y, s * a.z};
  return v;
}
static double dot(vec a, vec b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
static vec cross(vec a, vec b) {
  vec v = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  return v;
}
static vec unit(vec a) {
  return mul(1.0 / sqrt(dot(a, a)), a);
}

/* 1 - n1.n2 over both diagonal splits of quad (a, b, c, d). */
static double planarity(vec a, vec b, vec c, vec d) {
  const double s02 = 1.0 - dot(unit(cross(sub(b, a), sub(c, a))), unit(cross(sub(c, a), sub(d, a))));
  const double s13 = 1.0 - dot(unit(cross(sub(c, b), sub(d, b))), unit(cross(sub(d, b), sub(a, b))));
  return s02 > s13 ? s02 : s13;
}

/* Distance from p to triangle (a, b, c): the minimum over the face interior (if the projection falls
 * inside) and the three edges. */
static double segment_distance(vec p, vec a, vec b) {
  const vec ab = sub(b, a);
  double t = dot(sub(p, a), ab) / dot(ab, ab);
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  const vec d = sub(p, add(a, mul(t, ab)));
  return sqrt(dot(d, d));
}
static double triangle_distance(vec p, vec a, vec b, vec c) {
  const vec n = unit(cross(sub(b, a), sub(c, a)));
  const double h = dot(sub(p, a), n);
  const vec q = sub(p, mul(h, n));
  const int inside = dot(cross(sub(b, a), sub(q, a)), n) >= 0 && dot(cross(sub(c, b), sub(q, b)), n) >= 0 &&
                     dot(cross(sub(a, c), sub(q, c)), n) >= 0;
  double best = inside ? fabs(h) : 1e300;
  const double e[3] = {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)};
  for (int k = 0; k < 3; ++k)
    if (e[k] < best) best = e[k];
  return best;
}

/* The sphere's centre from the scene's path: (0.3, 0.2, -1.45) until frame 120, straight to
 * (-0.3, 0.2, -1.35) at 180, held after (every drape scene shares it). */
static vec sphere_centre(int frame) {
  const double s = frame <= 120 ? 0.0 : frame >= 180 ? 1.0 : (frame - 120) / 60.0;
  const vec centre = {0.3 - 0.6 * s, 0.2, -1.45 + 0.1 * s};
  return centre;
}

/* Over every panel of positions x at `frame`: the largest planarity of a top or bottom quad, which
 * must equal the reported one (m), and the deepest point of a panel face (top or bottom triangle)
 * inside the sphere of `radius` at `centre`, kept in *inside_max. */
static void panel_checks(const double* x, const int32_t* corner, int32_t panels, vec centre, double radius,
                         const embra_panel_metrics* m, int frame, double* inside_max) {
  double planarity_max = 0.0;
  for (int32_t p = 0; p < panels; ++p)
    for (int layer = 0; layer < 2; ++layer) {
      const int32_t* c = corner + 8 * p + 4 * layer;
      const vec q0 = at(x, c[0]), q1 = at(x, c[1]), q2 = at(x, c[2]), q3 = at(x, c[3]);
      const double pl = planarity(q0, q1, q2, q3);
      if (pl > planarity_max) planarity_max = pl;
      const double d1 = radius - triangle_distance(centre, q0, q1, q2);
      const double d2 = radius - triangle_distance(centre, q0, q2, q3);
      if (d1 > *inside_max) *inside_max = d1;
      if (d2 > *inside_max) *inside_max = d2;
    }
  const double reported =
      m->planarity_top.max > m->planarity_bottom.max ? m->planarity_top.max : m->planarity_bottom.max;
  CAPI_CONTEXT("frame %d", frame);
  CHECK_NEAR(planarity_max, reported, 1e-15);
}

/* Loads a drape scene and finds its panel mesh (the scene's first body) and the particle of each
 * panel corner (8 a panel, body-local, into *corner: free it): NULL if it cannot. Corners welded,
 * 8 particles a panel; shared, 2 a vertex of the grid. */
static embra_world* open_drape(const char* path, int32_t expect_panels, int32_t* first, int32_t* count,
                               int32_t** corner) {
  embra_world* w = NULL;
  *corner = NULL;
  CHECK_OK(embra_world_load_file(&w, path));
  if (w == NULL) return NULL;
  const embra_body_id body = {0, 1};
  int32_t panels = 0;
  CHECK_OK(embra_panel_mesh_get_panel_count(w, body, &panels));
  CHECK_INT(panels, expect_panels);
  CHECK_OK(embra_body_get_particles(w, body, first, count));
  int64_t n = 0;
  CHECK_OK(embra_panel_mesh_get_corner_particles(w, body, NULL, 0, &n));
  CHECK_INT((int)n, 8 * expect_panels);
  *corner = malloc(sizeof(int32_t) * (size_t)(8 * expect_panels));
  if (!CHECK(*corner != NULL) || panels != expect_panels) {
    embra_world_destroy(w);
    return NULL;
  }
  CHECK_OK(embra_panel_mesh_get_corner_particles(w, body, *corner, n, &n));
  int32_t side = 1;
  while (side * side < panels) ++side;
  const int shared = panels > 1 && (*corner)[1] == (*corner)[8 + 0]; /* panel 0's corner 1 is panel 1's corner 0 */
  CHECK_INT(*count, shared ? 2 * (side + 1) * (side + 1) : 8 * expect_panels);
  for (int64_t i = 0; i < n; ++i) {
    (*corner)[i] -= *first;
    CHECK((*corner)[i] >= 0 && (*corner)[i] < *count);
  }
  return w;
}

static void test_drape(const char* dir) {
  char path[4096];
  snprintf(path, sizeof path, "%s/poq_drape.json", dir);
  const embra_body_id body = {0, 1};
  const int32_t panels = 16;
  int32_t first = 0, count = 0;
  int32_t* corner = NULL;
  embra_world* w = open_drape(path, panels, &first, &count, &corner);
  if (w == NULL) return;
  /* The scene's objects through the id lists: one body, its four corner pins (each on a particle
   * sitting at its target before any step) and the sphere where the scene puts it. */
  embra_body_id bodies[2];
  embra_pin_id pins[8];
  embra_collider_id ball[2];
  int32_t n_ids = 0;
  CHECK_OK(embra_world_get_bodies(w, bodies, 2, &n_ids));
  CHECK_INT(n_ids, 1);
  CHECK(bodies[0].index == body.index && bodies[0].generation == body.generation);
  CHECK_OK(embra_world_get_pins(w, pins, 8, &n_ids));
  CHECK_INT(n_ids, 4);
  for (int i = 0; i < n_ids; ++i) {
    int32_t particle = -1;
    double target[3], xp[3];
    CHECK_OK(embra_pin_get_particle(w, pins[i], &particle));
    CHECK_OK(embra_pin_get_target(w, pins[i], target));
    CHECK_OK(embra_world_get_positions(w, xp, 3, particle, 1));
    CHECK(xp[0] == target[0] && xp[1] == target[1] && xp[2] == target[2]);
  }
  CHECK_OK(embra_world_get_colliders(w, ball, 2, &n_ids));
  CHECK_INT(n_ids, 1);
  double ball_at[3], ball_rot[4];
  CHECK_OK(embra_collider_get_transform(w, ball[0], ball_at, ball_rot));
  CHECK(ball_at[0] == 0.3 && ball_at[1] == 0.2 && ball_at[2] == -1.45);
  CHECK(ball_rot[0] == 1.0 && ball_rot[1] == 0.0 && ball_rot[2] == 0.0 && ball_rot[3] == 0.0);
  double ball_off = 0.0; /* the largest distance of the read-back sphere from its scripted path */
  embra_tolerances tol;
  CHECK_OK(embra_world_get_tolerances(w, &tol));
  CHECK_NEAR(tol.unit_scale, 1250.0, 0.0);
  CHECK_NEAR(tol.thickness.target, 5e-5, 0.0);
  double* x = malloc(sizeof(double) * 3 * (size_t)count);
  if (!CHECK(x != NULL)) {
    free(corner);
    embra_world_destroy(w);
    return;
  }
  const double radius = 1.0;
  double worst_inside = 0.0;
  int settled_from = -1, back_from = -1;
  embra_panel_metrics at100;
  memset(&at100, 0, sizeof at100);
  for (int f = 1; f <= 300; ++f) {
    const embra_status st = embra_world_step(w);
    CHECK_OK(st);
    if (st != EMBRA_OK) break;
    embra_step_report r;
    embra_panel_metrics m;
    CHECK_OK(embra_world_get_report(w, &r));
    CHECK_OK(embra_panel_mesh_get_metrics(w, body, NULL, &m));
    CHECK_OK(embra_world_get_positions(w, x, 3 * (int64_t)count, first, count));
    if (f <= 120) {
      if (r.settled && settled_from < 0) settled_from = f;
      if (!r.settled) settled_from = -1;
    }
    if (f == 100) at100 = m;
    if (f >= 180) {
      if (m.within_tolerance && back_from < 0) back_from = f;
      if (!m.within_tolerance) back_from = -1;
    }
    const vec centre = sphere_centre(f);
    CHECK_OK(embra_collider_get_transform(w, ball[0], ball_at, ball_rot));
    for (int k = 0; k < 3; ++k) {
      const double off = fabs(ball_at[k] - (k == 0 ? centre.x : k == 1 ? centre.y : centre.z));
      if (off > ball_off) ball_off = off;
    }
    panel_checks(x, corner, panels, centre, radius, &m, f, &worst_inside);
  }
  CAPI_CONTEXT("%s", "");
  printf(
      "drape: settled from frame %d; at frame 100 thickness %.3e, planarity %.3e / %.3e, miter %.3e; "
      "within tolerance again from frame %d; deepest face inside the sphere %.3e\n",
      settled_from, at100.thickness.max, at100.planarity_top.max, at100.planarity_bottom.max, at100.miter.max,
      back_from, worst_inside);
  CHECK(settled_from > 0 && settled_from <= 100);
  CHECK(at100.thickness.max <= 5e-5);
  CHECK(at100.planarity_top.max <= 1e-6);
  CHECK(at100.planarity_bottom.max <= 1e-6);
  CHECK(at100.miter.max <= 1e-3);
  CHECK(back_from > 0 && back_from <= 210);
  CHECK(worst_inside <= 1e-6);
  CHECK(ball_off <= 1e-12);
  /* Per-vertex fields: one value per particle, none above the reported max. */
  double field[128];
  int64_t n = 0;
  CHECK_OK(embra_panel_mesh_get_vertex_errors(w, body, EMBRA_PANEL_METRIC_MITER, field, 128, &n));
  CHECK_INT(n, 128);
  embra_panel_metrics m;
  CHECK_OK(embra_panel_mesh_get_metrics(w, body, NULL, &m));
  double top = 0.0;
  for (int i = 0; i < 128; ++i)
    if (field[i] > top) top = field[i];
  CHECK_NEAR(top, m.miter.max, 0.0);
  /* Cut list: JSON through the two-call pattern. */
  int64_t len = 0;
  CHECK_OK(embra_panel_mesh_export_cuts(w, body, EMBRA_CUTS_JSON, NULL, 0, &len));
  CHECK(len > 100);
  char small[8];
  CHECK_STATUS(embra_panel_mesh_export_cuts(w, body, EMBRA_CUTS_JSON, small, 8, &len), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_STATUS(embra_panel_mesh_export_cuts(w, body, 7, NULL, 0, &len), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_panel_mesh_get_vertex_errors(w, body, 9, NULL, 0, &n), EMBRA_ERROR_INVALID_ARGUMENT);
  free(x);
  free(corner);
  embra_world_destroy(w);
}

static void test_large(const char* path, int32_t panels) {
  const embra_body_id body = {0, 1};
  int32_t first = 0, count = 0;
  int32_t* corner = NULL;
  embra_world* w = open_drape(path, panels, &first, &count, &corner);
  if (w == NULL) return;
  double* x = malloc(sizeof(double) * 3 * (size_t)count);
  if (!CHECK(x != NULL)) {
    free(corner);
    embra_world_destroy(w);
    return;
  }
  double worst_inside = 0.0;
  int settled_from = -1, within_from = -1;
  embra_panel_metrics m;
  memset(&m, 0, sizeof m);
  embra_step_report r;
  memset(&r, 0, sizeof r);
  for (int f = 1; f <= 300; ++f) {
    const embra_status st = embra_world_step(w);
    CHECK_OK(st);
    if (st != EMBRA_OK) break;
    CHECK_OK(embra_world_get_report(w, &r));
    CHECK_OK(embra_panel_mesh_get_metrics(w, body, NULL, &m));
    CHECK_OK(embra_world_get_positions(w, x, 3 * (int64_t)count, first, count));
    if (r.settled && settled_from < 0) settled_from = f;
    if (!r.settled) settled_from = -1;
    const int within =
        m.thickness.max <= 5e-5 && m.planarity_top.max <= 1e-6 && m.planarity_bottom.max <= 1e-6 && m.miter.max <= 1e-3;
    if (within && within_from < 0) within_from = f;
    if (!within) within_from = -1;
    panel_checks(x, corner, panels, sphere_centre(f), 1.0, &m, f, &worst_inside);
  }
  CAPI_CONTEXT("%s", "");
  printf(
      "%s: settled from frame %d; within the issue's three tolerances from frame %d; at frame 300 thickness "
      "%.3e, planarity %.3e / %.3e, miter %.3e, corner off plane %.3e; deepest face inside the sphere %.3e\n",
      path, settled_from, within_from, m.thickness.max, m.planarity_top.max, m.planarity_bottom.max, m.miter.max,
      m.corner_distance_top.max > m.corner_distance_bottom.max ? m.corner_distance_top.max
                                                               : m.corner_distance_bottom.max,
      worst_inside);
  /* The welds' error, from positions alone: grid panel p = (column i, row j) has corners (i, j),
   * (i + 1, j), (i + 1, j + 1), (i, j + 1); every copy of a mesh vertex against every other. */
  int32_t side = 1;
  while (side * side < panels) ++side;
  double own_gap = 0.0;
  for (int32_t p = 0; p < panels; ++p)
    for (int32_t q = p + 1; q < panels; ++q)
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l) {
          const int32_t vi = p % side + (k == 1 || k == 2), vj = p / side + (k >= 2);
          const int32_t ui = q % side + (l == 1 || l == 2), uj = q / side + (l >= 2);
          if (vi != ui || vj != uj) continue;
          for (int layer = 0; layer < 2; ++layer) {
            const vec d = sub(at(x, corner[8 * p + 4 * layer + k]), at(x, corner[8 * q + 4 * layer + l]));
            if (sqrt(dot(d, d)) > own_gap) own_gap = sqrt(dot(d, d));
          }
        }
  embra_metric_summary gap;
  CHECK_OK(embra_panel_mesh_get_corner_gap(w, body, &gap));
  printf("corner gap (welds) at frame 300: %.3e (own %.3e), rms %.3e over %lld vertices\n", gap.max, own_gap, gap.rms,
         (long long)gap.count);
  CHECK_NEAR(gap.max, own_gap, 0.0);
  CHECK_INT((int)gap.count, (side + 1) * (side + 1) - 4);
  CHECK(r.settled);
  CHECK(m.within_tolerance); /* the scene's tolerance document: corner off plane too */
  CHECK(m.thickness.max <= 5e-5);
  CHECK(m.planarity_top.max <= 1e-6);
  CHECK(m.planarity_bottom.max <= 1e-6);
  CHECK(m.miter.max <= 1e-3);
  CHECK(worst_inside <= 1e-6);
  free(x);
  free(corner);
  embra_world_destroy(w);
}

/* The builder through the C ABI: a grid, and refused calls that create nothing. */
static void test_create(void) {
  embra_world* w = NULL;
  CHECK_OK(embra_world_create(&w, NULL));
  embra_panel_mesh_def d = embra_default_panel_mesh_def();
  embra_body_id body;
  int32_t first = -1;
  embra_world_counts c;
  d.thickness = -1.0;
  CHECK_STATUS(embra_panel_mesh_create(w, &d, &body, &first), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_panel_mesh_def();
  d.version = 99;
  CHECK_STATUS(embra_panel_mesh_create(w, &d, &body, &first), EMBRA_ERROR_VERSION);
  d = embra_default_panel_mesh_def();
  d.panel_size = NAN;
  CHECK_STATUS(embra_panel_mesh_create(w, &d, &body, &first), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_panel_mesh_def();
  d.vertex_count = 4;
  d.quad_count = 1;
  d.positions = NULL;
  CHECK_STATUS(embra_panel_mesh_create(w, &d, &body, &first), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_panel_mesh_def();
  CHECK_INT(d.precision, EMBRA_PANEL_PRECISION_FULL);
  d.precision = EMBRA_PANEL_PRECISION_SINGLE + 1;
  CHECK_STATUS(embra_panel_mesh_create(w, &d, &body, &first), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "precision");
  d.precision = -1;
  CHECK_STATUS(embra_panel_mesh_create(w, &d, &body, &first), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_OK(embra_world_get_counts(w, &c));
  CHECK_INT(c.particles, 0);
  CHECK_INT(c.bodies, 0);
  d = embra_default_panel_mesh_def();
  d.grid_columns = 2;
  d.grid_rows = 3;
  d.pins = EMBRA_PANEL_PINS_TOP_AND_BOTTOM_CORNERS;
  CHECK_OK(embra_panel_mesh_create(w, &d, &body, &first));
  CHECK_OK(embra_world_get_counts(w, &c));
  CHECK_INT(c.particles, 48);
  CHECK_INT(c.pins, 8);
  embra_panel_metrics m;
  CHECK_OK(embra_panel_mesh_get_metrics(w, body, NULL, &m));
  CHECK_INT(m.within_tolerance, 1);
  CHECK_INT((int)m.miter.count, 2 * 4 + 3 * 3);
  embra_tolerances t = embra_default_tolerances();
  t.thickness.target = 2.0;
  CHECK_STATUS(embra_world_set_tolerances(w, &t), EMBRA_ERROR_INVALID_ARGUMENT); /* target above max */
  t = embra_default_tolerances();
  t.miter.target = 0.5;
  t.miter.max = 1.0;
  CHECK_OK(embra_world_set_tolerances(w, &t));
  embra_tolerances back;
  CHECK_OK(embra_world_get_tolerances(w, &back));
  CHECK_NEAR(back.miter.target, 0.5, 0.0);
  embra_body_id not_panels;
  embra_body_def bd = embra_default_body_def();
  const double tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int32_t idx[3] = {0, 1, 2};
  bd.vertex_count = 3;
  bd.positions = tri;
  bd.triangle_count = 1;
  bd.triangles = idx;
  CHECK_OK(embra_body_create(w, &bd, &not_panels, NULL));
  CHECK_STATUS(embra_panel_mesh_get_metrics(w, not_panels, NULL, &m), EMBRA_ERROR_INVALID_ARGUMENT);
  embra_metric_summary gap;
  CHECK_STATUS(embra_panel_mesh_get_corner_gap(w, not_panels, &gap), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_panel_mesh_get_corner_gap(w, body, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_panel_mesh_get_corner_gap(NULL, body, &gap), EMBRA_ERROR_INVALID_ARGUMENT);
  const embra_body_id stale_body = {body.index, body.generation + 1};
  CHECK_STATUS(embra_panel_mesh_get_corner_gap(w, stale_body, &gap), EMBRA_ERROR_STALE_ID);
  CHECK_OK(embra_panel_mesh_get_corner_gap(w, body, &gap));
  CHECK_NEAR(gap.max, 0.0, 0.0);        /* as built: every copy of a vertex where the grid puts it */
  CHECK_INT((int)gap.count, 3 * 4 - 4); /* a 2 x 3 grid of panels: 12 mesh vertices, 4 of one panel */
  /* The metrics follow the positions however often they are read: the first panel's four top
   * corners lifted by 1 mm stand 1 mm above their copies on the other panels (three of them are
   * shared); put back, they meet again. */
  double top4[12], lifted[12];
  CHECK_OK(embra_world_get_positions(w, top4, 12, first, 4));
  for (int k = 0; k < 12; ++k) lifted[k] = top4[k] + (k % 3 == 2 ? 1e-3 : 0.0);
  for (int round = 0; round < 2; ++round) {
    CHECK_OK(embra_world_set_positions(w, lifted, first, 4));
    CHECK_OK(embra_panel_mesh_get_metrics(w, body, NULL, &m));
    CHECK_OK(embra_panel_mesh_get_corner_gap(w, body, &gap));
    CHECK_NEAR(gap.max, 1e-3, 1e-12);
    double errors[48];
    int64_t n = 0;
    CHECK_OK(embra_panel_mesh_get_vertex_errors(w, body, EMBRA_PANEL_METRIC_THICKNESS, errors, 48, &n));
    CHECK_NEAR(errors[0], 1e-3, 1e-12); /* a lifted top corner: 1 mm off its panel's thickness */
    CHECK_OK(embra_world_set_positions(w, top4, first, 4));
    CHECK_OK(embra_panel_mesh_get_corner_gap(w, body, &gap));
    CHECK_NEAR(gap.max, 0.0, 0.0);
    CHECK_OK(embra_panel_mesh_get_vertex_errors(w, body, EMBRA_PANEL_METRIC_THICKNESS, errors, 48, &n));
    CHECK_NEAR(errors[0], 0.0, 1e-15);
  }
  embra_world_destroy(w);
}

/* A host that sets what a scene action drives takes over: the sphere set by hand while its path is
 * under way stays where the host put it, a pin target set by hand is not pulled back along the
 * scene's path, and gravity set by hand holds. Without the host's calls the scene moves them. */
static void test_host_takes_over(const char* dir) {
  char path[4096];
  snprintf(path, sizeof path, "%s/poq_drape.json", dir);
  embra_world* w = NULL;
  CHECK_OK(embra_world_load_file(&w, path));
  if (w == NULL) return;
  embra_pin_id pins[4];
  embra_collider_id ball;
  int32_t n = 0;
  CHECK_OK(embra_world_get_pins(w, pins, 4, &n));
  CHECK_OK(embra_world_get_colliders(w, &ball, 1, &n));
  const double held[3] = {-1.5, -1.6, 0.05}, at[3] = {0.2, 0.1, -1.5}, rot[4] = {1, 0, 0, 0};
  double got[3], q[4];
  for (int f = 1; f <= 5; ++f) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_pin_set_target(w, pins[0], held)); /* the scene draws it to (-1.44, -1.6, 0) by frame 30 */
  for (int f = 6; f <= 130; ++f) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_pin_get_target(w, pins[0], got));
  CHECK(got[0] == held[0] && got[1] == held[1] && got[2] == held[2]);
  CHECK_OK(embra_pin_get_target(w, pins[1], got)); /* untouched: where its path ends */
  CHECK(got[0] == 1.44 && got[1] == -1.6 && got[2] == 0.0);
  CHECK_OK(embra_collider_get_transform(w, ball, got, q)); /* on its path: 10 of 60 frames along */
  CHECK_NEAR(got[0], 0.3 - 0.6 * 10.0 / 60.0, 1e-12);
  CHECK_OK(embra_collider_set_transform(w, ball, at, rot));
  for (int f = 131; f <= 200; ++f) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_collider_get_transform(w, ball, got, q));
  CHECK(got[0] == at[0] && got[1] == at[1] && got[2] == at[2]);
  embra_world_destroy(w);
}

int main(int argc, char** argv) {
  if (argc == 4 && strcmp(argv[1], "--large") == 0) {
    capi_test_name = "test_large";
    test_large(argv[2], atoi(argv[3]));
    return capi_test_finish();
  }
  if (argc != 2) {
    fprintf(stderr, "usage: test_capi_panels EXAMPLES_DIR\n       test_capi_panels --large SCENE PANELS\n");
    return 2;
  }
  RUN(test_create);
  capi_test_name = "test_drape";
  test_drape(argv[1]);
  capi_test_name = "test_host_takes_over";
  test_host_takes_over(argv[1]);
  return capi_test_finish();
}
