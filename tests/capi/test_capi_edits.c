/* Edits without a rebuild: a constraint's compliance, rest and group, its removal, a group
 * disabled and enabled, a body's material and a field's parameters, each changing only what it
 * names. Checked against what one can work out by hand:
 *   - a particle of mass m hanging from a fixed point by a distance of compliance c comes to rest
 *     stretched by m g c (XPBD's steady state, exactly); after the compliance or the rest length is
 *     edited it comes to rest where the new values put it;
 *   - a disabled group, or a removed constraint, leaves the world stepping to the same bits as a
 *     world that never had the constraint;
 *   - a vortex field set to strength s accelerates a particle at distance r from its axis by
 *     s exp(-r^2 / R^2) r / R;
 *   - the saved scene differs from the one before an edit in that one number only, and the
 *     positions and velocities are those before the edit, to the bit.
 * Every refused edit leaves the saved world as it was. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

static const double kG = 9.81;

/* The one differing stretch of two texts (their common prefix and suffix cut off) is a single
 * number in each: only digits, a point, a sign or an exponent. */
static int only_one_number_differs(const char* a, const char* b) {
  const size_t na = strlen(a), nb = strlen(b);
  size_t p = 0, s = 0, i;
  while (p < na && p < nb && a[p] == b[p]) ++p;
  while (s < na - p && s < nb - p && a[na - 1 - s] == b[nb - 1 - s]) ++s;
  if (p == na && p == nb) return 0; /* no difference at all */
  for (i = p; i < na - s; ++i)
    if (!strchr("0123456789.eE+-", a[i])) return 0;
  for (i = p; i < nb - s; ++i)
    if (!strchr("0123456789.eE+-", b[i])) return 0;
  return 1;
}

/* World holding particle `first` fixed at the origin and `first + 1` of mass `m` 1 m below it, one
 * body; with link_compliance >= 0 the body's one edge joins them, its generated stretch of that
 * compliance (no automatic tethers). */
static embra_world* pair_world(double damping, double m, double link_compliance, embra_body_id* body, int32_t* first) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  embra_body_def b = embra_default_body_def();
  embra_body_id id;
  const double xyz[6] = {0, 0, 0, 0, 0, -1};
  const int32_t edge[2] = {0, 1};
  double masses[2];
  masses[0] = 0.0;
  masses[1] = m;
  s.damping = damping;
  s.settle_speed = 1e-7; /* at rest: swinging less than 1e-7 / omega, a few nanometres */
  if (link_compliance >= 0.0) s.tethers = 0;
  CHECK_OK(embra_world_create(&w, &s));
  b.vertex_count = 2;
  b.positions = xyz;
  b.masses = masses;
  if (link_compliance >= 0.0) {
    b.edges = edge;
    b.edge_count = 1;
    b.material.stretch_compliance = link_compliance;
  }
  CHECK_OK(embra_body_create(w, &b, body ? body : &id, first));
  return w;
}

static embra_world* hanging_world(double damping, double m, int32_t* first) {
  return pair_world(damping, m, -1.0, NULL, first);
}

static double z_of(const embra_world* w, int32_t particle) {
  double xyz[6] = {0};
  CHECK_OK(embra_world_get_positions(w, xyz, 6, 0, 2));
  return xyz[3 * particle + 2];
}

static void solve_to_rest(embra_world* w) {
  embra_solve_def d = embra_default_solve_def();
  embra_solve_result r;
  d.until = EMBRA_SOLVE_UNTIL_SETTLED;
  d.max_frames = 3000;
  CHECK_OK(embra_world_solve(w, &d, &r));
  CHECK_INT(r.outcome, EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE);
}

static int same_bits(const embra_world* a, const embra_world* b) {
  double pa[6], pb[6], va[6], vb[6];
  CHECK_OK(embra_world_get_positions(a, pa, 6, 0, 2));
  CHECK_OK(embra_world_get_positions(b, pb, 6, 0, 2));
  CHECK_OK(embra_world_get_velocities(a, va, 6, 0, 2));
  CHECK_OK(embra_world_get_velocities(b, vb, 6, 0, 2));
  return memcmp(pa, pb, sizeof pa) == 0 && memcmp(va, vb, sizeof va) == 0;
}

/* Compliance and rest edits of an added distance: the rest state moves to m g c and to the new
 * rest length; the edit itself moves nothing, and the saved scene differs in that number only. */
static void test_compliance_and_rest(void) {
  const double m = 2.0, c1 = 1e-3, c2 = 4e-3;
  int32_t first = 0, count = 0, generated = -1;
  embra_world* w = hanging_world(6.0, m, &first);
  embra_group_id def = {0, 0};
  embra_constraint_def c = embra_default_constraint_def(), got;
  double before[6], after[6];
  char *saved_before, *saved_after;
  c.particles[0] = first;
  c.particles[1] = first + 1;
  c.rest_from_current = 0;
  c.rest = 1.0;
  c.compliance = c1;
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_group_get_constraint_count(w, def, EMBRA_CONSTRAINT_DISTANCE, &count, &generated));
  CHECK_INT(count, 1);
  CHECK_INT(generated, 0); /* the body's stretch went nowhere: a point pair without edges */
  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.0, m * kG * c1, 1e-6);

  CHECK_OK(embra_world_get_positions(w, before, 6, 0, 2));
  saved_before = capi_test_save(w);
  CHECK_OK(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, c2));
  saved_after = capi_test_save(w);
  CHECK_OK(embra_world_get_positions(w, after, 6, 0, 2));
  CHECK(memcmp(before, after, sizeof before) == 0);
  CHECK(saved_before && saved_after && only_one_number_differs(saved_before, saved_after));
  CHECK_OK(embra_constraint_get(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, &got));
  CHECK_SAME_DOUBLE(got.compliance, c2);
  CHECK_SAME_DOUBLE(got.rest, 1.0);
  CHECK_INT(got.particles[0], first);
  CHECK_INT(got.particles[1], first + 1);
  CHECK_INT(got.particles[2], -1);
  CHECK_INT(got.rest_from_current, 0);
  free(saved_before);
  free(saved_after);
  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.0, m * kG * c2, 1e-6);

  saved_before = capi_test_save(w);
  CHECK_OK(embra_constraint_set_rest(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, 1.5));
  saved_after = capi_test_save(w);
  CHECK(saved_before && saved_after && only_one_number_differs(saved_before, saved_after));
  free(saved_before);
  free(saved_after);
  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.5, m * kG * c2, 1e-6);
  embra_world_destroy(w);
}

/* A disabled group, and a removed constraint: the world steps to the bits of one that never had
 * the constraint (the particle falls freely); enabled again, the group holds the particle again. */
static void test_disable_move_remove(void) {
  int32_t first = 0, fa = 0, index = -1, enabled = -1, count = -1;
  embra_world* w = hanging_world(0.0, 1.0, &first);
  embra_world* free_fall = hanging_world(0.0, 1.0, &fa);
  embra_group_def gd = embra_default_group_def();
  embra_group_id g, def = {0, 0};
  embra_constraint_def c = embra_default_constraint_def(), got;
  embra_kind_residual res[16];
  int32_t n = 0, f;
  char* saved;
  embra_world* loaded = NULL;
  c.particles[0] = first;
  c.particles[1] = first + 1;
  /* Three copies of the link: the middle one moves to group g, the other two are removed. */
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_group_create(w, &gd, &g));
  CHECK_OK(embra_constraint_set_group(w, def, EMBRA_CONSTRAINT_DISTANCE, 1, g, &index));
  CHECK_INT(index, 0);
  CHECK_OK(embra_group_get_constraint_count(w, def, EMBRA_CONSTRAINT_DISTANCE, &count, NULL));
  CHECK_INT(count, 2);
  /* Remove the two left in the default group: the one in g holds the particle alone. */
  CHECK_OK(embra_constraint_remove(w, def, EMBRA_CONSTRAINT_DISTANCE, 1));
  CHECK_OK(embra_constraint_remove(w, def, EMBRA_CONSTRAINT_DISTANCE, 0));
  CHECK_OK(embra_group_get_constraint_count(w, def, EMBRA_CONSTRAINT_DISTANCE, &count, NULL));
  CHECK_INT(count, 0);
  CHECK_OK(embra_constraint_get(w, g, EMBRA_CONSTRAINT_DISTANCE, 0, &got));
  CHECK_INT(got.particles[1], first + 1);

  /* Disabled: the same bits as the world without any constraint, frame after frame. */
  CHECK_OK(embra_group_set_enabled(w, g, 0));
  CHECK_OK(embra_group_get_enabled(w, g, &enabled));
  CHECK_INT(enabled, 0);
  for (f = 0; f < 20; ++f) {
    CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_step(free_fall));
  }
  CHECK(same_bits(w, free_fall));
  CHECK(z_of(w, first + 1) < -1.5); /* it fell: 0.5 g t^2 = 0.54 m in 1/3 s */
  CHECK_OK(embra_world_get_residuals(w, res, 16, &n));
  for (f = 0; f < n; ++f) CHECK(res[f].kind != EMBRA_CONSTRAINT_DISTANCE); /* not measured while disabled */

  /* Saved and loaded back disabled. */
  saved = capi_test_save(w);
  CHECK(saved != NULL && strstr(saved, "\"enabled\": false") != NULL);
  CHECK_OK(embra_world_load_json(&loaded, saved, (int64_t)strlen(saved), "."));
  if (loaded) {
    embra_group_id groups[4];
    int32_t ng = 0, k, disabled = 0;
    CHECK_OK(embra_world_get_groups(loaded, groups, 4, &ng));
    for (k = 0; k < ng; ++k) {
      CHECK_OK(embra_group_get_enabled(loaded, groups[k], &enabled));
      disabled += enabled == 0;
    }
    CHECK_INT(disabled, 1);
    embra_world_destroy(loaded);
  }
  free(saved);

  /* Enabled again, the link pulls the particle back to 1 m. */
  CHECK_OK(embra_group_set_enabled(w, g, 1));
  CHECK_OK(embra_world_step(w));
  {
    double xyz[6];
    CHECK_OK(embra_world_get_positions(w, xyz, 6, 0, 2));
    CHECK_NEAR(sqrt(xyz[3] * xyz[3] + xyz[4] * xyz[4] + xyz[5] * xyz[5]), 1.0, 1e-9);
  }
  embra_world_destroy(w);
  embra_world_destroy(free_fall);

  /* A removed constraint is the same as none. */
  w = hanging_world(0.0, 1.0, &first);
  free_fall = hanging_world(0.0, 1.0, &fa);
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_set_positions(w, (const double[6]){0, 0, 0, 0, 0, -1}, first, 2));
  CHECK_OK(embra_world_set_velocities(w, (const double[6]){0}, first, 2));
  CHECK_OK(embra_constraint_remove(w, def, EMBRA_CONSTRAINT_DISTANCE, 0));
  for (f = 0; f < 10; ++f) {
    CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_step(free_fall));
  }
  CHECK(same_bits(w, free_fall));
  embra_world_destroy(w);
  embra_world_destroy(free_fall);
}

/* A body's material: its generated stretch follows the material's compliance (rest at m g c, then
 * at the new m g c'); editing the generated constraint itself, or the mass, is refused. */
static void test_material(void) {
  embra_body_id body;
  embra_material mat, got;
  embra_group_id def = {0, 0};
  int32_t first = 0, count = 0, generated = 0;
  char *saved_before, *saved_after;
  embra_world* w = pair_world(6.0, 2.0, 1e-3, &body, &first);
  CHECK_OK(embra_group_get_constraint_count(w, def, EMBRA_CONSTRAINT_DISTANCE, &count, &generated));
  CHECK_INT(count, 1);
  CHECK_INT(generated, 1);
  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.0, 2.0 * kG * 1e-3, 1e-6);

  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, 0.0),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "embra_body_set_material");
  CHECK_STATUS(embra_constraint_remove(w, def, EMBRA_CONSTRAINT_DISTANCE, 0), EMBRA_ERROR_INVALID_ARGUMENT);

  CHECK_OK(embra_body_get_material(w, body, &mat));
  CHECK_SAME_DOUBLE(mat.stretch_compliance, 1e-3);
  mat.mass = 5.0;
  CHECK_STATUS(embra_body_set_material(w, body, &mat), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "mass");
  CHECK_OK(embra_body_get_material(w, body, &mat));
  mat.stretch_compliance = 3e-3;
  saved_before = capi_test_save(w);
  CHECK_OK(embra_body_set_material(w, body, &mat));
  saved_after = capi_test_save(w);
  CHECK(saved_before && saved_after && only_one_number_differs(saved_before, saved_after));
  free(saved_before);
  free(saved_after);
  CHECK_OK(embra_body_get_material(w, body, &got));
  CHECK_SAME_DOUBLE(got.stretch_compliance, 3e-3);
  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.0, 2.0 * kG * 3e-3, 1e-6);
  mat.damping = -1.0;
  CHECK_STATUS(embra_body_set_material(w, body, &mat), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_set_material(w, body, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_get_material(w, body, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  body.index += 7;
  CHECK_STATUS(embra_body_get_material(w, body, &got), EMBRA_ERROR_STALE_ID);
  embra_world_destroy(w);
}

/* A vortex field edited between steps: strength 0 leaves a weightless particle where it is; set to
 * s, it is pushed along axis x d at s exp(-r^2/R^2) r / R. */
static void test_field(void) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  embra_body_def b = embra_default_body_def();
  embra_body_id body;
  embra_vortex_def v = embra_default_vortex_def(), got;
  embra_wind_def wind = embra_default_wind_def();
  embra_field_id field;
  const double xyz[3] = {0.5, 0, 0};
  double p[3], vel[3];
  const double strength = 2.0, radius = 1.0, r = 0.5;
  const double a = strength * exp(-r * r / (radius * radius)) * r / radius;
  int32_t first = 0;
  char *saved_before, *saved_after;
  s.gravity[2] = 0.0;
  CHECK_OK(embra_world_create(&w, &s));
  b.vertex_count = 1;
  b.positions = xyz;
  CHECK_OK(embra_body_create(w, &b, &body, &first));
  CHECK_OK(embra_vortex_create(w, &v, &field));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_positions(w, p, 3, 0, 1));
  CHECK_SAME_DOUBLE(p[1], 0.0);

  v.strength = strength;
  v.radius = radius;
  saved_before = capi_test_save(w);
  CHECK_OK(embra_vortex_set(w, field, &v));
  saved_after = capi_test_save(w);
  CHECK(saved_before && saved_after && only_one_number_differs(saved_before, saved_after));
  free(saved_before);
  free(saved_after);
  CHECK_OK(embra_vortex_get(w, field, &got));
  CHECK_SAME_DOUBLE(got.strength, strength);
  CHECK_INT(got.body.generation, 0);
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_velocities(w, vel, 3, 0, 1));
  CHECK_NEAR(vel[1], a / 60.0, 1e-3 * a / 60.0); /* one frame of 1/60 s from rest */

  /* Refused, nothing changed: another kind's setter, a non-finite strength, another body. */
  saved_before = capi_test_save(w);
  CHECK_STATUS(embra_wind_set(w, field, &wind), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_wind_get(w, field, &wind), EMBRA_ERROR_INVALID_ARGUMENT);
  v.strength = NAN;
  CHECK_STATUS(embra_vortex_set(w, field, &v), EMBRA_ERROR_INVALID_ARGUMENT);
  v.strength = 1.0;
  v.body = body;
  CHECK_STATUS(embra_vortex_set(w, field, &v), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "body");
  v.body.index = 0;
  v.body.generation = 0;
  v.version = 99;
  CHECK_STATUS(embra_vortex_set(w, field, &v), EMBRA_ERROR_VERSION);
  CHECK_STATUS(embra_vortex_set(w, field, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_vortex_get(w, field, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  saved_after = capi_test_save(w);
  CHECK(saved_before && saved_after && strcmp(saved_before, saved_after) == 0);
  free(saved_before);
  free(saved_after);
  CHECK_OK(embra_field_destroy(w, field));
  CHECK_STATUS(embra_vortex_get(w, field, &got), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_vortex_set(w, field, &got), EMBRA_ERROR_STALE_ID);
  embra_world_destroy(w);
}

/* Every refusal names what is wrong and leaves the saved world as it was. */
static void test_refusals(void) {
  int32_t first = 0, out = -7;
  embra_world* w = hanging_world(0.0, 1.0, &first);
  embra_group_def gd = embra_default_group_def();
  embra_group_id def = {0, 0}, g, contacts, stale;
  embra_constraint_def c = embra_default_constraint_def();
  char *before, *after;
  int32_t count = 0;
  c.particles[0] = first;
  c.particles[1] = first + 1;
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_group_create(w, &gd, &stale));
  CHECK_OK(embra_group_destroy(w, stale));
  CHECK_OK(embra_group_create(w, &gd, &g));
  CHECK_OK(embra_world_contact_group(w, &contacts));
  CHECK_OK(embra_world_step(w));
  before = capi_test_save(w);

  CHECK_STATUS(embra_constraint_set_compliance(w, stale, EMBRA_CONSTRAINT_DISTANCE, 0, 1.0), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, -1, 0, 1.0), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, 99, 0, 1.0), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, -1, 1.0),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, 1, 1.0),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "outside [0, 1)");
  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_TETHER, 0, 1.0), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, NAN),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, -1.0),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, INFINITY),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_rest(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, NAN), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_rest(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, -0.5), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_rest(w, stale, EMBRA_CONSTRAINT_DISTANCE, 0, 1.0), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_constraint_set_group(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, contacts, &out),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_group(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, stale, &out), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_constraint_set_group(w, def, EMBRA_CONSTRAINT_DISTANCE, 3, g, &out), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_INT(out, -7);
  CHECK_STATUS(embra_constraint_remove(w, def, EMBRA_CONSTRAINT_DISTANCE, 1), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_remove(w, stale, EMBRA_CONSTRAINT_DISTANCE, 0), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_constraint_get(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_get(w, def, EMBRA_CONSTRAINT_DISTANCE, 5, &c), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_group_get_constraint_count(w, def, EMBRA_CONSTRAINT_DISTANCE, NULL, NULL),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_group_get_constraint_count(w, stale, EMBRA_CONSTRAINT_DISTANCE, &count, NULL),
               EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_group_get_constraint_count(w, def, 42, &count, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_group_set_enabled(w, contacts, 0), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "contact");
  CHECK_STATUS(embra_group_set_enabled(w, g, 2), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_group_set_enabled(w, stale, 0), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_group_get_enabled(w, g, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_compliance(NULL, def, EMBRA_CONSTRAINT_DISTANCE, 0, 1.0),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_group_set_enabled(NULL, g, 0), EMBRA_ERROR_INVALID_ARGUMENT);

  after = capi_test_save(w);
  CHECK(before && after && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

/* Plasticity and rupture through the C ABI: refusals change nothing; a weight hung on a link whose
 * static strain (m g c / L = 0.0981) is past its rupture strain (0.05) breaks it, one event names
 * it, read with the two-call pattern (a count leaves the list; a read empties it), and the freed
 * weight falls on. */
static void test_plasticity_and_broken(void) {
  int32_t first = 0, count = -1, n = 0;
  embra_world* w = hanging_world(5.0, 1.0, &first);
  embra_group_id def = {0, 0}, stale, g;
  embra_group_def gd = embra_default_group_def();
  embra_constraint_def c = embra_default_constraint_def();
  embra_broken_constraint out[4];
  embra_step_report report;
  double yield = -1.0, rupture = -1.0;
  char *before, *after;
  c.particles[0] = first;
  c.particles[1] = first + 1;
  c.compliance = 0.01;
  CHECK_OK(embra_constraint_add(w, &c));
  CHECK_OK(embra_group_create(w, &gd, &stale));
  CHECK_OK(embra_group_destroy(w, stale));
  CHECK_OK(embra_group_create(w, &gd, &g));
  before = capi_test_save(w);
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, NAN, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, 0.0, -0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, INFINITY, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 1, 0.0, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, -1, 0.0, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_TETHER, 0, 0.0, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "distance and dihedral");
  CHECK_STATUS(embra_constraint_set_plasticity(w, def, 77, 0, 0.0, 0.05), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, g, EMBRA_CONSTRAINT_DISTANCE, 0, 0.0, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_set_plasticity(w, stale, EMBRA_CONSTRAINT_DISTANCE, 0, 0.0, 0.05),
               EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_constraint_set_plasticity(NULL, def, EMBRA_CONSTRAINT_DISTANCE, 0, 0.0, 0.05),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_get_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, NULL, &rupture),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_constraint_get_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, &yield, NULL),
               EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_broken(w, out, 4, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_broken(w, out, -1, &count), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_broken(w, NULL, 4, &count), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_broken(NULL, out, 4, &count), EMBRA_ERROR_INVALID_ARGUMENT);
  after = capi_test_save(w);
  CHECK(before && after && strcmp(before, after) == 0);
  free(before);
  free(after);

  CHECK_OK(embra_constraint_get_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, &yield, &rupture));
  CHECK(yield == 0.0 && rupture == 0.0);
  CHECK_OK(embra_constraint_set_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, 0.0, 0.05));
  CHECK_OK(embra_constraint_get_plasticity(w, def, EMBRA_CONSTRAINT_DISTANCE, 0, &yield, &rupture));
  CHECK(yield == 0.0 && rupture == 0.05);
  for (int f = 0; f < 120 && n == 0; ++f) {
    CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_get_broken(w, NULL, 0, &n));
  }
  CHECK_INT(n, 1);
  CHECK_OK(embra_world_get_broken(w, NULL, 0, &count));
  CHECK_INT(count, 1); /* a count alone keeps the list */
  CHECK_STATUS(embra_world_get_broken(w, out, 0, &count), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_OK(embra_world_get_broken(w, out, 4, &count));
  CHECK_INT(count, 1);
  CHECK_OK(embra_world_get_report(w, &report));
  CHECK_INT(out[0].kind, EMBRA_CONSTRAINT_DISTANCE);
  CHECK_INT(out[0].index, 0);
  CHECK_INT(out[0].particles[0], first);
  CHECK_INT(out[0].particles[1], first + 1);
  CHECK_INT(out[0].particles[2], -1);
  CHECK(out[0].frame == report.frame);
  CHECK(out[0].strain > 0.05);
  CHECK_OK(embra_world_get_broken(w, NULL, 0, &count));
  CHECK_INT(count, 0); /* read: emptied */
  CHECK_OK(embra_group_get_constraint_count(w, def, EMBRA_CONSTRAINT_DISTANCE, &count, NULL));
  CHECK_INT(count, 0);
  /* The weight falls free (1 s more, at up to g / damping = 2 m/s): the world steps on. */
  for (int f = 0; f < 60; ++f) CHECK_OK(embra_world_step(w));
  CHECK(z_of(w, first + 1) < -2.0);
  embra_world_destroy(w);
}

/* A net of n x n particles 0.1 m apart at z = 0, edges along the grid (compliance c), the rest
 * 0.01 kg each: its four corners immovable (mass 0), or with `flap` its first row (y = 0), so
 * it swings down from that edge. */
#define NET 9
static embra_world* net_world(double c, int flap, embra_body_id* body) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  embra_body_def b = embra_default_body_def();
  double xyz[3 * NET * NET], masses[NET * NET];
  int32_t edges[2 * 2 * NET * (NET - 1)], e = 0, i, j, first = 0;
  for (j = 0; j < NET; ++j)
    for (i = 0; i < NET; ++i) {
      const int32_t k = j * NET + i;
      xyz[3 * k] = 0.1 * i;
      xyz[3 * k + 1] = 0.1 * j;
      xyz[3 * k + 2] = 0.0;
      masses[k] = 0.01;
      if (i + 1 < NET) {
        edges[e++] = k;
        edges[e++] = k + 1;
      }
      if (j + 1 < NET) {
        edges[e++] = k;
        edges[e++] = k + NET;
      }
    }
  if (flap)
    for (i = 0; i < NET; ++i) masses[i] = 0.0;
  else
    masses[0] = masses[NET - 1] = masses[NET * (NET - 1)] = masses[NET * NET - 1] = 0.0;
  s.damping = 10.0;
  s.settle_speed = 1e-7;
  CHECK_OK(embra_world_create(&w, &s));
  b.vertex_count = NET * NET;
  b.positions = xyz;
  b.masses = masses;
  b.edges = edges;
  b.edge_count = e / 2;
  b.material.stretch_compliance = c;
  CHECK_OK(embra_body_create(w, &b, body, &first));
  return w;
}

/* Steps until at rest: a compliant net's Gauss-Seidel static error keeps its residuals above the
 * solve's targets, so "settled out of tolerance" is at rest too. */
static void settle(embra_world* w) {
  embra_solve_def d = embra_default_solve_def();
  embra_solve_result r;
  d.until = EMBRA_SOLVE_UNTIL_SETTLED;
  d.max_frames = 3000;
  CHECK_OK(embra_world_solve(w, &d, &r));
  CHECK(r.outcome == EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE || r.outcome == EMBRA_SOLVE_SETTLED_OUT_OF_TOLERANCE);
}

/* The lowest z of the particles whose x is below (side 0) or above (side 1) the middle column. */
static double lowest_of_half(const embra_world* w, int side) {
  double xyz[3 * NET * NET], low = 0.0;
  int32_t i, j;
  CHECK_OK(embra_world_get_positions(w, xyz, 3 * NET * NET, 0, NET * NET));
  for (j = 0; j < NET; ++j)
    for (i = side ? NET / 2 + 1 : 0; i < (side ? NET : NET / 2); ++i)
      if (xyz[3 * (j * NET + i) + 2] < low) low = xyz[3 * (j * NET + i) + 2];
  return low;
}

static int same_state(const embra_world* a, const embra_world* b, int32_t n) {
  double pa[3 * NET * NET], pb[3 * NET * NET], va[3 * NET * NET], vb[3 * NET * NET];
  CHECK_OK(embra_world_get_positions(a, pa, 3 * n, 0, n));
  CHECK_OK(embra_world_get_positions(b, pb, 3 * n, 0, n));
  CHECK_OK(embra_world_get_velocities(a, va, 3 * n, 0, n));
  CHECK_OK(embra_world_get_velocities(b, vb, 3 * n, 0, n));
  return memcmp(pa, pb, 3 * (size_t)n * sizeof(double)) == 0 && memcmp(va, vb, 3 * (size_t)n * sizeof(double)) == 0;
}

/* Masses set on a running world: a particle hung on a compliant link (0.002 m/N) settles m g c below
 * its rest length for each new mass, and set immovable (0) it stays where it is; the edit moves
 * nothing by itself; a world saved after the edit and loaded again steps on to the same bits. */
static void test_masses_hang(void) {
  embra_world* loaded = NULL;
  embra_body_id body;
  double got[2] = {-1, -1}, heavier[2] = {0.0, 3.5}, still[2] = {0.0, 0.0}, before[6], after[6];
  int32_t first = 0, n = 0, k;
  char* saved;
  embra_world* w = pair_world(6.0, 1.0, 2e-3, &body, &first);
  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.0, 1.0 * kG * 2e-3, 1e-6);

  CHECK_OK(embra_body_get_masses(w, body, NULL, 0, &n));
  CHECK_INT(n, 2);
  CHECK_OK(embra_world_get_positions(w, before, 6, 0, 2));
  CHECK_OK(embra_body_set_masses(w, body, heavier, 2));
  CHECK_OK(embra_world_get_positions(w, after, 6, 0, 2));
  CHECK(memcmp(before, after, sizeof before) == 0); /* the edit moves nothing */
  CHECK_OK(embra_body_get_masses(w, body, got, 2, &n));
  CHECK_SAME_DOUBLE(got[0], 0.0);
  CHECK_SAME_DOUBLE(got[1], 3.5);

  /* Saved right after the edit: the loaded world steps as the edited one does, bit for bit. */
  saved = capi_test_save(w);
  CHECK(saved != NULL);
  CHECK_OK(embra_world_load_json(&loaded, saved, (int64_t)strlen(saved), "."));
  free(saved);
  for (k = 0; k < 50; ++k) {
    CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_step(loaded));
  }
  CHECK(same_bits(w, loaded));
  embra_world_destroy(loaded);

  solve_to_rest(w);
  CHECK_NEAR(-z_of(w, first + 1) - 1.0, 3.5 * kG * 2e-3, 1e-6);
  printf("  hung on 2e-3 m/N: 3.5 kg settles %.9f m below its rest length (m g c = %.9f m)\n",
         -z_of(w, first + 1) - 1.0, 3.5 * kG * 2e-3);

  /* Both immovable: the bob stays where it is, however long the world steps. */
  CHECK_OK(embra_world_get_positions(w, before, 6, 0, 2));
  CHECK_OK(embra_body_set_masses(w, body, still, 2));
  for (k = 0; k < 30; ++k) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_positions(w, after, 6, 0, 2));
  CHECK(memcmp(before, after, sizeof before) == 0);
  embra_world_destroy(w);
}

/* A uniform scale of every mass changes no motion: gravity accelerates every mass alike and a hard
 * link divides its correction by the masses' ratio. A pendulum (a bob on a 1 m link from an
 * immovable pivot, started level) and a free particle beside it, their masses times 7 after 10
 * frames, follow the unscaled world's paths for 200 frames (to 1e-9 m: only rounding differs). */
static void test_masses_uniform_scale(void) {
  embra_world* w[2] = {NULL, NULL};
  embra_body_id body[2];
  const double xyz[9] = {0, 0, 0, 1, 0, 0, 3, 0, 0}, masses[3] = {0.0, 0.4, 0.25};
  const double scaled[3] = {0.0, 7 * 0.4, 7 * 0.25};
  const int32_t edge[2] = {0, 1};
  double pa[9], pb[9], worst = 0.0, fall;
  int32_t v, k, i;
  for (v = 0; v < 2; ++v) {
    embra_solver_def s = embra_default_solver_def();
    embra_body_def b = embra_default_body_def();
    s.tethers = 0;
    CHECK_OK(embra_world_create(&w[v], &s));
    b.vertex_count = 3;
    b.positions = xyz;
    b.masses = masses;
    b.edges = edge;
    b.edge_count = 1;
    CHECK_OK(embra_body_create(w[v], &b, &body[v], NULL));
  }
  for (k = 0; k < 210; ++k) {
    if (k == 10) CHECK_OK(embra_body_set_masses(w[1], body[1], scaled, 3));
    CHECK_OK(embra_world_step(w[0]));
    CHECK_OK(embra_world_step(w[1]));
    CHECK_OK(embra_world_get_positions(w[0], pa, 9, 0, 3));
    CHECK_OK(embra_world_get_positions(w[1], pb, 9, 0, 3));
    for (i = 0; i < 9; ++i)
      if (fabs(pa[i] - pb[i]) > worst) worst = fabs(pa[i] - pb[i]);
  }
  CHECK_NEAR(worst, 0.0, 1e-9);
  fall = -pb[8];
  CHECK_NEAR(hypot(pb[3], pb[5]), 1.0, 1e-6); /* the link held */
  CHECK(fall > 3.0);                          /* 3.5 s of free fall: g t^2 / 2 = 60 m */
  printf("  masses x7: paths within %.3g m of the unscaled world's over 210 frames\n", worst);
  embra_world_destroy(w[0]);
  embra_world_destroy(w[1]);
}

/* A net held at its corners on compliant edges sags symmetrically; its right half made four times
 * heavier (without a rebuild), that half sags lower than the left, and lower than before. */
static void test_masses_heavier_half(void) {
  embra_body_id body;
  embra_world* w = net_world(0.02, 0, &body);
  double masses[NET * NET], left, right, left0, right0;
  int32_t n = 0, i, j;
  settle(w);
  left0 = lowest_of_half(w, 0);
  right0 = lowest_of_half(w, 1);
  CHECK_NEAR(left0, right0, 1e-4); /* Gauss-Seidel's order is not symmetric: 1.1e-5 m apart */
  CHECK_OK(embra_body_get_masses(w, body, masses, NET * NET, &n));
  CHECK_INT(n, NET * NET);
  for (j = 0; j < NET; ++j)
    for (i = NET / 2 + 1; i < NET; ++i) masses[j * NET + i] *= 4.0;
  CHECK_OK(embra_body_set_masses(w, body, masses, NET * NET));
  settle(w);
  left = lowest_of_half(w, 0);
  right = lowest_of_half(w, 1);
  CHECK(right < left - 0.01);
  CHECK(right < right0 - 0.01);
  printf("  net: both halves %.4f m; right half x4: left %.4f m, right %.4f m\n", left0, left, right);
  embra_world_destroy(w);
}

/* An inextensible flap hung from its first row: its centre made immovable (0) stays put and
 * anchors it (automatic tethers attach to it), made movable again it falls; each time the saved and
 * reloaded world steps to the same bits; a hard-pinned particle given a mass keeps following its
 * pin, and falls once the pin is gone. */
static void test_masses_anchors_and_pins(void) {
  embra_body_id body;
  embra_world *w = net_world(0.0, 1, &body), *loaded = NULL;
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id pin;
  double masses[NET * NET], xyz[3 * NET * NET], z_pinned;
  const int32_t centre = (NET / 2) * NET + NET / 2, held = NET * (NET - 1) + 1;
  int32_t n = 0, k, round;
  char* saved;
  CHECK_OK(embra_body_get_masses(w, body, masses, NET * NET, &n));
  pd.particle = held;
  pd.target[0] = 0.1;
  pd.target[1] = 0.1 * (NET - 1);
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  for (round = 0; round < 2; ++round) {
    masses[centre] = round == 0 ? 0.0 : 0.05; /* the centre an anchor, then free again */
    masses[held] = round == 0 ? 0.5 : 0.01;
    CHECK_OK(embra_body_set_masses(w, body, masses, NET * NET));
    saved = capi_test_save(w);
    CHECK(saved != NULL);
    CHECK_OK(embra_world_load_json(&loaded, saved, (int64_t)strlen(saved), "."));
    free(saved);
    for (k = 0; k < 60; ++k) {
      CHECK_OK(embra_world_step(w));
      CHECK_OK(embra_world_step(loaded));
    }
    CAPI_CONTEXT("round %d", round);
    CHECK(same_state(w, loaded, NET * NET));
    embra_world_destroy(loaded);
    loaded = NULL;
    CHECK_OK(embra_world_get_positions(w, xyz, 3 * NET * NET, 0, NET * NET));
    CHECK_SAME_DOUBLE(xyz[3 * held + 2], 0.0); /* hard-pinned whatever its mass */
    if (round == 0) CHECK_SAME_DOUBLE(xyz[3 * centre + 2], 0.0);
    if (round == 1) CHECK(xyz[3 * centre + 2] < -0.05);
    printf("  flap, centre %s: centre at z = %.4f m after 60 frames\n", round == 0 ? "immovable" : "0.05 kg",
           xyz[3 * centre + 2]);
  }
  CAPI_CONTEXT("%s", "");
  CHECK_OK(embra_pin_destroy(w, pin));
  for (k = 0; k < 30; ++k) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_positions(w, xyz, 3 * NET * NET, 0, NET * NET));
  z_pinned = xyz[3 * held + 2];
  CHECK(z_pinned < -0.01);
  embra_world_destroy(w);
}

/* Every refusal of embra_body_set_masses and embra_body_get_masses changes nothing: the saved scene
 * is the same text before and after. */
static void test_masses_refusals(void) {
  embra_body_id body, stale;
  embra_world *w = net_world(1e-3, 0, &body), *other = NULL;
  embra_solver_def s = embra_default_solver_def();
  double masses[NET * NET], bad[NET * NET], small[3] = {-7.0, -7.0, -7.0};
  const double wrong[] = {-1.0, NAN, INFINITY, -INFINITY, 1e-310, 2e300, -1e-300};
  int32_t n = 0, i, k;
  char *before, *after;
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_body_get_masses(w, body, masses, NET * NET, &n));
  before = capi_test_save(w);

  CHECK_STATUS(embra_body_set_masses(NULL, body, masses, NET * NET), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_set_masses(w, body, NULL, NET * NET), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "masses");
  CHECK_STATUS(embra_body_set_masses(w, body, masses, NET * NET - 1), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "81 particles");
  CHECK_STATUS(embra_body_set_masses(w, body, masses, NET * NET + 1), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_set_masses(w, body, masses, -1), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_set_masses(w, body, masses, 0), EMBRA_ERROR_INVALID_ARGUMENT);
  stale = body;
  stale.index += 3;
  CHECK_STATUS(embra_body_set_masses(w, stale, masses, NET * NET), EMBRA_ERROR_STALE_ID);
  stale = body;
  stale.generation += 1;
  CHECK_STATUS(embra_body_set_masses(w, stale, masses, NET * NET), EMBRA_ERROR_STALE_ID);
  CHECK_OK(embra_world_create(&other, &s));
  CHECK_STATUS(embra_body_set_masses(other, body, masses, NET * NET), EMBRA_ERROR_STALE_ID);
  embra_world_destroy(other);
  for (k = 0; k < (int32_t)(sizeof wrong / sizeof wrong[0]); ++k)
    for (i = 0; i < NET * NET; i += NET * NET - 1) { /* the first and the last particle */
      memcpy(bad, masses, sizeof bad);
      bad[i] = wrong[k];
      CAPI_CONTEXT("masses[%d] = %g", i, wrong[k]);
      CHECK_STATUS(embra_body_set_masses(w, body, bad, NET * NET), EMBRA_ERROR_INVALID_ARGUMENT);
      CHECK_CONTAINS(embra_last_error_message(), "mass");
    }
  CAPI_CONTEXT("%s", "");
  CHECK_STATUS(embra_body_get_masses(w, body, small, 3, &n), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_SAME_DOUBLE(small[0], -7.0); /* nothing written */
  CHECK_SAME_DOUBLE(small[2], -7.0);
  CHECK_STATUS(embra_body_get_masses(w, body, NULL, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_get_masses(w, body, NULL, 5, &n), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_get_masses(w, body, masses, -1, &n), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_body_get_masses(NULL, body, masses, NET * NET, &n), EMBRA_ERROR_INVALID_ARGUMENT);

  after = capi_test_save(w);
  CHECK(before && after && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

int main(void) {
  RUN(test_compliance_and_rest);
  RUN(test_disable_move_remove);
  RUN(test_material);
  RUN(test_field);
  RUN(test_refusals);
  RUN(test_plasticity_and_broken);
  RUN(test_masses_hang);
  RUN(test_masses_uniform_scale);
  RUN(test_masses_heavier_half);
  RUN(test_masses_anchors_and_pins);
  RUN(test_masses_refusals);
  return capi_test_finish();
}
