/* Error paths of the C ABI's scene functions: embra_world_load_json, embra_world_load_file,
 * embra_world_save_json, embra_world_save_file, embra_world_get_scene_frames and
 * embra_body_get_triangles. Each refusal returns the documented status, names the function in
 * embra_last_error_message(), writes nothing it should not (out buffers keep their bytes, no file
 * or temporary file is left) and leaves *out_world NULL where there is one.
 *
 * Usage: test_scene_capi_errors WORK_DIR SCENE.json
 *   WORK_DIR is created (its parent must exist); SCENE.json is a valid scene with bodies. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "capi_test.h"
#include "scene_test_util.h"

static const char* g_work;
static const char* g_scene;
static int g_sentinel;
#define SENTINEL ((embra_world*)(void*)&g_sentinel)

static const char kScene[] =
    "{\"format\": \"embra-scene\", \"version\": 1, \"frames\": 42, \"bodies\": ["
    "{\"name\": \"cloth\", \"mesh\": {\"vertices\": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], "
    "\"triangles\": [[0, 1, 2], [1, 3, 2]]}},"
    "{\"name\": \"block\", \"mesh\": {\"vertices\": [[0, 0, 1], [1, 0, 1], [0, 1, 1], [0, 0, 2]], "
    "\"tets\": [[0, 1, 2, 3]]}},"
    "{\"name\": \"tent\", \"mesh\": {\"generator\": \"triangle\", \"side\": 1, \"rows\": 2, \"origin\": [0, 0, 3]}}]}";

static int exists(const char* path) {
  struct stat st;
  return stat(path, &st) == 0;
}

static embra_world* scene_world(void) {
  embra_world* w = NULL;
  CHECK_OK(embra_world_load_json(&w, kScene, (int64_t)strlen(kScene), NULL));
  return w;
}

static void load_json_errors(void) {
  embra_world* w;
  const int64_t n = (int64_t)strlen(kScene);

  CAPI_CONTEXT("out_world NULL");
  CHECK_STATUS(embra_world_load_json(NULL, kScene, n, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_load_json");
  CHECK_CONTAINS(embra_last_error_message(), "out_world");

  CAPI_CONTEXT("json NULL");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_json(&w, NULL, n, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "json");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_json(&w, NULL, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);

  CAPI_CONTEXT("negative length");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_json(&w, kScene, -1, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "length");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_json(&w, kScene, INT64_MIN, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);

  CAPI_CONTEXT("length 0");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_json(&w, kScene, 0, NULL), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "not valid JSON");

  CAPI_CONTEXT("base_dir NULL and a valid scene");
  w = NULL;
  CHECK_OK(embra_world_load_json(&w, kScene, n, NULL));
  CHECK(w != NULL);
  embra_world_destroy(w);

  CAPI_CONTEXT("a relative OBJ with a base_dir that does not hold it");
  {
    static const char obj_scene[] =
        "{\"format\": \"embra-scene\", \"version\": 1, \"bodies\": [{\"name\": \"scan\", \"mesh\": {\"obj\": "
        "\"quad.obj\"}}]}";
    char dir[4096];
    scene_folder_of(g_scene, dir, sizeof dir);
    w = SENTINEL;
    CHECK_STATUS(embra_world_load_json(&w, obj_scene, (int64_t)strlen(obj_scene), "/nonexistent-embra-dir"),
                 EMBRA_ERROR_SCHEMA);
    CHECK(w == NULL);
    CHECK_CONTAINS(embra_last_error_message(), "/bodies/0/mesh/obj");
    CHECK_CONTAINS(embra_last_error_message(), "/nonexistent-embra-dir/quad.obj");
    /* The same text with the folder that holds quad.obj loads. */
    w = NULL;
    CHECK_OK(embra_world_load_json(&w, obj_scene, (int64_t)strlen(obj_scene), dir));
    embra_world_destroy(w);
  }
}

static void load_file_errors(void) {
  embra_world* w;
  char path[4200];

  CAPI_CONTEXT("out_world NULL");
  CHECK_STATUS(embra_world_load_file(NULL, g_scene), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_load_file");

  CAPI_CONTEXT("path NULL");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_file(&w, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "path");

  CAPI_CONTEXT("a missing path");
  snprintf(path, sizeof path, "%s/no-such-scene.json", g_work);
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_file(&w, path), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_load_file");
  CHECK_CONTAINS(embra_last_error_message(), "no-such-scene.json");
  CHECK_CONTAINS(embra_last_error_message(), "No such file");

  CAPI_CONTEXT("a missing folder");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_file(&w, "/nonexistent-embra-dir/scene.json"), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);

  CAPI_CONTEXT("a folder");
  w = SENTINEL;
  CHECK_STATUS(embra_world_load_file(&w, g_work), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), g_work);

  CAPI_CONTEXT("an empty path");
  w = SENTINEL;
  CHECK(embra_world_load_file(&w, "") != EMBRA_OK);
  CHECK(w == NULL);

  CAPI_CONTEXT("the valid scene");
  w = NULL;
  CHECK_OK(embra_world_load_file(&w, g_scene));
  CHECK(w != NULL);
  embra_world_destroy(w);
}

static void save_json_errors(void) {
  embra_world* w = scene_world();
  int64_t needed = -1, got = -1;
  char* text;
  char* buffer;
  size_t i;
  int untouched;
  if (w == NULL) return;

  CAPI_CONTEXT("world NULL");
  got = -7;
  CHECK_STATUS(embra_world_save_json(NULL, NULL, 0, &got), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_INT(got, -7);
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_save_json");

  CAPI_CONTEXT("out_length NULL");
  CHECK_STATUS(embra_world_save_json(w, NULL, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "out_length");

  CAPI_CONTEXT("the size query");
  CHECK_OK(embra_world_save_json(w, NULL, 0, &needed));
  CHECK(needed > 100);
  text = scene_save(w, NULL);
  if (!CHECK(text != NULL)) {
    embra_world_destroy(w);
    return;
  }
  CHECK_INT((int64_t)strlen(text) + 1, needed);

  buffer = (char*)malloc((size_t)needed + 64);
  if (buffer == NULL) return;

  CAPI_CONTEXT("out NULL with a capacity");
  got = -7;
  CHECK_STATUS(embra_world_save_json(w, NULL, needed, &got), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "out");

  /* Too small, by one byte and entirely: nothing written, the needed length reported. */
  {
    const int64_t capacities[4] = {needed - 1, 1, 0, -5};
    int k;
    for (k = 0; k < 4; ++k) {
      CAPI_CONTEXT("capacity %lld of %lld", (long long)capacities[k], (long long)needed);
      memset(buffer, 0xAB, (size_t)needed + 64);
      got = -7;
      if (capacities[k] >= 0) {
        CHECK_STATUS(embra_world_save_json(w, buffer, capacities[k], &got), EMBRA_ERROR_BUFFER_TOO_SMALL);
        CHECK_INT(got, needed);
        CHECK_CONTAINS(embra_last_error_message(), "embra_world_save_json");
      } else {
        CHECK(embra_world_save_json(w, buffer, capacities[k], &got) != EMBRA_OK);
      }
      untouched = 1;
      for (i = 0; i < (size_t)needed + 64; ++i) untouched &= (unsigned char)buffer[i] == 0xAB;
      CHECK_MSG(untouched, "a refused save_json wrote into the buffer");
    }
  }

  CAPI_CONTEXT("exactly the needed capacity");
  memset(buffer, 0xAB, (size_t)needed + 64);
  got = -7;
  CHECK_OK(embra_world_save_json(w, buffer, needed, &got));
  CHECK_INT(got, needed);
  CHECK(buffer[needed - 1] == '\0' && strcmp(buffer, text) == 0);
  CHECK((unsigned char)buffer[needed] == 0xAB);

  CAPI_CONTEXT("a larger capacity");
  memset(buffer, 0xAB, (size_t)needed + 64);
  CHECK_OK(embra_world_save_json(w, buffer, needed + 64, &got));
  CHECK_INT(got, needed);
  CHECK(strcmp(buffer, text) == 0);
  untouched = 1;
  for (i = (size_t)needed; i < (size_t)needed + 64; ++i) untouched &= (unsigned char)buffer[i] == 0xAB;
  CHECK_MSG(untouched, "save_json wrote past the NUL");

  free(buffer);
  free(text);
  embra_world_destroy(w);
}

/* 1 when the file holds exactly `text`. */
static int file_holds(const char* path, const char* text) {
  int64_t n = 0;
  char* got = scene_read_file(path, &n);
  const int same = got != NULL && n == (int64_t)strlen(text) && memcmp(got, text, (size_t)n) == 0;
  free(got);
  return same;
}

static void save_file_errors(void) {
  embra_world* w = scene_world();
  char path[4200], tmp[4300], blocked[4200];
  char* text;
  FILE* f;
  if (w == NULL) return;
  text = scene_save(w, NULL);
  if (!CHECK(text != NULL)) return;

  CAPI_CONTEXT("world NULL");
  snprintf(path, sizeof path, "%s/never.json", g_work);
  CHECK_STATUS(embra_world_save_file(NULL, path), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(!exists(path));
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_save_file");

  CAPI_CONTEXT("path NULL");
  CHECK_STATUS(embra_world_save_file(w, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "path");

  CAPI_CONTEXT("a missing folder");
  snprintf(path, sizeof path, "%s/no-such-folder/scene.json", g_work);
  CHECK_STATUS(embra_world_save_file(w, path), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(!exists(path));
  CHECK_CONTAINS(embra_last_error_message(), "no-such-folder");

  CAPI_CONTEXT("a folder of /proc");
  CHECK_STATUS(embra_world_save_file(w, "/proc/embra-cannot-write.json"), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(!exists("/proc/embra-cannot-write.json") && !exists("/proc/embra-cannot-write.json.tmp"));

  CAPI_CONTEXT("the path is a folder");
  snprintf(path, sizeof path, "%s/a-folder.json", g_work);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  CHECK(mkdir(path, 0755) == 0 || errno == EEXIST);
  CHECK_STATUS(embra_world_save_file(w, path), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(!exists(tmp));
  {
    struct stat st;
    CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));
  }

  CAPI_CONTEXT("the temporary file cannot be made");
  snprintf(path, sizeof path, "%s/blocked.json", g_work);
  snprintf(blocked, sizeof blocked, "%s/blocked.json.tmp", g_work);
  CHECK(mkdir(blocked, 0755) == 0 || errno == EEXIST);
  CHECK_STATUS(embra_world_save_file(w, path), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(!exists(path));

  /* A write that fails part-way (the file size limit, as on a full disk): no partial file, and an
   * existing file keeps its old content. */
  CAPI_CONTEXT("a write that fails part-way");
  snprintf(path, sizeof path, "%s/limited.json", g_work);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  f = fopen(path, "wb");
  if (CHECK(f != NULL)) {
    fputs("old content\n", f);
    fclose(f);
  }
  {
    struct rlimit old_limit, small;
    void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
    if (CHECK(getrlimit(RLIMIT_FSIZE, &old_limit) == 0)) {
      small = old_limit;
      small.rlim_cur = 100; /* bytes: the scene is larger */
      if (CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0)) {
        CHECK_STATUS(embra_world_save_file(w, path), EMBRA_ERROR_INVALID_ARGUMENT);
        CHECK(setrlimit(RLIMIT_FSIZE, &old_limit) == 0);
        CHECK(!exists(tmp));
        CHECK(file_holds(path, "old content\n"));
      }
    }
    signal(SIGXFSZ, old_handler);
  }

  CAPI_CONTEXT("a successful save replaces the file whole");
  CHECK_OK(embra_world_save_file(w, path));
  CHECK(file_holds(path, text));
  CHECK(!exists(tmp));

  free(text);
  embra_world_destroy(w);
}

static void scene_frames(void) {
  embra_world* w = scene_world();
  embra_world* api = NULL;
  int64_t frames = -1;
  if (w == NULL) return;
  CAPI_CONTEXT("NULL arguments");
  CHECK_STATUS(embra_world_get_scene_frames(NULL, &frames), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_get_scene_frames(w, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "embra_world_get_scene_frames");
  CHECK_INT(frames, -1);
  CAPI_CONTEXT("values");
  CHECK_OK(embra_world_get_scene_frames(w, &frames));
  CHECK_INT(frames, 42);
  CHECK_OK(embra_world_create(&api, NULL));
  CHECK_OK(embra_world_get_scene_frames(api, &frames));
  CHECK_INT(frames, 600);
  embra_world_destroy(api);
  embra_world_destroy(w);
}

static void get_triangles_errors(void) {
  embra_world* w = scene_world();
  const embra_body_id cloth = {0, 1}, block = {1, 1}, tent = {2, 1};
  const embra_body_id stale = {0, 2}, never = {7, 1};
  int64_t count = -1;
  int32_t buffer[64];
  size_t i;
  int untouched;
  if (w == NULL) return;

  CAPI_CONTEXT("NULL arguments");
  CHECK_STATUS(embra_body_get_triangles(NULL, cloth, NULL, 0, &count), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_INT(count, -1);
  CHECK_STATUS(embra_body_get_triangles(w, cloth, NULL, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_CONTAINS(embra_last_error_message(), "embra_body_get_triangles");
  CHECK_STATUS(embra_body_get_triangles(w, cloth, NULL, 6, &count), EMBRA_ERROR_INVALID_ARGUMENT);

  CAPI_CONTEXT("the count query");
  CHECK_OK(embra_body_get_triangles(w, cloth, NULL, 0, &count));
  CHECK_INT(count, 6);
  CHECK_OK(embra_body_get_triangles(w, block, NULL, 0, &count));
  CHECK_INT(count, 0);
  CHECK_OK(embra_body_get_triangles(w, tent, NULL, 0, &count));
  CHECK_INT(count, 3 * 4);

  CAPI_CONTEXT("too small a buffer");
  memset(buffer, 0x5A, sizeof buffer);
  CHECK_STATUS(embra_body_get_triangles(w, tent, buffer, 11, &count), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_STATUS(embra_body_get_triangles(w, tent, buffer, 0, &count), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_STATUS(embra_body_get_triangles(w, tent, buffer, -3, &count), EMBRA_ERROR_BUFFER_TOO_SMALL);
  untouched = 1;
  for (i = 0; i < sizeof buffer; ++i) untouched &= ((unsigned char*)buffer)[i] == 0x5A;
  CHECK_MSG(untouched, "a refused get_triangles wrote into the buffer");

  CAPI_CONTEXT("ids that are not bodies");
  CHECK(embra_body_get_triangles(w, stale, NULL, 0, &count) != EMBRA_OK);
  CHECK(embra_body_get_triangles(w, never, NULL, 0, &count) != EMBRA_OK);

  CAPI_CONTEXT("exact and larger buffers");
  count = -1;
  CHECK_OK(embra_body_get_triangles(w, cloth, buffer, 6, &count));
  CHECK_INT(count, 6);
  CHECK(buffer[0] == 0 && buffer[1] == 1 && buffer[2] == 2 && buffer[3] == 1 && buffer[4] == 3 && buffer[5] == 2);
  memset(buffer, 0x5A, sizeof buffer);
  CHECK_OK(embra_body_get_triangles(w, tent, buffer, 64, &count));
  CHECK_INT(count, 12);
  for (i = 0; i < 12; ++i) CHECK(buffer[i] >= 8 && buffer[i] < 14); /* the tent's particles, world indices */
  CHECK(((unsigned char*)buffer)[12 * sizeof(int32_t)] == 0x5A);
  CHECK_OK(embra_body_get_triangles(w, block, buffer, 0, &count));
  CHECK_INT(count, 0);
  embra_world_destroy(w);
}

int main(int argc, char** argv) {
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) return 1;
  if (argc != 3) {
    fprintf(stderr, "usage: test_scene_capi_errors WORK_DIR SCENE.json\n");
    return 2;
  }
  g_work = argv[1];
  g_scene = argv[2];
  if (mkdir(g_work, 0755) != 0 && errno != EEXIST) {
    fprintf(stderr, "cannot create %s\n", g_work);
    return 2;
  }
  RUN(load_json_errors);
  RUN(load_file_errors);
  RUN(save_json_errors);
  RUN(save_file_errors);
  RUN(scene_frames);
  RUN(get_triangles_errors);
  return capi_test_finish();
}
