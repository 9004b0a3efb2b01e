/* Scenes loaded on several threads at once give what they give on one.
 *
 * Each thread loads the same scenes (valid ones, and invalid ones refused by the schema's name
 * pattern, its length limit and its number ranges) several times, into worlds of its own, before
 * this process has loaded any scene: so the schema is compiled while the threads race for it. Every
 * load's status, message and saved scene must equal those of the same load done afterwards on one
 * thread. (Loading once checked names with std::regex, whose construction raced inside
 * libstdc++'s locale caches; run under ThreadSanitizer by the "threads" label.)
 *
 * Usage: test_scene_threads SCENE.json...   (valid scenes; OBJ paths relative to their folders) */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"
#include "scene_test_util.h"

enum { kThreads = 4, kRounds = 3, kMaxScenes = 16 };

typedef struct scene {
  char* text;
  int64_t length;
  char dir[4096];
  embra_status expected;
} scene;

typedef struct outcome {
  embra_status status;
  char* message; /* the error message, or the saved scene */
} outcome;

static scene g_scenes[kMaxScenes];
static int g_count;
static outcome g_threaded[kThreads][kRounds][kMaxScenes];
static pthread_barrier_t g_start;

static char* copy(const char* s) {
  char* out = (char*)malloc(strlen(s) + 1);
  if (out) strcpy(out, s);
  return out;
}

static outcome load_one(const scene* s) {
  outcome o;
  embra_world* w = NULL;
  o.status = embra_world_load_json(&w, s->text, s->length, s->dir);
  if (o.status == EMBRA_OK) {
    o.message = scene_save(w, NULL);
    embra_world_destroy(w);
  } else {
    o.message = copy(embra_last_error_message());
  }
  return o;
}

static void* worker(void* arg) {
  const int t = (int)(intptr_t)arg;
  int r, i;
  pthread_barrier_wait(&g_start);
  for (r = 0; r < kRounds; ++r)
    for (i = 0; i < g_count; ++i) g_threaded[t][r][(i + t) % g_count] = load_one(&g_scenes[(i + t) % g_count]);
  return NULL;
}

/* A scene text made here (base_dir "."), and what loading it returns. */
static void add_text(char* text, embra_status expected) {
  scene* s = &g_scenes[g_count++];
  s->text = text;
  s->length = text ? (int64_t)strlen(text) : 0;
  s->expected = expected;
  snprintf(s->dir, sizeof s->dir, ".");
}

/* A scene whose group is named `name`, repeated `n` times (with `tail` after). */
static char* named(char c, int n, const char* tail) {
  const char* head = "{\"format\": \"embra-scene\", \"version\": 1, \"groups\": [{\"name\": \"";
  const char* end = "\"}]}";
  const size_t size = strlen(head) + (size_t)n + strlen(tail) + strlen(end) + 1;
  char* text = (char*)malloc(size);
  if (text == NULL) return NULL;
  strcpy(text, head);
  memset(text + strlen(head), c, (size_t)n);
  strcpy(text + strlen(head) + n, tail);
  strcat(text, end);
  return text;
}

int main(int argc, char** argv) {
  pthread_t threads[kThreads];
  int t, r, i;
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) return 1;
  if (argc < 2 || argc - 1 > kMaxScenes - 5) {
    fprintf(stderr, "usage: test_scene_threads SCENE.json... (at most %d)\n", kMaxScenes - 5);
    return 2;
  }
  for (i = 1; i < argc; ++i) {
    scene* s = &g_scenes[g_count++];
    s->text = scene_read_file(argv[i], &s->length);
    if (s->text == NULL) {
      fprintf(stderr, "cannot read %s\n", argv[i]);
      return 2;
    }
    scene_folder_of(argv[i], s->dir, sizeof s->dir);
    s->expected = EMBRA_OK;
  }
  add_text(named('a', 40, ""), EMBRA_OK);
  add_text(named('a', 40, " b"), EMBRA_ERROR_SCHEMA);   /* the pattern refuses the space */
  add_text(named('a', 30000, "!"), EMBRA_ERROR_SCHEMA); /* too long, and a character the pattern refuses */
  add_text(named('z', 128, ""), EMBRA_OK);              /* the longest name */
  add_text(copy("{\"format\": \"embra-scene\", \"version\": 1, \"solver\": {\"dt\": 1e-310}}"),
           EMBRA_ERROR_SCHEMA); /* below the smallest positive */
  for (i = 0; i < g_count; ++i)
    if (g_scenes[i].text == NULL) return 2;

  /* Threaded first: nothing has compiled the schema yet. */
  pthread_barrier_init(&g_start, NULL, kThreads);
  for (t = 0; t < kThreads; ++t) CHECK(pthread_create(&threads[t], NULL, worker, (void*)(intptr_t)t) == 0);
  for (t = 0; t < kThreads; ++t) pthread_join(threads[t], NULL);
  pthread_barrier_destroy(&g_start);

  for (i = 0; i < g_count; ++i) {
    const outcome one = load_one(&g_scenes[i]);
    CAPI_CONTEXT("scene %d", i);
    CHECK(one.message != NULL);
    CHECK_STATUS(one.status, g_scenes[i].expected);
    for (t = 0; t < kThreads; ++t)
      for (r = 0; r < kRounds; ++r) {
        const outcome* o = &g_threaded[t][r][i];
        CAPI_CONTEXT("scene %d, thread %d, round %d", i, t, r);
        CHECK_INT(o->status, one.status);
        CHECK_MSG(o->message != NULL && one.message != NULL && strcmp(o->message, one.message) == 0,
                  "differs from the load on one thread: %.200s | %.200s", o->message ? o->message : "(null)",
                  one.message ? one.message : "(null)");
        free(o->message);
      }
    free(one.message);
  }
  for (i = 0; i < g_count; ++i) free(g_scenes[i].text);
  return capi_test_finish();
}
