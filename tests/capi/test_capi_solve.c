/* Residuals by kind, each in its own unit: a hanging cloth of hard stretch constraints and bending
 * hinges, whose distance residual is computed here from the positions alone (| |xi - xj| - rest |,
 * the rests being the grid's edge lengths), and the mixed residual_max is the largest of the kinds'.
 *
 * embra_world_solve: why the stepping stopped, checked against what one can work out by hand: a
 * pendulum with no damping swings for ever with period 2 pi sqrt(L / g); a damped chain comes to
 * rest (no panel mesh: within tolerance); a panel whose four top corners are pinned off one plane
 * can never be planar and comes to rest out of tolerance, naming that panel; bad arguments are
 * refused before any step. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "capi_test.h"

static const double kPi = 3.14159265358979323846;

static int64_t frame_of(const embra_world* w) {
  embra_step_report r;
  CHECK_OK(embra_world_get_report(w, &r));
  return r.frame;
}

/* A 1 m pendulum let go 0.1 rad from the vertical, no damping: still moving, oscillating, with the
 * period of the small-angle pendulum, 2 pi sqrt(1 / 9.81) (1 + 0.1^2 / 16) = 2.0073 s. */
static void test_pendulum_oscillates(void) {
  embra_world* w = NULL;
  embra_body_def b = embra_default_body_def();
  embra_body_id body;
  embra_constraint_def c = embra_default_constraint_def();
  embra_solve_def d = embra_default_solve_def();
  embra_solve_result r;
  const double theta = 0.1;
  const double xyz[6] = {0, 0, 0, sin(theta), 0, -cos(theta)};
  const double masses[2] = {0.0, 1.0};
  const double expected = 2.0 * kPi * sqrt(1.0 / 9.81) * (1.0 + theta * theta / 16.0);
  int32_t first = -1;
  CHECK_OK(embra_world_create(&w, NULL));
  b.vertex_count = 2;
  b.positions = xyz;
  b.masses = masses;
  CHECK_OK(embra_body_create(w, &b, &body, &first));
  c.particles[0] = first;
  c.particles[1] = first + 1;
  CHECK_OK(embra_constraint_add(w, &c));
  d.max_frames = 900; /* 15 s, about 7 periods */
  CHECK_OK(embra_world_solve(w, &d, &r));
  CHECK_INT(r.outcome, EMBRA_SOLVE_OSCILLATING);
  CHECK_INT(r.frames, 900);
  CHECK_NEAR(r.period, expected, 0.01 * expected);
  CHECK_INT(r.worst_metric, -1); /* no panel mesh */
  CHECK_INT(frame_of(w), 900);
  embra_world_destroy(w);
}

/* A damped chain of 8 links between two pins: at rest within the budget, and with no panel mesh
 * that is "within tolerance"; a second call returns after hold_frames frames. */
static void test_chain_settles(void) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  embra_body_def b = embra_default_body_def();
  embra_body_id body;
  embra_solve_def d = embra_default_solve_def();
  embra_solve_result r;
  double xyz[27];
  int32_t first = -1, i;
  s.damping = 4.0;
  CHECK_OK(embra_world_create(&w, &s));
  for (i = 0; i < 9; ++i) {
    xyz[3 * i] = 0.1 * i;
    xyz[3 * i + 1] = 0.0;
    xyz[3 * i + 2] = 0.0;
  }
  b.vertex_count = 9;
  b.positions = xyz;
  CHECK_OK(embra_body_create(w, &b, &body, &first));
  for (i = 0; i < 8; ++i) {
    embra_constraint_def c = embra_default_constraint_def();
    c.particles[0] = first + i;
    c.particles[1] = first + i + 1;
    c.rest_from_current = 0;
    c.rest = 0.12;
    CHECK_OK(embra_constraint_add(w, &c));
  }
  for (i = 0; i < 9; i += 8) {
    embra_pin_def p = embra_default_pin_def();
    embra_pin_id pin;
    p.particle = first + i;
    memcpy(p.target, &xyz[3 * i], sizeof p.target);
    CHECK_OK(embra_pin_create(w, &p, &pin));
  }
  CHECK_OK(embra_world_solve(w, &d, &r));
  CHECK_INT(r.outcome, EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE);
  CHECK(r.frames >= d.hold_frames && r.frames < d.max_frames);
  CHECK_INT(frame_of(w), r.frames);
  {
    embra_step_report rep;
    CHECK_OK(embra_world_get_report(w, &rep));
    CHECK_INT(rep.settled, 1);
  }
  d.until = EMBRA_SOLVE_UNTIL_SETTLED;
  CHECK_OK(embra_world_solve(w, &d, &r));
  CHECK_INT(r.outcome, EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE);
  CHECK_INT(r.frames, d.hold_frames);
  embra_world_destroy(w);
}

/* One 0.8 m panel, its top corners hard-pinned, one of them moved 5 cm off the plane of the other
 * three: the braced, planar top quad cannot follow; the rest of the panel comes to rest and the
 * worst metric is that panel's top layer, far above its target. */
static void test_panel_out_of_tolerance(void) {
  embra_world* w = NULL;
  embra_solver_def s = embra_form_finding_solver_def();
  embra_panel_mesh_def pm = embra_default_panel_mesh_def();
  embra_body_id body;
  embra_solve_def d = embra_default_solve_def();
  embra_solve_result r;
  embra_pin_id pins[16];
  int32_t first = -1, count = 0, i;
  s.damping = 2.0;
  CHECK_OK(embra_world_create(&w, &s));
  pm.grid_columns = 1;
  pm.grid_rows = 1;
  pm.pins = EMBRA_PANEL_PINS_TOP_CORNERS;
  CHECK_OK(embra_panel_mesh_create(w, &pm, &body, &first));
  CHECK_OK(embra_world_get_pins(w, pins, 16, &count));
  CHECK_INT(count, 4);
  for (i = 0; i < count; ++i) {
    int32_t particle = -1;
    CHECK_OK(embra_pin_get_particle(w, pins[i], &particle));
    if (particle == first + 2) { /* top corner 2, across from corner 0 */
      double t[3];
      CHECK_OK(embra_pin_get_target(w, pins[i], t));
      t[2] += 0.05;
      CHECK_OK(embra_pin_set_target(w, pins[i], t));
    }
  }
  CHECK_OK(embra_world_solve(w, &d, &r));
  CHECK_INT(r.outcome, EMBRA_SOLVE_SETTLED_OUT_OF_TOLERANCE);
  CHECK(r.frames < d.max_frames);
  CHECK(r.worst_metric == EMBRA_PANEL_METRIC_PLANARITY || r.worst_metric == EMBRA_PANEL_METRIC_CORNER_DISTANCE);
  CHECK_INT(r.worst_layer, 0);
  CHECK_INT(r.worst_element, 0);
  CHECK(r.worst_body.index == body.index && r.worst_body.generation == body.generation);
  CHECK(r.worst_value > 100.0 * r.worst_target);
  {
    embra_panel_metrics m;
    CHECK_OK(embra_panel_mesh_get_metrics(w, body, NULL, &m));
    CHECK_INT(m.within_tolerance, 0);
    if (r.worst_metric == EMBRA_PANEL_METRIC_PLANARITY)
      CHECK_NEAR(r.worst_value, m.planarity_top.max, 0.0);
    else
      CHECK_NEAR(r.worst_value, m.corner_distance_top.max, 0.0);
  }
  embra_world_destroy(w);
}

static void test_residuals_by_kind(void) {
  enum { N = 6 };
  const double step = 0.2;
  double xyz[3 * N * N];
  int32_t tris[3 * 2 * (N - 1) * (N - 1)];
  embra_world* w = NULL;
  embra_body_def bd = embra_default_body_def();
  embra_body_id cloth;
  embra_kind_residual res[16];
  embra_step_report report;
  int32_t first = -1, t = 0, count = -1, i, j;
  double by_hand = 0.0, x[3 * N * N], biggest = 0.0;
  for (i = 0; i < N; ++i)
    for (j = 0; j < N; ++j) {
      xyz[3 * (i * N + j)] = step * j;
      xyz[3 * (i * N + j) + 1] = step * i;
      xyz[3 * (i * N + j) + 2] = 0.0;
    }
  for (i = 0; i + 1 < N; ++i)
    for (j = 0; j + 1 < N; ++j) {
      const int32_t v = i * N + j;
      tris[t++] = v, tris[t++] = v + 1, tris[t++] = v + N + 1;
      tris[t++] = v, tris[t++] = v + N + 1, tris[t++] = v + N;
    }
  CHECK_OK(embra_world_create(&w, NULL));
  bd.vertex_count = N * N;
  bd.positions = xyz;
  bd.triangle_count = 2 * (N - 1) * (N - 1);
  bd.triangles = tris;
  CHECK_OK(embra_body_create(w, &bd, &cloth, &first));
  for (i = 0; i < 2; ++i) {
    embra_pin_def p = embra_default_pin_def();
    embra_pin_id pin;
    p.particle = first + i * (N - 1);
    memcpy(p.target, &xyz[3 * i * (N - 1)], sizeof p.target);
    CHECK_OK(embra_pin_create(w, &p, &pin));
  }
  CHECK_OK(embra_world_get_residuals(w, NULL, 0, &count));
  CHECK_INT(count, 0); /* nothing measured before the first step */
  for (i = 0; i < 30; ++i) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_residuals(w, NULL, 0, &count));
  CHECK_INT(count, 3); /* distance, dihedral, pins (the automatic tethers only bound a stretch) */
  CHECK_STATUS(embra_world_get_residuals(w, res, 2, &count), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_OK(embra_world_get_residuals(w, res, 16, &count));
  CHECK_INT(count, 3);
  CHECK_INT(res[0].kind, EMBRA_CONSTRAINT_DISTANCE);
  CHECK_INT(res[1].kind, EMBRA_CONSTRAINT_DIHEDRAL);
  CHECK_INT(res[2].kind, EMBRA_RESIDUAL_PINS);
  CHECK_INT(res[0].count, 2 * N * (N - 1) + (N - 1) * (N - 1));       /* rows, columns, diagonals */
  CHECK_INT(res[1].count, 2 * (N - 1) * (N - 2) + (N - 1) * (N - 1)); /* interior edges */
  CHECK_INT(res[2].count, 2);
  CHECK_STR(embra_residual_unit(EMBRA_CONSTRAINT_DISTANCE), "m");
  CHECK_STR(embra_residual_unit(EMBRA_CONSTRAINT_DIHEDRAL), "rad");
  CHECK_STR(embra_residual_unit(EMBRA_CONSTRAINT_TET_VOLUME), "m^3");
  CHECK_STR(embra_residual_unit(EMBRA_RESIDUAL_CONTACTS), "m");
  CHECK(embra_residual_unit(99) == NULL);
  CHECK_STR(embra_residual_name(EMBRA_CONSTRAINT_PLANE_OFFSET), "plane_offset");
  CHECK_STR(embra_residual_name(EMBRA_RESIDUAL_PINS), "pins");
  CHECK_STR(embra_residual_name(EMBRA_RESIDUAL_CONTACTS), "contacts");
  CHECK(embra_residual_name(-3) == NULL);
  /* The distance residual from the positions: every edge hard, rest = its grid length. */
  CHECK_OK(embra_world_get_positions(w, x, 3 * N * N, first, N * N));
  for (t = 0; t < 2 * (N - 1) * (N - 1); ++t)
    for (j = 0; j < 3; ++j) {
      const int32_t a = tris[3 * t + j], b = tris[3 * t + (j + 1) % 3];
      const double dx = x[3 * a] - x[3 * b], dy = x[3 * a + 1] - x[3 * b + 1], dz = x[3 * a + 2] - x[3 * b + 2];
      const double rx = xyz[3 * a] - xyz[3 * b], ry = xyz[3 * a + 1] - xyz[3 * b + 1];
      const double r = fabs(sqrt(dx * dx + dy * dy + dz * dz) - sqrt(rx * rx + ry * ry));
      if (r > by_hand) by_hand = r;
    }
  CHECK(by_hand > 0.0);
  CHECK_NEAR(res[0].max, by_hand, 1e-15);
  CHECK(res[0].rms <= res[0].max && res[0].rms > 0.0);
  CHECK(res[2].max < 1e-12); /* hard pins hold */
  CHECK_OK(embra_world_get_report(w, &report));
  for (i = 0; i < count; ++i)
    if (res[i].max > biggest) biggest = res[i].max;
  CHECK_NEAR(report.residual_max, biggest, 0.0);
  CHECK_STATUS(embra_world_get_residuals(NULL, res, 16, &count), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_residuals(w, res, 16, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_residuals(w, res, -1, &count), EMBRA_ERROR_INVALID_ARGUMENT);
  embra_world_destroy(w);
}

/* A cable of 10 hard links hanging from one end; that end held by two soft pins (1e-3 m/N) to
 * targets 0.5 m to either side, each pin in its own group. The two groups pull the end straight apart
 * with 0.5 m / 1e-3 m/N = 500 N each (the cable's weight, 9.81 N, tilts them a little), so that pair
 * is the first conflict, about 500 N on one particle, and the two pins are the worst constraints
 * (stretched 0.5 m at 500 N); the cable's hard links, which carry 10 N, come after. */
static void test_fighting_groups(void) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  embra_body_def bd = embra_default_body_def();
  embra_body_id body;
  embra_group_def gd = embra_default_group_def();
  embra_group_id ga, gb;
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id pa, pb;
  embra_group_conflict conflicts[8];
  embra_constraint_residual worst[4];
  double xyz[33], res[16];
  int32_t first = -1, n = -1, i;
  int64_t count = -1;
  s.damping = 5.0;
  CHECK_OK(embra_world_create(&w, &s));
  for (i = 0; i < 11; ++i) {
    xyz[3 * i] = 0.0;
    xyz[3 * i + 1] = 0.0;
    xyz[3 * i + 2] = -0.1 * i;
  }
  bd.vertex_count = 11;
  bd.positions = xyz;
  bd.material.mass = 1.0;
  CHECK_OK(embra_body_create(w, &bd, &body, &first));
  for (i = 0; i < 10; ++i) {
    embra_constraint_def c = embra_default_constraint_def();
    c.particles[0] = first + i;
    c.particles[1] = first + i + 1;
    CHECK_OK(embra_constraint_add(w, &c));
  }
  gd.order = 1;
  CHECK_OK(embra_group_create(w, &gd, &ga));
  gd.order = 2;
  CHECK_OK(embra_group_create(w, &gd, &gb));
  pd.particle = first;
  pd.compliance = 1e-3;
  pd.target[0] = -0.5;
  pd.group = ga;
  CHECK_OK(embra_pin_create(w, &pd, &pa));
  pd.target[0] = 0.5;
  pd.group = gb;
  CHECK_OK(embra_pin_create(w, &pd, &pb));
  for (i = 0; i < 300; ++i) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_group_conflicts(w, NULL, 0, &n));
  CHECK(n >= 1);
  CHECK_OK(embra_world_get_group_conflicts(w, conflicts, 8, &n));
  CHECK(conflicts[0].a.index == ga.index && conflicts[0].b.index == gb.index);
  CHECK_NEAR(conflicts[0].force, 500.0, 10.0);
  CHECK_INT(conflicts[0].particles, 1);
  for (i = 1; i < n; ++i) CHECK(conflicts[i].force < 0.1 * conflicts[0].force);
  CHECK_OK(embra_world_get_worst_constraints(w, worst, 4, &n));
  CHECK_INT(n, 4);
  CHECK_INT(worst[0].kind, EMBRA_RESIDUAL_PINS);
  CHECK_INT(worst[1].kind, EMBRA_RESIDUAL_PINS);
  CHECK((worst[0].pin.index == pa.index && worst[1].pin.index == pb.index) ||
        (worst[0].pin.index == pb.index && worst[1].pin.index == pa.index));
  CHECK_INT(worst[0].particles[0], first);
  CHECK_INT(worst[0].particles[1], -1);
  CHECK_NEAR(worst[0].violation, 0.5, 0.02);
  CHECK_NEAR(worst[0].force, 500.0, 10.0);
  /* Nearly converged (one iteration a substep: 1.2 % left): the residual does not show the fight. */
  CHECK(worst[0].residual < 0.02 * worst[0].violation);
  CHECK_INT(worst[2].kind, EMBRA_CONSTRAINT_DISTANCE);
  CHECK(worst[2].force < 10.0 && worst[2].index >= 0 && worst[2].index < 10);
  /* The whole ranking (10 links and 2 pins): violation x force never rising, its first four the
     four above. */
  {
    embra_constraint_residual all[16];
    int32_t m = 0;
    CHECK_OK(embra_world_get_worst_constraints(w, all, 16, &m));
    CHECK_INT(m, 12);
    for (i = 1; i < m; ++i) CHECK(all[i].violation * all[i].force <= all[i - 1].violation * all[i - 1].force);
    for (i = 0; i < 4; ++i)
      CHECK(all[i].kind == worst[i].kind && all[i].index == worst[i].index && all[i].pin.index == worst[i].pin.index &&
            all[i].violation == worst[i].violation);
  }
  /* Per constraint, in the order added: the hard links' residuals. */
  {
    embra_group_id def_group;
    CHECK_OK(embra_world_default_group(w, &def_group));
    CHECK_OK(embra_group_get_residuals(w, def_group, EMBRA_CONSTRAINT_DISTANCE, NULL, 0, &count));
    CHECK_INT(count, 10);
    CHECK_OK(embra_group_get_residuals(w, def_group, EMBRA_CONSTRAINT_DISTANCE, res, 16, &count));
    /* Under 2e-3 of the 0.1 m link; the top one, next to the pins' 1,000 N, holds the most. */
    for (i = 0; i < 10; ++i) CHECK(res[i] >= 0.0 && res[i] < 2e-4);
    for (i = 1; i < 10; ++i) CHECK(res[i] < res[0]);
    CHECK_STATUS(embra_group_get_residuals(w, def_group, 42, res, 16, &count), EMBRA_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(embra_group_get_residuals(w, def_group, EMBRA_CONSTRAINT_DISTANCE, res, 5, &count),
                 EMBRA_ERROR_BUFFER_TOO_SMALL);
  }
  CHECK_STATUS(embra_world_get_worst_constraints(w, NULL, 4, &n), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_group_conflicts(w, conflicts, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  embra_world_destroy(w);
}

static void test_refusals(void) {
  embra_world* w = NULL;
  embra_solve_def d = embra_default_solve_def();
  embra_solve_result r;
  CHECK_INT(d.version, EMBRA_SOLVE_DEF_VERSION);
  CHECK_INT(d.until, EMBRA_SOLVE_UNTIL_TOLERANCE);
  CHECK_INT(d.max_frames, 1000);
  CHECK_INT(d.hold_frames, 10);
  CHECK_OK(embra_world_create(&w, NULL));
  CHECK_STATUS(embra_world_solve(NULL, &d, &r), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_solve(w, &d, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  d.max_frames = 0;
  CHECK_STATUS(embra_world_solve(w, &d, &r), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_solve_def();
  d.hold_frames = -1;
  CHECK_STATUS(embra_world_solve(w, &d, &r), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_solve_def();
  d.until = 2;
  CHECK_STATUS(embra_world_solve(w, &d, &r), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_solve_def();
  d.max_seconds = -1.0;
  CHECK_STATUS(embra_world_solve(w, &d, &r), EMBRA_ERROR_INVALID_ARGUMENT);
  d.max_seconds = 0.0 / 0.0;
  CHECK_STATUS(embra_world_solve(w, &d, &r), EMBRA_ERROR_INVALID_ARGUMENT);
  d = embra_default_solve_def();
  d.version = 99;
  CHECK_STATUS(embra_world_solve(w, &d, &r), EMBRA_ERROR_VERSION);
  CHECK_INT(frame_of(w), 0); /* nothing stepped */
  embra_world_destroy(w);
}

/* A scene's "preset": "form_finding" starts from embra_form_finding_solver_def, its other keys
 * overriding it; a 16-link chain hung at the preset comes to rest stretched (its links add up to more
 * than their 1.2 m), and the C door says so: settled out of tolerance, the distance residual named,
 * in metres, above EMBRA_SOLVE_RESIDUAL_TARGET_M, and equal to the largest |length - rest| of a link. */
/* A chain of 16 links of 7.5 cm built by hand on a circular arc of 1.2 m through two pins 1 m apart,
   at the form-finding preset with `solver_extra` added to its solver keys. Returns the world after
   embra_world_solve, its result in *r, and each link's distance off its 7.5 cm: the worst in *stretch,
   the chain's length in *length. */
static embra_world* solve_hand_built_chain(const char* solver_extra, embra_solve_result* r, double* stretch,
                                           double* length) {
  char scene[4096];
  int n = 0, k;
  embra_world* w = NULL;
  embra_solver_def got, want = embra_form_finding_solver_def();
  double positions[17 * 3], lo = 1e-6, hi = 3.0, t, radius;
  for (k = 0; k < 200; ++k) { /* the arc's half angle t: sin(t) / t = span / length = 1 / 1.2 */
    const double mid = 0.5 * (lo + hi);
    if (sin(mid) / mid > 1.0 / 1.2)
      lo = mid;
    else
      hi = mid;
  }
  t = 0.5 * (lo + hi);
  radius = 1.2 / (2.0 * t);
  n += snprintf(scene + n, sizeof scene - (size_t)n,
                "{\"format\": \"embra-scene\", \"version\": 1, \"solver\": {\"preset\": \"form_finding\", "
                "\"settle_speed\": 0.002%s}, \"bodies\": [{\"name\": \"chain\", \"mesh\": {\"vertices\": [",
                solver_extra);
  for (k = 0; k <= 16; ++k) { /* a circular arc of 1.2 m through two points 1 m apart */
    const double a = -t + 2.0 * t * k / 16.0;
    n += snprintf(scene + n, sizeof scene - (size_t)n, "%s[%.17g, 0, %.17g]", k ? ", " : "", radius * sin(a),
                  -radius * (cos(a) - cos(t)));
  }
  n += snprintf(scene + n, sizeof scene - (size_t)n,
                "]}, \"generate\": []}], \"constraints\": [{\"kind\": \"distance\", \"particles\": [");
  for (k = 0; k < 16; ++k) n += snprintf(scene + n, sizeof scene - (size_t)n, "%s[%d, %d]", k ? ", " : "", k, k + 1);
  n += snprintf(scene + n, sizeof scene - (size_t)n, "], \"rest\": [");
  for (k = 0; k < 16; ++k) n += snprintf(scene + n, sizeof scene - (size_t)n, "%s0.075", k ? ", " : "");
  snprintf(scene + n, sizeof scene - (size_t)n,
           "]}], \"pins\": [{\"particle\": {\"body\": \"chain\", \"vertex\": 0}}, "
           "{\"particle\": {\"body\": \"chain\", \"vertex\": 16}}]}");
  CHECK_OK(embra_world_load_json(&w, scene, (int64_t)strlen(scene), NULL));
  CHECK_OK(embra_world_get_solver(w, &got));
  want.settle_speed = 0.002;
  if (solver_extra[0] != '\0') want.global_solve = 0;
  CHECK(memcmp(&got, &want, sizeof got) == 0);
  CHECK_OK(embra_world_solve(w, NULL, r));
  CHECK_OK(embra_world_get_positions(w, positions, 3 * 17, 0, 17));
  *stretch = *length = 0.0;
  for (k = 0; k < 16; ++k) {
    const double dx = positions[3 * k + 3] - positions[3 * k], dy = positions[3 * k + 4] - positions[3 * k + 1],
                 dz = positions[3 * k + 5] - positions[3 * k + 2], l = sqrt(dx * dx + dy * dy + dz * dz);
    *length += l;
    if (fabs(l - 0.075) > *stretch) *stretch = fabs(l - 0.075);
  }
  return w;
}

/* The preset scene key gives embra_form_finding_solver_def; with it the hand-built chain comes to rest
   within tolerance, every link at its length (the global solve); without the global solve it rests
   stretched and solve says so, naming the distance residual. */
static void test_preset_scene_and_a_stretched_chain(void) {
  embra_solve_result r;
  double stretch, length;
  embra_world* w = solve_hand_built_chain("", &r, &stretch, &length);
  CHECK_INT(r.outcome, EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE);
  CHECK(stretch < 1e-9 * 0.075);
  CHECK_NEAR(length, 1.2, 1e-9);
  embra_world_destroy(w);
  w = solve_hand_built_chain(", \"global_solve\": 0", &r, &stretch, &length);
  CHECK_INT(r.outcome, EMBRA_SOLVE_SETTLED_OUT_OF_TOLERANCE);
  CHECK_INT(r.worst_metric, EMBRA_SOLVE_WORST_RESIDUAL);
  CHECK_INT(r.worst_element, EMBRA_CONSTRAINT_DISTANCE);
  CHECK_NEAR(r.worst_target, EMBRA_SOLVE_RESIDUAL_TARGET_M, 0.0);
  CHECK(length > 1.05 * 1.2);
  CHECK_NEAR(r.worst_value, stretch, 1e-9 * stretch);
  embra_world_destroy(w);
}

int main(void) {
  RUN(test_preset_scene_and_a_stretched_chain);
  RUN(test_pendulum_oscillates);
  RUN(test_chain_settles);
  RUN(test_panel_out_of_tolerance);
  RUN(test_residuals_by_kind);
  RUN(test_fighting_groups);
  RUN(test_refusals);
  return capi_test_finish();
}
