/* The conical dome's second stage: panels with an exact face offset.
 *
 * Stage 1 is the scene examples/conical_dome.json (`embra run` runs it alone): a quad grid on a
 * dome, every quad held planar and every interior vertex held conical. This program runs it as
 * `embra run` would (its own frames), then builds a panel mesh (top layer = the form-found quads,
 * a thickness of 0.02 m) from the result and measures it at frame 0, before a single step:
 *
 *   - the conical defect |(a1 + a3) - (a2 + a4)| of the face angles at every interior vertex,
 *     computed here from the positions and the quads (the planarity constraints' operands), and
 *     as the panel metrics measure it: both below 1e-8 rad;
 *   - the panel metrics (embra_panel_mesh_get_metrics): thickness error, corner distance from the
 *     plane of the other three (top and bottom: planarity) and miter twist, each below 1e-8 of the
 *     mean edge; the library builds the bottom layer by offsetting each face plane, which meets
 *     its neighbours along the edges' joint planes only when the mesh is conical.
 *
 * Prints the figures; exits 0 when every check holds, 1 when one fails, 2 on an embra error.
 *
 * usage: conical_panels [SCENE [PANELS.obj]]   (default: conical_dome.json in the working folder;
 *        PANELS.obj: the panel mesh written as OBJ, both layers) */
#include <embra/embra.h>

#include <math.h>
#include <stdio.h>
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
static double dot(vec a, vec b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
static double norm(vec a) {
  return sqrt(dot(a, a));
}
static double angle(vec a, vec b) {
  vec c = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  return atan2(norm(c), dot(a, b));
}

static int failures = 0;
static void check(int ok, const char* what, double value, double bound) {
  printf("%s %-58s %.3g (bound %.3g)\n", ok ? "ok  " : "FAIL", what, value, bound);
  if (!ok) ++failures;
}

#define TRY(call)                                                                                \
  do {                                                                                           \
    embra_status s_ = (call);                                                                    \
    if (s_ != EMBRA_OK) {                                                                        \
      fprintf(stderr, "%s: %s: %s\n", #call, embra_status_name(s_), embra_last_error_message()); \
      exit(2);                                                                                   \
    }                                                                                            \
  } while (0)

/* The conical defect at vertex v: its quads walked round it (quad q's corner c has the edges
 * v -> q[c+1] and v -> q[c-1]; the next quad round is the one whose v -> q[c'+1] is that
 * v -> q[c-1]), the face angles alternately added and subtracted. -1 when v is not an interior
 * vertex of valence 4. */
static double conical_defect(const double* x, const int32_t* quads, int32_t quad_count, int32_t v) {
  int32_t q[8], c[8], n = 0;
  for (int32_t k = 0; k < quad_count && n < 8; ++k)
    for (int32_t m = 0; m < 4; ++m)
      if (quads[4 * k + m] == v) {
        q[n] = k;
        c[n++] = m;
      }
  if (n != 4) return -1.0;
  double sum = 0.0;
  int32_t k = 0;
  for (int32_t step = 0; step < 4; ++step) {
    const int32_t* f = quads + 4 * q[k];
    const int32_t next = f[(c[k] + 1) % 4], prev = f[(c[k] + 3) % 4];
    sum += (step % 2 ? -1.0 : 1.0) * angle(sub(at(x, next), at(x, v)), sub(at(x, prev), at(x, v)));
    int32_t found = -1;
    for (int32_t j = 0; j < 4; ++j)
      if (quads[4 * q[j] + (c[j] + 1) % 4] == prev) found = j;
    if (found < 0) return -1.0; /* on the boundary */
    k = found;
  }
  return k == 0 ? fabs(sum) : -1.0;
}

/* The largest conical defect over the interior valence-4 vertices (*vertices counts them). */
static double max_defect(const double* x, int32_t n, const int32_t* quads, int32_t quad_count, int32_t* vertices) {
  double worst = 0.0;
  *vertices = 0;
  for (int32_t v = 0; v < n; ++v) {
    const double d = conical_defect(x, quads, quad_count, v);
    if (d < 0.0) continue;
    ++*vertices;
    if (d > worst) worst = d;
  }
  return worst;
}

/* A panel mesh of thickness 0.02 m on the top mesh (x, quads), measured at frame 0. */
static embra_panel_metrics panel_metrics(const double* x, int32_t n, const int32_t* quads, int32_t quad_count,
                                         const char* obj) {
  embra_solver_def solver = embra_default_solver_def();
  embra_world* panels = NULL;
  TRY(embra_world_create(&panels, &solver));
  embra_panel_mesh_def def = embra_default_panel_mesh_def();
  def.vertex_count = n;
  def.positions = x;
  def.quads = quads;
  def.quad_count = quad_count;
  def.thickness = 0.02;
  embra_body_id body;
  TRY(embra_panel_mesh_create(panels, &def, &body, NULL));
  embra_panel_metrics m;
  TRY(embra_panel_mesh_get_metrics(panels, body, NULL, &m));
  if (obj) TRY(embra_world_write_obj(panels, obj));
  embra_world_destroy(panels);
  return m;
}

int main(int argc, char** argv) {
  const char* scene = argc > 1 ? argv[1] : "conical_dome.json";
  TRY(embra_check_abi(EMBRA_ABI_VERSION));
  embra_world* world = NULL;
  TRY(embra_world_load_file(&world, scene));
  embra_world_counts counts;
  TRY(embra_world_get_counts(world, &counts));
  const int32_t n = counts.particles;
  double* x0 = malloc(sizeof *x0 * 3 * (size_t)n);
  double* x = malloc(sizeof *x * 3 * (size_t)n);
  if (!x0 || !x) return 2;
  TRY(embra_world_get_positions(world, x0, 3 * (int64_t)n, 0, n));
  int64_t frames = 0;
  TRY(embra_world_get_scene_frames(world, &frames));
  for (int64_t f = 0; f < frames; ++f) TRY(embra_world_step(world));
  TRY(embra_world_get_positions(world, x, 3 * (int64_t)n, 0, n));
  /* The quads: the planarity constraints' operands, in the order the scene lists them. */
  const embra_group_id group = {0, 0};
  int32_t quad_count = 0;
  TRY(embra_group_get_constraint_count(world, group, EMBRA_CONSTRAINT_PLANARITY, &quad_count, NULL));
  int32_t* quads = malloc(sizeof *quads * 4 * (size_t)(quad_count > 0 ? quad_count : 1));
  if (!quads) return 2;
  double edge = 0.0;
  for (int32_t k = 0; k < quad_count; ++k) {
    embra_constraint_def d;
    TRY(embra_constraint_get(world, group, EMBRA_CONSTRAINT_PLANARITY, k, &d));
    for (int m = 0; m < 4; ++m) quads[4 * k + m] = d.particles[m];
    for (int m = 0; m < 4; ++m) edge += norm(sub(at(x, d.particles[m]), at(x, d.particles[(m + 1) % 4])));
  }
  edge /= 4.0 * quad_count;
  int32_t vertices = 0;
  const double before = max_defect(x0, n, quads, quad_count, &vertices);
  const double defect = max_defect(x, n, quads, quad_count, &vertices);
  double moved = 0.0;
  for (int32_t v = 0; v < n; ++v) {
    const double d = norm(sub(at(x, v), at(x0, v)));
    if (d > moved) moved = d;
  }
  embra_step_report report;
  TRY(embra_world_get_report(world, &report));
  printf("%s: %d vertices, %d quads, mean edge %.6f m, after %lld frames (max speed %.3g m/s)\n", scene, n, quad_count,
         edge, (long long)frames, report.max_speed);

  /* Stage 2: the panels, measured before any step; and, for comparison, panels on the dome's grid
   * as it was before form finding (planar quads, but not conical). */
  const embra_panel_metrics m = panel_metrics(x, n, quads, quad_count, argc > 2 ? argv[2] : NULL);
  const embra_panel_metrics m0 = panel_metrics(x0, n, quads, quad_count, NULL);
  printf(
      "before form finding: conical defect %.3g rad (panel metric %.3g), panel miter twist %.3g m, thickness error "
      "%.3g m\n",
      before, m0.conical.max, m0.miter.max, m0.thickness.max);
  printf("form finding moved a vertex %.4f m at most (%.3f of the mean edge)\n", moved, moved / edge);

  const double bound = 1e-8 * edge;
  check(vertices == 49, "interior vertices of valence 4 (a 9 x 9 grid: 49)", vertices, 49);
  check(before > 1e-3, "conical defect before form finding (rad), far from conical", before, 1e-3);
  check(moved < 0.25 * edge, "largest move of a vertex, of the mean edge (stays on its dome)", moved / edge, 0.25);
  check(defect < 1e-8, "conical defect, from the positions (rad)", defect, 1e-8);
  check(m.conical.count == vertices && m.conical.max < 1e-8, "conical defect, panel metric (rad)", m.conical.max, 1e-8);
  check(m.thickness.max < bound, "thickness error (m)", m.thickness.max, bound);
  check(m.corner_distance_top.max < bound, "corner off the plane of the other three, top (m)",
        m.corner_distance_top.max, bound);
  check(m.corner_distance_bottom.max < bound, "corner off the plane of the other three, bottom (m)",
        m.corner_distance_bottom.max, bound);
  check(m.miter.max < bound, "miter twist (m)", m.miter.max, bound);
  check(m.within_tolerance == 1, "every metric within the default tolerances", m.within_tolerance, 1);

  embra_world_destroy(world);
  free(quads);
  free(x);
  free(x0);
  return failures ? 1 : 0;
}
