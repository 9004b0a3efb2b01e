/* test_capi_fields.c - the field calls (wind, pressure, surface tension, vortex): their defaults,
 * every refusal (which changes nothing) and one closed-form physical answer each. */
#include "capi_test.h"

#include <math.h>
#include <stdlib.h>

/* A world with no gravity, one substep of 0.01 s, and two bodies: a closed tetrahedron (wound
 * outwards) and a lone triangle in the x-y plane (normal +z), each vertex 1 kg. */
typedef struct {
  embra_world* w;
  embra_body_id tet, tri;
  int32_t tet_first, tri_first;
} fixture;

static const double kTetXyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const int32_t kTetTris[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
static const double kTriXyz[9] = {0, 0, 5, 1, 0, 5, 0, 1, 5};
static const int32_t kTriTris[3] = {0, 1, 2};
static const double kOnes[4] = {1, 1, 1, 1};

static int fixture_make(fixture* f, int generate) {
  embra_solver_def s = embra_default_solver_def();
  embra_body_def b;
  s.gravity[2] = 0.0;
  s.substeps = 1;
  s.iterations = 20;
  s.dt = 0.01;
  if (embra_world_create(&f->w, &s) != EMBRA_OK) return 0;
  b = embra_default_body_def();
  b.vertex_count = 4;
  b.positions = kTetXyz;
  b.masses = kOnes;
  b.triangle_count = 4;
  b.triangles = kTetTris;
  b.generate = generate;
  if (embra_body_create(f->w, &b, &f->tet, &f->tet_first) != EMBRA_OK) return 0;
  b.vertex_count = 3;
  b.positions = kTriXyz;
  b.triangle_count = 1;
  b.triangles = kTriTris;
  return embra_body_create(f->w, &b, &f->tri, &f->tri_first) == EMBRA_OK;
}

static int32_t field_count(const embra_world* w) {
  int32_t n = -1;
  embra_world_get_field_count(w, &n);
  return n;
}

static double tet_volume(const double* x) {
  double a[3], b[3], c[3];
  int k;
  for (k = 0; k < 3; ++k) {
    a[k] = x[3 + k] - x[k];
    b[k] = x[6 + k] - x[k];
    c[k] = x[9 + k] - x[k];
  }
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6.0;
}

static void test_defaults(void) {
  embra_wind_def w = embra_default_wind_def();
  embra_pressure_def p = embra_default_pressure_def();
  embra_surface_tension_def t = embra_default_surface_tension_def();
  embra_vortex_def v = embra_default_vortex_def();
  CHECK_INT(w.version, EMBRA_WIND_DEF_VERSION);
  CHECK(w.direction[0] == 1.0 && w.speed == 0.0 && w.air_density == 1.2 && w.drag == 1.0 && w.lift == 1.0);
  CHECK_INT(p.version, EMBRA_PRESSURE_DEF_VERSION);
  CHECK(p.keep_volume == 0 && p.inside_pressure == 0.0 && p.rest_volume == 0.0);
  CHECK_INT(t.version, EMBRA_SURFACE_TENSION_DEF_VERSION);
  CHECK(t.tension == 0.0 && t.regularisation == 1.0);
  CHECK_INT(v.version, EMBRA_VORTEX_DEF_VERSION);
  CHECK(v.axis[2] == 1.0 && v.radius == 1.0 && v.decay == 0.0);
}

/* Every refusal leaves the field count where it was. */
static void test_refusals(void) {
  fixture f;
  embra_field_id id;
  embra_body_id stale = {7, 1}, none = {0, 0};
  embra_wind_def w;
  embra_pressure_def p;
  embra_surface_tension_def t;
  embra_vortex_def v;
  if (!CHECK(fixture_make(&f, EMBRA_GENERATE_STRETCH))) return;
  w = embra_default_wind_def();
  CHECK_STATUS(embra_wind_create(NULL, &w, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_wind_create(f.w, NULL, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_wind_create(f.w, &w, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  w.version = 99;
  CHECK_STATUS(embra_wind_create(f.w, &w, &id), EMBRA_ERROR_VERSION);
  w = embra_default_wind_def();
  w.direction[0] = 0.0;
  CHECK_STATUS(embra_wind_create(f.w, &w, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  w = embra_default_wind_def();
  w.speed = NAN;
  CHECK_STATUS(embra_wind_create(f.w, &w, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  w = embra_default_wind_def();
  w.drag = -1.0;
  CHECK_STATUS(embra_wind_create(f.w, &w, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  w = embra_default_wind_def();
  w.body = stale;
  CHECK_STATUS(embra_wind_create(f.w, &w, &id), EMBRA_ERROR_STALE_ID);

  p = embra_default_pressure_def();
  p.body = none;
  CHECK_STATUS(embra_pressure_create(f.w, &p, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  p.body = f.tri; /* open */
  CHECK_STATUS(embra_pressure_create(f.w, &p, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "closed");
  p.body = f.tet;
  p.keep_volume = 2;
  CHECK_STATUS(embra_pressure_create(f.w, &p, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  p.keep_volume = 0;
  p.inside_pressure = INFINITY;
  CHECK_STATUS(embra_pressure_create(f.w, &p, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  p.inside_pressure = 0.0;
  p.rest_volume = -1.0;
  CHECK_STATUS(embra_pressure_create(f.w, &p, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  p.rest_volume = 0.0;
  p.version = 0;
  CHECK_STATUS(embra_pressure_create(f.w, &p, &id), EMBRA_ERROR_VERSION);

  t = embra_default_surface_tension_def();
  CHECK_STATUS(embra_surface_tension_create(f.w, &t, &id), EMBRA_ERROR_INVALID_ARGUMENT); /* no body */
  t.body = f.tri;
  t.regularisation = -0.5;
  CHECK_STATUS(embra_surface_tension_create(f.w, &t, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  t.regularisation = 1.0;
  t.tension = NAN;
  CHECK_STATUS(embra_surface_tension_create(f.w, &t, &id), EMBRA_ERROR_INVALID_ARGUMENT);

  v = embra_default_vortex_def();
  v.axis[2] = 0.0;
  CHECK_STATUS(embra_vortex_create(f.w, &v, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  v = embra_default_vortex_def();
  v.radius = 0.0;
  CHECK_STATUS(embra_vortex_create(f.w, &v, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  v = embra_default_vortex_def();
  v.decay = -1.0;
  CHECK_STATUS(embra_vortex_create(f.w, &v, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  v = embra_default_vortex_def();
  v.center[1] = NAN;
  CHECK_STATUS(embra_vortex_create(f.w, &v, &id), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_INT(field_count(f.w), 0);

  /* Destroy: the id goes stale. */
  v = embra_default_vortex_def();
  CHECK_OK(embra_vortex_create(f.w, &v, &id));
  CHECK_INT(field_count(f.w), 1);
  CHECK_OK(embra_field_destroy(f.w, id));
  CHECK_INT(field_count(f.w), 0);
  CHECK_STATUS(embra_field_destroy(f.w, id), EMBRA_ERROR_STALE_ID);
  CHECK_STATUS(embra_field_destroy(NULL, id), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_field_count(f.w, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  embra_world_destroy(f.w);
}

/* Wind straight at a triangle (flow along its normal): no lift, drag
 * 0.5 rho v^2 A, a third on each 1 kg corner: after one 0.01 s step each corner moves at
 * 0.01 * drag / 3 along the flow (to the rounding of a velocity read back as a position change at
 * z = 5 over 0.01 s: 5 * 2^-52 / 0.01 = 1.1e-13). */
static void test_wind_drag(void) {
  fixture f;
  embra_field_id id;
  embra_wind_def w = embra_default_wind_def();
  double v[9];
  int k;
  if (!CHECK(fixture_make(&f, EMBRA_GENERATE_STRETCH))) return;
  w.body = f.tri;
  w.direction[0] = 0.0;
  w.direction[2] = 3.0; /* any length */
  w.speed = 2.0;
  CHECK_OK(embra_wind_create(f.w, &w, &id));
  CHECK_OK(embra_world_step(f.w));
  CHECK_OK(embra_world_get_velocities(f.w, v, 9, f.tri_first, 3));
  for (k = 0; k < 3; ++k) {
    CHECK_NEAR(v[3 * k + 2], 0.01 * (0.5 * 1.2 * 4.0 * 0.5) / 3.0, 2.5e-13);
    CHECK_NEAR(v[3 * k], 0.0, 1e-14);
  }
  embra_world_destroy(f.w);
}

/* Pressure inside a free tetrahedron pushes it apart with no net force (momentum stays zero) and
 * grows its volume; a hard volume constraint instead brings the volume to its rest value. */
static void test_pressure_and_volume(void) {
  fixture f;
  embra_field_id id;
  embra_pressure_def p = embra_default_pressure_def();
  double x[12], v[12], m[3] = {0, 0, 0};
  int k, i;
  if (!CHECK(fixture_make(&f, 0))) return;
  p.body = f.tet;
  p.inside_pressure = 100.0;
  p.outside_pressure = 20.0;
  CHECK_OK(embra_pressure_create(f.w, &p, &id));
  for (i = 0; i < 5; ++i) CHECK_OK(embra_world_step(f.w));
  CHECK_OK(embra_world_get_velocities(f.w, v, 12, f.tet_first, 4));
  CHECK_OK(embra_world_get_positions(f.w, x, 12, f.tet_first, 4));
  for (i = 0; i < 4; ++i)
    for (k = 0; k < 3; ++k) m[k] += v[3 * i + k];
  CHECK_NEAR(sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]), 0.0, 1e-12);
  CHECK(tet_volume(x) > 1.0 / 6.0);
  embra_world_destroy(f.w);

  if (!CHECK(fixture_make(&f, 0))) return;
  p = embra_default_pressure_def();
  p.body = f.tet;
  p.keep_volume = 1;
  p.rest_volume = 2.0 / 6.0;
  CHECK_OK(embra_pressure_create(f.w, &p, &id));
  for (i = 0; i < 10; ++i) CHECK_OK(embra_world_step(f.w));
  CHECK_OK(embra_world_get_positions(f.w, x, 12, f.tet_first, 4));
  CHECK_NEAR(tet_volume(x), 2.0 / 6.0, 1e-12);
  embra_world_destroy(f.w);
}

/* A particle at the falloff radius on the vortex's x axis: after one 0.01 s step it moves at
 * 0.01 * strength * e^-1 along +y (axis z x offset x). Decay 1/s from t = 0: the first substep
 * starts at t = 0, so no decay yet. */
static void test_vortex(void) {
  fixture f;
  embra_field_id id;
  embra_vortex_def d = embra_default_vortex_def();
  double v[3];
  if (!CHECK(fixture_make(&f, 0))) return;
  d.body = f.tet;
  d.radius = 1.0;
  d.strength = 3.0;
  d.decay = 1.0;
  CHECK_OK(embra_vortex_create(f.w, &d, &id));
  CHECK_OK(embra_world_step(f.w));
  CHECK_OK(embra_world_get_velocities(f.w, v, 3, f.tet_first + 1, 1)); /* vertex (1, 0, 0) */
  CHECK_NEAR(v[1], 0.01 * 3.0 * exp(-1.0), 1e-14);
  CHECK_NEAR(v[0], 0.0, 1e-14);
  embra_world_destroy(f.w);
}

int main(void) {
  RUN(test_defaults);
  RUN(test_refusals);
  RUN(test_wind_drag);
  RUN(test_pressure_and_volume);
  RUN(test_vortex);
  return capi_test_finish();
}
