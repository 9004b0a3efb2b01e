/* embra_world_solve: why the stepping stopped, checked against what one can work out by hand: a
 * pendulum with no damping swings for ever with period 2 pi sqrt(L / g); a damped chain comes to
 * rest (no panel mesh: within tolerance); a panel whose four top corners are pinned off one plane
 * can never be planar and comes to rest out of tolerance, naming that panel; bad arguments are
 * refused before any step. */
#include <stdint.h>
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

int main(void) {
  RUN(test_pendulum_oscillates);
  RUN(test_chain_settles);
  RUN(test_panel_out_of_tolerance);
  RUN(test_refusals);
  return capi_test_finish();
}
