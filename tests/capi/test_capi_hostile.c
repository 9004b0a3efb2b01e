/* What a hostile or careless host does to a world, and what embra.h promises it gets: a status,
 * never a crash, and a world that still saves and loads back.
 *
 * - every value the C API accepts (the extremes of RANGES AND LIMITS) saves and loads back, and
 *   the first value beyond each range is refused;
 * - a world whose group was destroyed still saves (a body naming it for a kind it does not
 *   generate names the default group instead; a group holding generated constraints stays);
 * - a failed step with scene actions leaves the saved scene byte-identical;
 * - an empty world steps; a huge dt with self-collision fails cleanly;
 * - the limits on particles and on work per step are refused before anything is allocated;
 * - a cancel request stops the next step and changes nothing, the last frame's contacts included. */
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"

/* Saves `w`, loads the text back and saves again: both texts must be the same bytes. */
static void check_round_trip(const embra_world* w, const char* what) {
  char* first = capi_test_save(w);
  embra_world* loaded = NULL;
  char* second = NULL;
  CAPI_CONTEXT("%s", what);
  CHECK_MSG(first != NULL, "save_json failed: %s", embra_last_error_message());
  if (first == NULL) return;
  CHECK_OK(embra_world_load_json(&loaded, first, (int64_t)strlen(first), NULL));
  if (loaded != NULL) {
    second = capi_test_save(loaded);
    CHECK(second != NULL && strcmp(first, second) == 0);
    embra_world_destroy(loaded);
  }
  free(first);
  free(second);
}

/* A 3 x 3 cloth of unit spacing (8 triangles) in `w`. */
static embra_body_id cloth(embra_world* w, double scale, double mass, int32_t* first) {
  static const int32_t tri[] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4, 3, 4, 7, 3, 7, 6, 4, 5, 8, 4, 8, 7};
  double xyz[27];
  embra_body_def d = embra_default_body_def();
  embra_body_id id = {0, 0};
  int i;
  for (i = 0; i < 9; ++i) {
    xyz[3 * i] = scale * (double)(i % 3);
    xyz[3 * i + 1] = scale * (double)(i / 3);
    xyz[3 * i + 2] = 0.0;
  }
  d.vertex_count = 9;
  d.positions = xyz;
  d.triangle_count = 8;
  d.triangles = tri;
  d.material.mass = mass;
  CHECK_OK(embra_body_create(w, &d, &id, first));
  return id;
}

static void test_extreme_values_round_trip(void) {
  embra_world* w = NULL;
  const double g[3] = {1e300, -1e300, 0.0};
  const double big[3] = {1e300, -1e300, 1e300};
  const double rot[4] = {1.0, 0.0, 0.0, 0.0};
  embra_pin_def pin = embra_default_pin_def();
  embra_collider_def col = embra_default_collider_def();
  embra_wind_def wind = embra_default_wind_def();
  embra_vortex_def vortex = embra_default_vortex_def();
  embra_tolerances tol = embra_default_tolerances();
  embra_pin_id pid;
  embra_collider_id cid;
  embra_field_id fid;
  int32_t first = 0;
  CHECK_OK(embra_world_create(&w, NULL));
  cloth(w, 1e70, 1e-290, &first); /* areas of 1e140, masses of 1e-291 per vertex */
  CHECK_OK(embra_world_set_gravity(w, g));
  CHECK_OK(embra_world_set_positions(w, big, first, 1));
  pin.particle = first + 8;
  memcpy(pin.target, big, sizeof pin.target);
  CHECK_OK(embra_pin_create(w, &pin, &pid));
  col.shape = EMBRA_COLLIDER_SPHERE;
  col.radius = 1e300;
  memcpy(col.position, big, sizeof col.position);
  CHECK_OK(embra_collider_create(w, &col, &cid));
  CHECK_OK(embra_collider_set_transform(w, cid, big, rot));
  wind.speed = 1e300;
  wind.air_density = 1e300;
  CHECK_OK(embra_wind_create(w, &wind, &fid));
  memcpy(vortex.center, big, sizeof vortex.center);
  vortex.strength = -1e300;
  CHECK_OK(embra_vortex_create(w, &vortex, &fid));
  tol.unit_scale = EMBRA_MAX_UNIT_SCALE;
  tol.thickness.max = 1e300;
  CHECK_OK(embra_world_set_tolerances(w, &tol));
  check_round_trip(w, "the API's extreme accepted values");
  embra_world_destroy(w);
}

/* The smallest positive sizes the API accepts (EMBRA_MIN_POSITIVE) save and load back, and a
 * plane collider's radius, which no plane uses, never reaches the scene. */
static void test_smallest_sizes_round_trip(void) {
  embra_world* w = NULL;
  embra_collider_def col = embra_default_collider_def();
  embra_vortex_def vortex = embra_default_vortex_def();
  embra_panel_mesh_def panels = embra_default_panel_mesh_def();
  embra_collider_id cid;
  embra_field_id fid;
  embra_body_id pb;
  int32_t first = 0;
  CHECK_OK(embra_world_create(&w, NULL));
  cloth(w, 1.0, 1.0, &first);
  col.shape = EMBRA_COLLIDER_SPHERE;
  col.radius = EMBRA_MIN_POSITIVE;
  CHECK_OK(embra_collider_create(w, &col, &cid));
  col.shape = EMBRA_COLLIDER_CAPSULE;
  CHECK_OK(embra_collider_create(w, &col, &cid));
  col.shape = EMBRA_COLLIDER_BOX;
  col.half_extents[0] = col.half_extents[1] = col.half_extents[2] = EMBRA_MIN_POSITIVE;
  CHECK_OK(embra_collider_create(w, &col, &cid));
  col.shape = EMBRA_COLLIDER_PLANE;
  col.radius = 0.0;
  CHECK_OK(embra_collider_create(w, &col, &cid));
  vortex.radius = EMBRA_MIN_POSITIVE;
  CHECK_OK(embra_vortex_create(w, &vortex, &fid));
  panels.grid_columns = 1;
  panels.grid_rows = 1;
  panels.thickness = EMBRA_MIN_POSITIVE;
  CHECK_OK(embra_panel_mesh_create(w, &panels, &pb, NULL));
  check_round_trip(w, "the API's smallest accepted sizes");
  embra_world_destroy(w);
}

/* Sizes below EMBRA_MIN_POSITIVE (positive, finite, but refused by the scene schema) are refused
 * by the API too, and change nothing. */
static void test_sizes_below_the_smallest_are_refused(void) {
  const double below = 1e-310; /* subnormal */
  embra_world* w = NULL;
  embra_collider_def col = embra_default_collider_def();
  embra_vortex_def vortex = embra_default_vortex_def();
  embra_panel_mesh_def panels = embra_default_panel_mesh_def();
  embra_collider_id cid;
  embra_field_id fid;
  embra_body_id pb;
  char* before;
  char* after;
  CHECK_OK(embra_world_create(&w, NULL));
  before = capi_test_save(w);
  col.shape = EMBRA_COLLIDER_SPHERE;
  col.radius = below;
  CHECK_STATUS(embra_collider_create(w, &col, &cid), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "sphere radius");
  col.shape = EMBRA_COLLIDER_CAPSULE;
  CHECK_STATUS(embra_collider_create(w, &col, &cid), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "capsule radius");
  col.shape = EMBRA_COLLIDER_BOX;
  col.half_extents[1] = below;
  CHECK_STATUS(embra_collider_create(w, &col, &cid), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "half_extents");
  vortex.radius = below;
  CHECK_STATUS(embra_vortex_create(w, &vortex, &fid), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "vortex radius");
  panels.grid_columns = 1;
  panels.grid_rows = 1;
  panels.thickness = below;
  CHECK_STATUS(embra_panel_mesh_create(w, &panels, &pb, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "panel thickness");
  panels.thickness = 0.01;
  panels.panel_size = below;
  CHECK_STATUS(embra_panel_mesh_create(w, &panels, &pb, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "panel size");
  after = capi_test_save(w);
  CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

static void test_values_beyond_the_ranges_are_refused(void) {
  embra_world* w = NULL;
  const double beyond = 1.0000001e300;
  const double g[3] = {beyond, 0.0, 0.0};
  const double tiny_mass = 4.9e-324;
  embra_body_def d = embra_default_body_def();
  embra_solver_def s = embra_default_solver_def();
  embra_tolerances tol = embra_default_tolerances();
  double xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  double masses[3] = {1.0, tiny_mass, 1.0};
  const int32_t tri[3] = {0, 1, 2};
  embra_body_id b;
  char* before;
  char* after;
  CHECK_OK(embra_world_create(&w, NULL));
  before = capi_test_save(w);
  CHECK_STATUS(embra_world_set_gravity(w, g), EMBRA_ERROR_INVALID_ARGUMENT);
  d.vertex_count = 3;
  d.positions = xyz;
  d.triangle_count = 1;
  d.triangles = tri;
  d.masses = masses;
  CHECK_STATUS(embra_body_create(w, &d, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "mass");
  d.masses = NULL;
  d.material.mass = tiny_mass;
  CHECK_STATUS(embra_body_create(w, &d, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  d.material.mass = 1.0;
  xyz[4] = beyond;
  CHECK_STATUS(embra_body_create(w, &d, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "1e300");
  xyz[4] = 0.0;
  /* A body whose size overflows when squared, and masses spread below the smallest. */
  d.material.mass = 1.0;
  xyz[3] = 1e200;
  xyz[7] = 1e200;
  CHECK_STATUS(embra_body_create(w, &d, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "too large");
  xyz[3] = 1.0;
  xyz[7] = 1.0;
  d.material.mass = 2e-300;
  CHECK_STATUS(embra_body_create(w, &d, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "inverse");
  tol.unit_scale = EMBRA_MAX_UNIT_SCALE * 1.001;
  CHECK_STATUS(embra_world_set_tolerances(w, &tol), EMBRA_ERROR_INVALID_ARGUMENT);
  s.dt = EMBRA_MAX_DT * 1.001;
  CHECK_STATUS(embra_world_set_solver(w, &s), EMBRA_ERROR_INVALID_ARGUMENT);
  s = embra_default_solver_def();
  s.substeps = 1000;
  s.iterations = 101; /* 101,000 passes per step */
  CHECK_STATUS(embra_world_set_solver(w, &s), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "100000");
  s.iterations = 100;
  CHECK_OK(embra_world_set_solver(w, &s));
  s = embra_default_solver_def();
  CHECK_OK(embra_world_set_solver(w, &s));
  after = capi_test_save(w);
  CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

static void test_particle_limit(void) {
  embra_world* w = NULL;
  embra_body_def d = embra_default_body_def();
  const int32_t n = EMBRA_MAX_PARTICLES + 1;
  double* xyz = (double*)calloc((size_t)3 * (size_t)n, sizeof(double));
  embra_body_id b;
  int32_t i;
  embra_world_counts c;
  CHECK(xyz != NULL);
  if (xyz == NULL) return;
  for (i = 0; i < n; ++i) xyz[3 * i] = (double)i;
  CHECK_OK(embra_world_create(&w, NULL));
  d.vertex_count = n;
  d.positions = xyz;
  d.generate = 0;
  d.material.mass = 1.0;
  CHECK_STATUS(embra_body_create(w, &d, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "2097152");
  CHECK_OK(embra_world_get_counts(w, &c));
  CHECK_INT(c.particles, 0);
  {
    /* 4096 x 4096 panels: 134 million particles, refused before anything is generated. */
    embra_panel_mesh_def p = embra_default_panel_mesh_def();
    p.grid_columns = 4096;
    p.grid_rows = 4096;
    CHECK_STATUS(embra_panel_mesh_create(w, &p, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
    CHECK_CONTAINS(embra_last_error_message(), "2097152");
    p.grid_columns = 512;
    p.grid_rows = 513; /* one row of panels beyond 512 x 512 = 2,097,152 particles */
    CHECK_STATUS(embra_panel_mesh_create(w, &p, &b, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  }
  CHECK_OK(embra_world_get_counts(w, &c));
  CHECK_INT(c.particles, 0);
  embra_world_destroy(w);
  free(xyz);
}

/* A body naming a group for a kind it does not generate; the group destroyed; the world saves. */
static void test_destroyed_group_still_saves(void) {
  embra_world* w = NULL;
  embra_group_def gd = embra_default_group_def();
  embra_group_id bend, stretch;
  embra_body_def d = embra_default_body_def();
  static const double xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  static const int32_t tri[3] = {0, 1, 2};
  embra_body_id b;
  char* text;
  CHECK_OK(embra_world_create(&w, NULL));
  CHECK_OK(embra_group_create(w, &gd, &bend));
  CHECK_OK(embra_group_create(w, &gd, &stretch));
  d.vertex_count = 3;
  d.positions = xyz;
  d.triangle_count = 1;
  d.triangles = tri;
  d.material.mass = 1.0;
  d.generate = EMBRA_GENERATE_STRETCH;
  d.stretch_group = stretch;
  d.bend_group = bend;
  CHECK_OK(embra_body_create(w, &d, &b, NULL));
  CHECK_OK(embra_group_destroy(w, bend));
  text = capi_test_save(w);
  CHECK_MSG(text != NULL, "save_json after destroying a named, unused group: %s", embra_last_error_message());
  free(text);
  CHECK_OK(embra_world_step(w));
  check_round_trip(w, "a world whose bend group was destroyed");
  /* The group holding the body's generated stretch constraints stays. */
  text = capi_test_save(w);
  CHECK_STATUS(embra_group_destroy(w, stretch), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "stretch");
  {
    char* again = capi_test_save(w);
    CHECK(text != NULL && again != NULL && strcmp(text, again) == 0);
    free(again);
  }
  free(text);
  embra_world_destroy(w);
}

/* Gravity ramps to -1e300 by frame 2 (an action), which sends the cloth to infinity: the failed
 * step must leave the world, its gravity and pin target, as saved before the call. */
static void test_failed_step_with_actions_changes_nothing(void) {
  static const char scene[] =
      "{\"format\": \"embra-scene\", \"version\": 1, \"name\": \"ramp\","
      " \"solver\": {\"dt\": 1e6, \"substeps\": 2},"
      " \"bodies\": [{\"name\": \"c\", \"mesh\": {\"generator\": \"grid\", \"size\": [1, 1], \"resolution\": [3, 3]},"
      "   \"material\": {\"mass\": 1}}],"
      " \"pins\": [{\"name\": \"p\", \"particle\": {\"body\": \"c\", \"vertex\": 0}}],"
      " \"actions\": [{\"type\": \"gravity\", \"keys\": [{\"frame\": 0, \"value\": [0, 0, -9.81]},"
      "     {\"frame\": 2, \"value\": [0, 0, -1e300]}]},"
      "   {\"type\": \"pin_target\", \"pin\": \"p\", \"keys\": [{\"frame\": 0, \"value\": [0, 0, 0]},"
      "     {\"frame\": 2, \"value\": [5, 5, 5]}]}]}";
  embra_world* w = NULL;
  embra_status st = EMBRA_OK;
  int frame;
  CHECK_OK(embra_world_load_json(&w, scene, (int64_t)strlen(scene), NULL));
  if (w == NULL) return;
  for (frame = 0; frame < 4 && st == EMBRA_OK; ++frame) {
    char* before = capi_test_save(w);
    st = embra_world_step(w);
    if (st != EMBRA_OK) {
      char* after = capi_test_save(w);
      CHECK_INT(st, EMBRA_ERROR_NUMERICAL);
      CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
      free(after);
    }
    free(before);
  }
  CHECK_INT(st, EMBRA_ERROR_NUMERICAL);
  embra_world_destroy(w);
}

static void test_empty_world_steps(void) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  embra_step_report r;
  s.self_collision = 1;
  CHECK_OK(embra_world_create(&w, &s));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_report(w, &r));
  CHECK_INT(r.frame, 1);
  embra_world_destroy(w);
}

/* The largest dt with self-collision on and an enormous gravity: the state overflows; the step
 * says so and the world is as before (UBSan checks the self-collision grid's arithmetic). */
static void test_huge_dt_with_self_collision(void) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  const double g[3] = {0.0, 0.0, -1e300};
  int32_t first = 0;
  char* before;
  char* after;
  s.self_collision = 1;
  s.dt = EMBRA_MAX_DT;
  CHECK_OK(embra_world_create(&w, &s));
  cloth(w, 0.1, 1.0, &first);
  CHECK_OK(embra_world_set_gravity(w, g));
  before = capi_test_save(w);
  CHECK_STATUS(embra_world_step(w), EMBRA_ERROR_NUMERICAL);
  after = capi_test_save(w);
  CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

static void test_cancel_before_a_step(void) {
  embra_world* w = NULL;
  int32_t first = 0;
  char* before;
  char* after;
  embra_step_report r;
  CHECK_STATUS(embra_world_cancel(NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_OK(embra_world_create(&w, NULL));
  cloth(w, 0.1, 1.0, &first);
  CHECK_OK(embra_world_step(w));
  before = capi_test_save(w);
  CHECK_OK(embra_world_cancel(w));
  CHECK_STATUS(embra_world_step(w), EMBRA_ERROR_CANCELLED);
  CHECK_STR(embra_status_name(EMBRA_ERROR_CANCELLED), "EMBRA_ERROR_CANCELLED");
  after = capi_test_save(w);
  CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
  CHECK_OK(embra_world_step(w)); /* the request was consumed */
  CHECK_OK(embra_world_get_report(w, &r));
  CHECK_INT(r.frame, 2);
  free(before);
  free(after);
  embra_world_destroy(w);
}

/* A cloth landing on the floor: the saved world carries the last frame's contact forces, and a
 * cancelled step keeps them. */
static void test_cancel_keeps_the_contacts(void) {
  embra_world* w = NULL;
  embra_collider_def ground = embra_default_collider_def(); /* a plane, normal +z */
  embra_collider_id cid;
  int32_t first = 0;
  char* before;
  char* after;
  CHECK_OK(embra_world_create(&w, NULL));
  cloth(w, 0.1, 1.0, &first);
  ground.position[2] = -0.001;
  CHECK_OK(embra_collider_create(w, &ground, &cid));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_step(w));
  before = capi_test_save(w);
  CHECK(before != NULL && strstr(before, "\"force_h2\"") != NULL);
  CHECK_OK(embra_world_cancel(w));
  CHECK_STATUS(embra_world_step(w), EMBRA_ERROR_CANCELLED);
  after = capi_test_save(w);
  CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

int main(void) {
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) return 1;
  RUN(test_extreme_values_round_trip);
  RUN(test_smallest_sizes_round_trip);
  RUN(test_sizes_below_the_smallest_are_refused);
  RUN(test_values_beyond_the_ranges_are_refused);
  RUN(test_particle_limit);
  RUN(test_destroyed_group_still_saves);
  RUN(test_failed_step_with_actions_changes_nothing);
  RUN(test_empty_world_steps);
  RUN(test_huge_dt_with_self_collision);
  RUN(test_cancel_before_a_step);
  RUN(test_cancel_keeps_the_contacts);
  return capi_test_finish();
}
