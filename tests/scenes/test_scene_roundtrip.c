/* JSON scenes round-trip exactly, through the C ABI only.
 *
 * For every scene file given on the command line (CMake passes every JSON file of examples/ and of
 * tests/scenes/valid/) and for a world built through the C ABI (a cloth grid and a tet block,
 * constraints of every kind added after the second body and one between the bodies, groups with
 * orders and weights, hard and soft pins, plane, line, polyline, axes and mesh supports, a plane and a sphere,
 * non-default solver settings, a rest scale, initial velocities, point, area and line loads, shape matches, and a
 * destroyed group, pin and collider whose slots are reused):
 *
 *   - load -> save -> load -> save is byte-identical (and a third round changes nothing);
 *   - the original world and the reloaded one, stepped 100 frames, have bit-identical positions,
 *     velocities and step reports after every frame (memcmp), and save to identical JSON;
 *   - a scene saved after 50 frames, loaded and stepped 50 more, ends bit-identical to the
 *     uninterrupted 100-frame run (positions, velocities, report, saved JSON).
 *
 * Usage: test_scene_roundtrip [--save-api PATH] SCENE.json...
 *   --save-api PATH writes the C-ABI world's scene to PATH (for the Python schema check). */
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"
#include "scene_test_util.h"

enum { FRAMES = 100, HALF = 50 };

/* Positions and velocities of every particle, as one buffer of 6 * n doubles. */
typedef struct state {
  double* xv;
  int32_t n;
} state;

static state state_of(const embra_world* w) {
  state s = {NULL, 0};
  embra_world_counts c;
  if (embra_world_get_counts(w, &c) != EMBRA_OK) return s;
  s.n = c.particles;
  s.xv = (double*)calloc((size_t)(6 * (c.particles > 0 ? c.particles : 1)), sizeof(double));
  if (s.xv == NULL) return s;
  if (embra_world_get_positions(w, s.xv, 3 * (int64_t)s.n, 0, s.n) != EMBRA_OK ||
      embra_world_get_velocities(w, s.xv + 3 * s.n, 3 * (int64_t)s.n, 0, s.n) != EMBRA_OK) {
    free(s.xv);
    s.xv = NULL;
  }
  return s;
}

/* 1 when both worlds have the same particle count and bit-identical positions, velocities and
 * last step report. */
static int same_state(const embra_world* a, const embra_world* b) {
  state sa = state_of(a), sb = state_of(b);
  embra_step_report ra, rb;
  int same =
      sa.xv != NULL && sb.xv != NULL && sa.n == sb.n && memcmp(sa.xv, sb.xv, sizeof(double) * 6 * (size_t)sa.n) == 0;
  memset(&ra, 0, sizeof ra);
  memset(&rb, 0, sizeof rb);
  same = same && embra_world_get_report(a, &ra) == EMBRA_OK && embra_world_get_report(b, &rb) == EMBRA_OK &&
         memcmp(&ra, &rb, sizeof ra) == 0;
  free(sa.xv);
  free(sb.xv);
  return same;
}

static int same_counts(const embra_world* a, const embra_world* b) {
  embra_world_counts ca, cb;
  memset(&ca, 0, sizeof ca);
  memset(&cb, 0, sizeof cb);
  return embra_world_get_counts(a, &ca) == EMBRA_OK && embra_world_get_counts(b, &cb) == EMBRA_OK &&
         memcmp(&ca, &cb, sizeof ca) == 0;
}

static embra_world* load_text(const char* text, int64_t length, const char* base_dir) {
  embra_world* w = NULL;
  CHECK_OK(embra_world_load_json(&w, text, length, base_dir));
  return w;
}

/* Steps `frames` frames; 0 on the first failed step. */
static int step(embra_world* w, int frames) {
  int f;
  for (f = 0; f < frames; ++f) {
    const embra_status s = embra_world_step(w);
    if (s != EMBRA_OK) {
      CHECK_MSG(s == EMBRA_OK, "step %d: %s: %s", f + 1, embra_status_name(s), embra_last_error_message());
      return 0;
    }
  }
  return 1;
}

/* The forces a world's readers give, in a form two worlds built alike compare by: per live group,
 * embra_group_get_forces of every kind but the weld (one buffer per group, groups in slot order);
 * the pins' reactions as (particle, force) records sorted by particle then bytes; the colliders'
 * force, moment and contacts in slot order. */
typedef struct forces {
  double** group;   /* per group */
  int64_t* group_n; /* doubles per group */
  int32_t groups;
  double* pins; /* 4 per pin: particle, force xyz */
  int32_t pin_count;
  double* colliders; /* 7 per collider */
  int32_t collider_count;
  int ok;
} forces;

static int compare_pin_record(const void* a, const void* b) {
  return memcmp(a, b, 4 * sizeof(double));
}

static forces forces_of(const embra_world* w) {
  forces f;
  embra_group_id ids[256];
  embra_reaction* r = NULL;
  embra_collider_reaction* c = NULL;
  int32_t g, k, i;
  memset(&f, 0, sizeof f);
  if (embra_world_get_groups(w, ids, 256, &f.groups) != EMBRA_OK ||
      embra_world_get_reactions(w, NULL, 0, &f.pin_count) != EMBRA_OK ||
      embra_world_get_collider_reactions(w, NULL, 0, &f.collider_count) != EMBRA_OK)
    return f;
  f.group = (double**)calloc((size_t)f.groups + 1, sizeof(double*));
  f.group_n = (int64_t*)calloc((size_t)f.groups + 1, sizeof(int64_t));
  f.pins = (double*)calloc(4 * (size_t)f.pin_count + 1, sizeof(double));
  f.colliders = (double*)calloc(7 * (size_t)f.collider_count + 1, sizeof(double));
  r = (embra_reaction*)calloc((size_t)f.pin_count + 1, sizeof(embra_reaction));
  c = (embra_collider_reaction*)calloc((size_t)f.collider_count + 1, sizeof(embra_collider_reaction));
  if (f.group == NULL || f.group_n == NULL || f.pins == NULL || f.colliders == NULL || r == NULL || c == NULL ||
      embra_world_get_reactions(w, r, f.pin_count, &f.pin_count) != EMBRA_OK ||
      embra_world_get_collider_reactions(w, c, f.collider_count, &f.collider_count) != EMBRA_OK) {
    free(r);
    free(c);
    return f;
  }
  for (g = 0; g < f.groups; ++g) {
    int64_t total = 0, n = 0;
    for (k = 0; embra_residual_name(k) != NULL; ++k) {
      if (k == EMBRA_CONSTRAINT_WELD || embra_group_get_forces(w, ids[g], k, NULL, 0, &n) != EMBRA_OK) continue;
      total += n;
    }
    f.group[g] = (double*)calloc((size_t)total + 1, sizeof(double));
    for (k = 0; f.group[g] != NULL && embra_residual_name(k) != NULL; ++k) {
      if (k == EMBRA_CONSTRAINT_WELD || embra_group_get_forces(w, ids[g], k, NULL, 0, &n) != EMBRA_OK) continue;
      if (embra_group_get_forces(w, ids[g], k, f.group[g] + f.group_n[g], n, &n) != EMBRA_OK) break;
      f.group_n[g] += n;
    }
    if (f.group[g] == NULL || f.group_n[g] != total) {
      free(r);
      free(c);
      return f;
    }
  }
  for (i = 0; i < f.pin_count; ++i) {
    f.pins[4 * i] = (double)r[i].particle;
    memcpy(f.pins + 4 * i + 1, r[i].force, 3 * sizeof(double));
  }
  qsort(f.pins, (size_t)f.pin_count, 4 * sizeof(double), compare_pin_record);
  for (i = 0; i < f.collider_count; ++i) {
    memcpy(f.colliders + 7 * i, c[i].force, 3 * sizeof(double));
    memcpy(f.colliders + 7 * i + 3, c[i].moment, 3 * sizeof(double));
    f.colliders[7 * i + 6] = (double)c[i].contacts;
  }
  free(r);
  free(c);
  f.ok = 1;
  return f;
}

static void forces_free(forces* f) {
  int32_t g;
  for (g = 0; f->group != NULL && g < f->groups; ++g) free(f->group[g]);
  free(f->group);
  free(f->group_n);
  free(f->pins);
  free(f->colliders);
}

/* 1 when both read the same forces, bit for bit (groups matched one to one by their forces, as the
 * slots of a loaded world's groups need not be the saved world's). */
static int same_forces(const forces* a, const forces* b) {
  int32_t g, h;
  char used[256];
  if (!a->ok || !b->ok || a->groups != b->groups || a->pin_count != b->pin_count ||
      a->collider_count != b->collider_count)
    return 0;
  if (memcmp(a->pins, b->pins, 4 * sizeof(double) * (size_t)a->pin_count) != 0 ||
      memcmp(a->colliders, b->colliders, 7 * sizeof(double) * (size_t)a->collider_count) != 0)
    return 0;
  memset(used, 0, sizeof used);
  for (g = 0; g < a->groups; ++g) {
    for (h = 0; h < b->groups; ++h)
      if (!used[h] && a->group_n[g] == b->group_n[h] &&
          memcmp(a->group[g], b->group[h], sizeof(double) * (size_t)a->group_n[g]) == 0)
        break;
    if (h == b->groups) return 0;
    used[h] = 1;
  }
  return 1;
}

/* All the round-trip checks on `original` (at frame 0, never stepped); `base_dir` resolves the
 * scene's relative paths. Destroys `original`. */
static void check_round_trip(const char* label, embra_world* original, const char* base_dir) {
  int64_t n1 = 0, n2 = 0, n3 = 0, nmid = 0;
  char *s1, *s2 = NULL, *s3 = NULL, *mid = NULL;
  char *end_original = NULL, *end_reloaded = NULL, *end_resumed = NULL;
  embra_world *reloaded = NULL, *third = NULL, *resumed = NULL;
  forces at_half;
  int64_t frames_a = -1, frames_b = -2;
  int f, diverged = 0;

  memset(&at_half, 0, sizeof at_half);
  CAPI_CONTEXT("%s", label);
  s1 = scene_save(original, &n1);
  if (!CHECK(s1 != NULL)) goto done;
  CHECK_INT((int64_t)strlen(s1), n1);
  CHECK(scene_valid_utf8(s1));

  /* load -> save -> load -> save */
  reloaded = load_text(s1, n1, base_dir);
  if (reloaded == NULL) goto done;
  s2 = scene_save(reloaded, &n2);
  if (!CHECK(s2 != NULL)) goto done;
  CHECK_MSG(n1 == n2 && memcmp(s1, s2, (size_t)n1) == 0,
            "%s: the second save differs from the first (%lld vs %lld bytes)", label, (long long)n1, (long long)n2);
  third = load_text(s2, n2, base_dir);
  if (third == NULL) goto done;
  s3 = scene_save(third, &n3);
  CHECK(s3 != NULL && n3 == n2 && memcmp(s2, s3, (size_t)n2) == 0);
  CHECK(same_counts(original, reloaded));
  CHECK(same_state(original, reloaded));
  CHECK_OK(embra_world_get_scene_frames(original, &frames_a));
  CHECK_OK(embra_world_get_scene_frames(reloaded, &frames_b));
  CHECK_INT(frames_a, frames_b);

  /* 100 frames of the original and of the reloaded world, compared after every frame; the state
   * after 50 frames is saved on the way. */
  for (f = 1; f <= FRAMES && !diverged; ++f) {
    if (!step(original, 1) || !step(reloaded, 1)) break;
    if (!same_state(original, reloaded)) {
      CHECK_MSG(0, "%s: the reloaded world diverges from the original at frame %d", label, f);
      diverged = 1;
    }
    if (f == HALF) {
      mid = scene_save(original, &nmid);
      CHECK(mid != NULL);
      at_half = forces_of(original);
      CHECK(at_half.ok);
    }
  }
  if (f <= FRAMES) goto done;
  CHECK(same_counts(original, reloaded));
  end_original = scene_save(original, NULL);
  end_reloaded = scene_save(reloaded, NULL);
  CHECK(end_original != NULL && end_reloaded != NULL && strcmp(end_original, end_reloaded) == 0);

  /* The scene saved at frame 50, loaded and stepped 50 more, ends where the original did. */
  if (mid == NULL) goto done;
  resumed = load_text(mid, nmid, base_dir);
  if (resumed == NULL) goto done;
  {
    embra_step_report r;
    CHECK_OK(embra_world_get_report(resumed, &r));
    CHECK_INT(r.frame, HALF);
  }
  /* Before its first step it reads the forces the world saved read (state.forces). */
  {
    forces loaded = forces_of(resumed);
    CHECK_MSG(same_forces(&at_half, &loaded), "%s: the scene saved at frame %d reads other forces once loaded", label,
              HALF);
    forces_free(&loaded);
  }
  if (!step(resumed, FRAMES - HALF)) goto done;
  CHECK_MSG(same_state(original, resumed), "%s: the run resumed from frame %d ends elsewhere", label, HALF);
  end_resumed = scene_save(resumed, NULL);
  CHECK(end_resumed != NULL && end_original != NULL && strcmp(end_original, end_resumed) == 0);

done:
  forces_free(&at_half);
  free(s1);
  free(s2);
  free(s3);
  free(mid);
  free(end_original);
  free(end_reloaded);
  free(end_resumed);
  embra_world_destroy(original);
  embra_world_destroy(reloaded);
  embra_world_destroy(third);
  embra_world_destroy(resumed);
}

/* --- a scene file ------------------------------------------------------------------------------ */

static void check_scene_file(const char* path) {
  char dir[4096];
  int64_t length = 0, n_file = 0, n_text = 0;
  char* text = scene_read_file(path, &length);
  embra_world *from_file = NULL, *from_text = NULL;
  char *s_file = NULL, *s_text = NULL;
  CAPI_CONTEXT("%s", path);
  if (!CHECK(text != NULL)) return;
  scene_folder_of(path, dir, sizeof dir);
  /* load_file and load_json (with the file's folder) build the same world. */
  CHECK_OK(embra_world_load_file(&from_file, path));
  CHECK_OK(embra_world_load_json(&from_text, text, length, dir));
  if (from_file != NULL && from_text != NULL) {
    s_file = scene_save(from_file, &n_file);
    s_text = scene_save(from_text, &n_text);
    CHECK(s_file != NULL && s_text != NULL && strcmp(s_file, s_text) == 0);
  }
  free(s_file);
  free(s_text);
  free(text);
  embra_world_destroy(from_text);
  if (from_file != NULL) check_round_trip(path, from_file, dir);
}

/* --- a world built through the C ABI ----------------------------------------------------------- */

enum { NX = 7, NY = 5, CLOTH_N = NX * NY, CLOTH_T = 2 * (NX - 1) * (NY - 1), BLOCK_N = 8, BLOCK_T = 5 };

/* Builds the world; NULL on failure (the failed call is reported). */
static embra_world* build_api_world(void) {
  static double cloth_xyz[3 * CLOTH_N], cloth_uv[2 * CLOTH_N];
  static int32_t cloth_tri[3 * CLOTH_T];
  /* A unit cube as five tetrahedra (a corner cut off at each of four corners, one in the middle). */
  static const double block_xyz[3 * BLOCK_N] = {-0.15, -0.15, 0.3, 0.15, -0.15, 0.3, 0.15, 0.15, 0.3, -0.15, 0.15, 0.3,
                                                -0.15, -0.15, 0.6, 0.15, -0.15, 0.6, 0.15, 0.15, 0.6, -0.15, 0.15, 0.6};
  static const int32_t block_tet[4 * BLOCK_T] = {0, 1, 3, 4, 1, 2, 3, 6, 1, 4, 5, 6, 3, 4, 6, 7, 1, 3, 4, 6};
  static const double block_mass[BLOCK_N] = {0.05, 0.05, 0.05, 0.05, 0.04, 0.04, 0.04, 0.06};
  embra_world* w = NULL;
  embra_solver_def sd = embra_default_solver_def();
  embra_group_def gd = embra_default_group_def();
  embra_group_id g_stretch, g_bend, g_tie, g_dead, g_default, g_contact;
  embra_body_def bd;
  embra_body_id cloth, block;
  int32_t c0 = -1, b0 = -1, t = 0, i, j;
  embra_constraint_def cd;
  embra_constraint_batch_def bat;
  embra_pin_def pd;
  embra_pin_id pin, dead_pin;
  embra_collider_def kd;
  embra_collider_id col, dead_col;
  const int failed_before = capi_test_failed;

  for (j = 0; j < NY; ++j)
    for (i = 0; i < NX; ++i) {
      const int32_t v = j * NX + i;
      cloth_xyz[3 * v] = -0.6 + 0.2 * i;
      cloth_xyz[3 * v + 1] = -0.4 + 0.2 * j;
      cloth_xyz[3 * v + 2] = 1.0 + 0.01 * i * j; /* slightly curved: non-zero rest dihedrals */
      cloth_uv[2 * v] = 0.2 * i;
      cloth_uv[2 * v + 1] = 0.2 * j;
    }
  for (j = 0; j + 1 < NY; ++j)
    for (i = 0; i + 1 < NX; ++i) {
      const int32_t a = j * NX + i, b = a + 1, c = a + NX + 1, d = a + NX;
      cloth_tri[3 * t] = a, cloth_tri[3 * t + 1] = b, cloth_tri[3 * t + 2] = c, ++t;
      cloth_tri[3 * t] = a, cloth_tri[3 * t + 1] = c, cloth_tri[3 * t + 2] = d, ++t;
    }

  sd.substeps = 5;
  sd.iterations = 3;
  sd.dt = 1.0 / 90.0;
  sd.gravity[0] = 0.3;
  sd.gravity[1] = -0.2;
  sd.gravity[2] = -9.81;
  sd.damping = 0.2;
  sd.settle_speed = 2e-3;
  sd.tethers = 1;
  sd.realign_passes = 2;
  sd.chain_solve = 0;
  if (!CHECK(embra_world_create(&w, &sd) == EMBRA_OK)) return NULL;
  CHECK_OK(embra_world_default_group(w, &g_default));
  CHECK_OK(embra_world_contact_group(w, &g_contact));
  CHECK_OK(embra_group_set_order(w, g_default, 4));
  CHECK_OK(embra_group_set_weight(w, g_contact, 2));
  gd.order = 7;
  CHECK_OK(embra_group_create(w, &gd, &g_dead));
  gd.order = -2;
  gd.weight = 3;
  CHECK_OK(embra_group_create(w, &gd, &g_stretch));
  gd.order = 7;
  gd.weight = 1;
  CHECK_OK(embra_group_create(w, &gd, &g_bend));
  gd.order = 7; /* the same order as g_bend: creation order breaks the tie */
  gd.weight = 2;
  CHECK_OK(embra_group_create(w, &gd, &g_tie));
  CHECK_OK(embra_group_destroy(w, g_dead));

  bd = embra_default_body_def();
  bd.vertex_count = CLOTH_N;
  bd.positions = cloth_xyz;
  bd.uvs = cloth_uv;
  bd.triangle_count = CLOTH_T;
  bd.triangles = cloth_tri;
  bd.generate = EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_SHEAR | EMBRA_GENERATE_BEND;
  bd.material.mass = 0.4;
  bd.material.stretch_compliance = 1e-4;
  bd.material.shear_compliance = 1e-3;
  bd.material.bend_compliance = 0.3;
  bd.material.damping = 0.05;
  bd.material.thickness = 0.02;
  bd.material.friction_static = 0.7;
  bd.material.friction_dynamic = 0.45;
  bd.stretch_group = g_stretch;
  bd.bend_group = g_bend;
  CHECK_OK(embra_body_create(w, &bd, &cloth, &c0));
  /* One constraint between the bodies, in the group and kind where the block's stretch goes: the
   * block's generated constraints are placed before it. */
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_DISTANCE;
  cd.particles[0] = c0 + 1;
  cd.particles[1] = c0 + 15;
  cd.compliance = 1e-3;
  CHECK_OK(embra_constraint_add(w, &cd));

  bd = embra_default_body_def();
  bd.vertex_count = BLOCK_N;
  bd.positions = block_xyz;
  bd.masses = block_mass;
  bd.tet_count = BLOCK_T;
  bd.tets = block_tet;
  bd.generate = EMBRA_GENERATE_STRETCH | EMBRA_GENERATE_VOLUME;
  bd.material.volume_compliance = 1e-7;
  bd.material.stretch_compliance = 1e-6;
  bd.volume_group = g_tie;
  CHECK_OK(embra_body_create(w, &bd, &block, &b0));
  if (capi_test_failed != failed_before) {
    embra_world_destroy(w);
    return NULL;
  }

  /* Constraints of every kind, after the second body. */
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_DISTANCE;
  cd.group = g_tie;
  cd.particles[0] = c0 + 17;
  cd.particles[1] = b0 + 6;
  cd.rest_from_current = 0;
  cd.rest = 0.5;
  cd.compliance = 1e-3;
  CHECK_OK(embra_constraint_add(w, &cd));
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_WELD;
  cd.particles[0] = c0 + 3;
  cd.particles[1] = c0 + 10;
  cd.rest_from_current = 0;
  cd.rest = 0.0;
  cd.compliance = 0.05;
  CHECK_OK(embra_constraint_add(w, &cd));
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_EDGE_ANGLE;
  cd.group = g_bend;
  cd.particles[0] = c0 + 8;
  cd.particles[1] = c0 + 9;
  cd.particles[2] = c0 + 15;
  cd.compliance = 0.01;
  CHECK_OK(embra_constraint_add(w, &cd));
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_DIHEDRAL;
  cd.group = g_stretch;
  cd.particles[0] = c0 + 9;
  cd.particles[1] = c0 + 16;
  cd.particles[2] = c0 + 8;
  cd.particles[3] = c0 + 17;
  cd.rest_from_current = 0;
  cd.rest = 0.2;
  cd.compliance = 0.5;
  CHECK_OK(embra_constraint_add(w, &cd));
  cd = embra_default_constraint_def();
  cd.kind = EMBRA_CONSTRAINT_TET_VOLUME;
  cd.particles[0] = b0 + 0;
  cd.particles[1] = b0 + 1;
  cd.particles[2] = b0 + 3;
  cd.particles[3] = b0 + 7;
  CHECK_OK(embra_constraint_add(w, &cd));
  {
    const int32_t tether_ids[4] = {c0 + 0, b0 + 4, c0 + NX - 1, b0 + 5};
    const double compliances[2] = {0.0, 1e-4};
    bat = embra_default_constraint_batch_def();
    bat.kind = EMBRA_CONSTRAINT_TETHER;
    bat.group = g_tie;
    bat.count = 2;
    bat.particles = tether_ids;
    bat.compliances = compliances;
    CHECK_OK(embra_constraints_add(w, &bat));
  }
  {
    const int32_t distance_ids[4] = {c0 + 20, c0 + 22, c0 + 30, b0 + 2};
    const double rest[2] = {0.35, 0.9};
    bat = embra_default_constraint_batch_def();
    bat.kind = EMBRA_CONSTRAINT_DISTANCE;
    bat.count = 2;
    bat.particles = distance_ids;
    bat.rest = rest;
    bat.compliance = 2e-4;
    CHECK_OK(embra_constraints_add(w, &bat));
  }

  /* Pins: hard at two cloth corners (one target away from its particle: it glides there), soft on
   * the block, and one destroyed. */
  pd = embra_default_pin_def();
  pd.particle = c0 + 0;
  memcpy(pd.target, &cloth_xyz[0], sizeof pd.target);
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  pd.particle = c0 + 3;
  CHECK_OK(embra_pin_create(w, &pd, &dead_pin));
  CHECK_OK(embra_pin_destroy(w, dead_pin));
  pd.particle = c0 + NX - 1;
  pd.target[0] = cloth_xyz[3 * (NX - 1)] - 0.1;
  pd.target[1] = cloth_xyz[3 * (NX - 1) + 1];
  pd.target[2] = cloth_xyz[3 * (NX - 1) + 2] + 0.05;
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  pd = embra_default_pin_def();
  pd.particle = b0 + 7;
  pd.target[0] = -0.2;
  pd.target[1] = 0.2;
  pd.target[2] = 0.7;
  pd.compliance = 1e-3;
  pd.group = g_bend;
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  /* Two more soft pins on one cloth particle in one group, the first made in a slot freed after
   * the second was made: the group projects them in creation order, which is not slot order. */
  pd = embra_default_pin_def();
  pd.particle = c0 + 24;
  pd.compliance = 2e-3;
  pd.group = g_stretch;
  memcpy(pd.target, &cloth_xyz[3 * 24], sizeof pd.target);
  pd.target[2] += 0.1;
  CHECK_OK(embra_pin_create(w, &pd, &dead_pin));
  pd.target[0] += 0.1;
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  CHECK_OK(embra_pin_destroy(w, dead_pin));
  pd.target[0] -= 0.2;
  pd.compliance = 5e-3;
  CHECK_OK(embra_pin_create(w, &pd, &pin));
  /* Sliding supports: a hard one on a tilted plane, a soft one on a line (axes of any length). */
  {
    embra_support_def su = embra_default_support_def();
    su.particle = c0 + 12;
    memcpy(su.target, &cloth_xyz[3 * 12], sizeof su.target);
    su.axis[0] = 0.1;
    su.axis[2] = 0.7;
    CHECK_OK(embra_support_create(w, &su, &pin));
    su.particle = c0 + 13;
    su.support = EMBRA_PIN_SUPPORT_LINE;
    su.compliance = 1e-3;
    su.group = g_stretch;
    CHECK_OK(embra_support_create(w, &su, &pin));
  }

  /* A tilted plane, a sphere, and a destroyed sphere. */
  kd = embra_default_collider_def();
  kd.shape = EMBRA_COLLIDER_SPHERE;
  kd.radius = 9.0;
  CHECK_OK(embra_collider_create(w, &kd, &dead_col));
  kd = embra_default_collider_def();
  kd.shape = EMBRA_COLLIDER_PLANE;
  kd.position[2] = 0.05;
  kd.rotation[0] = 0.99968751627570263; /* cos(0.05 / 2): 0.05 rad about x */
  kd.rotation[1] = 0.024997395914712332;
  kd.friction_static = 0.8;
  kd.friction_dynamic = 0.6;
  CHECK_OK(embra_collider_create(w, &kd, &col));
  CHECK_OK(embra_collider_destroy(w, dead_col));
  kd = embra_default_collider_def();
  kd.shape = EMBRA_COLLIDER_SPHERE;
  kd.position[0] = 0.3;
  kd.position[2] = 0.75;
  kd.radius = 0.2;
  kd.thickness = 0.01;
  CHECK_OK(embra_collider_create(w, &kd, &col));

  CHECK_OK(embra_body_set_rest_scale(w, cloth, 0.97, 1.0, 0.93));
  {
    double v[3 * BLOCK_N];
    for (i = 0; i < 3 * BLOCK_N; ++i) v[i] = 0.01 * (i % 5) - 0.02;
    CHECK_OK(embra_world_set_velocities(w, v, b0, BLOCK_N));
  }
  {
    /* Point loads on two particles (N), written to the scene's "loads" with every bit. */
    const double loads[6] = {0.1, -0.2, -1.0 / 3.0, 0.0, 0.0, 0.7};
    CHECK_OK(embra_world_set_loads(w, loads, b0, 2));
  }
  {
    /* Area loads in every mode and line loads (a direction of any length, pressures and loads
     * that are not short decimals), written to "area_loads" and "line_loads" with every bit. */
    embra_area_load area[3];
    embra_line_load line[2];
    for (i = 0; i < 3; ++i) {
      area[i].particles[0] = c0 + i;
      area[i].particles[1] = c0 + i + 1;
      area[i].particles[2] = c0 + i + NX;
      area[i].mode = i; /* EMBRA_AREA_LOAD_NORMAL, _TRUE_AREA, _PROJECTED_AREA */
      area[i].pressure = (i + 1) * 1.0 / 7.0;
      area[i].direction[0] = 0.1 * i;
      area[i].direction[1] = -1.0 / 3.0;
      area[i].direction[2] = -2.5;
    }
    for (i = 0; i < 2; ++i) {
      line[i].particles[0] = b0 + i;
      line[i].particles[1] = c0 + NX + i;
      line[i].load[0] = 0.2 / 3.0;
      line[i].load[1] = 0.0;
      line[i].load[2] = -0.3 - i;
    }
    /* A polyline support on a closed curve round the cloth's second row (points with every bit). */
    {
      double curve[3 * 4] = {0.0, 0.0, 0.0, 0.4, 0.1 / 3.0, 0.0, 0.4, 0.4, 0.05, 0.0, 0.4, -0.1};
      embra_polyline_support_def su = embra_default_polyline_support_def();
      embra_pin_id spin;
      su.particle = c0 + NX + 2;
      memcpy(su.target, &cloth_xyz[3 * (NX + 2)], sizeof su.target);
      su.points = curve;
      su.point_count = 4;
      su.closed = 1;
      su.compliance = 1e-4;
      CHECK_OK(embra_polyline_support_create(w, &su, &spin));
    }
    /* A mesh support: a tetrahedron round a cloth particle (vertices with every bit), hard. */
    {
      double verts[3 * 4] = {0.3, 0.0, 0.0, -0.1, 0.25 / 3.0, 0.0, -0.1, -0.25, 0.01, 0.0, 0.0, 0.4};
      int32_t tris[3 * 4] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
      embra_mesh_support_def me = embra_default_mesh_support_def();
      embra_pin_id mpin;
      me.particle = c0 + NX + 4;
      memcpy(me.target, &cloth_xyz[3 * (NX + 4)], sizeof me.target);
      me.vertices = verts;
      me.vertex_count = 4;
      me.triangles = tris;
      me.triangle_count = 4;
      CHECK_OK(embra_mesh_support_create(w, &me, &mpin));
    }
    /* A per-axis anchor holding x and z of a cloth particle (y free), compliant. */
    {
      embra_support_def ax = embra_default_support_def();
      embra_pin_id apin;
      ax.particle = c0 + NX + 3;
      ax.support = EMBRA_PIN_SUPPORT_AXES;
      memcpy(ax.target, &cloth_xyz[3 * (NX + 3)], sizeof ax.target);
      ax.target[2] += 0.1 / 3.0;
      ax.axis[0] = 1.0;
      ax.compliance = 2e-5;
      CHECK_OK(embra_support_create(w, &ax, &apin));
    }
    CHECK_OK(embra_world_set_area_loads(w, area, 3));
    CHECK_OK(embra_world_set_line_loads(w, line, 2));
    /* Shape matches: a soft one over a patch of the cloth in a group, a hard one over the block. */
    {
      const int32_t patch[5] = {c0 + 2 * NX + 1, c0 + 2 * NX + 2, c0 + 3 * NX + 1, c0 + 3 * NX + 2, c0 + 4 * NX + 3};
      const int32_t corners[4] = {b0 + 0, b0 + 1, b0 + 2, b0 + 5};
      int32_t index = -1;
      CHECK_OK(embra_shape_match_add(w, g_bend, patch, 5, 3e-4 / 7.0, &index));
      CHECK_INT(index, 0);
      CHECK_OK(embra_shape_match_add(w, (embra_group_id){0, 0}, corners, 4, 0.0, &index));
      CHECK_INT(index, 0);
    }
  }
  if (capi_test_failed != failed_before) {
    embra_world_destroy(w);
    return NULL;
  }
  return w;
}

static const char* g_save_api_path = NULL;

static void api_world_round_trips(void) {
  embra_world* w = build_api_world();
  embra_world_counts c;
  if (w == NULL) return;
  CHECK_OK(embra_world_get_counts(w, &c));
  CHECK_INT(c.bodies, 2);
  CHECK_INT(c.pins, 10); /* five pins and five supports */
  CHECK_INT(c.colliders, 2);
  if (g_save_api_path != NULL) CHECK_OK(embra_world_save_file(w, g_save_api_path));
  check_round_trip("the C-ABI world", w, NULL);
}

static int g_argc;
static char** g_argv;

static void scene_files_round_trip(void) {
  int i, files = 0;
  for (i = 1; i < g_argc; ++i) {
    if (strcmp(g_argv[i], "--save-api") == 0) {
      ++i;
      continue;
    }
    check_scene_file(g_argv[i]);
    ++files;
  }
  CHECK_MSG(files > 0, "no scene files given");
}

int main(int argc, char** argv) {
  int i;
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) return 1;
  g_argc = argc;
  g_argv = argv;
  for (i = 1; i + 1 < argc; ++i)
    if (strcmp(argv[i], "--save-api") == 0) g_save_api_path = argv[i + 1];
  RUN(api_world_round_trips);
  RUN(scene_files_round_trip);
  return capi_test_finish();
}
