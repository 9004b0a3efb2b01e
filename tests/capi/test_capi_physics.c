/* C-ABI happy paths, each checked against something one can work out by hand: free fall against
 * the discrete integrator, a pendulum's length, pins, colliders, group order, rest scales, the
 * constraint kinds, bodies' generated constraint counts and the restore on a numerical failure. */
#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"

static const double kPi = 3.14159265358979323846;

static embra_world* make_world(int32_t substeps, double dt, double gx, double gy, double gz) {
  embra_world* w = NULL;
  embra_solver_def s = embra_default_solver_def();
  s.substeps = substeps;
  s.dt = dt;
  s.gravity[0] = gx;
  s.gravity[1] = gy;
  s.gravity[2] = gz;
  CHECK_OK(embra_world_create(&w, &s));
  return w;
}

/* Adds n free particles (no elements) with the given masses (NULL: 1 kg each); returns the first. */
static int32_t add_points(embra_world* w, int32_t n, const double* xyz, const double* masses) {
  embra_body_def b = embra_default_body_def();
  embra_body_id id;
  int32_t first = -1;
  b.vertex_count = n;
  b.positions = xyz;
  b.masses = masses;
  CHECK_OK(embra_body_create(w, &b, &id, &first));
  return first;
}

static void get_x(const embra_world* w, int32_t i, double out[3]) {
  CHECK_OK(embra_world_get_positions(w, out, 3, i, 1));
}
static void get_v(const embra_world* w, int32_t i, double out[3]) {
  CHECK_OK(embra_world_get_velocities(w, out, 3, i, 1));
}
static double dist(const double* a, const double* b) {
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
static void sub(const double* a, const double* b, double* out) {
  int k;
  for (k = 0; k < 3; ++k) out[k] = a[k] - b[k];
}
static void cross(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static double norm(const double* a) {
  return sqrt(dot(a, a));
}

/* Free fall, one particle, no constraints. With h = dt / k, symplectic Euler per substep is
 *   v <- v + h g,  x <- x + h v,
 * so after n substeps  v_n = v0 + n h g  and  x_n = x0 + n h v0 + g h^2 n (n + 1) / 2. */
static void test_free_fall(void) {
  static const struct {
    int32_t substeps;
    double dt;
  } cases[] = {{1, 1.0 / 60.0}, {3, 0.01}, {8, 1.0 / 60.0}, {20, 0.05}};
  const double g[3] = {0.3, -0.2, -9.81};
  const double x0[3] = {1.0, 2.0, 3.0};
  const double v0[3] = {0.5, 0.0, 2.0};
  const double mass = 2.5;
  size_t c;
  for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
    const int32_t k = cases[c].substeps;
    const double h = cases[c].dt / k;
    embra_world* w = make_world(k, cases[c].dt, g[0], g[1], g[2]);
    embra_step_report r;
    double x[3], v[3], speed2 = 0.0;
    int frame, d;
    const int32_t i = add_points(w, 1, x0, &mass);
    CAPI_CONTEXT("substeps %d, dt %g", (int)k, cases[c].dt);
    CHECK_OK(embra_world_set_velocities(w, v0, i, 1));
    for (frame = 1; frame <= 30; ++frame) {
      const double n = (double)frame * k;
      CHECK_OK(embra_world_step(w));
      if (frame != 1 && frame != 30) continue;
      get_x(w, i, x);
      get_v(w, i, v);
      /* The formula holds to rounding. The solver takes v = (x - x_prev) / h each substep, an
       * error of ~ulp(x) / h per substep, which adds up over n substeps in v and, times h, in x. */
      for (d = 0; d < 3; ++d) {
        const double tol_v = 2.0 * n * (1.0 + fabs(x[d])) * DBL_EPSILON / h;
        const double tol_x = n * h * tol_v + 2.0 * n * (1.0 + fabs(x[d])) * DBL_EPSILON;
        CHECK_NEAR(x[d], x0[d] + n * h * v0[d] + g[d] * h * h * n * (n + 1.0) / 2.0, tol_x);
        CHECK_NEAR(v[d], v0[d] + n * h * g[d], tol_v);
      }
    }
    speed2 = dot(v, v);
    CHECK_OK(embra_world_get_report(w, &r));
    CHECK_INT(r.frame, 30);
    CHECK_NEAR(r.time, 30 * cases[c].dt, 1e-12);
    CHECK_NEAR(r.kinetic_energy, 0.5 * mass * speed2, 1e-9 * r.kinetic_energy);
    CHECK_NEAR(r.max_speed, sqrt(speed2), 1e-12 * r.max_speed);
    CHECK_INT(r.constraint_count, 0);
    CHECK_INT(r.contact_count, 0);
    CHECK_INT(r.settled, 0);
    embra_world_destroy(w);
  }
}

/* Reversing gravity (the Gaudi paradigm) and replacing the solver def between steps. */
static void test_gravity_and_solver(void) {
  embra_world* w = make_world(4, 0.02, 0, 0, -9.81);
  const double x0[3] = {0, 0, 0};
  const double up[3] = {0, 0, 9.81};
  double x[3];
  embra_solver_def s;
  const int32_t i = add_points(w, 1, x0, NULL);
  CHECK_OK(embra_world_set_gravity(w, up));
  CHECK_OK(embra_world_get_solver(w, &s));
  CHECK(s.gravity[0] == 0.0 && s.gravity[1] == 0.0 && s.gravity[2] == 9.81);
  CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  CHECK_NEAR(x[2], 9.81 * 0.005 * 0.005 * 4 * 5 / 2, 1e-15); /* rises */

  /* New dt, substeps and gravity: one more frame follows the formula from the current state. */
  s.dt = 0.1;
  s.substeps = 2;
  s.gravity[2] = -1.0;
  CHECK_OK(embra_world_set_solver(w, &s));
  {
    embra_solver_def back;
    double v[3];
    double z0, vz0;
    CHECK_OK(embra_world_get_solver(w, &back));
    CHECK(memcmp(&back, &s, sizeof s) == 0);
    get_x(w, i, x);
    get_v(w, i, v);
    z0 = x[2];
    vz0 = v[2];
    CHECK_OK(embra_world_step(w));
    get_x(w, i, x);
    CHECK_NEAR(x[2], z0 + 2 * 0.05 * vz0 - 1.0 * 0.05 * 0.05 * 3, 1e-12);
  }
  embra_world_destroy(w);
}

/* A pendulum: a bob on a hard distance constraint to an immovable particle keeps its length. */
static void test_pendulum(void) {
  embra_world* w = make_world(16, 1.0 / 60.0, 0, 0, -9.81);
  const double xyz[6] = {0, 0, 0, 1, 0, 0};
  const double masses[2] = {0.0, 1.0}; /* 0 = immovable */
  embra_constraint_def c = embra_default_constraint_def();
  embra_step_report r;
  double a[3], b[3], lowest = 1.0, worst = 0.0, highest = -1.0;
  int frame, still = 1;
  const int32_t first = add_points(w, 2, xyz, masses);
  c.particles[0] = first;
  c.particles[1] = first + 1;
  CHECK_OK(embra_constraint_add(w, &c));
  for (frame = 0; frame < 120; ++frame) {
    CHECK_OK(embra_world_step(w));
    get_x(w, first, a);
    get_x(w, first + 1, b);
    still = still && a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0;
    worst = fmax(worst, fabs(dist(a, b) - 1.0));
    lowest = fmin(lowest, b[2]);
    highest = fmax(highest, b[2]);
  }
  CHECK(still);                 /* the immovable end never moves */
  CHECK_NEAR(worst, 0.0, 1e-9); /* the length is kept at every frame */
  CHECK(lowest < -0.9);         /* it swings down through the bottom */
  CHECK(highest <= 1e-9);       /* and never rises above where it was let go */
  CHECK_OK(embra_world_get_report(w, &r));
  CHECK_INT(r.constraint_count, 1);
  CHECK(r.residual_max < 1e-9);
  embra_world_destroy(w);

  /* The same with a two-vertex rod body whose first vertex is held by a hard pin. */
  {
    embra_body_def bd = embra_default_body_def();
    embra_body_id body;
    embra_pin_def pd = embra_default_pin_def();
    embra_pin_id pin;
    embra_world_counts counts;
    const int32_t edge[2] = {0, 1};
    const double rod[6] = {0.5, 0.5, 2.0, 0.5, 1.25, 2.0};
    int32_t f = -1;
    w = make_world(16, 1.0 / 60.0, 0, 0, -9.81);
    bd.vertex_count = 2;
    bd.positions = rod;
    bd.edge_count = 1;
    bd.edges = edge;
    bd.material.mass = 0.3;
    CHECK_OK(embra_body_create(w, &bd, &body, &f));
    CHECK_OK(embra_world_get_counts(w, &counts));
    CHECK_INT(counts.constraints, 1);
    pd.particle = f;
    memcpy(pd.target, rod, sizeof pd.target);
    CHECK_OK(embra_pin_create(w, &pd, &pin));
    worst = 0.0;
    still = 1;
    for (frame = 0; frame < 90; ++frame) {
      CHECK_OK(embra_world_step(w));
      get_x(w, f, a);
      get_x(w, f + 1, b);
      still = still && memcmp(a, rod, sizeof a) == 0;
      worst = fmax(worst, fabs(dist(a, b) - 0.75));
    }
    CHECK(still);
    CHECK_NEAR(worst, 0.0, 1e-9);
    CHECK(b[2] < 2.0 - 0.3);
    embra_world_destroy(w);
  }
}

/* Positions and velocities round-trip through set/get, each leaving the other alone. */
static void test_roundtrip(void) {
  embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, -9.81);
  const double xyz[15] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0};
  const double newx[9] = {0.125, -7.5, 1e-300, 1e10, 3.0, -0.0, 5.5, 6.25, -1e-7};
  const double newv[6] = {1, 2, 3, -4, -5, -6};
  double got[18], expect[15], vel[15], zeros[15];
  int i;
  const int32_t first = add_points(w, 5, xyz, NULL);
  CHECK_INT(first, 0);
  memset(zeros, 0, sizeof zeros);

  CHECK_OK(embra_world_set_positions(w, newx, 1, 3));
  memcpy(expect, xyz, sizeof xyz);
  memcpy(expect + 3, newx, sizeof newx);
  for (i = 0; i < 18; ++i) got[i] = -42.0;
  CHECK_OK(embra_world_get_positions(w, got, 15, 0, 5));
  CHECK(memcmp(got, expect, sizeof expect) == 0);
  CHECK_OK(embra_world_get_velocities(w, vel, 15, 0, 5));
  CHECK(memcmp(vel, zeros, sizeof vel) == 0); /* velocities are kept */

  CHECK_OK(embra_world_set_velocities(w, newv, 3, 2));
  CHECK_OK(embra_world_get_velocities(w, vel, 15, 0, 5));
  CHECK(memcmp(vel, zeros, 9 * sizeof(double)) == 0);
  CHECK(memcmp(vel + 9, newv, sizeof newv) == 0);
  CHECK_OK(embra_world_get_positions(w, got, 15, 0, 5));
  CHECK(memcmp(got, expect, sizeof expect) == 0); /* positions are kept */

  /* A larger buffer than needed: exactly 3 * count doubles written. */
  for (i = 0; i < 18; ++i) got[i] = -42.0;
  CHECK_OK(embra_world_get_positions(w, got, 18, 2, 2));
  CHECK(memcmp(got, expect + 6, 6 * sizeof(double)) == 0);
  for (i = 6; i < 18; ++i) CHECK(got[i] == -42.0);

  /* Empty ranges are valid and change nothing. */
  CHECK_OK(embra_world_set_positions(w, newx, 5, 0));
  CHECK_OK(embra_world_set_velocities(w, newv, 0, 0));
  CHECK_OK(embra_world_get_positions(w, got, 0, 5, 0));
  CHECK_OK(embra_world_get_positions(w, got, 15, 0, 5));
  CHECK(memcmp(got, expect, sizeof expect) == 0);
  embra_world_destroy(w);
}

/* A hard pin holds its particle; a new target is reached exactly after one step. */
static void test_pins(void) {
  embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, -9.81);
  const double x0[3] = {0.1, 0.2, 0.3};
  const double target[3] = {0.7, -0.9, 1.3};
  double x[3], t[3];
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id pin, soft;
  embra_world_counts counts;
  int frame;
  const int32_t i = add_points(w, 1, x0, NULL);
  pd.particle = i;
  memcpy(pd.target, x0, sizeof pd.target);
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  CHECK(pin.generation != 0);
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.pins, 1);
  CHECK_OK(embra_pin_get_target(w, pin, t));
  CHECK(memcmp(t, x0, sizeof t) == 0);
  CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  CHECK(memcmp(x, x0, sizeof x) == 0); /* held against gravity */

  CHECK_OK(embra_pin_set_target(w, pin, target));
  CHECK_OK(embra_pin_get_target(w, pin, t));
  CHECK(memcmp(t, target, sizeof t) == 0);
  get_x(w, i, x);
  CHECK(memcmp(x, x0, sizeof x) == 0); /* nothing moves before the step */
  CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  /* "follows the target exactly". A core that places a hard-pinned particle at
   * target_prev + alpha * (target - target_prev) fails this: at alpha = 1 that is not always
   * `target` (here y: 0.2 + (-0.9 - 0.2) = -0.9000000000000001). */
  CHECK_SAME_DOUBLE(x[0], target[0]);
  CHECK_SAME_DOUBLE(x[1], target[1]);
  CHECK_SAME_DOUBLE(x[2], target[2]);
  CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  CHECK(memcmp(x, target, sizeof x) == 0);

  /* Released, it falls. */
  CHECK_OK(embra_pin_destroy(w, pin));
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.pins, 0);
  CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  CHECK(x[2] < target[2]);

  /* A soft pin pulls its particle to the target, sagging by m g compliance under gravity. */
  pd.compliance = 1e-6;
  memcpy(pd.target, target, sizeof pd.target);
  CHECK_OK(embra_pin_create(w, &pd, &soft));
  CHECK(memcmp(&soft, &pin, sizeof soft) != 0); /* a destroyed pin's id is not handed out again */
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.pins, 1);
  {
    const double damped[3] = {0, 0, 0};
    embra_solver_def s;
    CHECK_OK(embra_world_get_solver(w, &s));
    s.damping = 5.0;
    CHECK_OK(embra_world_set_solver(w, &s));
    CHECK_OK(embra_world_set_velocities(w, damped, i, 1));
  }
  for (frame = 0; frame < 240; ++frame) CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  CHECK_NEAR(dist(x, target), 9.81 * 1e-6, 1e-6);
  CHECK(x[2] < target[2]); /* it sags, not rises */
  embra_world_destroy(w);
}

/* Colliders keep particles out: a plane (level and tilted), thickness, a sphere, a moving plane. */
static void test_colliders(void) {
  const double start[3] = {0.2, -0.3, 1.0};
  embra_collider_def cd = embra_default_collider_def();
  embra_collider_id plane, sphere;
  embra_world_counts counts;
  embra_step_report r;
  double x[3], lowest;
  int frame;

  /* Level plane through the origin. */
  embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, -9.81);
  int32_t i = add_points(w, 1, start, NULL);
  CHECK_OK(embra_collider_create(w, &cd, &plane));
  CHECK(plane.generation != 0);
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.colliders, 1);
  lowest = 1.0;
  for (frame = 0; frame < 120; ++frame) {
    CHECK_OK(embra_world_step(w));
    get_x(w, i, x);
    lowest = fmin(lowest, x[2]);
  }
  CHECK(lowest >= -1e-12); /* never below the plane */
  CHECK_NEAR(x[2], 0.0, 1e-9);
  CHECK_NEAR(x[0], start[0], 1e-12); /* straight down, no sideways push */
  CHECK_NEAR(x[1], start[1], 1e-12);
  CHECK_OK(embra_world_get_report(w, &r));
  CHECK_INT(r.contact_count, 1);
  CHECK_INT(r.settled, 1);

  /* Moving the plane up by 0.5 m over one frame lifts the resting particle with it. */
  {
    const double up[3] = {0, 0, 0.5};
    const double id[4] = {1, 0, 0, 0};
    CHECK_OK(embra_collider_set_transform(w, plane, up, id));
    CHECK_OK(embra_world_step(w));
    get_x(w, i, x);
    CHECK(x[2] >= 0.5 - 1e-9);
  }
  /* Removed, it no longer holds anything: at rest just above it, the particle falls through. */
  {
    const double rest[3] = {0, 0, 0};
    x[2] = 0.5;
    CHECK_OK(embra_world_set_positions(w, x, i, 1));
    CHECK_OK(embra_world_set_velocities(w, rest, i, 1));
  }
  CHECK_OK(embra_collider_destroy(w, plane));
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.colliders, 0);
  for (frame = 0; frame < 30; ++frame) CHECK_OK(embra_world_step(w));
  get_x(w, i, x);
  CHECK(x[2] < 0.0);
  embra_world_destroy(w);

  /* A plane tilted 30 degrees about x, with a collider thickness and a body thickness:
   * the particle keeps thickness + half the body's off it. */
  {
    const double half = kPi / 12.0; /* half of 30 degrees */
    embra_body_def bd = embra_default_body_def();
    embra_body_id body;
    const double n[3] = {0.0, -sin(2 * half), cos(2 * half)};
    double rel[3], worst = 1.0;
    w = make_world(8, 1.0 / 60.0, 0, 0, -9.81);
    bd.vertex_count = 1;
    bd.positions = start;
    bd.material.thickness = 0.02;
    CHECK_OK(embra_body_create(w, &bd, &body, &i));
    cd = embra_default_collider_def();
    cd.rotation[0] = cos(half);
    cd.rotation[1] = sin(half);
    cd.thickness = 0.05;
    CHECK_OK(embra_collider_create(w, &cd, &plane));
    for (frame = 0; frame < 120; ++frame) {
      CHECK_OK(embra_world_step(w));
      get_x(w, i, x);
      sub(x, cd.position, rel);
      worst = fmin(worst, dot(rel, n));
    }
    CHECK(worst >= 0.05 + 0.01 - 1e-9);
    CHECK_NEAR(dot(rel, n), 0.06, 1e-6); /* resting on it (sliding: friction 0.5 < tan 30) */
    CHECK(x[1] < start[1]);              /* slid downhill, towards -y */
    embra_world_destroy(w);
  }

  /* A sphere: a particle dropped above its centre comes to rest on top. */
  {
    const double above[3] = {1.0, 2.0, 3.0};
    w = make_world(8, 1.0 / 60.0, 0, 0, -9.81);
    i = add_points(w, 1, above, NULL);
    cd = embra_default_collider_def();
    cd.shape = EMBRA_COLLIDER_SPHERE;
    cd.position[0] = 1.0;
    cd.position[1] = 2.0;
    cd.position[2] = 1.0;
    cd.radius = 0.75;
    CHECK_OK(embra_collider_create(w, &cd, &sphere));
    lowest = 10.0;
    for (frame = 0; frame < 120; ++frame) {
      CHECK_OK(embra_world_step(w));
      get_x(w, i, x);
      lowest = fmin(lowest, dist(x, cd.position));
    }
    CHECK(lowest >= 0.75 - 1e-9);
    CHECK_NEAR(x[2], 1.75, 1e-9);
    CHECK_NEAR(x[0], 1.0, 1e-12);
    CHECK_NEAR(x[1], 2.0, 1e-12);
    embra_world_destroy(w);
  }
}

/* Groups: counts, and `order` decides which of two conflicting hard constraints wins. */
static void test_groups(void) {
  embra_world* w = make_world(4, 1.0 / 60.0, 0, 0, 0);
  const double xyz[6] = {0, 0, 0, 1.5, 0, 0};
  const double masses[2] = {0.0, 1.0};
  embra_group_def gd = embra_default_group_def();
  embra_group_id a, b, c, again, def_group;
  embra_group_report gr;
  embra_world_counts counts;
  embra_constraint_def cd = embra_default_constraint_def();
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id soft;
  double x0[3], x1[3];
  const int32_t first = add_points(w, 2, xyz, masses);

  CHECK_OK(embra_group_create(w, &gd, &a));
  gd.order = 1;
  gd.weight = 3;
  CHECK_OK(embra_group_create(w, &gd, &b));
  gd.order = -7;
  gd.weight = 1000;
  CHECK_OK(embra_group_create(w, &gd, &c));
  CHECK(a.generation != 0 && b.generation != 0 && c.generation != 0);
  CHECK(memcmp(&a, &b, sizeof a) != 0 && memcmp(&b, &c, sizeof b) != 0 && memcmp(&a, &c, sizeof a) != 0);
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.groups, 5);

  /* Two hard distance constraints on the same pair: rest 1 in group a (order 0), rest 2 in group
   * b (order 1). The group projected last wins exactly. */
  cd.particles[0] = first;
  cd.particles[1] = first + 1;
  cd.rest_from_current = 0;
  cd.rest = 1.0;
  cd.group = a;
  CHECK_OK(embra_constraint_add(w, &cd));
  cd.rest = 2.0;
  cd.group = b;
  CHECK_OK(embra_constraint_add(w, &cd));
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.constraints, 2);
  CHECK_OK(embra_world_step(w));
  get_x(w, first, x0);
  get_x(w, first + 1, x1);
  CHECK_NEAR(dist(x0, x1), 2.0, 1e-12);
  CHECK_OK(embra_group_get_report(w, b, &gr));
  CHECK_INT(gr.count, 1);
  CHECK(gr.residual_max < 1e-12); /* b is satisfied */
  CHECK_OK(embra_group_get_report(w, a, &gr));
  CHECK_INT(gr.count, 1);
  CHECK_NEAR(gr.residual_max, 1.0, 1e-9); /* a is off by a metre */

  CHECK_OK(embra_group_set_order(w, a, 2)); /* now a goes last */
  CHECK_OK(embra_world_step(w));
  get_x(w, first + 1, x1);
  CHECK_NEAR(dist(x0, x1), 1.0, 1e-12);
  CHECK_OK(embra_group_set_weight(w, b, 1));
  CHECK_OK(embra_group_set_weight(w, b, 1000));
  CHECK_OK(embra_group_set_order(w, b, INT32_MAX));
  CHECK_OK(embra_world_step(w));
  get_x(w, first + 1, x1);
  CHECK_NEAR(dist(x0, x1), 2.0, 1e-12);

  /* A soft pin counts in its group's report. */
  pd.particle = first + 1;
  pd.compliance = 1.0;
  pd.group = c;
  memcpy(pd.target, x1, sizeof pd.target);
  CHECK_OK(embra_pin_create(w, &pd, &soft));
  CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_group_get_report(w, c, &gr));
  CHECK_INT(gr.count, 1);
  CHECK_OK(embra_pin_destroy(w, soft));

  /* Destroying a group destroys its constraints. */
  CHECK_OK(embra_group_destroy(w, b));
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.groups, 4);
  CHECK_INT(counts.constraints, 1);
  CHECK_STATUS(embra_group_set_order(w, b, 0), EMBRA_ERROR_STALE_ID);
  CHECK_OK(embra_world_step(w));
  get_x(w, first + 1, x1);
  CHECK_NEAR(dist(x0, x1), 1.0, 1e-12); /* only a's rest is left */
  CHECK_OK(embra_group_create(w, &gd, &again));
  CHECK(memcmp(&again, &b, sizeof again) != 0); /* never reused */
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.groups, 5);
  CHECK_OK(embra_group_destroy(w, again));
  CHECK_OK(embra_group_destroy(w, c));
  CHECK_OK(embra_group_destroy(w, a));
  CHECK_OK(embra_world_get_counts(w, &counts));
  CHECK_INT(counts.groups, 2);
  CHECK_INT(counts.constraints, 0);
  /* The default group and the contact group can be reordered and reweighted. */
  CHECK_OK(embra_world_default_group(w, &def_group));
  CHECK_OK(embra_group_set_order(w, def_group, 5));
  CHECK_OK(embra_group_set_weight(w, def_group, 2));
  embra_world_destroy(w);
}

/* Generated constraints: a square of two triangles has 5 edges, 1 hinge, 6 corner angles; a
 * tetrahedron has 6 edges and 1 volume. */
static void test_body_generation(void) {
  static const double square[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  static const int32_t tris[6] = {0, 1, 2, 0, 2, 3};
  static const double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  static const int32_t tet_ids[4] = {0, 1, 2, 3};
  static const struct {
    int32_t generate;
    int64_t square, tet;
  } cases[] = {
      {0, 0, 0},
      {EMBRA_GENERATE_STRETCH, 5, 6},
      {EMBRA_GENERATE_SHEAR, 6, 0},
      {EMBRA_GENERATE_BEND, 1, 0},
      {EMBRA_GENERATE_VOLUME, 0, 1},
      {EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_BEND | EMBRA_GENERATE_VOLUME, 6, 7},
      {15, 12, 7},
  };
  size_t c;
  for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
    embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, -9.81);
    embra_body_def bd = embra_default_body_def();
    embra_body_id cloth, solid;
    embra_world_counts counts;
    int32_t first = -1, f2 = -1, got_first = -1, got_count = -1;
    CAPI_CONTEXT("generate %d", (int)cases[c].generate);
    bd.vertex_count = 4;
    bd.positions = square;
    bd.triangle_count = 2;
    bd.triangles = tris;
    bd.generate = cases[c].generate;
    CHECK_OK(embra_body_create(w, &bd, &cloth, &first));
    CHECK_INT(first, 0);
    CHECK_OK(embra_world_get_counts(w, &counts));
    CHECK_INT(counts.constraints, cases[c].square);

    bd = embra_default_body_def();
    bd.vertex_count = 4;
    bd.positions = tet;
    bd.tet_count = 1;
    bd.tets = tet_ids;
    bd.generate = cases[c].generate;
    CHECK_OK(embra_body_create(w, &bd, &solid, NULL)); /* out_first_particle may be NULL */
    CHECK(memcmp(&cloth, &solid, sizeof cloth) != 0);
    CHECK_OK(embra_world_get_counts(w, &counts));
    CHECK_INT(counts.constraints, cases[c].square + cases[c].tet);
    CHECK_INT(counts.bodies, 2);
    CHECK_INT(counts.particles, 8);
    CHECK_OK(embra_body_get_particles(w, solid, &got_first, &got_count));
    CHECK_INT(got_first, 4);
    CHECK_INT(got_count, 4);
    CHECK_OK(embra_body_get_particles(w, cloth, &got_first, &got_count));
    CHECK_INT(got_first, 0);
    CHECK_INT(got_count, 4);

    /* The stretch constraints go to the group the def names. */
    if (cases[c].generate & EMBRA_GENERATE_STRETCH) {
      embra_group_def gd = embra_default_group_def();
      embra_group_id g;
      embra_group_report gr;
      CHECK_OK(embra_group_create(w, &gd, &g));
      bd.stretch_group = g;
      CHECK_OK(embra_body_create(w, &bd, &solid, &f2));
      CHECK_INT(f2, 8);
      CHECK_OK(embra_world_step(w));
      CHECK_OK(embra_group_get_report(w, g, &gr));
      CHECK_INT(gr.count, 6);
    }
    embra_world_destroy(w);
  }
}

static double tet_volume(const double* p) {
  double a[3], b[3], c[3], n[3];
  sub(p + 3, p, a);
  sub(p + 6, p, b);
  sub(p + 9, p, c);
  cross(b, c, n);
  return dot(a, n) / 6.0;
}

/* Rest scales: a rod along u of a 1 m edge scales with scale * scale_u, not with scale_v; a
 * tetrahedron's volume with scale^3. */
static void test_rest_scale(void) {
  static const struct {
    double s, su, sv, length;
  } cases[] = {{1, 1, 1, 1.0}, {0.5, 1, 1, 0.5},  {1, 0.5, 1, 0.5}, {1, 1, 0.5, 1.0},
               {2, 1, 1, 2.0}, {2, 0.25, 3, 0.5}, {0, 1, 1, 0.0}};
  static const double rod[6] = {0, 0, 0, 1, 0, 0};
  static const double masses[2] = {0, 1};
  static const double uvs[4] = {0, 0, 1, 0};
  static const int32_t edge[2] = {0, 1};
  size_t c;
  for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
    embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, 0);
    embra_body_def bd = embra_default_body_def();
    embra_body_id body, plain;
    double a[3], b[3];
    int32_t f;
    int frame;
    CAPI_CONTEXT("rest scale %g %g %g", cases[c].s, cases[c].su, cases[c].sv);
    bd.vertex_count = 2;
    bd.positions = rod;
    bd.masses = masses;
    bd.uvs = uvs;
    bd.edge_count = 1;
    bd.edges = edge;
    CHECK_OK(embra_body_create(w, &bd, &body, &f));
    bd.uvs = NULL; /* without uvs, the whole edge is "other": only `scale` applies */
    CHECK_OK(embra_body_create(w, &bd, &plain, NULL));
    CHECK_OK(embra_body_set_rest_scale(w, body, cases[c].s, cases[c].su, cases[c].sv));
    CHECK_OK(embra_body_set_rest_scale(w, plain, cases[c].s, cases[c].su, cases[c].sv));
    for (frame = 0; frame < 3; ++frame) CHECK_OK(embra_world_step(w));
    get_x(w, f, a);
    get_x(w, f + 1, b);
    CHECK_NEAR(dist(a, b), cases[c].length, 1e-12);
    get_x(w, f + 2, a);
    get_x(w, f + 3, b);
    CHECK_NEAR(dist(a, b), cases[c].s, 1e-12);
    embra_world_destroy(w);
  }
  {
    static const double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const int32_t ids[4] = {0, 1, 2, 3};
    embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, 0);
    embra_body_def bd = embra_default_body_def();
    embra_body_id body;
    double p[12];
    int frame;
    bd.vertex_count = 4;
    bd.positions = tet;
    bd.tet_count = 1;
    bd.tets = ids;
    bd.generate = EMBRA_GENERATE_VOLUME;
    CHECK_OK(embra_body_create(w, &bd, &body, NULL));
    CHECK_OK(embra_body_set_rest_scale(w, body, 1.5, 1, 1));
    for (frame = 0; frame < 20; ++frame) CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_get_positions(w, p, 12, 0, 4));
    CHECK_NEAR(tet_volume(p), 1.5 * 1.5 * 1.5 / 6.0, 1e-9);
    embra_world_destroy(w);
  }
}

static double angle_at(const double* c, const double* a, const double* b) {
  double u[3], v[3];
  sub(a, c, u);
  sub(b, c, v);
  return acos(dot(u, v) / (norm(u) * norm(v)));
}

/* Unsigned angle between triangles (x0,x1,x2) and (x1,x0,x3) (0 = flat). */
static double hinge_angle(const double* x0, const double* x1, const double* x2, const double* x3) {
  double e1[3], e2[3], e3[3], e4[3], n1[3], n2[3];
  sub(x1, x0, e1);
  sub(x2, x0, e2);
  sub(x0, x1, e3);
  sub(x3, x1, e4);
  cross(e1, e2, n1);
  cross(e3, e4, n2);
  return acos(fmax(-1.0, fmin(1.0, dot(n1, n2) / (norm(n1) * norm(n2)))));
}

/* One constraint of each kind with a given rest value, no gravity: the particles settle where
 * the measured quantity equals the rest value. */
static void test_constraint_kinds(void) {
  static const double xyz[12] = {0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0.0};
  embra_constraint_def cd = embra_default_constraint_def();
  embra_world_counts counts;
  double p[12];
  int kind, frame;
  for (kind = EMBRA_CONSTRAINT_DISTANCE; kind <= EMBRA_CONSTRAINT_TETHER; ++kind) {
    embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, 0);
    const int32_t f = add_points(w, 4, xyz, NULL);
    int k;
    CAPI_CONTEXT("kind %d", kind);
    cd = embra_default_constraint_def();
    cd.kind = kind;
    for (k = 0; k < 4; ++k) cd.particles[k] = f + k;
    cd.rest_from_current = 0;
    switch (kind) {
      case EMBRA_CONSTRAINT_DISTANCE:
        cd.rest = 0.7;
        break;
      case EMBRA_CONSTRAINT_EDGE_ANGLE:
        cd.particles[0] = f + 2; /* the angle at the apex, 2 atan(0.5) now */
        cd.particles[1] = f + 0;
        cd.particles[2] = f + 1;
        cd.rest = kPi / 3.0;
        break;
      case EMBRA_CONSTRAINT_DIHEDRAL:
        cd.rest = 0.5;
        break;
      case EMBRA_CONSTRAINT_TET_VOLUME:
        cd.particles[3] = f + 3;
        cd.rest = 0.1;
        break;
      case EMBRA_CONSTRAINT_WELD:
        cd.rest = 0.0;
        break;
      case EMBRA_CONSTRAINT_TETHER:
        cd.rest = 0.5;
        break;
      default:
        break;
    }
    CHECK_OK(embra_constraint_add(w, &cd));
    CHECK_OK(embra_world_get_counts(w, &counts));
    CHECK_INT(counts.constraints, 1);
    for (frame = 0; frame < 120; ++frame) CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_get_positions(w, p, 12, f, 4));
    switch (kind) {
      case EMBRA_CONSTRAINT_DISTANCE:
        CHECK_NEAR(dist(p, p + 3), 0.7, 1e-9);
        break;
      case EMBRA_CONSTRAINT_EDGE_ANGLE:
        CHECK_NEAR(angle_at(p + 6, p, p + 3), kPi / 3.0, 1e-6);
        break;
      case EMBRA_CONSTRAINT_DIHEDRAL:
        CHECK_NEAR(hinge_angle(p, p + 3, p + 6, p + 9), 0.5, 1e-6);
        break;
      case EMBRA_CONSTRAINT_TET_VOLUME:
        CHECK_NEAR(tet_volume(p), 0.1, 1e-9);
        break;
      case EMBRA_CONSTRAINT_WELD:
        CHECK_NEAR(dist(p, p + 3), 0.0, 1e-9);
        break;
      case EMBRA_CONSTRAINT_TETHER:
        CHECK_NEAR(dist(p, p + 3), 0.5, 1e-9);
        break;
      default:
        break;
    }
    embra_world_destroy(w);
  }

  /* A tether only pulls: slack (rest 2 on a 1 m pair) leaves the particles where they are. */
  {
    embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, 0);
    const int32_t f = add_points(w, 4, xyz, NULL);
    cd = embra_default_constraint_def();
    cd.kind = EMBRA_CONSTRAINT_TETHER;
    cd.particles[0] = f;
    cd.particles[1] = f + 1;
    cd.rest_from_current = 0;
    cd.rest = 2.0;
    CHECK_OK(embra_constraint_add(w, &cd));
    CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_world_get_positions(w, p, 12, f, 4));
    CHECK(memcmp(p, xyz, sizeof p) == 0);
    embra_world_destroy(w);
  }

  /* A batch: three distance constraints with their own rest values and compliances, all added. */
  {
    embra_world* w = make_world(8, 1.0 / 60.0, 0, 0, 0);
    const int32_t f = add_points(w, 4, xyz, NULL);
    embra_constraint_batch_def bd = embra_default_constraint_batch_def();
    const int32_t ids[6] = {f, f + 1, f + 1, f + 2, f + 2, f + 3};
    const double rest[3] = {1.25, 0.5, 0.0};
    const double compliance[3] = {0.0, 0.0, 1e-3};
    bd.count = 3;
    bd.particles = ids;
    bd.rest = rest;
    bd.compliances = compliance;
    CHECK_OK(embra_constraints_add(w, &bd));
    bd.rest = NULL; /* measured from current positions */
    bd.compliances = NULL;
    bd.compliance = 1e-4;
    bd.kind = EMBRA_CONSTRAINT_TETHER;
    CHECK_OK(embra_constraints_add(w, &bd));
    CHECK_OK(embra_world_get_counts(w, &counts));
    CHECK_INT(counts.constraints, 6);
    embra_world_destroy(w);
  }
}

/* A step that goes non-finite is refused with EMBRA_ERROR_NUMERICAL, leaves the world as it was
 * and records where; a twin world that never took the failed step then steps identically. */
static void test_numerical_failure(void) {
  /* Accepted values whose product overflows: gravity 1e300 over the longest frame (1e6 s). */
  const double xyz[6] = {0, 0, 1, 1e300, 0, 0};
  const double huge_g[3] = {1e300, 0, 0};
  const double normal_g[3] = {0, 0, -9.81};
  const double sane[3] = {1, 0, 1};
  embra_world* a = make_world(8, EMBRA_MAX_DT, 0, 0, -9.81);
  embra_world* b = make_world(8, EMBRA_MAX_DT, 0, 0, -9.81);
  double xa[6], xb[6], va[6], vb[6], before_x[6], before_v[6];
  embra_step_report ra, rb, before_r;
  embra_warning warn;
  const int32_t fa = add_points(a, 2, xyz, NULL);
  const int32_t fb = add_points(b, 2, xyz, NULL);
  CHECK_OK(embra_world_step(a));
  CHECK_OK(embra_world_step(b));
  CHECK_OK(embra_world_set_gravity(a, huge_g));
  CHECK_OK(embra_world_set_gravity(b, huge_g));
  CHECK_OK(embra_world_get_warning(a, &warn));
  CHECK_INT(warn.frame, -1);
  CHECK_INT(warn.particle, -1);

  CHECK_OK(embra_world_get_positions(a, before_x, 6, 0, 2));
  CHECK_OK(embra_world_get_velocities(a, before_v, 6, 0, 2));
  CHECK_OK(embra_world_get_report(a, &before_r));
  CHECK_STATUS(embra_world_step(a), EMBRA_ERROR_NUMERICAL);
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_step");
  CHECK_CONTAINS(embra_last_error_message(), "non-finite");
  CHECK_OK(embra_world_get_positions(a, xa, 6, 0, 2));
  CHECK_OK(embra_world_get_velocities(a, va, 6, 0, 2));
  CHECK_OK(embra_world_get_report(a, &ra));
  CHECK(memcmp(xa, before_x, sizeof xa) == 0);
  CHECK(memcmp(va, before_v, sizeof va) == 0);
  CHECK(memcmp(&ra, &before_r, sizeof ra) == 0);
  CHECK_OK(embra_world_get_warning(a, &warn));
  CHECK_INT(warn.frame, 1);
  CHECK_INT(warn.particle, fa);

  /* Fix gravity and the particle in both; from here on the two worlds step bit-identically. */
  CHECK_OK(embra_world_set_gravity(a, normal_g));
  CHECK_OK(embra_world_set_gravity(b, normal_g));
  CHECK_OK(embra_world_set_positions(a, sane, fa + 1, 1));
  CHECK_OK(embra_world_set_positions(b, sane, fb + 1, 1));
  CHECK_OK(embra_world_set_velocities(a, sane, fa + 1, 1));
  CHECK_OK(embra_world_set_velocities(b, sane, fb + 1, 1));
  CHECK_OK(embra_world_step(a));
  CHECK_OK(embra_world_step(b));
  CHECK_OK(embra_world_get_positions(a, xa, 6, 0, 2));
  CHECK_OK(embra_world_get_positions(b, xb, 6, 0, 2));
  CHECK_OK(embra_world_get_velocities(a, va, 6, 0, 2));
  CHECK_OK(embra_world_get_velocities(b, vb, 6, 0, 2));
  CHECK_OK(embra_world_get_report(a, &ra));
  CHECK_OK(embra_world_get_report(b, &rb));
  CHECK(memcmp(xa, xb, sizeof xa) == 0);
  CHECK(memcmp(va, vb, sizeof va) == 0);
  CHECK(memcmp(&ra, &rb, sizeof ra) == 0);
  CHECK_INT(ra.frame, 2);
  embra_world_destroy(a);
  embra_world_destroy(b);
}

/* A draped cloth: a 5 x 5 grid pinned at two corners, damped, settles; the report adds up. */
static void test_cloth_report(void) {
  enum { N = 5 };
  double xyz[3 * N * N];
  int32_t tris[3 * 2 * (N - 1) * (N - 1)];
  embra_world* w;
  embra_solver_def s = embra_default_solver_def();
  embra_body_def bd = embra_default_body_def();
  embra_body_id cloth;
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id p0, p1;
  embra_world_counts counts;
  embra_step_report r;
  int32_t first, t = 0;
  int i, j, frame;
  for (i = 0; i < N; ++i)
    for (j = 0; j < N; ++j) {
      xyz[3 * (i * N + j)] = 0.25 * j;
      xyz[3 * (i * N + j) + 1] = 0.25 * i;
      xyz[3 * (i * N + j) + 2] = 1.0;
    }
  for (i = 0; i + 1 < N; ++i)
    for (j = 0; j + 1 < N; ++j) {
      const int32_t v = i * N + j;
      tris[t++] = v, tris[t++] = v + 1, tris[t++] = v + N + 1;
      tris[t++] = v, tris[t++] = v + N + 1, tris[t++] = v + N;
    }
  s.damping = 2.0;
  s.iterations = 4;
  w = NULL;
  CHECK_OK(embra_world_create(&w, &s));
  bd.vertex_count = N * N;
  bd.positions = xyz;
  bd.triangle_count = 2 * (N - 1) * (N - 1);
  bd.triangles = tris;
  bd.material.mass = 0.2;
  bd.material.stretch_compliance = 1e-6;
  CHECK_OK(embra_body_create(w, &bd, &cloth, &first));
  pd.particle = first;
  memcpy(pd.target, xyz, sizeof pd.target);
  CHECK_OK(embra_pin_create(w, &pd, &p0));
  pd.particle = first + N - 1;
  memcpy(pd.target, xyz + 3 * (N - 1), sizeof pd.target);
  CHECK_OK(embra_pin_create(w, &pd, &p1));
  CHECK_OK(embra_world_get_counts(w, &counts));
  /* edges: N(N-1) rows + N(N-1) columns + (N-1)^2 diagonals; hinges: one per interior edge. */
  CHECK_INT(counts.constraints, (2 * N * (N - 1) + (N - 1) * (N - 1)) + (2 * (N - 1) * (N - 2) + (N - 1) * (N - 1)));
  CHECK_INT(counts.pins, 2);
  for (frame = 0; frame < 600; ++frame) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_report(w, &r));
  CHECK_INT(r.frame, 600);
  CHECK_INT(r.constraint_count, counts.constraints); /* no soft pins, no contacts */
  CHECK_INT(r.contact_count, 0);
  CHECK(r.residual_max < 1e-3);
  CHECK(r.residual_rms <= r.residual_max);
  CHECK_INT(r.settled, 1);
  CHECK(r.max_speed <= s.settle_speed);
  {
    double x[3 * N * N];
    double lowest = 1.0;
    CHECK_OK(embra_world_get_positions(w, x, 3 * N * N, first, N * N));
    for (i = 0; i < N * N; ++i) lowest = fmin(lowest, x[3 * i + 2]);
    CHECK(lowest < 0.5);                            /* it hangs */
    CHECK(memcmp(x, xyz, 3 * sizeof(double)) == 0); /* the pinned corner did not move */
  }
  embra_world_destroy(w);
}

/* A skew hexagon made planar (embra_polygon_planarity_add, hard, no gravity, 4 substeps of 10
 * iterations): six windows of four corners; after 200 frames every corner is on the plane through
 * corners 0, 2 and 4 (computed here) to 1e-12 of its size, and the hexagon keeps its size (after 60
 * frames the worst corner was 3.8e-12 off, and at 1 iteration a substep 4.6e-7: the windows share
 * corners and converge linearly), and a second call on a planar octagon adds eight windows that move
 * nothing. */
static void test_polygon_planarity(void) {
  double xyz[18], p[18], n[3], a[3], b[3], len;
  int32_t added = 0, k, frame;
  embra_world* w = NULL;
  embra_solver_def sd = embra_default_solver_def();
  int32_t f, ids[6];
  sd.substeps = 4;
  sd.iterations = 10;
  sd.gravity[0] = sd.gravity[1] = sd.gravity[2] = 0.0;
  CHECK_OK(embra_world_create(&w, &sd));
  for (k = 0; k < 6; ++k) { /* a hexagon of radius 1, its corners up and down by 0.2 in turn */
    xyz[3 * k] = cos(k * kPi / 3.0);
    xyz[3 * k + 1] = sin(k * kPi / 3.0);
    xyz[3 * k + 2] = k % 2 == 0 ? 0.2 : -0.2 + 0.05 * k;
  }
  f = add_points(w, 6, xyz, NULL);
  for (k = 0; k < 6; ++k) ids[k] = f + k;
  CHECK_OK(embra_polygon_planarity_add(w, (embra_group_id){0, 0}, ids, 6, 0.0, &added));
  CHECK_INT(added, 6);
  for (frame = 0; frame < 200; ++frame) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_positions(w, p, 18, f, 6));
  sub(p + 6, p, a);
  sub(p + 12, p, b);
  n[0] = a[1] * b[2] - a[2] * b[1], n[1] = a[2] * b[0] - a[0] * b[2], n[2] = a[0] * b[1] - a[1] * b[0];
  len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  CHECK(dist(p, p + 9) > 1.9 && dist(p + 3, p + 12) > 1.9 && dist(p + 6, p + 15) > 1.9);
  for (k = 0; k < 6; ++k) {
    double d[3];
    sub(p + 3 * k, p, d);
    CAPI_CONTEXT("corner %d", (int)k);
    CHECK((d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / len < 1e-12 &&
          (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / len > -1e-12);
  }
  embra_world_destroy(w);
  {
    double oct[24], got[24];
    embra_world* w2 = make_world(4, 1.0 / 60.0, 0, 0, 0);
    int32_t g, o[8];
    for (k = 0; k < 8; ++k) {
      oct[3 * k] = cos(k * kPi / 4.0), oct[3 * k + 1] = sin(k * kPi / 4.0), oct[3 * k + 2] = 0.5;
    }
    g = add_points(w2, 8, oct, NULL);
    for (k = 0; k < 8; ++k) o[k] = g + k;
    CHECK_OK(embra_polygon_planarity_add(w2, (embra_group_id){0, 0}, o, 8, 1e-6, NULL));
    CHECK_OK(embra_world_step(w2));
    CHECK_OK(embra_world_get_positions(w2, got, 24, g, 8));
    for (k = 0; k < 8; ++k) CHECK(fabs(got[3 * k + 2] - 0.5) < 1e-15);
    embra_world_destroy(w2);
  }
}

/* A rigid point set hung by one corner from a hard pin (embra_rigid_set_add, hard; 4 substeps of 40
 * iterations; gravity): it swings for 120 frames undamped (the worst change of a pairwise distance
 * then is printed), then is damped (5 /s) for 600 frames to rest. At rest every pairwise distance
 * is what it was to 1e-6 of the set's size (the bar of a hard instance), the first four points'
 * signed volume (the solid set's handedness) to 1e-6 of itself, and the set did move (it swung
 * down). The bracing is a stiff coupled system and Gauss-Seidel converges on it slowly: measured
 * worst change at rest, solid / flat set, 0.6 m: 10 iterations 8.4e-6 / 5.7e-7 m; 10 iterations
 * and 2 realignment passes 1.6e-8 / 1.9e-12 m; 40 iterations 6.9e-10 / 7.8e-16 m. */
static void rigid_swing(const double* xyz, int32_t n, double* swinging, double* settled) {
  double x0[30], x1[30], worst = 0.0, moved = 0.0, swing = 0.0;
  int32_t f, ids[10], added = 0, i, j, frame;
  embra_world* w = NULL;
  embra_solver_def sd = embra_default_solver_def();
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id pin;
  sd.substeps = 4;
  sd.iterations = 40;
  sd.tethers = 0;
  CHECK_OK(embra_world_create(&w, &sd));
  f = add_points(w, n, xyz, NULL);
  for (i = 0; i < n; ++i) ids[i] = f + i;
  CHECK_OK(embra_rigid_set_add(w, (embra_group_id){0, 0}, ids, n, 0.0, &added));
  CHECK_INT(added, 4 * n - 9);
  pd.particle = f;
  pd.target[0] = xyz[0], pd.target[1] = xyz[1], pd.target[2] = xyz[2];
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  CHECK_OK(embra_world_get_positions(w, x0, 3 * n, f, n));
  for (frame = 0; frame < 120; ++frame) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_positions(w, x1, 3 * n, f, n));
  for (i = 0; i < n; ++i)
    for (j = i + 1; j < n; ++j) {
      const double d = fabs(dist(x1 + 3 * i, x1 + 3 * j) - dist(x0 + 3 * i, x0 + 3 * j));
      swing = d > swing ? d : swing;
    }
  *swinging = swing;
  CHECK_OK(embra_world_get_solver(w, &sd));
  sd.damping = 5.0;
  CHECK_OK(embra_world_set_solver(w, &sd));
  for (frame = 0; frame < 600; ++frame) CHECK_OK(embra_world_step(w));
  CHECK_OK(embra_world_get_positions(w, x1, 3 * n, f, n));
  for (i = 0; i < n; ++i) {
    moved = dist(x0 + 3 * i, x1 + 3 * i) > moved ? dist(x0 + 3 * i, x1 + 3 * i) : moved;
    for (j = i + 1; j < n; ++j) {
      const double d = fabs(dist(x1 + 3 * i, x1 + 3 * j) - dist(x0 + 3 * i, x0 + 3 * j));
      worst = d > worst ? d : worst;
    }
  }
  CHECK(moved > 0.1);
  *settled = worst;
  if (n >= 4) { /* the signed volume of the first four points keeps its sign and size */
    double a[3], b[3], c[3], v0, v1;
    sub(x0 + 3, x0, a), sub(x0 + 6, x0, b), sub(x0 + 9, x0, c);
    v0 = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    sub(x1 + 3, x1, a), sub(x1 + 6, x1, b), sub(x1 + 9, x1, c);
    v1 = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    CHECK(fabs(v1 - v0) <= 1e-6 * (fabs(v0) + 1e-3));
  }
  embra_world_destroy(w);
}

static void test_rigid_set(void) {
  /* a tetrahedron of edge ~0.4 and two points beyond its faces; a flat 3 x 3 grid of 0.2 */
  static const double solid[18] = {0, 0, 1, 0.4, 0, 1, 0, 0.4, 1, 0, 0, 1.4, 0.3, 0.3, 1.3, -0.2, 0.1, 1.2};
  double grid[27], solid_swing, solid_rest, flat_swing, flat_rest;
  int k;
  for (k = 0; k < 9; ++k) grid[3 * k] = 0.2 * (k % 3), grid[3 * k + 1] = 0.2 * (k / 3), grid[3 * k + 2] = 1.0;
  rigid_swing(solid, 6, &solid_swing, &solid_rest);
  rigid_swing(grid, 9, &flat_swing, &flat_rest);
  printf(
      "rigid set, worst change of a pairwise distance: solid %.2e m swinging, %.2e m at rest; flat %.2e m "
      "swinging, %.2e m at rest\n",
      solid_swing, solid_rest, flat_swing, flat_rest);
  CHECK(solid_rest < 1e-6 * 0.6); /* the sets' sizes: about 0.6 m */
  CHECK(flat_rest < 1e-6 * 0.6);
}

int main(void) {
  RUN(test_free_fall);
  RUN(test_gravity_and_solver);
  RUN(test_pendulum);
  RUN(test_roundtrip);
  RUN(test_pins);
  RUN(test_colliders);
  RUN(test_groups);
  RUN(test_body_generation);
  RUN(test_rest_scale);
  RUN(test_constraint_kinds);
  RUN(test_polygon_planarity);
  RUN(test_rigid_set);
  RUN(test_numerical_failure);
  RUN(test_cloth_report);
  return capi_test_finish();
}
