/* What the fuzz targets (tests/fuzz) found, each as a plain test through embra.h (the input that
 * found it is replayed from tests/fuzz/regressions/ as well):
 *
 * - a hard-pinned particle the host moved with embra_world_set_positions glides back to its pin's
 *   target over the next step, in the world and in its saved and reloaded copy alike (the glide
 *   used to start from where the pin was at the end of the last step, which a saved scene does not
 *   hold, so the copy stepped differently);
 * - a collider the host moved with embra_collider_set_transform sweeps from its old pose over the
 *   next step, in the world and in its saved and reloaded copy alike (the saved scene held only the
 *   new pose, so the copy's collider stood still; /state/colliders now holds the frame's start);
 * - a hard pin's target moved 1e300 away (accepted: within EMBRA_MAX_ABS_VALUE) is reached in one
 *   frame at a speed beyond 1e300, which no scene can hold: the step stepped, and the saved world
 *   did not load back. Such a step now fails with EMBRA_ERROR_NUMERICAL and is undone, the members'
 *   forces and the worst constraints included (they read the failed frame's infinite multipliers, and
 *   the command line wrote "inf" into forces.json);
 * - a collider rotation a few ulp from unit length was normalized when set and normalized again
 *   when its saved scene was loaded, which changed its last bits: save, load, save differed.
 *   Normalizing is now idempotent (a rotation unit to rounding is kept as it is). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"

/* A rod of 4 particles along x, 0.1 m apart, stretch constraints generated. */
static void rod(embra_world* w) {
  static const int32_t edges[] = {0, 1, 1, 2, 2, 3};
  const double xyz[] = {0, 0, 1, 0.1, 0, 1, 0.2, 0, 1, 0.3, 0, 1};
  embra_body_def d = embra_default_body_def();
  embra_body_id id;
  d.vertex_count = 4;
  d.positions = xyz;
  d.edge_count = 3;
  d.edges = edges;
  d.material.mass = 0.4;
  CHECK_OK(embra_body_create(w, &d, &id, NULL));
}

static void test_moved_hard_pin_steps_the_same_after_save_and_load(void) {
  embra_solver_def s = embra_default_solver_def();
  embra_world* w = NULL;
  embra_world* copy = NULL;
  embra_pin_def pin = embra_default_pin_def();
  embra_pin_id pin_id;
  const double moved[3] = {0.05, 0.2, 1.3};
  double a[12], b[12];
  char *text, *again, *after_a, *after_b;
  int i;
  s.substeps = 4;
  CHECK_OK(embra_world_create(&w, &s));
  if (w == NULL) return;
  rod(w);
  pin.particle = 0;
  pin.target[2] = 1.0; /* where particle 0 is */
  CHECK_OK(embra_pin_create(w, &pin, &pin_id));
  CHECK_OK(embra_world_step(w)); /* the pin's target is where the frame ended */
  CHECK_OK(embra_world_set_positions(w, moved, 0, 1));

  text = capi_test_save(w);
  CHECK(text != NULL);
  if (text == NULL) return;
  CHECK_OK(embra_world_load_json(&copy, text, (int64_t)strlen(text), NULL));
  if (copy == NULL) return;
  again = capi_test_save(copy);
  CHECK(again != NULL && strcmp(text, again) == 0);

  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_step(copy));
  CHECK_OK(embra_world_get_positions(w, a, 12, 0, 4));
  CHECK_OK(embra_world_get_positions(copy, b, 12, 0, 4));
  CHECK(memcmp(a, b, sizeof a) == 0);
  /* The moved particle ends the step exactly on its pin's target. */
  CHECK_SAME_DOUBLE(a[0], 0.0);
  CHECK_SAME_DOUBLE(a[1], 0.0);
  CHECK_SAME_DOUBLE(a[2], 1.0);
  CHECK_OK(embra_world_get_velocities(w, a, 12, 0, 4));
  CHECK_OK(embra_world_get_velocities(copy, b, 12, 0, 4));
  CHECK(memcmp(a, b, sizeof a) == 0);
  /* It glided from where the host put it, a quarter of the way back in each of the 4 substeps:
   * its velocity is (target - moved) / dt. */
  for (i = 0; i < 3; ++i) CHECK_NEAR(a[i], ((i == 2 ? 1.0 : 0.0) - moved[i]) / s.dt, 1e-9);
  after_a = capi_test_save(w);
  after_b = capi_test_save(copy);
  CHECK(after_a != NULL && after_b != NULL && strcmp(after_a, after_b) == 0);

  free(text);
  free(again);
  free(after_a);
  free(after_b);
  embra_world_destroy(copy);
  embra_world_destroy(w);
}

/* The world and its saved-and-loaded copy step once and must agree to the byte. */
static void check_twins_step_alike(embra_world* w) {
  embra_world* copy = NULL;
  char* text = capi_test_save(w);
  char *again, *after_a, *after_b;
  CHECK(text != NULL);
  if (text == NULL) return;
  CHECK_OK(embra_world_load_json(&copy, text, (int64_t)strlen(text), NULL));
  if (copy == NULL) {
    free(text);
    return;
  }
  again = capi_test_save(copy);
  CHECK(again != NULL && strcmp(text, again) == 0);
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_step(copy));
  after_a = capi_test_save(w);
  after_b = capi_test_save(copy);
  CHECK(after_a != NULL && after_b != NULL && strcmp(after_a, after_b) == 0);
  free(text);
  free(again);
  free(after_a);
  free(after_b);
  embra_world_destroy(copy);
}

static void test_moved_collider_sweeps_the_same_after_save_and_load(void) {
  embra_world* w = NULL;
  embra_collider_def col = embra_default_collider_def();
  embra_collider_id cid;
  const double up[3] = {0.1, 0.0, 1.05};
  const double rot[4] = {1.0, 0.0, 0.0, 0.0};
  double x[12];
  char* text;
  int i;
  CHECK_OK(embra_world_create(&w, NULL));
  if (w == NULL) return;
  rod(w);
  col.shape = EMBRA_COLLIDER_SPHERE;
  col.radius = 0.2;
  col.position[0] = 0.1;
  col.position[2] = 0.5; /* below the rod */
  CHECK_OK(embra_collider_create(w, &col, &cid));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_collider_set_transform(w, cid, up, rot)); /* up through the rod's particle 1 */
  text = capi_test_save(w);
  CHECK(text != NULL && strstr(strstr(text, "\"state\""), "\"colliders\"") != NULL);
  free(text);
  check_twins_step_alike(w);
  /* The swept sphere carried the particles it passed: none is inside it. */
  CHECK_OK(embra_world_get_positions(w, x, 12, 0, 4));
  for (i = 0; i < 4; ++i) {
    const double dx = x[3 * i] - up[0], dy = x[3 * i + 1] - up[1], dz = x[3 * i + 2] - up[2];
    CHECK_MSG(dx * dx + dy * dy + dz * dz >= 0.2 * 0.2 * (1.0 - 1e-6), "particle %d is inside the sphere", i);
  }
  /* After the step the collider is where it was put: nothing more to sweep, nothing more saved. */
  text = capi_test_save(w);
  CHECK(text != NULL && strstr(strstr(text, "\"state\""), "\"colliders\"") == NULL);
  free(text);
  embra_world_destroy(w);
}

static void test_state_beyond_the_range_fails_the_step(void) {
  embra_world* w = NULL;
  embra_world* copy = NULL;
  embra_pin_def pin = embra_default_pin_def();
  embra_pin_id pin_id;
  embra_warning warning;
  const double far[3] = {-EMBRA_MAX_ABS_VALUE, -EMBRA_MAX_ABS_VALUE, 1e299};
  double before[12], after[12], forces_before[3], forces_after[3];
  embra_constraint_residual worst_before[3], worst_after[3];
  embra_group_id group;
  int64_t count = 0;
  int32_t worst_count = 0, worst_after_count = 0;
  char *text, *saved;
  int i;
  CHECK_OK(embra_world_create(&w, NULL));
  if (w == NULL) return;
  rod(w);
  pin.particle = 0;
  pin.target[2] = 1.0;
  CHECK_OK(embra_pin_create(w, &pin, &pin_id));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_pin_set_target(w, pin_id, far)); /* a target within the range is accepted */
  CHECK_OK(embra_world_get_positions(w, before, 12, 0, 4));
  CHECK_OK(embra_world_default_group(w, &group));
  CHECK_OK(embra_group_get_forces(w, group, EMBRA_CONSTRAINT_DISTANCE, forces_before, 3, &count));
  CHECK_OK(embra_world_get_worst_constraints(w, worst_before, 3, &worst_count));
  text = capi_test_save(w);
  CHECK_STATUS(embra_world_step(w), EMBRA_ERROR_NUMERICAL); /* reached at ~1e302 m/s */
  /* What the reports read is the last completed frame's too: the members' forces and the worst
   * constraints as before the failed step (the failed frame's multipliers were not finite). */
  CHECK_OK(embra_group_get_forces(w, group, EMBRA_CONSTRAINT_DISTANCE, forces_after, 3, &count));
  for (i = 0; i < 3; ++i) CHECK(isfinite(forces_before[i]) && forces_before[i] == forces_after[i]);
  CHECK_OK(embra_world_get_worst_constraints(w, worst_after, 3, &worst_after_count));
  CHECK_INT(worst_after_count, worst_count);
  for (i = 0; i < worst_count && i < worst_after_count; ++i) {
    CHECK(isfinite(worst_after[i].force) && isfinite(worst_after[i].residual));
    CHECK(worst_after[i].force == worst_before[i].force && worst_after[i].residual == worst_before[i].residual);
  }
  CHECK_OK(embra_world_get_warning(w, &warning));
  CHECK_INT(warning.particle, 0);
  CHECK_OK(embra_world_get_positions(w, after, 12, 0, 4));
  for (i = 0; i < 12; ++i) CHECK(before[i] == after[i]);
  saved = capi_test_save(w); /* the world is as before the step, and loads back */
  CHECK(text != NULL && saved != NULL && strcmp(text, saved) == 0);
  if (saved != NULL) {
    CHECK_OK(embra_world_load_json(&copy, saved, (int64_t)strlen(saved), NULL));
    embra_world_destroy(copy);
  }
  free(text);
  free(saved);
  embra_world_destroy(w);
}

static void test_collider_rotation_loads_back_to_the_same_bits(void) {
  embra_world* w = NULL;
  embra_world* copy = NULL;
  embra_collider_def col = embra_default_collider_def();
  embra_collider_id cid;
  const double at[3] = {1.796875, 1.796875, -1.328125};
  /* Not unit to the last bit: normalized when set, and that result must survive a reload. */
  const double rot[4] = {0.6920390075740227, -0.20161766362392786, -0.664793377354573, -0.19616853758003791};
  char *text, *again;
  CHECK_OK(embra_world_create(&w, NULL));
  if (w == NULL) return;
  col.shape = EMBRA_COLLIDER_SPHERE;
  col.radius = 0.2;
  CHECK_OK(embra_collider_create(w, &col, &cid));
  CHECK_OK(embra_collider_set_transform(w, cid, at, rot));
  text = capi_test_save(w);
  CHECK(text != NULL);
  if (text == NULL) return;
  CHECK_OK(embra_world_load_json(&copy, text, (int64_t)strlen(text), NULL));
  again = copy ? capi_test_save(copy) : NULL;
  CHECK(again != NULL && strcmp(text, again) == 0);
  free(text);
  free(again);
  embra_world_destroy(copy);
  embra_world_destroy(w);
}

int main(void) {
  RUN(test_moved_hard_pin_steps_the_same_after_save_and_load);
  RUN(test_moved_collider_sweeps_the_same_after_save_and_load);
  RUN(test_state_beyond_the_range_fails_the_step);
  RUN(test_collider_rotation_loads_back_to_the_same_bits);
  return capi_test_finish();
}
