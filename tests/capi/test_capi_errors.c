/* Every error path of embra.h, each checked the same way (REFUSED below):
 *
 *   - the status is the documented one;
 *   - embra_last_error_message() changed, is non-empty, names the function and mentions what was
 *     wrong (a field name, "NULL", "version", "finite", "degenerate", ...);
 *   - the world is unchanged: counts, every position and velocity (memcmp), the solver def, the
 *     last report and warning, pin targets and group reports are as before the call and as in a
 *     twin world built the same way that never saw the call;
 *   - stepping both worlds afterwards gives bit-identical positions, velocities and reports.
 *
 * The scene (scene_build) has a bit of everything, so a refused call that changed anything would
 * show: a pinned cloth with uvs in a custom group, a tetrahedron, a rod with an immovable end, a
 * free point, an immovable fixture with coincident, collinear and coplanar points (to provoke
 * degenerate constraints), extra constraints of every kind, a hard and a soft pin, a plane and a
 * sphere, and a destroyed group, pin and collider whose ids are stale. */
#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"

enum { MAX_PARTICLES = 32, TWIN_FRAMES = 3 };

typedef struct scene {
  embra_world* w;
  embra_group_id g_default, g_contact, g_custom, g_late;
  embra_group_id g_dead;      /* destroyed */
  embra_group_id g_wrong_gen; /* g_custom's slot, a generation it never had */
  embra_group_id g_never;     /* a slot never created */
  embra_body_id b_cloth, b_tet, b_rod, b_point, b_fixture;
  int32_t cloth, tet, rod, point, fixture; /* first particles */
  int32_t n;                               /* particle count */
  embra_pin_id pin_hard, pin_soft, pin_dead, pin_wrong_gen, pin_never;
  embra_collider_id col_plane, col_sphere, col_dead, col_wrong_gen, col_never;
} scene;

/* The fixture (immovable, masses 0): F0 = F1 coincide, F0 F2 F5 are collinear, F0 F2 F3 F4 are
 * coplanar. */
enum { F0 = 0, F1 = 1, F2 = 2, F3 = 3, F4 = 4, F5 = 5 };

static const double kCloth[27] = {0, 0,   1,    0.25, 0, 1,   0.5, 0,    1,   0, 0.25, 1,   0.25, 0.25,
                                  1, 0.5, 0.25, 1,    0, 0.5, 1,   0.25, 0.5, 1, 0.5,  0.5, 1};
static const double kClothUv[18] = {0, 0, 1, 0, 2, 0, 0, 1, 1, 1, 2, 1, 0, 2, 1, 2, 2, 2};
static const int32_t kClothTris[24] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4, 3, 4, 7, 3, 7, 6, 4, 5, 8, 4, 8, 7};

/* Builds the scene; the same calls give the same world and ids every time. */
static int scene_build(scene* s) {
  embra_solver_def sd = embra_default_solver_def();
  embra_group_def gd = embra_default_group_def();
  embra_body_def bd;
  embra_constraint_def cd;
  embra_constraint_batch_def bat;
  embra_pin_def pd;
  embra_collider_def kd;
  int ok = 1;
  memset(s, 0, sizeof *s);
  sd.substeps = 4;
  sd.iterations = 2;
  sd.damping = 0.05;
  ok &= embra_world_create(&s->w, &sd) == EMBRA_OK;
  if (!ok) return 0;
  ok &= embra_world_default_group(s->w, &s->g_default) == EMBRA_OK;
  ok &= embra_world_contact_group(s->w, &s->g_contact) == EMBRA_OK;
  gd.order = -5;
  gd.weight = 2;
  ok &= embra_group_create(s->w, &gd, &s->g_custom) == EMBRA_OK;
  gd.order = 10;
  gd.weight = 1;
  ok &= embra_group_create(s->w, &gd, &s->g_late) == EMBRA_OK;

  /* A 3 x 3 cloth at z = 1 with uvs: stretch in g_custom, shear and bend in the default group. */
  bd = embra_default_body_def();
  bd.vertex_count = 9;
  bd.positions = kCloth;
  bd.uvs = kClothUv;
  bd.triangle_count = 8;
  bd.triangles = kClothTris;
  bd.generate = EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_SHEAR | EMBRA_GENERATE_BEND;
  bd.material.mass = 0.5;
  bd.material.bend_compliance = 0.1;
  bd.material.thickness = 0.01;
  bd.stretch_group = s->g_custom;
  ok &= embra_body_create(s->w, &bd, &s->b_cloth, &s->cloth) == EMBRA_OK;

  /* A tetrahedron, its volume in g_late. */
  {
    static const double tet[12] = {1, 0, 0.5, 1.3, 0, 0.5, 1, 0.3, 0.5, 1, 0, 0.8};
    static const int32_t ids[4] = {0, 1, 2, 3};
    bd = embra_default_body_def();
    bd.vertex_count = 4;
    bd.positions = tet;
    bd.tet_count = 1;
    bd.tets = ids;
    bd.generate = EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_VOLUME;
    bd.material.density = 1000;
    bd.material.volume_compliance = 1e-6;
    bd.volume_group = s->g_late;
    ok &= embra_body_create(s->w, &bd, &s->b_tet, &s->tet) == EMBRA_OK;
  }
  /* A rod of three particles, the first immovable. */
  {
    static const double rod[9] = {2, 0, 1, 2.3, 0, 1, 2.6, 0, 1};
    static const double masses[3] = {0, 0.1, 0.1};
    static const int32_t edges[4] = {0, 1, 1, 2};
    bd = embra_default_body_def();
    bd.vertex_count = 3;
    bd.positions = rod;
    bd.masses = masses;
    bd.edge_count = 2;
    bd.edges = edges;
    ok &= embra_body_create(s->w, &bd, &s->b_rod, &s->rod) == EMBRA_OK;
  }
  /* A free point above the sphere. */
  {
    static const double point[3] = {0.25, 0.25, 0.6};
    bd = embra_default_body_def();
    bd.vertex_count = 1;
    bd.positions = point;
    ok &= embra_body_create(s->w, &bd, &s->b_point, &s->point) == EMBRA_OK;
  }
  /* The immovable fixture. */
  {
    static const double fix[18] = {3, 0, 0.25, 3, 0, 0.25, 4, 0, 0.25, 3, 1, 0.25, 4, 1, 0.25, 5, 0, 0.25};
    static const double zero[6] = {0, 0, 0, 0, 0, 0};
    bd = embra_default_body_def();
    bd.vertex_count = 6;
    bd.positions = fix;
    bd.masses = zero;
    ok &= embra_body_create(s->w, &bd, &s->b_fixture, &s->fixture) == EMBRA_OK;
  }
  {
    embra_world_counts c;
    ok &= embra_world_get_counts(s->w, &c) == EMBRA_OK;
    s->n = c.particles;
    ok &= s->n <= MAX_PARTICLES;
  }

  /* Extra constraints: a tether from the cloth to the point, a soft weld from the rod's end to
   * the tetrahedron, and a batch of each remaining kind. */
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_TETHER;
  cd.particles[0] = s->cloth + 8;
  cd.particles[1] = s->point;
  ok &= embra_constraint_add(s->w, &cd) == EMBRA_OK;
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_WELD;
  cd.particles[0] = s->rod + 2;
  cd.particles[1] = s->tet + 1;
  cd.compliance = 1e-3;
  cd.group = s->g_late;
  ok &= embra_constraint_add(s->w, &cd) == EMBRA_OK;
  {
    const int32_t ids[8] = {s->cloth + 4, s->cloth + 5, s->cloth + 7, s->cloth + 3,
                            s->cloth + 0, s->cloth + 1, s->cloth + 3, s->cloth + 4};
    const double rest[2] = {1.2, 1.0};
    bat = embra_default_constraint_batch_def();
    bat.kind = EMBRA_CONSTRAINT_EDGE_ANGLE;
    bat.count = 2;
    bat.particles = ids;
    bat.rest = rest;
    bat.compliance = 1e-4;
    ok &= embra_constraints_add(s->w, &bat) == EMBRA_OK;
  }
  {
    const int32_t ids[4] = {s->tet, s->rod + 1, s->cloth + 2, s->tet + 3};
    const double compliances[2] = {1e-5, 0};
    bat = embra_default_constraint_batch_def();
    bat.kind = EMBRA_CONSTRAINT_DISTANCE;
    bat.group = s->g_custom;
    bat.count = 2;
    bat.particles = ids;
    bat.compliances = compliances;
    ok &= embra_constraints_add(s->w, &bat) == EMBRA_OK;
  }

  /* Pins: a hard one on cloth vertex 0, moved a little; a soft one on vertex 2 in g_custom. */
  pd = embra_default_pin_def();
  pd.particle = s->cloth;
  pd.target[0] = 0.0;
  pd.target[1] = -0.05;
  pd.target[2] = 1.05;
  ok &= embra_pin_create(s->w, &pd, &s->pin_hard) == EMBRA_OK;
  pd.particle = s->cloth + 2;
  pd.target[0] = 0.55;
  pd.target[1] = 0.0;
  pd.target[2] = 1.0;
  pd.compliance = 1e-3;
  pd.group = s->g_custom;
  ok &= embra_pin_create(s->w, &pd, &s->pin_soft) == EMBRA_OK;

  /* Colliders: the ground and a tilted-in-place sphere. */
  kd = embra_default_collider_def();
  ok &= embra_collider_create(s->w, &kd, &s->col_plane) == EMBRA_OK;
  kd.shape = EMBRA_COLLIDER_SPHERE;
  kd.position[0] = 0.25;
  kd.position[1] = 0.25;
  kd.position[2] = 0.3;
  kd.radius = 0.2;
  kd.friction_static = 0.8;
  ok &= embra_collider_create(s->w, &kd, &s->col_sphere) == EMBRA_OK;

  /* Some motion. */
  {
    const double v[6] = {0.1, 0, 0, 0, 0.2, -0.1};
    ok &= embra_world_set_velocities(s->w, v, s->rod + 1, 2) == EMBRA_OK;
  }
  ok &= embra_world_step(s->w) == EMBRA_OK;

  /* The dead: created last and destroyed, so no later create takes their slots. */
  gd = embra_default_group_def();
  ok &= embra_group_create(s->w, &gd, &s->g_dead) == EMBRA_OK;
  ok &= embra_group_destroy(s->w, s->g_dead) == EMBRA_OK;
  pd = embra_default_pin_def();
  pd.particle = s->point;
  ok &= embra_pin_create(s->w, &pd, &s->pin_dead) == EMBRA_OK;
  ok &= embra_pin_destroy(s->w, s->pin_dead) == EMBRA_OK;
  kd = embra_default_collider_def();
  ok &= embra_collider_create(s->w, &kd, &s->col_dead) == EMBRA_OK;
  ok &= embra_collider_destroy(s->w, s->col_dead) == EMBRA_OK;

  s->g_wrong_gen = s->g_custom;
  s->g_wrong_gen.generation += 1;
  s->g_never.index = 40;
  s->g_never.generation = 1;
  s->pin_wrong_gen = s->pin_soft;
  s->pin_wrong_gen.generation += 7;
  s->pin_never.index = 40;
  s->pin_never.generation = 1;
  s->col_wrong_gen = s->col_sphere;
  s->col_wrong_gen.generation += 1;
  s->col_never.index = 40;
  s->col_never.generation = 1;
  return ok;
}

/* Everything observable about a world, zero-filled so it compares with memcmp. */
typedef struct snapshot {
  embra_world_counts counts;
  embra_solver_def solver;
  embra_step_report report;
  embra_warning warning;
  embra_group_report groups[4];
  double pin_targets[2][3];
  int32_t body_first[5], body_count[5];
  double x[3 * MAX_PARTICLES], v[3 * MAX_PARTICLES], loads[3 * MAX_PARTICLES];
  int ok;
} snapshot;

static void snapshot_take(const scene* s, snapshot* out) {
  const embra_body_id bodies[5] = {s->b_cloth, s->b_tet, s->b_rod, s->b_point, s->b_fixture};
  const embra_group_id groups[4] = {s->g_default, s->g_contact, s->g_custom, s->g_late};
  int ok = 1, i;
  memset(out, 0, sizeof *out);
  ok &= embra_world_get_counts(s->w, &out->counts) == EMBRA_OK;
  ok &= embra_world_get_solver(s->w, &out->solver) == EMBRA_OK;
  ok &= embra_world_get_report(s->w, &out->report) == EMBRA_OK;
  ok &= embra_world_get_warning(s->w, &out->warning) == EMBRA_OK;
  for (i = 0; i < 4; ++i) ok &= embra_group_get_report(s->w, groups[i], &out->groups[i]) == EMBRA_OK;
  ok &= embra_pin_get_target(s->w, s->pin_hard, out->pin_targets[0]) == EMBRA_OK;
  ok &= embra_pin_get_target(s->w, s->pin_soft, out->pin_targets[1]) == EMBRA_OK;
  for (i = 0; i < 5; ++i)
    ok &= embra_body_get_particles(s->w, bodies[i], &out->body_first[i], &out->body_count[i]) == EMBRA_OK;
  ok &= embra_world_get_positions(s->w, out->x, 3 * MAX_PARTICLES, 0, out->counts.particles) == EMBRA_OK;
  ok &= embra_world_get_velocities(s->w, out->v, 3 * MAX_PARTICLES, 0, out->counts.particles) == EMBRA_OK;
  ok &= embra_world_get_loads(s->w, out->loads, 3 * MAX_PARTICLES, 0, out->counts.particles) == EMBRA_OK;
  out->ok = ok;
}

static scene g_ref; /* the ids every build gives, for defs written before the call */

/* Text up to the first '(' of the call: the function's name. */
static void function_name(const char* call, char* out, size_t size) {
  size_t i = 0;
  while (call[i] != '\0' && call[i] != '(' && call[i] != ' ' && i + 1 < size) {
    out[i] = call[i];
    ++i;
  }
  out[i] = '\0';
}

/* Sets this thread's last-error message to something the next call must replace. */
static void prime_message(void) {
  embra_check_abi(-4242);
  CHECK_CONTAINS(embra_last_error_message(), "-4242");
}

/* The status and message half of a refusal check. */
static void check_refusal(const char* file, int line, const char* call, embra_status got, embra_status expected,
                          const char* needle) {
  char what[512], fn[96];
  const char* m = embra_last_error_message();
  const char* rest = m;
  function_name(call, fn, sizeof fn);
  snprintf(what, sizeof what, "%s returns %s", call, embra_status_name(expected));
  if (!capi_test_record(got == expected, file, line, what))
    fprintf(stderr, "    got %s (%d): \"%s\"\n", embra_status_name(got), (int)got, m ? m : "(NULL)");
  snprintf(what, sizeof what, "after %s, the message is new, non-empty and names %s", call, fn);
  if (!capi_test_record(m != NULL && m[0] != '\0' && !capi_test_contains(m, "-4242") && capi_test_contains(m, fn), file,
                        line, what))
    fprintf(stderr, "    message is \"%s\"\n", m ? m : "(NULL)");
  /* The needle must be in what the message says after naming the function, so that "world" or
   * "gravity" is not found in the function's own name. */
  if (m != NULL && fn[0] != '\0' && strstr(m, fn) != NULL) rest = strstr(m, fn) + strlen(fn);
  snprintf(what, sizeof what, "after %s, the message mentions \"%s\"", call, needle);
  if (!capi_test_record(capi_test_contains(rest, needle), file, line, what))
    fprintf(stderr, "    message is \"%s\"\n", m ? m : "(NULL)");
}

/* The "nothing changed" half: A (refused the call) against its own state before and against B
 * (its twin, never saw the call), then both stepped. */
static void check_unchanged(const char* file, int line, const char* call, const snapshot* before, scene* a, scene* b) {
  static snapshot after, twin; /* large: keep them off the stack */
  char what[512];
  int frame, stepped = 1;
  snapshot_take(a, &after);
  snapshot_take(b, &twin);
  snprintf(what, sizeof what, "after %s, the world reads back the same as before and as its twin", call);
  if (!capi_test_record(
          after.ok && twin.ok && memcmp(&after, before, sizeof after) == 0 && memcmp(&after, &twin, sizeof after) == 0,
          file, line, what)) {
    fprintf(stderr, "    counts %s, solver %s, report %s, positions %s, velocities %s, pins %s\n",
            memcmp(&after.counts, &twin.counts, sizeof after.counts) ? "differ" : "same",
            memcmp(&after.solver, &twin.solver, sizeof after.solver) ? "differs" : "same",
            memcmp(&after.report, &twin.report, sizeof after.report) ? "differs" : "same",
            memcmp(after.x, twin.x, sizeof after.x) ? "differ" : "same",
            memcmp(after.v, twin.v, sizeof after.v) ? "differ" : "same",
            memcmp(after.pin_targets, twin.pin_targets, sizeof after.pin_targets) ? "differ" : "same");
  }
  for (frame = 0; frame < TWIN_FRAMES; ++frame) {
    stepped &= embra_world_step(a->w) == EMBRA_OK;
    stepped &= embra_world_step(b->w) == EMBRA_OK;
  }
  snapshot_take(a, &after);
  snapshot_take(b, &twin);
  snprintf(what, sizeof what, "after %s, stepping gives bit-identical results to the twin", call);
  if (!capi_test_record(stepped && after.ok && twin.ok && memcmp(&after, &twin, sizeof after) == 0, file, line, what))
    fprintf(stderr, "    stepped %d, positions %s, velocities %s, report %s\n", stepped,
            memcmp(after.x, twin.x, sizeof after.x) ? "differ" : "same",
            memcmp(after.v, twin.v, sizeof after.v) ? "differ" : "same",
            memcmp(&after.report, &twin.report, sizeof after.report) ? "differs" : "same");
}

static scene g_a, g_b;
static snapshot g_before;

static void refuse_begin(const char* file, int line) {
  int built = scene_build(&g_a) & scene_build(&g_b);
  if (!capi_test_record(built, file, line, "the scene builds"))
    fprintf(stderr, "    last error: \"%s\"\n", embra_last_error_message());
  /* Deterministic ids: defs written against g_ref's ids name the same objects. */
  capi_test_record(
      memcmp((const char*)&g_a + sizeof g_a.w, (const char*)&g_ref + sizeof g_ref.w, sizeof g_a - sizeof g_a.w) == 0,
      file, line, "the scene's ids are the same on every build");
  snapshot_take(&g_a, &g_before);
  prime_message();
}

static void refuse_end(const char* file, int line, const char* call, embra_status got, embra_status expected,
                       const char* needle) {
  check_refusal(file, line, call, got, expected, needle);
  check_unchanged(file, line, call, &g_before, &g_a, &g_b);
  embra_world_destroy(g_a.w);
  embra_world_destroy(g_b.w);
}

/* REFUSED(status, needle, call): `call` may use W (the scene's world) and S (the scene). */
#define REFUSED(expected, needle, ...)                                                     \
  do {                                                                                     \
    refuse_begin(__FILE__, __LINE__);                                                      \
    {                                                                                      \
      scene* const S = &g_a;                                                               \
      embra_world* const W = g_a.w;                                                        \
      const embra_status refused_status_ = (__VA_ARGS__);                                  \
      (void)S;                                                                             \
      (void)W;                                                                             \
      refuse_end(__FILE__, __LINE__, #__VA_ARGS__, refused_status_, (expected), (needle)); \
    }                                                                                      \
  } while (0)

/* For calls that have no world to compare (a NULL world, world creation). */
#define REFUSED_NO_WORLD(expected, needle, ...)                                             \
  do {                                                                                      \
    embra_status refused_status_;                                                           \
    prime_message();                                                                        \
    refused_status_ = (__VA_ARGS__);                                                        \
    check_refusal(__FILE__, __LINE__, #__VA_ARGS__, refused_status_, (expected), (needle)); \
  } while (0)

static double bad_value(int i) {
  return i == 0 ? NAN : i == 1 ? INFINITY : -INFINITY;
}
static const char* bad_name(int i) {
  return i == 0 ? "nan" : i == 1 ? "+inf" : "-inf";
}

/* ------------------------------------------------------------------------------------------- */

static void test_null_world(void) {
  embra_world_counts counts;
  embra_solver_def sd = embra_default_solver_def();
  embra_group_def gd = embra_default_group_def();
  embra_body_def bd = embra_default_body_def();
  embra_constraint_def cd = embra_default_constraint_def();
  embra_constraint_batch_def cb = embra_default_constraint_batch_def();
  embra_pin_def pd = embra_default_pin_def();
  embra_collider_def kd = embra_default_collider_def();
  embra_group_id g = g_ref.g_custom;
  embra_body_id b = g_ref.b_cloth;
  embra_pin_id p = g_ref.pin_hard;
  embra_collider_id k = g_ref.col_plane;
  embra_group_report gr;
  embra_step_report sr;
  embra_warning wn;
  embra_body_id bo;
  embra_pin_id po;
  embra_collider_id ko;
  double xyz[3] = {0, 0, 0}, q[4] = {1, 0, 0, 0};
  int32_t i0, i1;
  const char* const w = "world is NULL";
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_solver(NULL, &sd));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_set_solver(NULL, &sd));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_set_gravity(NULL, xyz));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_counts(NULL, &counts));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_group_create(NULL, &gd, &g));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_group_destroy(NULL, g));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_group_set_order(NULL, g, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_group_set_weight(NULL, g, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_default_group(NULL, &g));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_contact_group(NULL, &g));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_group_get_report(NULL, g, &gr));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_body_create(NULL, &bd, &bo, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_body_get_particles(NULL, b, &i0, &i1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_body_set_rest_scale(NULL, b, 1, 1, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_constraint_add(NULL, &cd));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_constraints_add(NULL, &cb));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_pin_create(NULL, &pd, &po));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_pin_destroy(NULL, p));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_pin_set_target(NULL, p, xyz));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_pin_get_target(NULL, p, xyz));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_collider_create(NULL, &kd, &ko));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_collider_destroy(NULL, k));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_collider_set_transform(NULL, k, xyz, q));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_step(NULL));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_report(NULL, &sr));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_warning(NULL, &wn));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_positions(NULL, xyz, 3, 0, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_velocities(NULL, xyz, 3, 0, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_set_positions(NULL, xyz, 0, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_set_velocities(NULL, xyz, 0, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_bodies(NULL, NULL, 0, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_groups(NULL, NULL, 0, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_pins(NULL, NULL, 0, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_colliders(NULL, NULL, 0, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_pin_get_particle(NULL, p, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_collider_get_transform(NULL, k, xyz, q));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_set_loads(NULL, xyz, 0, 1));
  {
    const embra_support_def su = embra_default_support_def();
    REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_support_create(NULL, &su, &po));
  }
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_loads(NULL, xyz, 3, 0, 1));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w, embra_world_get_reactions(NULL, NULL, 0, &i0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, w,
                   embra_group_get_forces(NULL, g, EMBRA_CONSTRAINT_DISTANCE, NULL, 0, &counts.constraints));
}

/* embra_world_create: every refusal leaves *out_world NULL. */
static void test_world_create(void) {
  static int not_a_world;
  embra_world* w = NULL;
  embra_solver_def d;
  int i, k;
#define CREATE_REFUSED(expected, needle)                            \
  do {                                                              \
    w = (embra_world*)(void*)&not_a_world;                          \
    REFUSED_NO_WORLD(expected, needle, embra_world_create(&w, &d)); \
    CHECK(w == NULL);                                               \
  } while (0)
  d = embra_default_solver_def();
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, "out_world", embra_world_create(NULL, &d));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, "out_world", embra_world_create(NULL, NULL));
  d.version = 0;
  CREATE_REFUSED(EMBRA_ERROR_VERSION, "version");
  d.version = EMBRA_SOLVER_DEF_VERSION + 1;
  CREATE_REFUSED(EMBRA_ERROR_VERSION, "version");
  d.version = -1;
  CREATE_REFUSED(EMBRA_ERROR_VERSION, "version");
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("value %s", bad_name(i));
    d = embra_default_solver_def();
    d.dt = bad_value(i);
    CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "dt");
    for (k = 0; k < 3; ++k) {
      d = embra_default_solver_def();
      d.gravity[k] = bad_value(i);
      CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "gravity");
    }
    d = embra_default_solver_def();
    d.damping = bad_value(i);
    CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "damping");
    d = embra_default_solver_def();
    d.settle_speed = bad_value(i);
    CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "settle_speed");
  }
  CAPI_CONTEXT("out of range");
  d = embra_default_solver_def();
  d.dt = 0.0;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "dt");
  d.dt = -1.0 / 60.0;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "dt");
  d = embra_default_solver_def();
  d.substeps = 0;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "substeps");
  d.substeps = -8;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "substeps");
  d.substeps = 10001;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "substeps");
  d = embra_default_solver_def();
  d.iterations = 0;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "iterations");
  d.iterations = 10001;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "iterations");
  d = embra_default_solver_def();
  d.chebyshev_rho_milli = -1;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "chebyshev_rho_milli");
  d.chebyshev_rho_milli = 991;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "chebyshev_rho_milli");
  d = embra_default_solver_def();
  d.chain_solve = 2;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "chain_solve");
  d.chain_solve = -1;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "chain_solve");
  d = embra_default_solver_def();
  d.damping = -0.1;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "damping");
  d = embra_default_solver_def();
  d.settle_speed = -1e-3;
  CREATE_REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "settle_speed");
  /* the bounds themselves are accepted */
  d = embra_default_solver_def();
  d.substeps = 10000;
  d.iterations = 10; /* EMBRA_MAX_PASSES_PER_STEP */
  d.damping = 0.0;
  d.settle_speed = 0.0;
  d.chebyshev_rho_milli = 990;
  CHECK_OK(embra_world_create(&w, &d));
  embra_world_destroy(w);
#undef CREATE_REFUSED
}

static void test_solver_and_gravity(void) {
  embra_solver_def d;
  embra_solver_def* const none = NULL;
  double g[3];
  int i, k;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_def", embra_world_get_solver(W, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_world_set_solver(W, none));
  d = embra_default_solver_def();
  d.version = 1; /* the layout before threads */
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_world_set_solver(W, &d));
  d.version = 3;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_world_set_solver(W, &d));
  d = embra_default_solver_def();
  d.global_solve = EMBRA_GLOBAL_SOLVE_AUTO + 1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "global_solve", embra_world_set_solver(W, &d));
  d.global_solve = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "global_solve", embra_world_set_solver(W, &d));
  d = embra_default_solver_def();
  d.threads = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "threads", embra_world_set_solver(W, &d));
  d.threads = EMBRA_MAX_THREADS + 1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "threads", embra_world_set_solver(W, &d));
  d.version = 0;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_world_set_solver(W, &d));
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("value %s", bad_name(i));
    d = embra_default_solver_def();
    d.dt = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "dt", embra_world_set_solver(W, &d));
    for (k = 0; k < 3; ++k) {
      d = embra_default_solver_def();
      d.gravity[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "gravity", embra_world_set_solver(W, &d));
      g[0] = 0.0;
      g[1] = 1.0;
      g[2] = 2.0;
      g[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "gravity", embra_world_set_gravity(W, g));
    }
    d = embra_default_solver_def();
    d.damping = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "damping", embra_world_set_solver(W, &d));
    d = embra_default_solver_def();
    d.settle_speed = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "settle_speed", embra_world_set_solver(W, &d));
  }
  CAPI_CONTEXT("out of range");
  d = embra_default_solver_def();
  d.dt = 0.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "dt", embra_world_set_solver(W, &d));
  d.dt = -0.01;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "dt", embra_world_set_solver(W, &d));
  d = embra_default_solver_def();
  d.substeps = 0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "substeps", embra_world_set_solver(W, &d));
  d.substeps = 10001;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "substeps", embra_world_set_solver(W, &d));
  d = embra_default_solver_def();
  d.iterations = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "iterations", embra_world_set_solver(W, &d));
  d.iterations = 10001;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "iterations", embra_world_set_solver(W, &d));
  d = embra_default_solver_def();
  d.damping = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "damping", embra_world_set_solver(W, &d));
  d = embra_default_solver_def();
  d.settle_speed = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "settle_speed", embra_world_set_solver(W, &d));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "gravity", embra_world_set_gravity(W, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_counts", embra_world_get_counts(W, NULL));
}

static void test_groups(void) {
  embra_group_def d;
  embra_group_id out;
  embra_group_report r;
  const embra_group_id zero = {0, 0};
  const embra_group_id stale[4] = {g_ref.g_dead, g_ref.g_wrong_gen, g_ref.g_never, zero};
  int i;
  d = embra_default_group_def();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_group_create(W, NULL, &out));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_group", embra_group_create(W, &d, NULL));
  d.version = 2;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_group_create(W, &d, &out));
  d = embra_default_group_def();
  d.weight = 0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weight", embra_group_create(W, &d, &out));
  d.weight = -3;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weight", embra_group_create(W, &d, &out));
  d.weight = 1001;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weight", embra_group_create(W, &d, &out));

  for (i = 0; i < 4; ++i) {
    CAPI_CONTEXT("stale group %d {%u, %u}", i, (unsigned)stale[i].index, (unsigned)stale[i].generation);
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_group_destroy(W, stale[i]));
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_group_set_order(W, stale[i], 3));
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_group_set_weight(W, stale[i], 3));
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_group_get_report(W, stale[i], &r));
  }
  CAPI_CONTEXT("built-in groups");
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "default", embra_group_destroy(W, S->g_default));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "contact", embra_group_destroy(W, S->g_contact));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "soft pin", embra_group_destroy(W, S->g_custom)); /* holds pin_soft */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weight", embra_group_set_weight(W, S->g_custom, 0));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weight", embra_group_set_weight(W, S->g_custom, 1001));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weight", embra_group_set_weight(W, S->g_default, -1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_group", embra_world_default_group(W, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_group", embra_world_contact_group(W, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_report", embra_group_get_report(W, S->g_custom, NULL));
}

/* A valid body def (a square of two triangles and a tetrahedron over 5 vertices), to break. */
static double g_pos[15];
static double g_mass[5];
static double g_uv[10];
static int32_t g_edges[4];
static int32_t g_tris[6];
static int32_t g_tets[4];

static embra_body_def good_body(void) {
  static const double pos[15] = {0, 0, 2, 1, 0, 2, 1, 1, 2, 0, 1, 2, 0.5, 0.5, 3};
  static const double mass[5] = {1, 1, 1, 1, 2};
  static const double uv[10] = {0, 0, 1, 0, 1, 1, 0, 1, 0.5, 0.5};
  static const int32_t edges[4] = {0, 4, 2, 4};
  static const int32_t tris[6] = {0, 1, 2, 0, 2, 3};
  static const int32_t tets[4] = {0, 1, 2, 4};
  embra_body_def d = embra_default_body_def();
  memcpy(g_pos, pos, sizeof pos);
  memcpy(g_mass, mass, sizeof mass);
  memcpy(g_uv, uv, sizeof uv);
  memcpy(g_edges, edges, sizeof edges);
  memcpy(g_tris, tris, sizeof tris);
  memcpy(g_tets, tets, sizeof tets);
  d.vertex_count = 5;
  d.positions = g_pos;
  d.uvs = g_uv;
  d.edge_count = 2;
  d.edges = g_edges;
  d.triangle_count = 2;
  d.triangles = g_tris;
  d.tet_count = 1;
  d.tets = g_tets;
  d.generate = 15;
  return d;
}

static void test_body_create(void) {
  embra_body_def d;
  embra_body_id out;
  int32_t first;
  int i, k, f;
  /* The good def is good (on a scene like the others). */
  {
    scene s;
    CHECK(scene_build(&s));
    d = good_body();
    CHECK_OK(embra_body_create(s.w, &d, &out, &first));
    d.masses = g_mass;
    CHECK_OK(embra_body_create(s.w, &d, &out, NULL));
    embra_world_destroy(s.w);
  }
  d = good_body();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_body_create(W, NULL, &out, &first));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_body", embra_body_create(W, &d, NULL, &first));
  d.version = 0;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_body_create(W, &d, &out, &first));
  d.version = 2;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("counts");
  d = good_body();
  d.vertex_count = 0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "vertex_count", embra_body_create(W, &d, &out, &first));
  d.vertex_count = -5;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "vertex_count", embra_body_create(W, &d, &out, &first));
  d.vertex_count = INT32_MAX; /* refused before the (short) arrays are read */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "at most 2097152 particles", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.edge_count = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "edge_count", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.triangle_count = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "triangle_count", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.tet_count = INT32_MIN;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "tet_count", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("NULL arrays with counts");
  d = good_body();
  d.positions = NULL;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "positions", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.edges = NULL;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "edges", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.triangles = NULL;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "triangles", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.tets = NULL;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "tets", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("generate flags");
  d = good_body();
  d.generate = 16;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "flags", embra_body_create(W, &d, &out, &first));
  d.generate = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "flags", embra_body_create(W, &d, &out, &first));
  d.generate = INT32_MIN | EMBRA_GENERATE_STRETCH;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "flags", embra_body_create(W, &d, &out, &first));

  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("non-finite %s", bad_name(i));
    for (k = 0; k < 15; ++k) {
      d = good_body();
      g_pos[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_body_create(W, &d, &out, &first));
    }
    for (k = 0; k < 5; ++k) {
      d = good_body();
      d.masses = g_mass;
      g_mass[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "mass", embra_body_create(W, &d, &out, &first));
    }
    for (k = 0; k < 10; ++k) {
      d = good_body();
      g_uv[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "uv", embra_body_create(W, &d, &out, &first));
    }
    for (f = 0; f < 10; ++f) {
      static const char* const fields[10] = {
          "mass",    "density",   "stretch_compliance", "shear_compliance", "bend_compliance", "volume_compliance",
          "damping", "thickness", "friction_static",    "friction_dynamic"};
      double* const m = &d.material.mass;
      d = good_body();
      m[f] = bad_value(i); /* embra_material is ten doubles in this order (see test_capi_basics) */
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, fields[f], embra_body_create(W, &d, &out, &first));
      d = good_body();
      m[f] = -0.5; /* negative material values are refused too */
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, fields[f], embra_body_create(W, &d, &out, &first));
    }
  }
  CAPI_CONTEXT("masses");
  d = good_body();
  d.masses = g_mass;
  g_mass[3] = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "mass", embra_body_create(W, &d, &out, &first));
  d = good_body();
  d.material.mass = 0.0;
  d.material.density = 0.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "density", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("indices out of range");
  d = good_body();
  g_edges[1] = 5;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "edge", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_edges[2] = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "edge", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_tris[5] = 5;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "triangle", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_tris[0] = INT32_MIN;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "triangle", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_tets[3] = 99;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "tetrahedron", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_tets[0] = -2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "tetrahedron", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("repeated vertex in an element");
  d = good_body();
  g_edges[3] = g_edges[2];
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_tris[5] = g_tris[3];
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_body_create(W, &d, &out, &first));
  d = good_body();
  g_tets[3] = g_tets[1];
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("degenerate elements");
  d = good_body(); /* vertex 4 moved onto vertex 0: edge 0-4 has zero length */
  memcpy(&g_pos[12], &g_pos[0], 3 * sizeof(double));
  d.tet_count = 0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "zero length", embra_body_create(W, &d, &out, &first));
  d = good_body(); /* vertex 3 moved onto the diagonal 0-2: triangle 0 2 3 has zero area */
  g_pos[9] = 0.25;
  g_pos[10] = 0.25;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "zero area", embra_body_create(W, &d, &out, &first));
  d = good_body(); /* vertex 4 moved into the plane of 0 1 2: the tetrahedron is flat */
  g_pos[14] = 2.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "zero volume", embra_body_create(W, &d, &out, &first));

  CAPI_CONTEXT("stale groups");
  for (k = 0; k < 4; ++k) {
    const embra_group_id bad[3] = {g_ref.g_dead, g_ref.g_wrong_gen, g_ref.g_never};
    for (i = 0; i < 3; ++i) {
      CAPI_CONTEXT("stale group %d in group field %d", i, k);
      d = good_body();
      if (k == 0) d.stretch_group = bad[i];
      if (k == 1) d.shear_group = bad[i];
      if (k == 2) d.bend_group = bad[i];
      if (k == 3) d.volume_group = bad[i];
      REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_body_create(W, &d, &out, &first));
    }
  }
}

static void test_body_queries(void) {
  const embra_body_id stale[4] = {{5, 1}, {0, 2}, {0, 0}, {UINT32_MAX, 1}};
  int32_t first, count;
  int i, k;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_first", embra_body_get_particles(W, S->b_cloth, NULL, &count));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", embra_body_get_particles(W, S->b_cloth, &first, NULL));
  for (i = 0; i < 4; ++i) {
    CAPI_CONTEXT("stale body {%u, %u}", (unsigned)stale[i].index, (unsigned)stale[i].generation);
    REFUSED(EMBRA_ERROR_STALE_ID, "body", embra_body_get_particles(W, stale[i], &first, &count));
    REFUSED(EMBRA_ERROR_STALE_ID, "body", embra_body_set_rest_scale(W, stale[i], 0.5, 1, 1));
  }
  for (i = 0; i < 3; ++i) {
    for (k = 0; k < 3; ++k) {
      double s[3] = {0.9, 1.1, 1.0};
      CAPI_CONTEXT("rest scale %d = %s", k, bad_name(i));
      s[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_body_set_rest_scale(W, S->b_cloth, s[0], s[1], s[2]));
      s[k] = -0.25;
      CAPI_CONTEXT("rest scale %d negative", k);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest scale", embra_body_set_rest_scale(W, S->b_cloth, s[0], s[1], s[2]));
    }
  }
}

/* A valid single constraint on the scene, to break (the cloth is flat: a planarity quad on it would
 * have parallel diagonals, so that one takes the tetrahedron's corners). */
static embra_constraint_def good_constraint(embra_constraint_kind kind) {
  embra_constraint_def d = embra_default_constraint_def();
  const int32_t c = g_ref.cloth;
  d.kind = kind;
  d.particles[0] = c + 4;
  d.particles[1] = c + 5;
  d.particles[2] = c + 8;
  d.particles[3] = c + 1;
  if (kind == EMBRA_CONSTRAINT_TET_VOLUME || kind == EMBRA_CONSTRAINT_PLANARITY) {
    d.particles[0] = g_ref.tet;
    d.particles[1] = g_ref.tet + 1;
    d.particles[2] = g_ref.tet + 2;
    d.particles[3] = g_ref.point;
  }
  return d;
}

/* The first number that is no constraint kind (the kinds are numbered 0, 1, ...). */
static int32_t kind_count(void) {
  int32_t n = 0;
  while (embra_constraint_arity(n) > 0) ++n;
  return n;
}

static void test_constraint_add(void) {
  embra_constraint_def d;
  int kind, slot, i;
  /* The good defs are good, for every kind, from current positions and with a rest value. */
  {
    scene s;
    CHECK(scene_build(&s));
    for (kind = 0; embra_constraint_arity(kind) > 0 && embra_constraint_arity(kind) <= 4; ++kind) {
      CAPI_CONTEXT("kind %d", kind);
      d = good_constraint(kind);
      CHECK_OK(embra_constraint_add(s.w, &d));
      d.rest_from_current = 0;
      d.rest = kind == EMBRA_CONSTRAINT_WELD ? 0.0 : 0.5;
      CHECK_OK(embra_constraint_add(s.w, &d));
    }
    embra_world_destroy(s.w);
  }
  d = good_constraint(EMBRA_CONSTRAINT_DISTANCE);
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_constraint_add(W, NULL));
  d.version = 0;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_constraint_add(W, &d));
  d.version = 2;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_DISTANCE);
  d.kind = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "kind", embra_constraint_add(W, &d));
  d.kind = kind_count();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "kind", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_DISTANCE);
  d.rest_from_current = 2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest_from_current", embra_constraint_add(W, &d));
  d.rest_from_current = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest_from_current", embra_constraint_add(W, &d));

  for (kind = 0; embra_constraint_arity(kind) > 0; ++kind) {
    const int32_t n = embra_constraint_arity(kind);
    if (n > 4) { /* more particles than the def holds: embra_constraints_add (test_constraints_add) */
      CAPI_CONTEXT("kind %d, one at a time", kind);
      d = good_constraint(kind);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "embra_constraints_add", embra_constraint_add(W, &d));
      continue;
    }
    for (slot = 0; slot < n; ++slot) {
      /* Equal length's and direction's two edges may share a particle (slots 1 and 2, 3 and 0); one
       * edge may not. */
      const int shared_edges =
          (kind == EMBRA_CONSTRAINT_EQUAL_LENGTH || kind == EMBRA_CONSTRAINT_DIRECTION) && slot % 2 == 1;
      CAPI_CONTEXT("kind %d, particle %d", kind, slot);
      d = good_constraint(kind);
      d.particles[slot] = -1;
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraint_add(W, &d));
      d.particles[slot] = g_ref.n;
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraint_add(W, &d));
      d = good_constraint(kind);
      d.particles[slot] = d.particles[(slot + 1) % n];
      if (shared_edges) {
        scene s;
        CHECK(scene_build(&s));
        CHECK_OK(embra_constraint_add(s.w, &d));
        embra_world_destroy(s.w);
      } else {
        REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_constraint_add(W, &d));
      }
    }
    CAPI_CONTEXT("kind %d, groups", kind);
    d = good_constraint(kind);
    d.group = g_ref.g_dead;
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_constraint_add(W, &d));
    d.group = g_ref.g_wrong_gen;
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_constraint_add(W, &d));
    d.group = g_ref.g_never;
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_constraint_add(W, &d));
    for (i = 0; i < 3; ++i) {
      CAPI_CONTEXT("kind %d, %s", kind, bad_name(i));
      d = good_constraint(kind);
      d.rest_from_current = 0;
      d.rest = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_constraint_add(W, &d));
      d = good_constraint(kind);
      d.compliance = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraint_add(W, &d));
    }
    CAPI_CONTEXT("kind %d, negative compliance", kind);
    d = good_constraint(kind);
    d.compliance = -1e-6;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraint_add(W, &d));
  }

  CAPI_CONTEXT("rest out of the kind's range");
  d = good_constraint(EMBRA_CONSTRAINT_DISTANCE);
  d.rest_from_current = 0;
  d.rest = -0.1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest", embra_constraint_add(W, &d));
  d.kind = EMBRA_CONSTRAINT_TETHER;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_EDGE_ANGLE);
  d.rest_from_current = 0;
  d.rest = 3.2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));
  d.rest = -0.01;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_DIHEDRAL);
  d.rest_from_current = 0;
  d.rest = -3.14159265358979323846;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));
  d.rest = 3.2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_WELD);
  d.rest_from_current = 0;
  d.rest = 0.5;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weld", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_LENGTH_MIN);
  d.rest_from_current = 0;
  d.rest = -0.1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest length", embra_constraint_add(W, &d));
  d = good_constraint(EMBRA_CONSTRAINT_COLINEAR);
  d.rest_from_current = 0;
  d.rest = -0.1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest distance", embra_constraint_add(W, &d));
  for (kind = EMBRA_CONSTRAINT_ANGLE_MIN; kind <= EMBRA_CONSTRAINT_DIRECTION; ++kind) {
    if (kind == EMBRA_CONSTRAINT_COLINEAR) continue;
    CAPI_CONTEXT("kind %d, rest angle out of [0, pi]", kind);
    d = good_constraint(kind);
    d.rest_from_current = 0;
    d.rest = 3.2;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));
    d.rest = -0.01;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));
  }
  CAPI_CONTEXT("cocircular rest beyond 2 pi");
  d = good_constraint(EMBRA_CONSTRAINT_COCIRCULAR);
  d.rest_from_current = 0;
  d.rest = -6.3;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraint_add(W, &d));

  CAPI_CONTEXT("degenerate, rest measured from current positions");
  d = embra_default_constraint_def(); /* F0 and F1 coincide */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d.kind = EMBRA_CONSTRAINT_TETHER;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_EDGE_ANGLE; /* an edge of zero length */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F1;
  d.particles[2] = g_ref.fixture + F2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_DIHEDRAL; /* the first triangle F0 F2 F5 is a line */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F2;
  d.particles[2] = g_ref.fixture + F5;
  d.particles[3] = g_ref.fixture + F3;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_TET_VOLUME; /* F0 F2 F3 F4 lie in a plane */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F2;
  d.particles[2] = g_ref.fixture + F3;
  d.particles[3] = g_ref.fixture + F4;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_LENGTH_MIN; /* F0 and F1 coincide: no direction to push apart in */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  for (kind = EMBRA_CONSTRAINT_ANGLE_MIN; kind <= EMBRA_CONSTRAINT_ANGLE_MAX; ++kind) {
    d = embra_default_constraint_def();
    d.kind = kind; /* an edge of zero length */
    d.particles[0] = g_ref.fixture + F0;
    d.particles[1] = g_ref.fixture + F1;
    d.particles[2] = g_ref.fixture + F2;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  }
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_COLINEAR; /* the line's ends F0 and F1 coincide */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F2;
  d.particles[2] = g_ref.fixture + F1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_DIRECTION; /* the reference edge F0-F1 has zero length */
  d.particles[0] = g_ref.fixture + F2;
  d.particles[1] = g_ref.fixture + F3;
  d.particles[2] = g_ref.fixture + F0;
  d.particles[3] = g_ref.fixture + F1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
  d = embra_default_constraint_def();
  d.kind = EMBRA_CONSTRAINT_COCIRCULAR; /* the corner at F2 is straight (F0 F2 F5 collinear) */
  d.particles[0] = g_ref.fixture + F0;
  d.particles[1] = g_ref.fixture + F2;
  d.particles[2] = g_ref.fixture + F5;
  d.particles[3] = g_ref.fixture + F3;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraint_add(W, &d));
}

/* embra_polygon_planarity_add: the cloth's boundary ring (eight corners, planar) is good; a corner
 * outside the world or given twice, fewer than four corners, a bad compliance, a stale group and
 * four corners in line are refused. */
static void test_polygon_planarity_add(void) {
  const int32_t c = g_ref.cloth;
  int32_t ring[8], line[4], added = -1, i;
  const embra_group_id deflt = {0, 0};
  ring[0] = c + 0, ring[1] = c + 1, ring[2] = c + 2, ring[3] = c + 5;
  ring[4] = c + 8, ring[5] = c + 7, ring[6] = c + 6, ring[7] = c + 3;
  {
    scene s;
    CHECK(scene_build(&s));
    CHECK_OK(embra_polygon_planarity_add(s.w, deflt, ring, 8, 0.0, &added));
    CHECK_INT(added, 8);
    CHECK_OK(embra_polygon_planarity_add(s.w, deflt, ring, 4, 1e-3, &added));
    CHECK_INT(added, 1);
    embra_world_destroy(s.w);
  }
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, "world", embra_polygon_planarity_add(NULL, deflt, ring, 8, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "particles", embra_polygon_planarity_add(W, deflt, NULL, 8, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_polygon_planarity_add(W, deflt, ring, 3, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_polygon_planarity_add(W, deflt, ring, -1, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_polygon_planarity_add(W, deflt, ring, INT32_MAX, 0.0, NULL));
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("polygon compliance %s", bad_name(i));
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance",
            embra_polygon_planarity_add(W, deflt, ring, 8, bad_value(i), NULL));
  }
  CAPI_CONTEXT("polygon");
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_polygon_planarity_add(W, deflt, ring, 8, -1e-6, NULL));
  REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_polygon_planarity_add(W, g_ref.g_dead, ring, 8, 0.0, NULL));
  ring[5] = g_ref.n;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_polygon_planarity_add(W, deflt, ring, 8, 0.0, NULL));
  ring[5] = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_polygon_planarity_add(W, deflt, ring, 8, 0.0, NULL));
  ring[5] = c + 1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_polygon_planarity_add(W, deflt, ring, 8, 0.0, NULL));
  /* F0 F2 F5 and one more on their line would be parallel diagonals; F0 F2 F5 F3: F3 off it. A
   * window (F0, F2, F5, F1) with F1 = F0: diagonals F0-F5 and F2-F1, both along the line. */
  line[0] = g_ref.fixture + F0, line[1] = g_ref.fixture + F2, line[2] = g_ref.fixture + F5;
  line[3] = g_ref.fixture + F1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_polygon_planarity_add(W, deflt, line, 4, 0.0, NULL));
}

/* The refusals embra_rigid_set_add and embra_shape_match_add share (one signature): no world, no
 * particles, a count below 3, negative or past the array, a compliance non-finite or negative, a
 * stale group, a point outside the world or given twice. */
typedef embra_status (*point_set_add_fn)(embra_world*, embra_group_id, const int32_t*, int32_t, double, int32_t*);
static void refuse_point_set_arguments(point_set_add_fn add, const char* what) {
  const int32_t c = g_ref.cloth;
  int32_t cloth[9], i;
  const embra_group_id deflt = {0, 0};
  for (i = 0; i < 9; ++i) cloth[i] = c + i;
  CAPI_CONTEXT("%s", what);
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, "world", add(NULL, deflt, cloth, 9, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "particles", add(W, deflt, NULL, 9, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", add(W, deflt, cloth, 2, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", add(W, deflt, cloth, -1, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", add(W, deflt, cloth, INT32_MAX, 0.0, NULL));
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("%s compliance %s", what, bad_name(i));
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", add(W, deflt, cloth, 9, bad_value(i), NULL));
  }
  CAPI_CONTEXT("%s", what);
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", add(W, deflt, cloth, 9, -1.0, NULL));
  REFUSED(EMBRA_ERROR_STALE_ID, "group", add(W, g_ref.g_dead, cloth, 9, 0.0, NULL));
  cloth[7] = g_ref.n;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", add(W, deflt, cloth, 9, 0.0, NULL));
  cloth[7] = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", add(W, deflt, cloth, 9, 0.0, NULL));
  cloth[7] = c + 2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", add(W, deflt, cloth, 9, 0.0, NULL));
}

/* embra_rigid_set_add: the flat cloth (nine points) and the tetrahedron with the free point (solid)
 * are good, 4 n - 9 constraints each; a point outside the world or given twice, fewer than three, a
 * bad compliance, a stale group, two points at one place and a set on one line are refused. */
static void test_rigid_set_add(void) {
  const int32_t c = g_ref.cloth;
  int32_t cloth[9], solid[5], bad[3], added = -1, i;
  const embra_group_id deflt = {0, 0};
  for (i = 0; i < 9; ++i) cloth[i] = c + i;
  for (i = 0; i < 4; ++i) solid[i] = g_ref.tet + i;
  solid[4] = g_ref.point;
  {
    scene s;
    CHECK(scene_build(&s));
    CHECK_OK(embra_rigid_set_add(s.w, deflt, cloth, 9, 0.0, &added));
    CHECK_INT(added, 27);
    CHECK_OK(embra_rigid_set_add(s.w, deflt, solid, 5, 1e-6, &added));
    CHECK_INT(added, 11);
    embra_world_destroy(s.w);
  }
  refuse_point_set_arguments(embra_rigid_set_add, "rigid set");
  bad[0] = g_ref.fixture + F0, bad[1] = g_ref.fixture + F2, bad[2] = g_ref.fixture + F5; /* on one line */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "line", embra_rigid_set_add(W, deflt, bad, 3, 0.0, NULL));
  bad[1] = g_ref.fixture + F1, bad[2] = g_ref.fixture + F3; /* F0 and F1 at one place */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_rigid_set_add(W, deflt, bad, 3, 0.0, NULL));
}

/* embra_shape_match_add / _remove / embra_group_get_shape_match_count: the flat cloth (nine
 * points, a rest shape in a plane) and the tetrahedron with the free point are accepted, then removed. */
static void test_shape_match_add(void) {
  const int32_t c = g_ref.cloth;
  int32_t cloth[9], solid[5], bad[3], index = -1, count = -1, i;
  const embra_group_id deflt = {0, 0};
  for (i = 0; i < 9; ++i) cloth[i] = c + i;
  for (i = 0; i < 4; ++i) solid[i] = g_ref.tet + i;
  solid[4] = g_ref.point;
  {
    scene s;
    CHECK(scene_build(&s));
    CHECK_OK(embra_shape_match_add(s.w, deflt, cloth, 9, 0.0, &index));
    CHECK_INT(index, 0);
    CHECK_OK(embra_shape_match_add(s.w, deflt, solid, 5, 1e-6, &index));
    CHECK_INT(index, 1);
    CHECK_OK(embra_group_get_shape_match_count(s.w, deflt, &count));
    CHECK_INT(count, 2);
    CHECK_OK(embra_shape_match_remove(s.w, deflt, 0));
    CHECK_OK(embra_group_get_shape_match_count(s.w, deflt, &count));
    CHECK_INT(count, 1);
    embra_world_destroy(s.w);
  }
  refuse_point_set_arguments(embra_shape_match_add, "shape match");
  bad[0] = g_ref.fixture + F0, bad[1] = g_ref.fixture + F2, bad[2] = g_ref.fixture + F5; /* on one line */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "line", embra_shape_match_add(W, deflt, bad, 3, 0.0, NULL));
  bad[1] = g_ref.fixture + F1; /* F0 and F1 at one place: with F5, two places, a line */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "line", embra_shape_match_add(W, deflt, bad, 3, 0.0, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "shape match", embra_shape_match_remove(W, deflt, 0));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "shape match", embra_shape_match_remove(W, deflt, -1));
  REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_shape_match_remove(W, g_ref.g_dead, 0));
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, "world", embra_shape_match_remove(NULL, deflt, 0));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", embra_group_get_shape_match_count(W, deflt, NULL));
}

static void test_constraints_add(void) {
  embra_constraint_batch_def d;
  int32_t ids[8];
  double rest[2], comp[2];
  int i;
#define GOOD_BATCH()                                    \
  do {                                                  \
    d = embra_default_constraint_batch_def();           \
    ids[0] = g_ref.cloth + 1, ids[1] = g_ref.cloth + 7; \
    ids[2] = g_ref.rod + 1, ids[3] = g_ref.cloth + 6;   \
    rest[0] = 0.5, rest[1] = 0.75;                      \
    comp[0] = 0.0, comp[1] = 1e-4;                      \
    d.count = 2;                                        \
    d.particles = ids;                                  \
    d.rest = rest;                                      \
    d.compliances = comp;                               \
  } while (0)
  {
    scene s;
    CHECK(scene_build(&s));
    GOOD_BATCH();
    CHECK_OK(embra_constraints_add(s.w, &d));
    embra_world_destroy(s.w);
  }
  {
    /* A conical vertex: the cloth's middle particle and its four neighbours round it (its five
     * particles do not fit embra_constraint_def). */
    const int32_t c = g_ref.cloth;
    int32_t cone[5];
    double cone_rest = 0.0;
    scene s;
    CAPI_CONTEXT("conical");
    d = embra_default_constraint_batch_def();
    d.kind = EMBRA_CONSTRAINT_CONICAL;
    d.count = 1;
    d.particles = cone;
    cone[0] = c + 4, cone[1] = c + 5, cone[2] = c + 7, cone[3] = c + 3, cone[4] = c + 1;
    CHECK(scene_build(&s));
    CHECK_OK(embra_constraints_add(s.w, &d));
    embra_world_destroy(s.w);
    cone[4] = g_ref.n;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraints_add(W, &d));
    cone[4] = c + 5;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_constraints_add(W, &d));
    cone[4] = c + 1;
    d.rest = &cone_rest;
    cone_rest = 6.3; /* beyond 2 pi */
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest angle", embra_constraints_add(W, &d));
    for (i = 0; i < 3; ++i) {
      CAPI_CONTEXT("conical, %s", bad_name(i));
      cone_rest = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_constraints_add(W, &d));
    }
  }
  {
    /* Five points on one sphere: the tetrahedron's four corners and the cloth's middle particle (its
     * five particles do not fit embra_constraint_def). */
    int32_t five[5];
    double five_rest = 0.0;
    scene s;
    CAPI_CONTEXT("cospherical");
    d = embra_default_constraint_batch_def();
    d.kind = EMBRA_CONSTRAINT_COSPHERICAL;
    d.count = 1;
    d.particles = five;
    five[0] = g_ref.tet, five[1] = g_ref.tet + 1, five[2] = g_ref.tet + 2, five[3] = g_ref.tet + 3;
    five[4] = g_ref.cloth + 4;
    CHECK(scene_build(&s));
    CHECK_OK(embra_constraints_add(s.w, &d));
    d.rest = &five_rest;
    CHECK_OK(embra_constraints_add(s.w, &d));
    d.rest = NULL;
    embra_world_destroy(s.w);
    five[4] = -1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraints_add(W, &d));
    five[4] = g_ref.n;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraints_add(W, &d));
    five[4] = g_ref.tet + 1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_constraints_add(W, &d));
    five[4] = g_ref.cloth + 4;
    d.rest = &five_rest;
    for (i = 0; i < 3; ++i) {
      CAPI_CONTEXT("cospherical, %s", bad_name(i));
      five_rest = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_constraints_add(W, &d));
    }
    CAPI_CONTEXT("cospherical, flat");
    d.rest = NULL; /* F0 F2 F3 F4 lie in a plane: no sphere through them */
    five[0] = g_ref.fixture + F0, five[1] = g_ref.fixture + F2, five[2] = g_ref.fixture + F3;
    five[3] = g_ref.fixture + F4, five[4] = g_ref.fixture + F5;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraints_add(W, &d));
  }
  GOOD_BATCH();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_constraints_add(W, NULL));
  d.version = 0;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_constraints_add(W, &d));
  GOOD_BATCH();
  d.kind = kind_count();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "kind", embra_constraints_add(W, &d));
  d.kind = INT32_MIN;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "kind", embra_constraints_add(W, &d));
  GOOD_BATCH();
  d.count = 0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_constraints_add(W, &d));
  d.count = -2;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_constraints_add(W, &d));
  GOOD_BATCH();
  d.particles = NULL;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "particles", embra_constraints_add(W, &d));
  /* All or nothing: the first constraint is fine, the second is not. */
  GOOD_BATCH();
  ids[3] = g_ref.n;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraints_add(W, &d));
  GOOD_BATCH();
  ids[3] = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_constraints_add(W, &d));
  GOOD_BATCH();
  ids[3] = ids[2];
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "twice", embra_constraints_add(W, &d));
  GOOD_BATCH();
  d.group = g_ref.g_dead;
  REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_constraints_add(W, &d));
  d.group = g_ref.g_never;
  REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_constraints_add(W, &d));
  GOOD_BATCH();
  rest[1] = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rest", embra_constraints_add(W, &d));
  GOOD_BATCH();
  comp[1] = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraints_add(W, &d));
  GOOD_BATCH();
  d.compliances = NULL;
  d.compliance = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraints_add(W, &d));
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("%s", bad_name(i));
    GOOD_BATCH();
    rest[1] = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_constraints_add(W, &d));
    GOOD_BATCH();
    comp[1] = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraints_add(W, &d));
    GOOD_BATCH();
    d.compliances = NULL;
    d.compliance = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraints_add(W, &d));
    GOOD_BATCH();
    d.compliance = bad_value(i); /* unused when `compliances` is given, but still a bad number */
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_constraints_add(W, &d));
  }
  CAPI_CONTEXT("degenerate second constraint");
  GOOD_BATCH();
  d.rest = NULL;
  ids[2] = g_ref.fixture + F0;
  ids[3] = g_ref.fixture + F1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_constraints_add(W, &d));
  GOOD_BATCH(); /* a weld has no rest value but 0 */
  d.kind = EMBRA_CONSTRAINT_WELD;
  rest[0] = 0.0;
  rest[1] = 0.5;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "weld", embra_constraints_add(W, &d));
#undef GOOD_BATCH
}

static void test_pins(void) {
  embra_pin_def d;
  embra_pin_id out;
  double t[3];
  int32_t particle = 0;
  const embra_pin_id zero = {0, 0};
  const embra_pin_id stale[4] = {g_ref.pin_dead, g_ref.pin_wrong_gen, g_ref.pin_never, zero};
  int i, k;
#define GOOD_PIN()               \
  do {                           \
    d = embra_default_pin_def(); \
    d.particle = g_ref.point;    \
    d.target[0] = 0.3;           \
    d.target[1] = 0.2;           \
    d.target[2] = 0.9;           \
  } while (0)
  {
    scene s;
    CHECK(scene_build(&s));
    GOOD_PIN();
    CHECK_OK(embra_pin_create(s.w, &d, &out));
    d.compliance = 1e-3;
    d.group = g_ref.g_late;
    CHECK_OK(embra_pin_create(s.w, &d, &out)); /* a soft pin beside a hard one is fine */
    embra_world_destroy(s.w);
  }
  GOOD_PIN();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_pin_create(W, NULL, &out));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_pin", embra_pin_create(W, &d, NULL));
  d.version = 0;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_pin_create(W, &d, &out));
  d.version = 99;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_pin_create(W, &d, &out));
  GOOD_PIN();
  d.particle = -1;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_pin_create(W, &d, &out));
  d.particle = g_ref.n;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_pin_create(W, &d, &out));
  GOOD_PIN();
  d.particle = g_ref.cloth; /* already has pin_hard */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "hard pin", embra_pin_create(W, &d, &out));
  GOOD_PIN();
  d.compliance = -1e-3;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_pin_create(W, &d, &out));
  /* Supports: a known kind, a finite nonzero axis (a plane needs its normal, a line its direction). */
  {
    scene s;
    embra_support_def sd = embra_default_support_def();
    CHECK(sd.version == EMBRA_SUPPORT_DEF_VERSION && sd.support == EMBRA_PIN_SUPPORT_PLANE);
    CHECK(sd.axis[0] == 0.0 && sd.axis[1] == 0.0 && sd.axis[2] == 1.0 && sd.compliance == 0.0);
    CHECK(scene_build(&s));
    sd.particle = g_ref.cloth; /* a hard support beside the particle's hard pin is fine */
    CHECK_OK(embra_support_create(s.w, &sd, &out));
    sd.support = EMBRA_PIN_SUPPORT_LINE;
    sd.axis[0] = 3.0;
    sd.particle = g_ref.point;
    CHECK_OK(embra_support_create(s.w, &sd, &out));
    CHECK_OK(embra_world_step(s.w));
    embra_world_destroy(s.w);
  }
  {
    embra_support_def sd;
#define GOOD_SUPPORT()                \
  do {                                \
    sd = embra_default_support_def(); \
    sd.particle = g_ref.point;        \
  } while (0)
    GOOD_SUPPORT();
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_support_create(W, NULL, &out));
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_pin", embra_support_create(W, &sd, NULL));
    sd.version = 2;
    REFUSED(EMBRA_ERROR_VERSION, "version", embra_support_create(W, &sd, &out));
    GOOD_SUPPORT();
    sd.particle = g_ref.n;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_support_create(W, &sd, &out));
    GOOD_SUPPORT();
    sd.support = EMBRA_PIN_SUPPORT_MESH + 1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "support", embra_support_create(W, &sd, &out));
    sd.support = -1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "support", embra_support_create(W, &sd, &out));
    GOOD_SUPPORT();
    sd.compliance = -1.0;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_support_create(W, &sd, &out));
    GOOD_SUPPORT();
    sd.group = g_ref.g_dead;
    REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_support_create(W, &sd, &out));
    for (k = EMBRA_PIN_SUPPORT_PLANE; k <= EMBRA_PIN_SUPPORT_LINE; ++k) {
      GOOD_SUPPORT();
      sd.support = k;
      sd.axis[2] = 0.0;
      CAPI_CONTEXT("support %d, axis 0", k);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "axis is zero", embra_support_create(W, &sd, &out));
      sd.axis[1] = 1e-320; /* denormal: its length does not normalise */
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "axis is zero", embra_support_create(W, &sd, &out));
      for (i = 0; i < 3; ++i) {
        GOOD_SUPPORT();
        sd.support = k;
        sd.axis[i % 3] = bad_value(i);
        CAPI_CONTEXT("support %d, axis = %s", k, bad_name(i));
        REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "axis", embra_support_create(W, &sd, &out));
        GOOD_SUPPORT();
        sd.target[i % 3] = bad_value(i);
        REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "target", embra_support_create(W, &sd, &out));
      }
    }
#undef GOOD_SUPPORT
  }
  CAPI_CONTEXT("pins");
  GOOD_PIN();
  d.compliance = 1e-3;
  d.group = g_ref.g_dead;
  REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_pin_create(W, &d, &out));
  d.group = g_ref.g_wrong_gen;
  REFUSED(EMBRA_ERROR_STALE_ID, "group", embra_pin_create(W, &d, &out));
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("%s", bad_name(i));
    for (k = 0; k < 3; ++k) {
      GOOD_PIN();
      d.target[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "target", embra_pin_create(W, &d, &out));
      t[0] = 0.1;
      t[1] = 0.2;
      t[2] = 0.3;
      t[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "target", embra_pin_set_target(W, S->pin_hard, t));
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "target", embra_pin_set_target(W, S->pin_soft, t));
    }
    GOOD_PIN();
    d.compliance = bad_value(i);
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", embra_pin_create(W, &d, &out));
  }
  t[0] = t[1] = t[2] = 0.0;
  for (i = 0; i < 4; ++i) {
    CAPI_CONTEXT("stale pin {%u, %u}", (unsigned)stale[i].index, (unsigned)stale[i].generation);
    REFUSED(EMBRA_ERROR_STALE_ID, "pin", embra_pin_destroy(W, stale[i]));
    REFUSED(EMBRA_ERROR_STALE_ID, "pin", embra_pin_set_target(W, stale[i], t));
    REFUSED(EMBRA_ERROR_STALE_ID, "pin", embra_pin_get_target(W, stale[i], t));
    REFUSED(EMBRA_ERROR_STALE_ID, "pin", embra_pin_get_particle(W, stale[i], &particle));
  }
  CAPI_CONTEXT("NULL");
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "target", embra_pin_set_target(W, S->pin_hard, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_target", embra_pin_get_target(W, S->pin_hard, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_particle", embra_pin_get_particle(W, S->pin_hard, NULL));
#undef GOOD_PIN
}

static void test_colliders(void) {
  embra_collider_def d;
  embra_collider_id out;
  double p[3], q[4];
  const embra_collider_id zero = {0, 0};
  const embra_collider_id stale[4] = {g_ref.col_dead, g_ref.col_wrong_gen, g_ref.col_never, zero};
  int i, k, shape;
#define GOOD_COLLIDER(s)              \
  do {                                \
    d = embra_default_collider_def(); \
    d.shape = (s);                    \
    d.position[0] = 1.0;              \
    d.position[1] = -1.0;             \
    d.position[2] = 0.5;              \
    d.rotation[0] = 0.6;              \
    d.rotation[3] = 0.8;              \
    d.radius = 0.25;                  \
  } while (0)
#define GOOD_TRANSFORM()                \
  do {                                  \
    p[0] = 0.0, p[1] = 0.0, p[2] = 0.1; \
    q[0] = 0.0, q[1] = 0.0, q[2] = 1.0; \
    q[3] = 0.0;                         \
  } while (0)
  {
    scene s;
    CHECK(scene_build(&s));
    GOOD_COLLIDER(EMBRA_COLLIDER_PLANE);
    CHECK_OK(embra_collider_create(s.w, &d, &out));
    GOOD_COLLIDER(EMBRA_COLLIDER_SPHERE);
    CHECK_OK(embra_collider_create(s.w, &d, &out));
    GOOD_TRANSFORM();
    CHECK_OK(embra_collider_set_transform(s.w, out, p, q));
    embra_world_destroy(s.w);
  }
  GOOD_COLLIDER(EMBRA_COLLIDER_SPHERE);
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "def", embra_collider_create(W, NULL, &out));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_collider", embra_collider_create(W, &d, NULL));
  d.version = 0;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_collider_create(W, &d, &out));
  d.version = 3;
  REFUSED(EMBRA_ERROR_VERSION, "version", embra_collider_create(W, &d, &out));
  GOOD_COLLIDER(6);
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "shape", embra_collider_create(W, &d, &out));
  GOOD_COLLIDER(-1);
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "shape", embra_collider_create(W, &d, &out));

  {
    /* Box, capsule, convex and mesh: their own fields, each refused with nothing changed. */
    static const double tetra[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    static const int32_t tri_out[3] = {0, 1, 4};
    static const int32_t tri_flat[3] = {0, 1, 1};
    CAPI_CONTEXT("box, capsule, convex, mesh");
    for (i = 0; i < 3; ++i) {
      GOOD_COLLIDER(EMBRA_COLLIDER_BOX);
      d.half_extents[i] = i == 0 ? 0.0 : bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "half_extents", embra_collider_create(W, &d, &out));
      GOOD_COLLIDER(EMBRA_COLLIDER_CAPSULE);
      d.half_length = i == 0 ? -1.0 : bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "half_length", embra_collider_create(W, &d, &out));
    }
    GOOD_COLLIDER(EMBRA_COLLIDER_CAPSULE);
    d.radius = 0.0;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "radius", embra_collider_create(W, &d, &out));
    GOOD_COLLIDER(EMBRA_COLLIDER_CONVEX);
    d.vertex_count = 4;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "vertices", embra_collider_create(W, &d, &out));
    d.vertices = flat;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_collider_create(W, &d, &out));
    d.vertices = tetra;
    d.vertex_count = 3;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "at least 4", embra_collider_create(W, &d, &out));
    d.vertex_count = -1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "vertex_count", embra_collider_create(W, &d, &out));
    GOOD_COLLIDER(EMBRA_COLLIDER_MESH);
    d.vertex_count = 4;
    d.vertices = tetra;
    d.triangle_count = 1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "triangles", embra_collider_create(W, &d, &out));
    d.triangles = tri_out;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", embra_collider_create(W, &d, &out));
    d.triangles = tri_flat;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "degenerate", embra_collider_create(W, &d, &out));
    d.triangle_count = 0;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "no triangles", embra_collider_create(W, &d, &out));
  }

  for (shape = 0; shape < 2; ++shape) {
    for (i = 0; i < 3; ++i) {
      CAPI_CONTEXT("shape %d, %s", shape, bad_name(i));
      for (k = 0; k < 3; ++k) {
        GOOD_COLLIDER(shape);
        d.position[k] = bad_value(i);
        REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "position", embra_collider_create(W, &d, &out));
      }
      for (k = 0; k < 4; ++k) {
        GOOD_COLLIDER(shape);
        d.rotation[k] = bad_value(i);
        REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rotation", embra_collider_create(W, &d, &out));
      }
      GOOD_COLLIDER(shape);
      d.radius = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "radius", embra_collider_create(W, &d, &out));
      GOOD_COLLIDER(shape);
      d.thickness = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "thickness", embra_collider_create(W, &d, &out));
      GOOD_COLLIDER(shape);
      d.friction_static = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "friction_static", embra_collider_create(W, &d, &out));
      GOOD_COLLIDER(shape);
      d.friction_dynamic = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "friction_dynamic", embra_collider_create(W, &d, &out));
    }
    CAPI_CONTEXT("shape %d, out of range", shape);
    GOOD_COLLIDER(shape);
    d.thickness = -0.01;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "thickness", embra_collider_create(W, &d, &out));
    GOOD_COLLIDER(shape);
    d.friction_static = -0.1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "friction_static", embra_collider_create(W, &d, &out));
    GOOD_COLLIDER(shape);
    d.friction_dynamic = -0.1;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "friction_dynamic", embra_collider_create(W, &d, &out));
    GOOD_COLLIDER(shape);
    d.rotation[0] = 1.0; /* {1, 0, 0, 0.8}: not unit */
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "unit quaternion", embra_collider_create(W, &d, &out));
    GOOD_COLLIDER(shape);
    d.rotation[0] = 0.0;
    d.rotation[3] = 0.0;
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "unit quaternion", embra_collider_create(W, &d, &out));
  }
  CAPI_CONTEXT("sphere radius");
  GOOD_COLLIDER(EMBRA_COLLIDER_SPHERE);
  d.radius = 0.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "radius", embra_collider_create(W, &d, &out));
  d.radius = -1.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "radius", embra_collider_create(W, &d, &out));

  for (i = 0; i < 4; ++i) {
    CAPI_CONTEXT("stale collider {%u, %u}", (unsigned)stale[i].index, (unsigned)stale[i].generation);
    GOOD_TRANSFORM();
    REFUSED(EMBRA_ERROR_STALE_ID, "collider", embra_collider_destroy(W, stale[i]));
    REFUSED(EMBRA_ERROR_STALE_ID, "collider", embra_collider_set_transform(W, stale[i], p, q));
    REFUSED(EMBRA_ERROR_STALE_ID, "collider", embra_collider_get_transform(W, stale[i], p, q));
  }
  CAPI_CONTEXT("set_transform");
  GOOD_TRANSFORM();
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "position", embra_collider_set_transform(W, S->col_sphere, NULL, q));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rotation", embra_collider_set_transform(W, S->col_sphere, p, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_position", embra_collider_get_transform(W, S->col_sphere, NULL, q));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_rotation", embra_collider_get_transform(W, S->col_sphere, p, NULL));
  for (i = 0; i < 3; ++i) {
    CAPI_CONTEXT("set_transform %s", bad_name(i));
    for (k = 0; k < 3; ++k) {
      GOOD_TRANSFORM();
      p[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "position", embra_collider_set_transform(W, S->col_plane, p, q));
    }
    for (k = 0; k < 4; ++k) {
      GOOD_TRANSFORM();
      q[k] = bad_value(i);
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "rotation", embra_collider_set_transform(W, S->col_sphere, p, q));
    }
  }
  CAPI_CONTEXT("set_transform non-unit");
  GOOD_TRANSFORM();
  q[2] = 1.01;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "unit quaternion", embra_collider_set_transform(W, S->col_plane, p, q));
  q[2] = 0.0;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "unit quaternion", embra_collider_set_transform(W, S->col_sphere, p, q));
#undef GOOD_COLLIDER
#undef GOOD_TRANSFORM
}

/* The id lists: every live object once, in creation order, none destroyed; the two-call pattern's
 * refusals write nothing. */
static void test_id_lists(void) {
  embra_world_counts c;
  embra_pin_id pins[16];
  embra_collider_id cols[16];
  embra_group_id groups[16];
  embra_body_id bodies[16];
  int32_t n = -1, i, particle = -1;
  double pos[3], rot[4];
  if (!CHECK(scene_build(&g_a))) return;
  CHECK_OK(embra_world_get_counts(g_a.w, &c));
  CHECK_OK(embra_world_get_bodies(g_a.w, NULL, 0, &n));
  CHECK_INT(n, c.bodies);
  CHECK_OK(embra_world_get_bodies(g_a.w, bodies, 16, &n));
  CHECK(memcmp(&bodies[0], &g_a.b_cloth, sizeof bodies[0]) == 0);
  CHECK(memcmp(&bodies[n - 1], &g_a.b_fixture, sizeof bodies[0]) == 0);
  CHECK_OK(embra_world_get_groups(g_a.w, groups, 16, &n));
  CHECK_INT(n, c.groups);
  CHECK(memcmp(&groups[0], &g_a.g_default, sizeof groups[0]) == 0);
  CHECK(memcmp(&groups[1], &g_a.g_contact, sizeof groups[0]) == 0);
  for (i = 0; i < n; ++i) CHECK(memcmp(&groups[i], &g_a.g_dead, sizeof groups[0]) != 0);
  CHECK_OK(embra_world_get_pins(g_a.w, pins, 16, &n));
  CHECK_INT(n, c.pins);
  for (i = 0; i < n; ++i) {
    CHECK(memcmp(&pins[i], &g_a.pin_dead, sizeof pins[0]) != 0);
    CHECK_OK(embra_pin_get_particle(g_a.w, pins[i], &particle));
    CHECK(particle >= 0 && particle < g_a.n);
  }
  CHECK_OK(embra_pin_get_particle(g_a.w, g_a.pin_hard, &particle));
  CHECK_INT(particle, g_a.cloth);
  CHECK_OK(embra_world_get_colliders(g_a.w, cols, 16, &n));
  CHECK_INT(n, c.colliders);
  for (i = 0; i < n; ++i) CHECK(memcmp(&cols[i], &g_a.col_dead, sizeof cols[0]) != 0);
  /* A collider reads back the pose it was last sent to. */
  pos[0] = 0.5, pos[1] = -0.25, pos[2] = 2.0;
  rot[0] = 0.0, rot[1] = 0.0, rot[2] = 0.0, rot[3] = 1.0; /* half a turn about z */
  CHECK_OK(embra_collider_set_transform(g_a.w, g_a.col_sphere, pos, rot));
  memset(pos, 0, sizeof pos);
  CHECK_OK(embra_collider_get_transform(g_a.w, g_a.col_sphere, pos, rot));
  CHECK(pos[0] == 0.5 && pos[1] == -0.25 && pos[2] == 2.0);
  CHECK(rot[0] == 0.0 && rot[1] == 0.0 && rot[2] == 0.0 && rot[3] == 1.0);
  embra_world_destroy(g_a.w);

  memset(pins, 0x5A, sizeof pins);
  REFUSED(EMBRA_ERROR_BUFFER_TOO_SMALL, "needed", embra_world_get_pins(W, pins, 1, &n));
  CHECK(pins[0].index == 0x5A5A5A5Au); /* nothing written */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "capacity", embra_world_get_colliders(W, cols, -1, &n));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", embra_world_get_groups(W, groups, 16, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out", embra_world_get_bodies(W, NULL, 4, &n));
}

static void test_particles(void) {
  double buf[3 * MAX_PARTICLES + 3], sentinel[3 * MAX_PARTICLES + 3];
  double xyz[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  embra_step_report r;
  embra_warning wn;
  int i, k, which;
  for (i = 0; i < 3 * MAX_PARTICLES + 3; ++i) sentinel[i] = -12345.678;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_report", embra_world_get_report(W, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_warning", embra_world_get_warning(W, NULL));
  (void)r;
  (void)wn;

  for (which = 0; which < 2; ++which) {
    embra_status (*get)(const embra_world*, double*, int64_t, int32_t, int32_t) =
        which == 0 ? embra_world_get_positions : embra_world_get_velocities;
    const char* name = which == 0 ? "embra_world_get_positions" : "embra_world_get_velocities";
    /* Through a function pointer, the REFUSED text would not name the function; check it here. */
    CAPI_CONTEXT("%s", name);
    prime_message();
    {
      scene s;
      CHECK(scene_build(&s));
      CHECK_STATUS(get(s.w, NULL, 3, 0, 1), EMBRA_ERROR_INVALID_ARGUMENT);
      CHECK_CONTAINS(embra_last_error_message(), name);
      embra_world_destroy(s.w);
    }
    /* Bad ranges and too small buffers: refused, the buffer untouched. */
    {
      static const int32_t ranges[][2] = {
          {-1, 1}, {0, -1}, {0, MAX_PARTICLES + 1}, {1, -1}, {INT32_MAX, 1}, {INT32_MAX, INT32_MAX}, {INT32_MIN, 2}};
      size_t j;
      for (j = 0; j < sizeof ranges / sizeof ranges[0]; ++j) {
        const int32_t first = ranges[j][0];
        int32_t count = ranges[j][1];
        scene s;
        embra_status st;
        CAPI_CONTEXT("%s range [%ld, +%ld)", name, (long)first, (long)count);
        CHECK(scene_build(&s));
        if (count == MAX_PARTICLES + 1) count = s.n + 1;
        memcpy(buf, sentinel, sizeof buf);
        prime_message();
        st = get(s.w, buf, 3 * MAX_PARTICLES + 3, first, count);
        CHECK_INT(st, EMBRA_ERROR_INVALID_ARGUMENT);
        CHECK_CONTAINS(embra_last_error_message(), "range");
        CHECK(memcmp(buf, sentinel, sizeof buf) == 0);
        embra_world_destroy(s.w);
      }
    }
    {
      static const int64_t caps[] = {0, 1, 5, 3 * 4 - 1, -1, INT64_MIN};
      size_t j;
      for (j = 0; j < sizeof caps / sizeof caps[0]; ++j) {
        scene s;
        embra_status st;
        CAPI_CONTEXT("%s capacity %lld for 4 particles", name, (long long)caps[j]);
        CHECK(scene_build(&s));
        memcpy(buf, sentinel, sizeof buf);
        prime_message();
        st = get(s.w, buf, caps[j], 2, 4);
        CHECK_INT(st, EMBRA_ERROR_BUFFER_TOO_SMALL);
        CHECK_CONTAINS(embra_last_error_message(), name);
        CHECK_CONTAINS(embra_last_error_message(), "buffer");
        CHECK(memcmp(buf, sentinel, sizeof buf) == 0); /* nothing written */
        embra_world_destroy(s.w);
      }
    }
  }
  /* The same through REFUSED (world unchanged, twin-identical). */
  memcpy(buf, sentinel, sizeof buf);
  REFUSED(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer", embra_world_get_positions(W, buf, 2, 0, 1));
  REFUSED(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer", embra_world_get_velocities(W, buf, 3 * 5 - 1, 1, 5));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_xyz", embra_world_get_positions(W, NULL, 3, 0, 1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_xyz", embra_world_get_velocities(W, NULL, 3, 0, 1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_get_positions(W, buf, 300, S->n - 1, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_get_velocities(W, buf, 300, -1, 2));
  CHECK(memcmp(buf, sentinel, sizeof buf) == 0);

  /* Setters. */
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "xyz", embra_world_set_positions(W, NULL, 0, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "xyz", embra_world_set_velocities(W, NULL, 0, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_world_set_positions(W, xyz, 0, -1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_world_set_velocities(W, xyz, 0, INT32_MIN));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_positions(W, xyz, -1, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_velocities(W, xyz, -1, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_positions(W, xyz, S->n - 1, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_velocities(W, xyz, S->n, 1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_positions(W, xyz, INT32_MAX, 2));
  for (i = 0; i < 3; ++i)
    for (k = 0; k < 6; ++k) {
      double v[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
      CAPI_CONTEXT("xyz[%d] = %s", k, bad_name(i));
      v[k] = bad_value(i); /* the second particle's coordinate: all or nothing */
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_world_set_positions(W, v, S->cloth + 3, 2));
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_world_set_velocities(W, v, S->rod + 1, 2));
    }
}

/* Point loads, member forces and reactions: every argument checked, a refusal changes nothing. */
static void test_statics(void) {
  const double xyz[6] = {1, 2, 3, 4, 5, 6};
  double buf[64];
  embra_reaction r[8];
  embra_collider_reaction cr[8];
  int32_t n32 = -7;
  int64_t n64 = -7;
  int i, k;
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "xyz", embra_world_set_loads(W, NULL, 0, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "count", embra_world_set_loads(W, xyz, 0, -1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_loads(W, xyz, -1, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_loads(W, xyz, S->n - 1, 2));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_set_loads(W, xyz, INT32_MAX, 2));
  for (i = 0; i < 3; ++i)
    for (k = 0; k < 6; ++k) {
      double v[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
      CAPI_CONTEXT("xyz[%d] = %s", k, bad_name(i));
      v[k] = bad_value(i); /* all or nothing: the first particle's load is not set either */
      REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", embra_world_set_loads(W, v, S->cloth + 3, 2));
    }
  CAPI_CONTEXT("statics");
  {
    double big[3] = {0.0, 2e300, 0.0};
    REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "1e300", embra_world_set_loads(W, big, 0, 1));
  }
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_xyz", embra_world_get_loads(W, NULL, 3, 0, 1));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "range", embra_world_get_loads(W, buf, 64, S->n - 1, 2));
  REFUSED(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer", embra_world_get_loads(W, buf, 5, 0, 2));

  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", embra_world_get_reactions(W, r, 8, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "capacity", embra_world_get_reactions(W, r, -1, &n32));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out", embra_world_get_reactions(W, NULL, 8, &n32));
  REFUSED(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer", embra_world_get_reactions(W, r, 1, &n32));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", embra_world_get_collider_reactions(W, cr, 8, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "capacity", embra_world_get_collider_reactions(W, cr, -1, &n32));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out", embra_world_get_collider_reactions(W, NULL, 8, &n32));
  /* Too small: nothing written (the sentinel survives), the count needed reported. */
  n32 = -7;
  memset(cr, 0xab, sizeof cr);
  REFUSED(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer", embra_world_get_collider_reactions(W, cr, 1, &n32));
  {
    unsigned char sentinel[sizeof cr];
    memset(sentinel, 0xab, sizeof sentinel);
    CHECK(memcmp(cr, sentinel, sizeof cr) == 0);
  }

  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count",
          embra_group_get_forces(W, S->g_default, EMBRA_CONSTRAINT_DISTANCE, buf, 64, NULL));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "capacity",
          embra_group_get_forces(W, S->g_default, EMBRA_CONSTRAINT_DISTANCE, buf, -1, &n64));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "kind", embra_group_get_forces(W, S->g_default, 42, buf, 64, &n64));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "kind", embra_group_get_forces(W, S->g_default, -1, buf, 64, &n64));
  REFUSED(EMBRA_ERROR_INVALID_ARGUMENT, "3 multipliers",
          embra_group_get_forces(W, S->g_default, EMBRA_CONSTRAINT_WELD, buf, 64, &n64));
  REFUSED(EMBRA_ERROR_STALE_ID, "group",
          embra_group_get_forces(W, S->g_dead, EMBRA_CONSTRAINT_DISTANCE, buf, 64, &n64));

  /* The two-call pattern: the counts, then the values; the hard pin's reaction holds its particle's
   * share of the cloth, the soft pin's is its multiplier. */
  {
    scene s;
    embra_pin_id pins[8];
    int32_t np = 0, count = 0;
    int64_t nf = 0;
    CHECK(scene_build(&s));
    CHECK_OK(embra_world_step(s.w));
    CHECK_OK(embra_world_get_pins(s.w, pins, 8, &np));
    CHECK_OK(embra_world_get_reactions(s.w, NULL, 0, &count));
    CHECK(count == np && count > 0 && count <= 8);
    CHECK_OK(embra_world_get_reactions(s.w, r, 8, &count));
    for (i = 0; i < count; ++i) {
      CHECK(r[i].pin.index == pins[i].index && r[i].pin.generation == pins[i].generation);
      CHECK(isfinite(r[i].force[0]) && isfinite(r[i].force[1]) && isfinite(r[i].force[2]));
    }
    /* The colliders (the plane and the sphere; the destroyed one is not listed), in slot order. */
    {
      embra_collider_id cols[8];
      int32_t nc = 0;
      CHECK_OK(embra_world_get_colliders(s.w, cols, 8, &nc));
      CHECK_OK(embra_world_get_collider_reactions(s.w, NULL, 0, &count));
      CHECK(count == nc && count == 2);
      CHECK_OK(embra_world_get_collider_reactions(s.w, cr, 8, &count));
      for (i = 0; i < count; ++i) {
        CHECK(cr[i].collider.index == cols[i].index && cr[i].collider.generation == cols[i].generation);
        CHECK(cr[i].contacts >= 0);
        for (k = 0; k < 3; ++k) CHECK(isfinite(cr[i].force[k]) && isfinite(cr[i].moment[k]));
      }
    }
    CHECK_OK(embra_group_get_forces(s.w, s.g_custom, EMBRA_CONSTRAINT_DISTANCE, NULL, 0, &nf));
    CHECK(nf > 0 && nf <= 64);
    CHECK_OK(embra_group_get_forces(s.w, s.g_custom, EMBRA_CONSTRAINT_DISTANCE, buf, 64, &nf));
    for (i = 0; i < (int)nf; ++i) CHECK(isfinite(buf[i]));
    embra_world_destroy(s.w);
  }
}

/* The world's scene JSON, malloc'ed (NULL on failure). */
static char* saved_json(const embra_world* w) {
  int64_t n = 0;
  char* text;
  if (embra_world_save_json(w, NULL, 0, &n) != EMBRA_OK || n <= 0) return NULL;
  text = (char*)malloc((size_t)n);
  if (text != NULL && embra_world_save_json(w, text, n, &n) != EMBRA_OK) {
    free(text);
    return NULL;
  }
  return text;
}

/* A refused call on s's world: the status, a message naming the function and `needle`, and the
 * saved scene byte-identical to `before`. */
#define REFUSED_SAVED(expected, needle, before, w, ...)                                   \
  do {                                                                                    \
    char* after_;                                                                         \
    prime_message();                                                                      \
    check_refusal(__FILE__, __LINE__, #__VA_ARGS__, (__VA_ARGS__), (expected), (needle)); \
    after_ = saved_json(w);                                                               \
    CHECK(after_ != NULL && (before) != NULL && strcmp(after_, (before)) == 0);           \
    free(after_);                                                                         \
  } while (0)

/* Area and line loads: every argument checked; a refused call leaves the saved scene as it was. */
static void test_distributed_loads(void) {
  scene s;
  char* before;
  embra_area_load area[2], bad, got[2];
  embra_line_load line[1], badl, gotl[1];
  int32_t n = -1;
  int i, k;
  CHECK(scene_build(&s));
  for (i = 0; i < 2; ++i) {
    area[i].particles[0] = s.cloth;
    area[i].particles[1] = s.cloth + 1;
    area[i].particles[2] = s.cloth + 2 + i;
    area[i].mode = i == 0 ? EMBRA_AREA_LOAD_NORMAL : EMBRA_AREA_LOAD_PROJECTED_AREA;
    area[i].pressure = 25.0 + i;
    area[i].direction[0] = 0.0;
    area[i].direction[1] = 0.0;
    area[i].direction[2] = -3.0;
  }
  line[0].particles[0] = s.cloth;
  line[0].particles[1] = s.cloth + 3;
  line[0].load[0] = 1.0;
  line[0].load[1] = 0.0;
  line[0].load[2] = -40.0;
  CHECK_OK(embra_world_set_area_loads(s.w, area, 2));
  CHECK_OK(embra_world_set_line_loads(s.w, line, 1));
  CHECK_OK(embra_world_step(s.w));
  before = saved_json(s.w);
  CHECK(before != NULL && strstr(before, "\"area_loads\"") != NULL && strstr(before, "\"line_loads\"") != NULL);

  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "world", before, s.w, embra_world_set_area_loads(NULL, area, 1));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "loads", before, s.w, embra_world_set_area_loads(s.w, NULL, 1));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "count", before, s.w, embra_world_set_area_loads(s.w, area, -1));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "loads", before, s.w, embra_world_set_line_loads(s.w, NULL, 1));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "count", before, s.w, embra_world_set_line_loads(s.w, line, -1));
  for (k = 0; k < 3; ++k) {
    const int32_t out_of_range[3] = {-1, s.n, INT32_MAX};
    CAPI_CONTEXT("corner %d", k);
    for (i = 0; i < 3; ++i) {
      embra_area_load two[2];
      two[0] = area[0];
      two[1] = area[1];
      two[1].particles[k] = out_of_range[i]; /* all or nothing: the first load is not set either */
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_world_set_area_loads(s.w, two, 2));
    }
    bad = area[0];
    bad.particles[k] = bad.particles[(k + 1) % 3];
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "repeats a corner", before, s.w,
                  embra_world_set_area_loads(s.w, &bad, 1));
  }
  CAPI_CONTEXT("area load values");
  bad = area[0];
  bad.mode = 3;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "mode", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
  bad.mode = -1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "mode", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
  for (i = 0; i < 3; ++i) {
    bad = area[0];
    bad.pressure = bad_value(i);
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
    for (k = 0; k < 3; ++k) {
      bad = area[1];
      bad.direction[k] = bad_value(i);
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
      badl = line[0];
      badl.load[k] = bad_value(i);
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", before, s.w, embra_world_set_line_loads(s.w, &badl, 1));
    }
  }
  bad = area[0];
  bad.pressure = 2e300;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "1e300", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
  bad = area[1];
  bad.direction[0] = bad.direction[1] = bad.direction[2] = 0.0;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "zero", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
  bad.mode = EMBRA_AREA_LOAD_TRUE_AREA;
  bad.direction[2] = 1e-320; /* too short to normalise */
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "zero", before, s.w, embra_world_set_area_loads(s.w, &bad, 1));
  CAPI_CONTEXT("line load particles");
  badl = line[0];
  badl.particles[1] = badl.particles[0];
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "itself", before, s.w, embra_world_set_line_loads(s.w, &badl, 1));
  badl = line[0];
  badl.particles[0] = s.n;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_world_set_line_loads(s.w, &badl, 1));

  CAPI_CONTEXT("reading back");
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", before, s.w, embra_world_get_area_loads(s.w, got, 2, NULL));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "capacity", before, s.w, embra_world_get_area_loads(s.w, got, -1, &n));
  REFUSED_SAVED(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer", before, s.w, embra_world_get_area_loads(s.w, got, 1, &n));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out", before, s.w, embra_world_get_line_loads(s.w, NULL, 1, &n));
  CHECK_OK(embra_world_get_area_loads(s.w, NULL, 0, &n));
  CHECK(n == 2);
  CHECK_OK(embra_world_get_area_loads(s.w, got, 2, &n));
  CHECK(n == 2 && memcmp(got, area, sizeof area) == 0);
  CHECK_OK(embra_world_get_line_loads(s.w, gotl, 1, &n));
  CHECK(n == 1 && memcmp(gotl, line, sizeof line) == 0);
  /* count 0 clears, with or without an array. */
  CHECK_OK(embra_world_set_area_loads(s.w, NULL, 0));
  CHECK_OK(embra_world_set_line_loads(s.w, line, 0));
  CHECK_OK(embra_world_get_area_loads(s.w, NULL, 0, &n));
  CHECK(n == 0);
  CHECK_OK(embra_world_get_line_loads(s.w, NULL, 0, &n));
  CHECK(n == 0);
  free(before);
  embra_world_destroy(s.w);
}

/* Polyline supports: the curve checked whole; a refused call leaves the saved scene as it was. */
static void test_polyline_supports(void) {
  scene s;
  char* before;
  embra_polyline_support_def pd;
  embra_support_def sd;
  embra_pin_id out = {0, 0};
  double pts[3 * 5] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0.5, -0.5, 0.5, 0.2};
  int i, k;
  CHECK(scene_build(&s));
  pd = embra_default_polyline_support_def();
  CHECK(pd.version == EMBRA_POLYLINE_SUPPORT_DEF_VERSION && pd.point_count == 0 && pd.closed == 0);
  CHECK(pd.points == NULL && pd.compliance == 0.0 && pd.target[0] == 0.0 && pd.target[2] == 0.0);
  pd.particle = s.point;
  pd.points = pts;
  pd.point_count = 5;
  pd.closed = 1;
  CHECK_OK(embra_polyline_support_create(s.w, &pd, &out));
  CHECK_OK(embra_world_step(s.w));
  before = saved_json(s.w);
  CHECK(before != NULL && strstr(before, "\"polyline\"") != NULL);
#define GOOD_POLYLINE()                        \
  do {                                         \
    pd = embra_default_polyline_support_def(); \
    pd.particle = s.point;                     \
    pd.points = pts;                           \
    pd.point_count = 5;                        \
  } while (0)
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "world", before, s.w, embra_polyline_support_create(NULL, &pd, &out));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "def", before, s.w, embra_polyline_support_create(s.w, NULL, &out));
  GOOD_POLYLINE();
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out_pin", before, s.w, embra_polyline_support_create(s.w, &pd, NULL));
  pd.version = 2;
  REFUSED_SAVED(EMBRA_ERROR_VERSION, "version", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  GOOD_POLYLINE();
  pd.points = NULL;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "points", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  GOOD_POLYLINE();
  pd.point_count = 0;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "points", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  pd.point_count = 1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "points", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  pd.point_count = -1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "point_count", before, s.w,
                embra_polyline_support_create(s.w, &pd, &out));
  pd.point_count = INT32_MAX;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "point_count", before, s.w,
                embra_polyline_support_create(s.w, &pd, &out));
  GOOD_POLYLINE();
  pd.point_count = 2;
  pd.closed = 1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "closed", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  pd.closed = 2;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "closed", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  GOOD_POLYLINE();
  pd.particle = s.n;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  GOOD_POLYLINE();
  pd.compliance = -1.0;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  GOOD_POLYLINE();
  pd.group = g_ref.g_dead;
  REFUSED_SAVED(EMBRA_ERROR_STALE_ID, "group", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
  for (i = 0; i < 3; ++i) {
    GOOD_POLYLINE();
    pd.target[i] = bad_value(i);
    CAPI_CONTEXT("target[%d] = %s", i, bad_name(i));
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "target", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
    for (k = 0; k < 15; k += 4) {
      double bad[3 * 5];
      memcpy(bad, pts, sizeof bad);
      bad[k] = bad_value(i);
      CAPI_CONTEXT("points[%d] = %s", k, bad_name(i));
      GOOD_POLYLINE();
      pd.points = bad;
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", before, s.w, embra_polyline_support_create(s.w, &pd, &out));
    }
  }
  CAPI_CONTEXT("degenerate segments");
  {
    double repeated[3 * 5];
    memcpy(repeated, pts, sizeof repeated);
    memcpy(&repeated[6], &repeated[3], 3 * sizeof(double)); /* point 2 = point 1 */
    GOOD_POLYLINE();
    pd.points = repeated;
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "zero length", before, s.w,
                  embra_polyline_support_create(s.w, &pd, &out));
    memcpy(repeated, pts, sizeof repeated);
    memcpy(&repeated[12], &repeated[0], 3 * sizeof(double)); /* last = first: degenerate when closed */
    pd.closed = 1;
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "zero length", before, s.w,
                  embra_polyline_support_create(s.w, &pd, &out));
  }
#undef GOOD_POLYLINE
  CAPI_CONTEXT("embra_support_create");
  sd = embra_default_support_def();
  sd.particle = s.point;
  sd.support = EMBRA_PIN_SUPPORT_POLYLINE; /* its curve comes through embra_polyline_support_create */
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "embra_polyline_support_create", before, s.w,
                embra_support_create(s.w, &sd, &out));
  free(before);
  embra_world_destroy(s.w);
}

/* Per-axis anchors (EMBRA_PIN_SUPPORT_AXES): the axis flags checked; a refused call leaves the saved
 * scene as it was. */
static void test_anchor_supports(void) {
  scene s;
  char* before;
  embra_support_def sd;
  embra_pin_id out = {0, 0}, dead;
  const double not_flags[] = {0.5, 2.0, -1.0, 1e-300, 1.0 + 1e-15};
  int i, k;
  CHECK(scene_build(&s));
  sd = embra_default_support_def();
  sd.particle = s.point;
  sd.support = EMBRA_PIN_SUPPORT_AXES; /* the default axis {0, 0, 1}: z held */
  CHECK_OK(embra_support_create(s.w, &sd, &dead));
  CHECK_OK(embra_pin_destroy(s.w, dead));
  sd.axis[0] = 1.0;
  CHECK_OK(embra_support_create(s.w, &sd, &out));
  CHECK_OK(embra_world_step(s.w));
  before = saved_json(s.w);
  CHECK(before != NULL && strstr(before, "\"axes\"") != NULL);
#define GOOD_ANCHOR()                    \
  do {                                   \
    sd = embra_default_support_def();    \
    sd.particle = s.point;               \
    sd.support = EMBRA_PIN_SUPPORT_AXES; \
  } while (0)
  GOOD_ANCHOR();
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "world", before, s.w, embra_support_create(NULL, &sd, &out));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "def", before, s.w, embra_support_create(s.w, NULL, &out));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out_pin", before, s.w, embra_support_create(s.w, &sd, NULL));
  sd.particle = -1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_support_create(s.w, &sd, &out));
  sd.particle = s.n;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_support_create(s.w, &sd, &out));
  GOOD_ANCHOR();
  sd.axis[2] = 0.0; /* nothing held */
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "holds no coordinate", before, s.w, embra_support_create(s.w, &sd, &out));
  for (k = 0; k < 3; ++k)
    for (i = 0; i < (int)(sizeof not_flags / sizeof not_flags[0]); ++i) {
      GOOD_ANCHOR();
      sd.axis[k] = not_flags[i];
      CAPI_CONTEXT("axis[%d] = %.17g", k, not_flags[i]);
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "1 (that coordinate held) or 0", before, s.w,
                    embra_support_create(s.w, &sd, &out));
    }
  for (i = 0; i < 3; ++i) {
    GOOD_ANCHOR();
    sd.axis[i] = bad_value(i);
    CAPI_CONTEXT("axis[%d] = %s", i, bad_name(i));
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "axis", before, s.w, embra_support_create(s.w, &sd, &out));
    GOOD_ANCHOR();
    sd.target[i] = bad_value(i);
    CAPI_CONTEXT("target[%d] = %s", i, bad_name(i));
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "target", before, s.w, embra_support_create(s.w, &sd, &out));
  }
  CAPI_CONTEXT("compliance, group, stale pin");
  GOOD_ANCHOR();
  sd.compliance = -1.0;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", before, s.w, embra_support_create(s.w, &sd, &out));
  sd.compliance = NAN;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", before, s.w, embra_support_create(s.w, &sd, &out));
  GOOD_ANCHOR();
  sd.group = s.g_dead;
  REFUSED_SAVED(EMBRA_ERROR_STALE_ID, "group", before, s.w, embra_support_create(s.w, &sd, &out));
  {
    const double t[3] = {0.0, 0.0, 0.0};
    REFUSED_SAVED(EMBRA_ERROR_STALE_ID, "pin", before, s.w, embra_pin_set_target(s.w, dead, t));
  }
#undef GOOD_ANCHOR
  free(before);
  embra_world_destroy(s.w);
}

/* A polyline support's points read back (embra_polyline_support_get_points): exactly as created, and
 * unchanged by embra_pin_set_target, which moves the curve with the target; every refusal leaves the
 * saved scene as it was. */
static void test_polyline_support_points(void) {
  scene s;
  char* before;
  embra_polyline_support_def pd;
  embra_support_def sd;
  embra_pin_id poly, plane;
  const double pts[3 * 4] = {0.1, -0.2, 0.3, 1.0 / 3.0, 0.25, -0.125, 0.7, 0.9, 0.05, -0.4, 0.6, 0.2};
  const double moved[3] = {0.5, -1.25, 2.0};
  double got[3 * 4], target[3], big[3 * 6];
  int32_t n = -1;
  CHECK(scene_build(&s));
  pd = embra_default_polyline_support_def();
  pd.particle = s.point;
  pd.target[0] = 0.25;
  pd.target[1] = 0.25;
  pd.target[2] = 0.6;
  pd.points = pts;
  pd.point_count = 4;
  pd.closed = 1;
  CHECK_OK(embra_polyline_support_create(s.w, &pd, &poly));
  sd = embra_default_support_def();
  sd.particle = s.point;
  CHECK_OK(embra_support_create(s.w, &sd, &plane));
  /* Two calls: the count, then the points, bit for bit as created. */
  CHECK_OK(embra_polyline_support_get_points(s.w, poly, NULL, 0, &n));
  CHECK_INT(n, 4);
  memset(got, 0, sizeof got);
  n = -1;
  CHECK_OK(embra_polyline_support_get_points(s.w, poly, got, 4, &n));
  CHECK_INT(n, 4);
  CHECK(memcmp(got, pts, sizeof pts) == 0);
  n = -1;
  CHECK_OK(embra_polyline_support_get_points(s.w, poly, big, 6, &n)); /* a larger buffer is fine */
  CHECK_INT(n, 4);
  CHECK(memcmp(big, pts, sizeof pts) == 0);
  /* Moving the target moves the curve: the offsets read back unchanged, the target is the new one. */
  CHECK_OK(embra_pin_set_target(s.w, poly, moved));
  CHECK_OK(embra_world_step(s.w));
  CHECK_OK(embra_polyline_support_get_points(s.w, poly, got, 4, &n));
  CHECK(memcmp(got, pts, sizeof pts) == 0);
  CHECK_OK(embra_pin_get_target(s.w, poly, target));
  CHECK(memcmp(target, moved, sizeof moved) == 0);
  before = saved_json(s.w);
  CHECK(before != NULL);
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "world", before, s.w,
                embra_polyline_support_get_points(NULL, poly, got, 4, &n));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out_count", before, s.w,
                embra_polyline_support_get_points(s.w, poly, got, 4, NULL));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "capacity", before, s.w,
                embra_polyline_support_get_points(s.w, poly, got, -1, &n));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out", before, s.w,
                embra_polyline_support_get_points(s.w, poly, NULL, 4, &n));
  memset(got, 0, sizeof got);
  REFUSED_SAVED(EMBRA_ERROR_BUFFER_TOO_SMALL, "4 needed", before, s.w,
                embra_polyline_support_get_points(s.w, poly, got, 3, &n));
  CHECK(got[0] == 0.0 && got[8] == 0.0); /* nothing written */
  REFUSED_SAVED(EMBRA_ERROR_STALE_ID, "pin", before, s.w,
                embra_polyline_support_get_points(s.w, s.pin_dead, got, 4, &n));
  REFUSED_SAVED(EMBRA_ERROR_STALE_ID, "pin", before, s.w,
                embra_polyline_support_get_points(s.w, s.pin_wrong_gen, got, 4, &n));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "not a polyline support", before, s.w,
                embra_polyline_support_get_points(s.w, plane, got, 4, &n));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "not a polyline support", before, s.w,
                embra_polyline_support_get_points(s.w, s.pin_soft, got, 4, &n));
  free(before);
  embra_world_destroy(s.w);
}

/* Mesh supports: the mesh checked whole; a refused call leaves the saved scene as it was. */
static void test_mesh_supports(void) {
  scene s;
  char* before;
  embra_mesh_support_def md;
  embra_support_def sd;
  embra_pin_id out = {0, 0};
  /* A tetrahedron round the target: 4 vertices, 4 triangles, counter-clockwise from outside. */
  double verts[3 * 4] = {0.3, 0, 0, -0.1, 0.25, 0, -0.1, -0.25, 0, 0, 0, 0.4};
  int32_t tris[3 * 4] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  int i, k;
  CHECK(scene_build(&s));
  md = embra_default_mesh_support_def();
  CHECK(md.version == EMBRA_MESH_SUPPORT_DEF_VERSION && md.vertex_count == 0 && md.triangle_count == 0);
  CHECK(md.vertices == NULL && md.triangles == NULL && md.compliance == 0.0 && md.target[0] == 0.0);
  md.particle = s.point;
  md.target[0] = 0.25;
  md.target[1] = 0.25;
  md.target[2] = 0.5;
  md.vertices = verts;
  md.vertex_count = 4;
  md.triangles = tris;
  md.triangle_count = 4;
  md.compliance = 1e-5;
  CHECK_OK(embra_mesh_support_create(s.w, &md, &out));
  CHECK_OK(embra_world_step(s.w));
  before = saved_json(s.w);
  CHECK(before != NULL && strstr(before, "\"mesh\"") != NULL);
#define GOOD_MESH()                        \
  do {                                     \
    md = embra_default_mesh_support_def(); \
    md.particle = s.point;                 \
    md.vertices = verts;                   \
    md.vertex_count = 4;                   \
    md.triangles = tris;                   \
    md.triangle_count = 4;                 \
  } while (0)
  GOOD_MESH();
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "world", before, s.w, embra_mesh_support_create(NULL, &md, &out));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "def", before, s.w, embra_mesh_support_create(s.w, NULL, &out));
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "out_pin", before, s.w, embra_mesh_support_create(s.w, &md, NULL));
  md.version = 2;
  REFUSED_SAVED(EMBRA_ERROR_VERSION, "version", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.vertices = NULL;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "vertices", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.triangles = NULL;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "triangles", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.vertex_count = 2;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "vertices", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  md.vertex_count = -1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "vertex_count", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  md.vertex_count = INT32_MAX;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "vertex_count", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.triangle_count = 0;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "triangles", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  md.triangle_count = -1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "triangle_count", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  md.triangle_count = INT32_MAX;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "triangle_count", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.particle = s.n;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  md.particle = -1;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.compliance = -1.0;
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "compliance", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  GOOD_MESH();
  md.group = s.g_dead;
  REFUSED_SAVED(EMBRA_ERROR_STALE_ID, "group", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  for (i = 0; i < 3; ++i) {
    GOOD_MESH();
    md.target[i] = bad_value(i);
    CAPI_CONTEXT("target[%d] = %s", i, bad_name(i));
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "target", before, s.w, embra_mesh_support_create(s.w, &md, &out));
    for (k = 0; k < 12; k += 5) {
      double bad[3 * 4];
      memcpy(bad, verts, sizeof bad);
      bad[k] = bad_value(i);
      CAPI_CONTEXT("vertices[%d] = %s", k, bad_name(i));
      GOOD_MESH();
      md.vertices = bad;
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "finite", before, s.w, embra_mesh_support_create(s.w, &md, &out));
    }
  }
  CAPI_CONTEXT("indices out of range");
  for (k = 0; k < 12; k += 7) {
    int32_t bad[3 * 4];
    const int32_t wrong[2] = {4, -1};
    for (i = 0; i < 2; ++i) {
      memcpy(bad, tris, sizeof bad);
      bad[k] = wrong[i];
      GOOD_MESH();
      md.triangles = bad;
      REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "outside", before, s.w, embra_mesh_support_create(s.w, &md, &out));
    }
  }
  CAPI_CONTEXT("degenerate triangles");
  {
    int32_t repeated[3 * 4];
    double flat[3 * 4];
    memcpy(repeated, tris, sizeof repeated);
    repeated[5] = repeated[4]; /* triangle 1 = (0, 1, 1) */
    GOOD_MESH();
    md.triangles = repeated;
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "zero area", before, s.w, embra_mesh_support_create(s.w, &md, &out));
    memcpy(flat, verts, sizeof flat);
    flat[9] = 0.1; /* vertex 3 onto the line through vertices 0 and 1: triangle 1 collinear */
    flat[10] = 0.125;
    flat[11] = 0.0;
    GOOD_MESH();
    md.vertices = flat;
    REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "zero area", before, s.w, embra_mesh_support_create(s.w, &md, &out));
  }
#undef GOOD_MESH
  CAPI_CONTEXT("embra_support_create");
  sd = embra_default_support_def();
  sd.particle = s.point;
  sd.support = EMBRA_PIN_SUPPORT_MESH; /* its mesh comes through embra_mesh_support_create */
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "embra_mesh_support_create", before, s.w,
                embra_support_create(s.w, &sd, &out));
  free(before);
  embra_world_destroy(s.w);
}

/* The panel builder's planarity refusal follows the tolerances in force: a quad with a corner 2e-5 m
 * off the plane of a 1 m square (its diagonals 1e-5 of an edge apart, refused by the old fixed 1e-6
 * bound; planarity 1 - 1/sqrt(1 + 2 (2e-5)^2) = 4e-10) is refused under a document whose planarity
 * target is 1e-10, leaving the saved scene as it was, and built under the default tolerances
 * (planarity target 1e-6). */
static void test_panel_planarity_tolerance(void) {
  scene s;
  char* before;
  const double pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 2e-5, 0, 1, 0};
  const int32_t quad[4] = {0, 1, 2, 3};
  embra_panel_mesh_def pd;
  embra_tolerances t = embra_default_tolerances();
  embra_body_id body;
  embra_panel_metrics m;
  CHECK(scene_build(&s));
  t.planarity.target = 1e-10;
  CHECK_OK(embra_world_set_tolerances(s.w, &t));
  pd = embra_default_panel_mesh_def();
  pd.vertex_count = 4;
  pd.positions = pos;
  pd.quads = quad;
  pd.quad_count = 1;
  before = saved_json(s.w);
  CHECK(before != NULL);
  REFUSED_SAVED(EMBRA_ERROR_INVALID_ARGUMENT, "not planar within the tolerances", before, s.w,
                embra_panel_mesh_create(s.w, &pd, &body, NULL));
  t = embra_default_tolerances();
  CHECK_OK(embra_world_set_tolerances(s.w, &t));
  CHECK_OK(embra_panel_mesh_create(s.w, &pd, &body, NULL));
  memset(&m, 0, sizeof m);
  m.version = EMBRA_PANEL_METRICS_VERSION;
  CHECK_OK(embra_panel_mesh_get_metrics(s.w, body, NULL, &m));
  CHECK(m.planarity_top.max <= t.planarity.target);
  CHECK(m.corner_distance_top.max <= t.planarity_distance.target && m.corner_distance_top.max > 1e-6);
  CHECK(m.thickness.max <= t.thickness.target);
  CHECK(m.miter.max <= t.miter.target);
  free(before);
  embra_world_destroy(s.w);
}

static void test_step(void) {
  REFUSED_NO_WORLD(EMBRA_ERROR_INVALID_ARGUMENT, "world", embra_world_step(NULL));
}

/* Whether `s` is well-formed UTF-8 (RFC 3629: no overlong form, surrogate or value past U+10FFFF). */
static int valid_utf8(const char* s) {
  const unsigned char* p = (const unsigned char*)s;
  while (*p != 0) {
    int n, k;
    unsigned cp;
    if (*p < 0x80) {
      ++p;
      continue;
    }
    if ((*p & 0xe0) == 0xc0)
      n = 1, cp = *p & 0x1fu;
    else if ((*p & 0xf0) == 0xe0)
      n = 2, cp = *p & 0x0fu;
    else if ((*p & 0xf8) == 0xf0)
      n = 3, cp = *p & 0x07u;
    else
      return 0;
    for (k = 1; k <= n; ++k) {
      if ((p[k] & 0xc0) != 0x80) return 0;
      cp = cp << 6 | (p[k] & 0x3fu);
    }
    if ((n == 1 && cp < 0x80) || (n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) || cp > 0x10ffff ||
        (cp >= 0xd800 && cp <= 0xdfff))
      return 0;
    p += n + 1;
  }
  return 1;
}

/* A message longer than EMBRA_MAX_ERROR_MESSAGE (a scene's unknown key of 3,000 two-byte
 * characters, after 0, 1 and 2 one-byte ones so that the cut falls at each place in a character):
 * the message keeps its start, fills the buffer to within one character and stays valid UTF-8. */
static void test_long_message_cut(void) {
  enum { CHARS = 3000 };
  static const char head[] = "{\"format\": \"embra-scene\", \"version\": 1, \"";
  static const char tail[] = "\": 1}";
  int shift;
  for (shift = 0; shift < 3; ++shift) {
    char* doc = (char*)malloc(sizeof head + 2 * CHARS + 2 + sizeof tail);
    embra_world* w = NULL;
    size_t n = 0;
    int k;
    const char* m;
    CAPI_CONTEXT("%d one-byte characters first", shift);
    CHECK(doc != NULL);
    if (doc == NULL) return;
    memcpy(doc, head, sizeof head - 1), n = sizeof head - 1;
    for (k = 0; k < shift; ++k) doc[n++] = 'x';
    for (k = 0; k < CHARS; ++k) doc[n++] = (char)0xc3, doc[n++] = (char)0xa9; /* U+00E9 */
    memcpy(doc + n, tail, sizeof tail), n += sizeof tail - 1;
    CHECK_STATUS(embra_world_load_json(&w, doc, (int64_t)n, NULL), EMBRA_ERROR_SCHEMA);
    CHECK(w == NULL);
    m = embra_last_error_message();
    CHECK_MSG(strncmp(m, "embra_world_load_json: ", 23) == 0, "the message starts: %.40s", m);
    CHECK_CONTAINS(m, "unknown key");
    CHECK_MSG(strlen(m) <= EMBRA_MAX_ERROR_MESSAGE - 1 && strlen(m) >= EMBRA_MAX_ERROR_MESSAGE - 2, "%d bytes",
              (int)strlen(m));
    CHECK(valid_utf8(m));
    free(doc);
  }
}

int main(void) {
  if (!scene_build(&g_ref)) {
    fprintf(stderr, "the scene does not build: %s\n", embra_last_error_message());
    CHECK(0);
    return capi_test_finish();
  }
  embra_world_destroy(g_ref.w);
  g_ref.w = NULL;
  RUN(test_null_world);
  RUN(test_world_create);
  RUN(test_solver_and_gravity);
  RUN(test_groups);
  RUN(test_body_create);
  RUN(test_body_queries);
  RUN(test_constraint_add);
  RUN(test_constraints_add);
  RUN(test_polygon_planarity_add);
  RUN(test_rigid_set_add);
  RUN(test_shape_match_add);
  RUN(test_pins);
  RUN(test_colliders);
  RUN(test_id_lists);
  RUN(test_particles);
  RUN(test_statics);
  RUN(test_distributed_loads);
  RUN(test_polyline_supports);
  RUN(test_anchor_supports);
  RUN(test_polyline_support_points);
  RUN(test_mesh_supports);
  RUN(test_panel_planarity_tolerance);
  RUN(test_step);
  RUN(test_long_message_cut);
  return capi_test_finish();
}
