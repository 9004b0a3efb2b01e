/* Scenes from someone else, through the C ABI: what a scene may make the loader read, and actions
 * that must keep stepping.
 *
 * - OBJ paths: relative to base_dir and confined to it (an absolute path, ".." or a symbolic link
 *   leading out is refused unless embra_load_options.allow_paths_outside_base); only regular files
 *   (a folder, /dev/zero, /dev/null or a FIFO is refused, and opening a FIFO does not block); a
 *   file larger than EMBRA_MAX_OBJ_BYTES is refused before it is read; embra_world_load_file
 *   confines a scene to its own folder, and reads a scene from a regular file only. Every refusal is EMBRA_ERROR_SCHEMA
 * with the pointer of the "obj" value and leaves *out_world NULL.
 * - Error messages about an OBJ file never repeat its content (a token of the file is a secret
 *   the host may not mean to show).
 * - A collider_pose action keyed from q to -q (one rotation) steps through every frame, and a
 *   turn between two keys takes the shorter way (30 to 120 degrees about z passes 75 at the
 *   midpoint, whichever sign the keys are written with).
 *
 * Usage: test_scene_hostile WORK_DIR   (created; its parent must exist) */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "capi_test.h"
#include "scene_test_util.h"

static char g_base[4096];    /* the scene's folder */
static char g_outside[4096]; /* a folder beside it */

static const char kQuad[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

static int write_text(const char* path, const char* text) {
  FILE* f = fopen(path, "wb");
  if (f == NULL) return 0;
  fputs(text, f);
  return fclose(f) == 0;
}

static void path_in(char* out, size_t capacity, const char* dir, const char* name) {
  snprintf(out, capacity, "%s/%s", dir, name);
}

/* A scene with one body whose mesh is the OBJ file `obj` (a JSON string's content, no escapes). */
static void body_scene(char* out, size_t capacity, const char* obj) {
  snprintf(out, capacity,
           "{\"format\": \"embra-scene\", \"version\": 1, \"bodies\": [{\"name\": \"scan\", \"mesh\": {\"obj\": "
           "\"%s\"}}]}",
           obj);
}

/* Loads `scene` with base_dir g_base, outside paths allowed or not; returns the status and destroys
 * any world. *out_world is checked to be NULL on failure. */
static embra_status load(const char* scene, int allow_outside) {
  static int sentinel;
  embra_world* w = (embra_world*)(void*)&sentinel;
  embra_load_options o = embra_default_load_options();
  embra_status s;
  o.base_dir = g_base;
  o.allow_paths_outside_base = allow_outside;
  s = embra_world_load_json_with_options(&w, scene, (int64_t)strlen(scene), &o);
  if (s != EMBRA_OK) {
    CHECK(w == NULL);
  } else {
    embra_world_counts c;
    CHECK_OK(embra_world_get_counts(w, &c));
    CHECK(c.particles >= 4);
  }
  embra_world_destroy(s == EMBRA_OK ? w : NULL);
  return s;
}

/* `obj` loads (allowed or confined as `confined_ok` says) and, with outside paths allowed, as
 * `allowed_ok` says; each refusal names the pointer and contains `fragment`. */
static void expect(const char* obj, int confined_ok, int allowed_ok, const char* fragment) {
  char scene[8192];
  int allow;
  body_scene(scene, sizeof scene, obj);
  for (allow = 0; allow <= 1; ++allow) {
    const int ok = allow ? allowed_ok : confined_ok;
    CAPI_CONTEXT("obj \"%.200s\", allow_paths_outside_base %d", obj, allow);
    if (ok) {
      CHECK_OK(load(scene, allow));
    } else {
      CHECK_STATUS(load(scene, allow), EMBRA_ERROR_SCHEMA);
      CHECK_CONTAINS(embra_last_error_message(), "embra_world_load_json_with_options: /bodies/0/mesh/obj: ");
      CHECK_CONTAINS(embra_last_error_message(), fragment);
      CHECK(scene_valid_utf8(embra_last_error_message()));
    }
  }
}

static void prepare(const char* work) {
  char p[4200], q[4200];
  snprintf(g_base, sizeof g_base, "%s/scene", work);
  snprintf(g_outside, sizeof g_outside, "%s/elsewhere", work);
  CHECK(mkdir(work, 0755) == 0 || errno == EEXIST);
  CHECK(mkdir(g_base, 0755) == 0 || errno == EEXIST);
  CHECK(mkdir(g_outside, 0755) == 0 || errno == EEXIST);
  path_in(p, sizeof p, g_base, "sub");
  CHECK(mkdir(p, 0755) == 0 || errno == EEXIST);
  path_in(p, sizeof p, g_base, "folder.obj");
  CHECK(mkdir(p, 0755) == 0 || errno == EEXIST);
  path_in(p, sizeof p, g_base, "mesh.obj");
  CHECK(write_text(p, kQuad));
  path_in(p, sizeof p, g_base, "sub/mesh.obj");
  CHECK(write_text(p, kQuad));
  path_in(p, sizeof p, g_outside, "mesh.obj");
  CHECK(write_text(p, kQuad));
  /* Links made fresh on every run. */
  path_in(p, sizeof p, g_base, "link_in.obj");
  unlink(p);
  CHECK(symlink("sub/mesh.obj", p) == 0);
  path_in(p, sizeof p, g_base, "link_out.obj");
  unlink(p);
  CHECK(symlink("../elsewhere/mesh.obj", p) == 0);
  path_in(p, sizeof p, g_base, "link_dir");
  unlink(p);
  CHECK(symlink(g_outside, p) == 0);
  path_in(p, sizeof p, g_base, "zero.obj");
  unlink(p);
  CHECK(symlink("/dev/zero", p) == 0);
  path_in(p, sizeof p, g_base, "fifo.obj");
  unlink(p);
  CHECK(mkfifo(p, 0644) == 0);
  /* One byte more than the largest OBJ file: sparse, so it costs no disk (and must not be read). */
  path_in(p, sizeof p, g_base, "big.obj");
  CHECK(write_text(p, ""));
  CHECK(truncate(p, (off_t)EMBRA_MAX_OBJ_BYTES + 1) == 0);
  path_in(q, sizeof q, g_base, "secret_face.obj");
  CHECK(write_text(q, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 secret_token_from_file\n"));
  path_in(q, sizeof q, g_base, "secret_vertex.obj");
  CHECK(write_text(q, "v 0 0 0\nv secret_token_from_file 0 0\nv 0 1 0\nf 1 2 3\n"));
  path_in(q, sizeof q, g_base, "secret_index.obj");
  CHECK(write_text(q, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 424242\n"));
}

static void paths_inside_load(void) {
  expect("mesh.obj", 1, 1, "");
  expect("sub/mesh.obj", 1, 1, "");
  expect("sub/../mesh.obj", 1, 1, "");
  expect("./sub/./mesh.obj", 1, 1, "");
  expect("link_in.obj", 1, 1, "");
}

static void paths_outside_are_refused(void) {
  char abs_out[4200], abs_in[4200];
  path_in(abs_out, sizeof abs_out, g_outside, "mesh.obj");
  path_in(abs_in, sizeof abs_in, g_base, "mesh.obj");
  expect("../elsewhere/mesh.obj", 0, 1, "leads outside the scene's folder");
  expect("sub/../../elsewhere/mesh.obj", 0, 1, "leads outside the scene's folder");
  expect("link_out.obj", 0, 1, "leads outside the scene's folder");
  expect("link_dir/mesh.obj", 0, 1, "leads outside the scene's folder");
  expect(abs_out, 0, 1, "an absolute path is refused");
  expect(abs_in, 0, 1, "an absolute path is refused"); /* absolute is refused even when inside */
  expect("missing.obj", 0, 0, "No such file");
  expect("../missing.obj", 0, 0, "\"../missing.obj\""); /* outside; with outside allowed, missing */
}

static void special_files_are_refused(void) {
  char big[64];
  expect("zero.obj", 0, 0, ""); /* outside when confined; not a regular file when allowed */
  expect("/dev/zero", 0, 0, "");
  expect("/dev/null", 0, 0, "");
  expect("fifo.obj", 0, 0, "is not a regular file");
  expect("folder.obj", 0, 0, "is not a regular file");
  expect(".", 0, 0, "is not a regular file");
  snprintf(big, sizeof big, "larger than %lld bytes", (long long)EMBRA_MAX_OBJ_BYTES);
  expect("big.obj", 0, 0, big);
  {
    char scene[512];
    int allow;
    body_scene(scene, sizeof scene, "/dev/zero");
    for (allow = 0; allow <= 1; ++allow) {
      CAPI_CONTEXT("/dev/zero, allow %d", allow);
      CHECK_STATUS(load(scene, allow), EMBRA_ERROR_SCHEMA);
      CHECK_CONTAINS(embra_last_error_message(), allow ? "is not a regular file" : "an absolute path is refused");
    }
  }
}

static void messages_never_show_the_file(void) {
  static const struct {
    const char* obj;
    const char* says;
    const char* hidden;
  } cases[] = {{"secret_face.obj", "line 4: bad face index", "secret_token"},
               {"secret_vertex.obj", "line 2: a vertex needs three finite numbers", "secret_token"},
               {"secret_index.obj", "line 4: a face index is outside the 3 vertices before it", "424242"}};
  size_t i;
  for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    char scene[512];
    body_scene(scene, sizeof scene, cases[i].obj);
    CAPI_CONTEXT("%s", cases[i].obj);
    CHECK_STATUS(load(scene, 0), EMBRA_ERROR_SCHEMA);
    CHECK_CONTAINS(embra_last_error_message(), cases[i].says);
    CHECK_MSG(strstr(embra_last_error_message(), cases[i].hidden) == NULL, "the message shows the file: %s",
              embra_last_error_message());
  }
}

/* Panel meshes read OBJ files through the same door. */
static void panel_obj_paths_are_confined(void) {
  char scene[512];
  embra_world* w = NULL;
  embra_load_options o = embra_default_load_options();
  snprintf(scene, sizeof scene,
           "{\"format\": \"embra-scene\", \"version\": 1, \"panel_meshes\": [{\"name\": \"roof\", \"generator\": "
           "\"obj\", \"obj\": \"../elsewhere/mesh.obj\"}]}");
  o.base_dir = g_base;
  CAPI_CONTEXT("panel mesh OBJ outside");
  CHECK_STATUS(embra_world_load_json_with_options(&w, scene, (int64_t)strlen(scene), &o), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "/panel_meshes/0/obj: ");
  CHECK_CONTAINS(embra_last_error_message(), "leads outside the scene's folder");
  o.allow_paths_outside_base = 1;
  CHECK_OK(embra_world_load_json_with_options(&w, scene, (int64_t)strlen(scene), &o));
  embra_world_destroy(w);
}

/* embra_world_load_file and embra_world_load_json confine a scene to its folder. */
static void other_entry_points_confine(void) {
  char path[4200], scene[512];
  embra_world* w = NULL;
  body_scene(scene, sizeof scene, "../elsewhere/mesh.obj");
  path_in(path, sizeof path, g_base, "escaping.json");
  CHECK(write_text(path, scene));
  CAPI_CONTEXT("embra_world_load_file");
  CHECK_STATUS(embra_world_load_file(&w, path), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "leads outside the scene's folder");
  CAPI_CONTEXT("embra_world_load_json");
  CHECK_STATUS(embra_world_load_json(&w, scene, (int64_t)strlen(scene), g_base), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  body_scene(scene, sizeof scene, "sub/mesh.obj");
  path_in(path, sizeof path, g_base, "inside.json");
  CHECK(write_text(path, scene));
  CAPI_CONTEXT("embra_world_load_file, inside");
  CHECK_OK(embra_world_load_file(&w, path));
  embra_world_destroy(w);
}

/* embra_world_load_file reads regular files only: a FIFO is refused without waiting for a writer,
 * /dev/zero without reading it, a folder without trying. */
static void scene_files_must_be_regular(void) {
  char fifo[4200];
  const char* paths[3];
  size_t i;
  path_in(fifo, sizeof fifo, g_base, "fifo.obj");
  paths[0] = fifo;
  paths[1] = "/dev/zero";
  paths[2] = g_base;
  for (i = 0; i < 3; ++i) {
    embra_world* w = NULL;
    CAPI_CONTEXT("embra_world_load_file(%s)", paths[i]);
    CHECK_STATUS(embra_world_load_file(&w, paths[i]), EMBRA_ERROR_INVALID_ARGUMENT);
    CHECK(w == NULL);
    CHECK_CONTAINS(embra_last_error_message(), "is not a regular file");
  }
}

/* The rotation angle (radians, in [0, pi]) and the axis' z of a unit quaternion, either sign. */
static double angle_of(const double q[4]) {
  const double w = fabs(q[0]);
  return 2.0 * acos(w > 1.0 ? 1.0 : w);
}

static void collider_pose_takes_the_short_way(void) {
  const double pi = 3.14159265358979323846;
  const double a30 = pi / 12.0, a120 = pi / 3.0; /* half angles of 30 and 120 degrees */
  char scene[2048];
  embra_world* w = NULL;
  embra_collider_id ids[2];
  int32_t n = 0;
  int frame;
  /* "flip": q to -q, one rotation; "turn": +30 degrees about z to -(+120 degrees about z). */
  snprintf(scene, sizeof scene,
           "{\"format\": \"embra-scene\", \"version\": 1, \"frames\": 10,"
           " \"bodies\": [{\"name\": \"rod\", \"mesh\": {\"vertices\": [[0, 0, 2], [1, 0, 2]], \"edges\": [[0, 1]]}}],"
           " \"colliders\": [{\"name\": \"flip\", \"shape\": \"box\"}, {\"name\": \"turn\", \"shape\": \"box\"}],"
           " \"actions\": ["
           "{\"type\": \"collider_pose\", \"collider\": \"flip\", \"keys\": [{\"frame\": 0, \"value\": [0, 0, 0, 0.6, "
           "0, 0.8, 0]}, {\"frame\": 10, \"value\": [0, 0, 0, -0.6, 0, -0.8, 0]}]},"
           "{\"type\": \"collider_pose\", \"collider\": \"turn\", \"keys\": [{\"frame\": 0, \"value\": [0, 0, 0, "
           "%.17g, 0, 0, %.17g]}, {\"frame\": 10, \"value\": [0, 0, 0, %.17g, 0, 0, %.17g]}]}]}",
           cos(a30), sin(a30), -cos(a120), -sin(a120));
  CHECK_OK(embra_world_load_json(&w, scene, (int64_t)strlen(scene), NULL));
  if (w == NULL) return;
  CHECK_OK(embra_world_get_colliders(w, ids, 2, &n));
  CHECK_INT(n, 2);
  for (frame = 1; frame <= 12; ++frame) {
    double pos[3], flip[4], turn[4];
    CAPI_CONTEXT("frame %d", frame);
    CHECK_OK(embra_world_step(w));
    CHECK_OK(embra_collider_get_transform(w, ids[0], pos, flip));
    CHECK_OK(embra_collider_get_transform(w, ids[1], pos, turn));
    /* The flip keeps its one rotation (about y by 2 acos 0.6) at every frame. */
    CHECK_NEAR(angle_of(flip), 2.0 * acos(0.6), 1e-12);
    CHECK_NEAR(fabs(flip[2]) / sin(acos(0.6)), 1.0, 1e-12);
    if (frame == 5) {
      /* Halfway between 30 and 120 degrees about +z: 75 degrees (the long way would pass -105). */
      CHECK_NEAR(angle_of(turn), 75.0 * pi / 180.0, 1e-12);
      CHECK(turn[0] * turn[3] > 0.0); /* the axis is +z (w and z of one sign) */
    }
    if (frame >= 10) CHECK_NEAR(angle_of(turn), 2.0 * a120, 1e-12);
  }
  embra_world_destroy(w);
}

int main(int argc, char** argv) {
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) return 1;
  if (argc != 2) {
    fprintf(stderr, "usage: test_scene_hostile WORK_DIR\n");
    return 2;
  }
  prepare(argv[1]);
  RUN(paths_inside_load);
  RUN(paths_outside_are_refused);
  RUN(special_files_are_refused);
  RUN(messages_never_show_the_file);
  RUN(panel_obj_paths_are_confined);
  RUN(other_entry_points_confine);
  RUN(scene_files_must_be_regular);
  RUN(collider_pose_takes_the_short_way);
  return capi_test_finish();
}
