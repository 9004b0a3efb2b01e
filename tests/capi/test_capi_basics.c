/* C-ABI basics: versions and the ABI check, status names, the last-error message, the layout of
 * every public struct (what a ctypes or P/Invoke mirror relies on), the documented defaults of
 * every embra_default_* function, and the life of an empty world. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <string.h>

#include "capi_test.h"

static void test_versions(void) {
  char expected[64];
  CHECK_INT(embra_version(), EMBRA_VERSION_MAJOR * 10000 + EMBRA_VERSION_MINOR * 100 + EMBRA_VERSION_PATCH);
  CHECK_STR(embra_version_string(), EMBRA_VERSION_STRING);
  snprintf(expected, sizeof expected, "%d.%d.%d", EMBRA_VERSION_MAJOR, EMBRA_VERSION_MINOR, EMBRA_VERSION_PATCH);
  CHECK_STR(embra_version_string(), expected);
  CHECK(embra_version_string() == embra_version_string()); /* static: the same pointer every call */
  CHECK_INT(embra_abi_version(), EMBRA_ABI_VERSION);
}

static void test_check_abi(void) {
  CHECK_OK(embra_check_abi(EMBRA_ABI_VERSION));
  CHECK_STATUS(embra_check_abi(EMBRA_ABI_VERSION + 1), EMBRA_ERROR_VERSION);
  CHECK_CONTAINS(embra_last_error_message(), "embra_check_abi");
  CHECK_CONTAINS(embra_last_error_message(), "ABI");
  CHECK_STATUS(embra_check_abi(-1), EMBRA_ERROR_VERSION);
  CHECK_CONTAINS(embra_last_error_message(), "-1");
  CHECK_STATUS(embra_check_abi(INT32_MAX), EMBRA_ERROR_VERSION);
  CHECK_STATUS(embra_check_abi(INT32_MIN), EMBRA_ERROR_VERSION);
  /* A successful call leaves the last failure's message in place ("the last failed call"). */
  CHECK_OK(embra_check_abi(EMBRA_ABI_VERSION));
  CHECK_CONTAINS(embra_last_error_message(), "embra_check_abi");
}

static void test_status_names(void) {
  static const struct {
    embra_status status;
    const char* name;
  } codes[] = {
      {EMBRA_OK, "EMBRA_OK"},
      {EMBRA_ERROR_INVALID_ARGUMENT, "EMBRA_ERROR_INVALID_ARGUMENT"},
      {EMBRA_ERROR_STALE_ID, "EMBRA_ERROR_STALE_ID"},
      {EMBRA_ERROR_BUFFER_TOO_SMALL, "EMBRA_ERROR_BUFFER_TOO_SMALL"},
      {EMBRA_ERROR_SCHEMA, "EMBRA_ERROR_SCHEMA"},
      {EMBRA_ERROR_VERSION, "EMBRA_ERROR_VERSION"},
      {EMBRA_ERROR_LOCKED, "EMBRA_ERROR_LOCKED"},
      {EMBRA_ERROR_NUMERICAL, "EMBRA_ERROR_NUMERICAL"},
      {EMBRA_ERROR_INTERNAL, "EMBRA_ERROR_INTERNAL"},
  };
  static const embra_status unknown[] = {1, 2, -9, -100, INT32_MAX, INT32_MIN};
  size_t i, k;
  /* The documented values of the codes. */
  CHECK_INT(EMBRA_OK, 0);
  CHECK_INT(EMBRA_ERROR_INVALID_ARGUMENT, -1);
  CHECK_INT(EMBRA_ERROR_STALE_ID, -2);
  CHECK_INT(EMBRA_ERROR_BUFFER_TOO_SMALL, -3);
  CHECK_INT(EMBRA_ERROR_SCHEMA, -4);
  CHECK_INT(EMBRA_ERROR_VERSION, -5);
  CHECK_INT(EMBRA_ERROR_LOCKED, -6);
  CHECK_INT(EMBRA_ERROR_NUMERICAL, -7);
  CHECK_INT(EMBRA_ERROR_INTERNAL, -8);
  for (i = 0; i < sizeof codes / sizeof codes[0]; ++i) {
    CAPI_CONTEXT("status %d", (int)codes[i].status);
    CHECK_STR(embra_status_name(codes[i].status), codes[i].name);
  }
  for (i = 0; i < sizeof unknown / sizeof unknown[0]; ++i) {
    const char* name = embra_status_name(unknown[i]);
    CAPI_CONTEXT("unknown status %ld", (long)unknown[i]);
    CHECK(name != NULL);
    if (name == NULL) continue;
    CHECK(name[0] != '\0');
    for (k = 0; k < sizeof codes / sizeof codes[0]; ++k) CHECK(strcmp(name, codes[k].name) != 0);
  }
}

/* The public structs have no padding and the sizes a hand-written FFI mirror computes. */
static void test_struct_layout(void) {
  const size_t id = 2 * sizeof(uint32_t);
  const size_t ptr = sizeof(void*);
  CHECK_INT(sizeof(embra_status), 4);
  CHECK_INT(sizeof(embra_constraint_kind), 4);
  CHECK_INT(sizeof(embra_collider_shape), 4);
  CHECK_INT(sizeof(embra_group_id), 8);
  CHECK_INT(sizeof(embra_body_id), 8);
  CHECK_INT(sizeof(embra_pin_id), 8);
  CHECK_INT(sizeof(embra_collider_id), 8);
  CHECK_INT(offsetof(embra_group_id, generation), 4);

  CHECK_INT(sizeof(embra_solver_def), 10 * 4 + 6 * 8);
  CHECK_INT(offsetof(embra_solver_def, substeps), 4);
  CHECK_INT(offsetof(embra_solver_def, dt), 8);
  CHECK_INT(offsetof(embra_solver_def, iterations), 16);
  CHECK_INT(offsetof(embra_solver_def, chebyshev_rho_milli), 20);
  CHECK_INT(offsetof(embra_solver_def, gravity), 24);
  CHECK_INT(offsetof(embra_solver_def, damping), 48);
  CHECK_INT(offsetof(embra_solver_def, settle_speed), 56);
  CHECK_INT(offsetof(embra_solver_def, tethers), 64);
  CHECK_INT(offsetof(embra_solver_def, self_collision), 72);
  CHECK_INT(offsetof(embra_solver_def, chain_solve), 76);
  CHECK_INT(offsetof(embra_solver_def, threads), 80);
  CHECK_INT(offsetof(embra_solver_def, global_solve), 84);

  CHECK_INT(sizeof(embra_world_counts), 6 * 4 + 8);
  CHECK_INT(offsetof(embra_world_counts, constraints), 24);
  CHECK_INT(sizeof(embra_group_def), 12);

  CHECK_INT(sizeof(embra_material), 10 * 8);
  CHECK_INT(offsetof(embra_material, friction_dynamic), 72);

  CHECK_INT(sizeof(embra_body_def), 8 + 3 * ptr + 8 + 3 * ptr + 8 + sizeof(embra_material) + 4 * id);
  CHECK_INT(offsetof(embra_body_def, positions), 8);
  CHECK_INT(offsetof(embra_body_def, edge_count), 8 + 3 * ptr);
  CHECK_INT(offsetof(embra_body_def, tet_count), 16 + 6 * ptr);
  CHECK_INT(offsetof(embra_body_def, material), 24 + 6 * ptr);
  CHECK_INT(offsetof(embra_body_def, stretch_group), 24 + 6 * ptr + sizeof(embra_material));
  CHECK_INT(offsetof(embra_body_def, volume_group), 24 + 6 * ptr + sizeof(embra_material) + 3 * id);

  CHECK_INT(sizeof(embra_constraint_def), 4 + 4 + id + 16 + 4 + 4 + 8 + 8);
  CHECK_INT(offsetof(embra_constraint_def, particles), 16);
  CHECK_INT(offsetof(embra_constraint_def, rest), 40);
  CHECK_INT(sizeof(embra_constraint_batch_def), 4 + 4 + id + 4 + 4 + 3 * ptr + 8);
  CHECK_INT(offsetof(embra_constraint_batch_def, particles), 24);
  CHECK_INT(offsetof(embra_constraint_batch_def, compliance), 24 + 3 * ptr);

  CHECK_INT(sizeof(embra_pin_def), 4 + 4 + 24 + 8 + id);
  CHECK_INT(offsetof(embra_pin_def, target), 8);
  CHECK_INT(offsetof(embra_pin_def, group), 40);

  CHECK_INT(sizeof(embra_collider_def), 4 + 4 + 24 + 32 + 4 * 8 + 24 + 8 + 4 + 4 + 2 * (int)sizeof(void*));
  CHECK_INT(offsetof(embra_collider_def, half_extents), 96);
  CHECK_INT(offsetof(embra_collider_def, vertex_count), 128);
  CHECK_INT(offsetof(embra_collider_def, vertices), 136);
  CHECK_INT(offsetof(embra_collider_def, rotation), 32);
  CHECK_INT(offsetof(embra_collider_def, radius), 64);

  CHECK_INT(sizeof(embra_step_report), 8 * 8 + 2 * 4);
  CHECK_INT(offsetof(embra_step_report, settled), 64);
  CHECK_INT(sizeof(embra_group_report), 24);
  CHECK_INT(sizeof(embra_warning), 16);
}

static void test_defaults(void) {
  const embra_solver_def s = embra_default_solver_def();
  const embra_group_def g = embra_default_group_def();
  const embra_material m = embra_default_material();
  const embra_body_def b = embra_default_body_def();
  const embra_constraint_def c = embra_default_constraint_def();
  const embra_constraint_batch_def cb = embra_default_constraint_batch_def();
  const embra_pin_def p = embra_default_pin_def();
  const embra_collider_def k = embra_default_collider_def();

  CHECK_INT(s.version, EMBRA_SOLVER_DEF_VERSION);
  CHECK_INT(s.substeps, 16);
  CHECK_NEAR(s.dt, 1.0 / 60.0, 0.0);
  CHECK_INT(s.iterations, 1);
  CHECK_INT(s.chebyshev_rho_milli, 0);
  CHECK_NEAR(s.gravity[0], 0.0, 0.0);
  CHECK_NEAR(s.gravity[1], 0.0, 0.0);
  CHECK_NEAR(s.gravity[2], -9.81, 0.0);
  CHECK_NEAR(s.damping, 0.0, 0.0);
  CHECK_NEAR(s.settle_speed, 1e-3, 0.0);
  CHECK_INT(s.tethers, 2);
  CHECK_INT(s.threads, 1);
  {
    /* The form-finding preset: the defaults but for dt 1/15 s, 1 substep, 1 iteration, damping 6/s and
       the global solve on while its system is small. */
    embra_solver_def f = embra_form_finding_solver_def(), d = s;
    CHECK_NEAR(f.dt, 1.0 / 15.0, 0.0);
    CHECK_INT(f.substeps, 1);
    CHECK_INT(f.iterations, 1);
    CHECK_NEAR(f.damping, 6.0, 0.0);
    CHECK_INT(f.global_solve, EMBRA_GLOBAL_SOLVE_AUTO);
    CHECK_INT(s.global_solve, 0);
    d.global_solve = f.global_solve;
    d.dt = f.dt;
    d.substeps = f.substeps;
    d.iterations = f.iterations;
    d.damping = f.damping;
    CHECK(memcmp(&d, &f, sizeof d) == 0);
  }

  CHECK_INT(g.version, EMBRA_GROUP_DEF_VERSION);
  CHECK_INT(g.order, 0);
  CHECK_INT(g.weight, 1);

  CHECK_NEAR(m.mass, 0.0, 0.0);
  CHECK_NEAR(m.density, 1.0, 0.0);
  CHECK_NEAR(m.stretch_compliance, 0.0, 0.0);
  CHECK_NEAR(m.shear_compliance, 0.0, 0.0);
  CHECK_NEAR(m.bend_compliance, 1.0, 0.0);
  CHECK_NEAR(m.volume_compliance, 0.0, 0.0);
  CHECK_NEAR(m.damping, 0.0, 0.0);
  CHECK_NEAR(m.thickness, 0.0, 0.0);
  CHECK_NEAR(m.friction_static, 0.5, 0.0);
  CHECK_NEAR(m.friction_dynamic, 0.3, 0.0);

  CHECK_INT(b.version, EMBRA_BODY_DEF_VERSION);
  CHECK_INT(b.vertex_count, 0);
  CHECK(b.positions == NULL && b.masses == NULL && b.uvs == NULL);
  CHECK(b.edges == NULL && b.triangles == NULL && b.tets == NULL);
  CHECK_INT(b.edge_count, 0);
  CHECK_INT(b.triangle_count, 0);
  CHECK_INT(b.tet_count, 0);
  CHECK_INT(b.generate, EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_BEND | EMBRA_GENERATE_VOLUME);
  CHECK(memcmp(&b.material, &m, sizeof m) == 0);
  CHECK(b.stretch_group.index == 0 && b.stretch_group.generation == 0);
  CHECK(b.shear_group.index == 0 && b.shear_group.generation == 0);
  CHECK(b.bend_group.index == 0 && b.bend_group.generation == 0);
  CHECK(b.volume_group.index == 0 && b.volume_group.generation == 0);

  CHECK_INT(c.version, EMBRA_CONSTRAINT_DEF_VERSION);
  CHECK_INT(c.kind, EMBRA_CONSTRAINT_DISTANCE);
  CHECK(c.group.index == 0 && c.group.generation == 0);
  CHECK_INT(c.rest_from_current, 1);
  CHECK_NEAR(c.compliance, 0.0, 0.0);

  CHECK_INT(cb.version, EMBRA_CONSTRAINT_BATCH_DEF_VERSION);
  CHECK_INT(cb.kind, EMBRA_CONSTRAINT_DISTANCE);
  CHECK_INT(cb.count, 0);
  CHECK(cb.particles == NULL && cb.rest == NULL && cb.compliances == NULL);
  CHECK_NEAR(cb.compliance, 0.0, 0.0);

  CHECK_INT(p.version, EMBRA_PIN_DEF_VERSION);
  CHECK_NEAR(p.compliance, 0.0, 0.0);
  CHECK(p.group.index == 0 && p.group.generation == 0);

  CHECK_INT(k.version, EMBRA_COLLIDER_DEF_VERSION);
  CHECK_INT(k.shape, EMBRA_COLLIDER_PLANE);
  CHECK(k.rotation[0] == 1.0 && k.rotation[1] == 0.0 && k.rotation[2] == 0.0 && k.rotation[3] == 0.0);
  CHECK(k.position[0] == 0.0 && k.position[1] == 0.0 && k.position[2] == 0.0);
  CHECK_NEAR(k.radius, 1.0, 0.0);
  CHECK_NEAR(k.thickness, 0.0, 0.0);
  CHECK_NEAR(k.friction_static, 0.5, 0.0);
  CHECK_NEAR(k.friction_dynamic, 0.3, 0.0);
}

static void test_constraint_arity(void) {
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_DISTANCE), 2);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_EDGE_ANGLE), 3);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_DIHEDRAL), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_TET_VOLUME), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_WELD), 2);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_TETHER), 2);
  CHECK_INT(embra_constraint_arity(-1), 0);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_PLANARITY), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_PLANE_OFFSET), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_EQUAL_LENGTH), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_CONICAL), 5);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_LENGTH_MIN), 2);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_ANGLE_MIN), 3);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_ANGLE_MAX), 3);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_COLINEAR), 3);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_DIRECTION), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_COCIRCULAR), 4);
  CHECK_INT(embra_constraint_arity(EMBRA_CONSTRAINT_COSPHERICAL), 5);
  CHECK_INT(embra_constraint_arity(17), 0);
  CHECK_INT(embra_constraint_arity(INT32_MAX), 0);
  CHECK_INT(embra_constraint_arity(INT32_MIN), 0);
}

/* An empty world: counts, the two built-in groups, the solver def it was given, and destroy. */
static void test_world_lifecycle(void) {
  embra_world* world = NULL;
  embra_world_counts counts;
  embra_solver_def in = embra_default_solver_def(), out;
  embra_group_id def_group, contact_group;
  embra_group_report gr;
  embra_step_report report;
  embra_warning warning;
  static const embra_step_report zero_report;

  embra_world_destroy(NULL); /* documented no-op */
  CHECK(1);

  CHECK_OK(embra_world_create(&world, NULL));
  CHECK(world != NULL);
  memset(&out, 0xAB, sizeof out);
  CHECK_OK(embra_world_get_solver(world, &out));
  CHECK(memcmp(&out, &in, sizeof in) == 0); /* NULL def = the defaults */

  memset(&counts, 0xAB, sizeof counts);
  CHECK_OK(embra_world_get_counts(world, &counts));
  CHECK_INT(counts.particles, 0);
  CHECK_INT(counts.bodies, 0);
  CHECK_INT(counts.groups, 2); /* the default and contact groups */
  CHECK_INT(counts.pins, 0);
  CHECK_INT(counts.colliders, 0);
  CHECK_INT(counts.reserved0, 0);
  CHECK_INT(counts.constraints, 0);

  CHECK_OK(embra_world_default_group(world, &def_group));
  CHECK_OK(embra_world_contact_group(world, &contact_group));
  CHECK(def_group.generation != 0); /* a live id is never the zeroed "none" */
  CHECK(contact_group.generation != 0);
  CHECK(memcmp(&def_group, &contact_group, sizeof def_group) != 0);
  CHECK_OK(embra_group_get_report(world, def_group, &gr));
  CHECK_INT(gr.count, 0);
  CHECK_OK(embra_group_get_report(world, contact_group, &gr));
  CHECK_INT(gr.count, 0);

  memset(&report, 0xAB, sizeof report);
  CHECK_OK(embra_world_get_report(world, &report));
  CHECK(memcmp(&report, &zero_report, sizeof report) == 0); /* all zero before the first step */
  CHECK_OK(embra_world_get_warning(world, &warning));
  CHECK_INT(warning.frame, -1);
  CHECK_INT(warning.particle, -1);

  /* An empty world steps. */
  CHECK_OK(embra_world_step(world));
  CHECK_OK(embra_world_get_report(world, &report));
  CHECK_INT(report.frame, 1);
  CHECK_NEAR(report.time, 1.0 / 60.0, 1e-15);
  CHECK_INT(report.settled, 1);
  embra_world_destroy(world);

  /* A custom def is kept as given, and a world from it starts with the same counts. */
  in.substeps = 3;
  in.dt = 0.01;
  in.iterations = 4;
  in.gravity[0] = 1.0;
  in.gravity[2] = 9.81;
  in.damping = 0.5;
  in.settle_speed = 0.25;
  world = NULL;
  CHECK_OK(embra_world_create(&world, &in));
  CHECK_OK(embra_world_get_solver(world, &out));
  CHECK(memcmp(&out, &in, sizeof in) == 0);
  CHECK_OK(embra_world_get_counts(world, &counts));
  CHECK_INT(counts.groups, 2);
  embra_world_destroy(world);
}

/* The last-error message: never NULL, "" before any failure on a thread, names the function. */
static void test_last_error_message(void) {
  const char* m = embra_last_error_message();
  CHECK(m != NULL);
  CHECK_STATUS(embra_world_get_counts(NULL, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  m = embra_last_error_message();
  CHECK(m != NULL && m[0] != '\0');
  CHECK_CONTAINS(m, "embra_world_get_counts");
  CHECK_CONTAINS(m, "world");
}

int main(void) {
  /* Before any failure on this thread the message is "". */
  const char* first = embra_last_error_message();
  CHECK(first != NULL && first[0] == '\0');
  RUN(test_versions);
  RUN(test_check_abi);
  RUN(test_status_names);
  RUN(test_struct_layout);
  RUN(test_defaults);
  RUN(test_constraint_arity);
  RUN(test_world_lifecycle);
  RUN(test_last_error_message);
  return capi_test_finish();
}
