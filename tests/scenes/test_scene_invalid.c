/* Every invalid scene of the corpus is refused through the C ABI, cleanly.
 *
 * Reads the manifest (tests/scenes/invalid/README.md: one table row per file with its class, JSON
 * pointer and message fragment). For each file, both embra_world_load_json (with the file's folder
 * as base_dir) and embra_world_load_file must return EMBRA_ERROR_SCHEMA, set *out_world to NULL
 * (it is set to a non-NULL sentinel first), and leave a message that starts with the function's
 * name and the row's pointer, contains the row's fragment and is valid UTF-8.
 *
 * Also: a valid scene cut short by `length`, with a NUL inside, of length 0, or after a 64-level
 * nesting limit's edge is refused the same way; a valid scene still loads after all of that.
 *
 * Usage: test_scene_invalid MANIFEST INVALID_DIR GENERATED_DIR
 *   Rows of the manifest's table after the line "Generated at test time" are files in GENERATED_DIR
 *   (written at test time); the others are in INVALID_DIR. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"
#include "scene_test_util.h"

static const char* g_manifest;
static const char* g_dir;
static const char* g_generated;

/* Copies the text between the next pair of backticks after *p into out; advances *p past it. */
static int next_quoted(const char** p, char* out, size_t capacity) {
  const char* a = strchr(*p, '`');
  const char* b;
  if (a == NULL) return 0;
  b = strchr(a + 1, '`');
  if (b == NULL || (size_t)(b - a - 1) >= capacity) return 0;
  memcpy(out, a + 1, (size_t)(b - a - 1));
  out[b - a - 1] = '\0';
  *p = b + 1;
  return 1;
}

/* The class column: the text between the second and third '|' of the row, trimmed. */
static int class_of(const char* row, char* out, size_t capacity) {
  const char* a = strchr(row, '|');
  const char *b, *c;
  size_t n;
  if (a == NULL || (b = strchr(a + 1, '|')) == NULL || (c = strchr(b + 1, '|')) == NULL) return 0;
  ++b;
  while (b < c && *b == ' ') ++b;
  while (c > b && c[-1] == ' ') --c;
  n = (size_t)(c - b);
  if (n >= capacity) return 0;
  memcpy(out, b, n);
  out[n] = '\0';
  return 1;
}

/* One load through both entry points, checked. */
static void check_refused(const char* path, const char* dir, const char* pointer, const char* fragment) {
  static int sentinel;
  int64_t length = 0;
  char* text = scene_read_file(path, &length);
  char expected[1200];
  embra_world* w;
  if (!CHECK(text != NULL)) return;

  w = (embra_world*)(void*)&sentinel;
  CHECK_STATUS(embra_world_load_json(&w, text, length, dir), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  snprintf(expected, sizeof expected, "embra_world_load_json: %s: ", pointer);
  CHECK_MSG(strncmp(embra_last_error_message(), expected, strlen(expected)) == 0,
            "message \"%s\" does not start \"%s\"", embra_last_error_message(), expected);
  CHECK_CONTAINS(embra_last_error_message(), fragment);
  CHECK(scene_valid_utf8(embra_last_error_message()));
  embra_world_destroy(w);

  w = (embra_world*)(void*)&sentinel;
  CHECK_STATUS(embra_world_load_file(&w, path), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  snprintf(expected, sizeof expected, "embra_world_load_file: %s: ", pointer);
  CHECK_MSG(strncmp(embra_last_error_message(), expected, strlen(expected)) == 0,
            "message \"%s\" does not start \"%s\"", embra_last_error_message(), expected);
  CHECK_CONTAINS(embra_last_error_message(), fragment);
  CHECK(scene_valid_utf8(embra_last_error_message()));
  embra_world_destroy(w);
  free(text);
}

static void corpus_is_refused(void) {
  int64_t length = 0;
  char* manifest = scene_read_file(g_manifest, &length);
  char *line, *save = NULL;
  int rows = 0, committed = 0, generated = 0, in_generated = 0;
  CAPI_CONTEXT("%s", g_manifest);
  if (!CHECK(manifest != NULL)) return;
  for (line = strtok_r(manifest, "\n", &save); line != NULL; line = strtok_r(NULL, "\n", &save)) {
    const char* p = line;
    char file[256], cls[32], pointer[256], fragment[512], path[4096];
    FILE* probe;
    const char* dir;
    if (strncmp(line, "Generated at test time", 22) == 0) in_generated = 1;
    if (strncmp(line, "| `", 3) != 0) continue;
    CAPI_CONTEXT("manifest row %.200s", line);
    if (!CHECK(next_quoted(&p, file, sizeof file) && class_of(line, cls, sizeof cls) &&
               next_quoted(&p, pointer, sizeof pointer) && next_quoted(&p, fragment, sizeof fragment)))
      continue;
    CAPI_CONTEXT("%.120s (%.16s)", file, cls);
    CHECK(strcmp(cls, "syntax") == 0 || strcmp(cls, "schema") == 0 || strcmp(cls, "semantic") == 0 ||
          strcmp(cls, "depth") == 0);
    dir = in_generated ? g_generated : g_dir;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    probe = fopen(path, "rb");
    CAPI_CONTEXT("%.60s: not in %.160s", file, dir);
    if (!CHECK(probe != NULL)) continue;
    if (in_generated)
      ++generated;
    else
      ++committed;
    CAPI_CONTEXT("%.120s (%.16s)", file, cls);
    fclose(probe);
    check_refused(path, dir, pointer, fragment);
    ++rows;
  }
  CAPI_CONTEXT("manifest");
  CHECK_MSG(committed >= 40, "only %d committed corpus files", committed);
  CHECK(generated >= 1);
  printf("%d corpus files refused (%d committed, %d generated)\n", rows, committed, generated);
  free(manifest);
}

static const char kValid[] =
    "{\"format\": \"embra-scene\", \"version\": 1, \"bodies\": [{\"name\": \"rod\", \"mesh\": "
    "{\"vertices\": [[0, 0, 0], [1, 0, 0]], \"edges\": [[0, 1]]}}]}";

/* A scene with `depth` arrays nested in the free-form tolerances object, a number in the last. */
static char* nested(int depth) {
  const char* head = "{\"format\": \"embra-scene\", \"version\": 1, \"tolerances\": {\"x\": ";
  const size_t n = strlen(head) + 2 * (size_t)depth + 4;
  char* text = (char*)malloc(n);
  int i;
  if (text == NULL) return NULL;
  strcpy(text, head);
  for (i = 0; i < depth; ++i) strcat(text, "[");
  strcat(text, "1"); /* a value at the deepest level */
  for (i = 0; i < depth; ++i) strcat(text, "]");
  strcat(text, "}}");
  return text;
}

static void buffers_are_refused(void) {
  static int sentinel;
  embra_world* w;
  char with_nul[sizeof kValid];
  char* deep;
  const int64_t n = (int64_t)strlen(kValid);
  int64_t cut;

  /* Every proper prefix of a valid scene is refused (none is a whole JSON document). */
  for (cut = 0; cut < n; ++cut) {
    CAPI_CONTEXT("the first %lld bytes", (long long)cut);
    w = (embra_world*)(void*)&sentinel;
    CHECK_STATUS(embra_world_load_json(&w, kValid, cut, NULL), EMBRA_ERROR_SCHEMA);
    CHECK(w == NULL);
    CHECK_CONTAINS(embra_last_error_message(), "embra_world_load_json: /");
  }
  CAPI_CONTEXT("a NUL inside");
  memcpy(with_nul, kValid, sizeof kValid);
  with_nul[40] = '\0';
  w = (embra_world*)(void*)&sentinel;
  CHECK_STATUS(embra_world_load_json(&w, with_nul, n, NULL), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "not valid JSON");

  /* Nesting: the document itself is 2 levels, then the tolerances' arrays. 62 arrays make 64
   * levels: parsed, then refused by the tolerances schema (not by the depth limit); 63 make 65,
   * refused while parsing. */
  CAPI_CONTEXT("64 levels");
  deep = nested(62);
  w = (embra_world*)(void*)&sentinel;
  CHECK_STATUS(embra_world_load_json(&w, deep, (int64_t)strlen(deep), NULL), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "tolerances schema");
  CHECK(strstr(embra_last_error_message(), "nests deeper") == NULL);
  free(deep);
  CAPI_CONTEXT("65 levels");
  deep = nested(63);
  w = (embra_world*)(void*)&sentinel;
  CHECK_STATUS(embra_world_load_json(&w, deep, (int64_t)strlen(deep), NULL), EMBRA_ERROR_SCHEMA);
  CHECK(w == NULL);
  CHECK_CONTAINS(embra_last_error_message(), "deeper than 64 levels");
  free(deep);

  CAPI_CONTEXT("the whole valid scene, after all the refusals");
  w = NULL;
  CHECK_OK(embra_world_load_json(&w, kValid, n, NULL));
  CHECK(w != NULL);
  embra_world_destroy(w);
}

int main(int argc, char** argv) {
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) return 1;
  if (argc != 4) {
    fprintf(stderr, "usage: test_scene_invalid MANIFEST INVALID_DIR GENERATED_DIR\n");
    return 2;
  }
  g_manifest = argv[1];
  g_dir = argv[2];
  g_generated = argv[3];
  RUN(corpus_is_refused);
  RUN(buffers_are_refused);
  return capi_test_finish();
}
