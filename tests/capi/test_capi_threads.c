/* Threading, as embra.h states it: the last-error message is per thread, and different worlds
 * may be used from different threads at once (each giving what it gives on one thread). */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdlib.h>

#include "capi_test.h"

/* --- the last-error message is per thread ---------------------------------------------------
 *
 *   B: fail with "ABI 111"  -> signal, wait
 *   A:                                 fail with "ABI 222", check its own message, done
 *   B:                                                                      still "ABI 111"
 */

typedef struct {
  pthread_mutex_t lock;
  pthread_cond_t changed;
  int stage; /* 0 start, 1 B has failed, 2 A has failed */
  /* results, read by the main thread after joining (checks are counted on the main thread) */
  int a_fresh_empty, a_status, a_has_own, a_has_other;
  int b_fresh_empty, b_status, b_kept_own, b_has_other, b_same_after_success;
} handoff;

static void wait_stage(handoff* h, int stage) {
  pthread_mutex_lock(&h->lock);
  while (h->stage < stage) pthread_cond_wait(&h->changed, &h->lock);
  pthread_mutex_unlock(&h->lock);
}

static void set_stage(handoff* h, int stage) {
  pthread_mutex_lock(&h->lock);
  h->stage = stage;
  pthread_cond_broadcast(&h->changed);
  pthread_mutex_unlock(&h->lock);
}

static void* thread_a(void* arg) {
  handoff* h = (handoff*)arg;
  const char* m;
  wait_stage(h, 1);
  m = embra_last_error_message();
  h->a_fresh_empty = m != NULL && m[0] == '\0'; /* B's failure is not A's */
  h->a_status = embra_check_abi(222);
  m = embra_last_error_message();
  h->a_has_own = capi_test_contains(m, "222");
  h->a_has_other = capi_test_contains(m, "111");
  set_stage(h, 2);
  return NULL;
}

static void* thread_b(void* arg) {
  handoff* h = (handoff*)arg;
  const char* m = embra_last_error_message();
  h->b_fresh_empty = m != NULL && m[0] == '\0';
  h->b_status = embra_check_abi(111);
  set_stage(h, 1);
  wait_stage(h, 2);
  m = embra_last_error_message();
  h->b_kept_own = capi_test_contains(m, "111");
  h->b_has_other = capi_test_contains(m, "222");
  embra_check_abi(EMBRA_ABI_VERSION); /* a success on B changes nothing either */
  h->b_same_after_success = capi_test_contains(embra_last_error_message(), "111");
  return NULL;
}

static void test_last_error_is_per_thread(void) {
  handoff h;
  pthread_t a, b;
  memset(&h, 0, sizeof h);
  pthread_mutex_init(&h.lock, NULL);
  pthread_cond_init(&h.changed, NULL);

  /* The main thread's own message, to see that neither thread touches it. */
  CHECK_STATUS(embra_check_abi(333), EMBRA_ERROR_VERSION);

  CHECK_INT(pthread_create(&b, NULL, thread_b, &h), 0);
  CHECK_INT(pthread_create(&a, NULL, thread_a, &h), 0);
  CHECK_INT(pthread_join(a, NULL), 0);
  CHECK_INT(pthread_join(b, NULL), 0);

  CHECK(h.b_fresh_empty);
  CHECK_INT(h.b_status, EMBRA_ERROR_VERSION);
  CHECK(h.a_fresh_empty);
  CHECK_INT(h.a_status, EMBRA_ERROR_VERSION);
  CHECK(h.a_has_own);
  CHECK(!h.a_has_other);
  CHECK(h.b_kept_own);
  CHECK(!h.b_has_other);
  CHECK(h.b_same_after_success);
  CHECK_CONTAINS(embra_last_error_message(), "333");
  CHECK(!capi_test_contains(embra_last_error_message(), "111"));
  CHECK(!capi_test_contains(embra_last_error_message(), "222"));
  pthread_cond_destroy(&h.changed);
  pthread_mutex_destroy(&h.lock);
}

/* --- different worlds on different threads ---------------------------------------------------
 * Each thread builds and steps its own hanging cloth and refuses a few calls along the way; the
 * positions are bit-identical to the same run done alone on the main thread. */

enum { GRID = 6, FRAMES = 120, THREADS = 4 };

typedef struct {
  int seed;
  int ok;
  int messages_ok;
  double x[3 * GRID * GRID];
} cloth_run;

static void* run_cloth(void* arg) {
  cloth_run* r = (cloth_run*)arg;
  double xyz[3 * GRID * GRID];
  int32_t tris[3 * 2 * (GRID - 1) * (GRID - 1)];
  embra_world* w = NULL;
  embra_body_def bd = embra_default_body_def();
  embra_body_id body;
  embra_pin_def pd = embra_default_pin_def();
  embra_pin_id pin;
  embra_pin_id stale = {77, 3};
  int32_t first = 0, t = 0;
  int i, j, frame, ok = 1, messages_ok = 1;
  char tag[32];
  for (i = 0; i < GRID; ++i)
    for (j = 0; j < GRID; ++j) {
      xyz[3 * (i * GRID + j)] = 0.2 * j;
      xyz[3 * (i * GRID + j) + 1] = 0.2 * i;
      xyz[3 * (i * GRID + j) + 2] = 0.1 * r->seed;
    }
  for (i = 0; i + 1 < GRID; ++i)
    for (j = 0; j + 1 < GRID; ++j) {
      const int32_t v = i * GRID + j;
      tris[t++] = v, tris[t++] = v + 1, tris[t++] = v + GRID + 1;
      tris[t++] = v, tris[t++] = v + GRID + 1, tris[t++] = v + GRID;
    }
  ok &= embra_world_create(&w, NULL) == EMBRA_OK;
  bd.vertex_count = GRID * GRID;
  bd.positions = xyz;
  bd.triangle_count = 2 * (GRID - 1) * (GRID - 1);
  bd.triangles = tris;
  bd.material.mass = 0.1 * (r->seed + 1);
  ok &= embra_body_create(w, &bd, &body, &first) == EMBRA_OK;
  pd.particle = first;
  memcpy(pd.target, xyz, sizeof pd.target);
  ok &= embra_pin_create(w, &pd, &pin) == EMBRA_OK;
  for (frame = 0; frame < FRAMES; ++frame) {
    ok &= embra_world_step(w) == EMBRA_OK;
    if (frame % 10 == 0) {
      /* A refusal whose message carries this thread's seed, checked right away. */
      const int32_t bad_abi = 1000 + r->seed;
      snprintf(tag, sizeof tag, "%d", (int)bad_abi);
      ok &= embra_check_abi(bad_abi) == EMBRA_ERROR_VERSION;
      ok &= embra_pin_destroy(w, stale) == EMBRA_ERROR_STALE_ID;
      messages_ok &= capi_test_contains(embra_last_error_message(), "embra_pin_destroy");
      ok &= embra_check_abi(bad_abi) == EMBRA_ERROR_VERSION;
      messages_ok &= capi_test_contains(embra_last_error_message(), tag);
    }
  }
  ok &= embra_world_get_positions(w, r->x, 3 * GRID * GRID, first, GRID * GRID) == EMBRA_OK;
  embra_world_destroy(w);
  r->ok = ok;
  r->messages_ok = messages_ok;
  return NULL;
}

static void test_worlds_in_parallel(void) {
  cloth_run alone[THREADS], together[THREADS];
  pthread_t threads[THREADS];
  int i;
  memset(alone, 0, sizeof alone);
  memset(together, 0, sizeof together);
  for (i = 0; i < THREADS; ++i) {
    alone[i].seed = together[i].seed = i;
    run_cloth(&alone[i]);
  }
  for (i = 0; i < THREADS; ++i) CHECK_INT(pthread_create(&threads[i], NULL, run_cloth, &together[i]), 0);
  for (i = 0; i < THREADS; ++i) CHECK_INT(pthread_join(threads[i], NULL), 0);
  for (i = 0; i < THREADS; ++i) {
    CAPI_CONTEXT("thread %d", i);
    CHECK(alone[i].ok);
    CHECK(together[i].ok);
    CHECK(alone[i].messages_ok);
    CHECK(together[i].messages_ok);
    CHECK(memcmp(alone[i].x, together[i].x, sizeof alone[i].x) == 0);
  }
  /* and the runs differ from each other (the seed matters), so the comparison means something */
  CHECK(memcmp(alone[0].x, alone[1].x, sizeof alone[0].x) != 0);
}

/* --- one world, two threads -------------------------------------------------------------------
 * Two threads step and read the same world as fast as they can: every call returns EMBRA_OK or
 * EMBRA_ERROR_LOCKED (never a crash, never another status), some calls do meet the lock, and the
 * frames that succeeded add up. */

enum { SHARED_CALLS = 400 };

typedef struct {
  embra_world* world;
  int32_t count;
  int ok, locked, other;
  pthread_barrier_t* start;
} shared_run;

static void* hammer(void* arg) {
  shared_run* r = (shared_run*)arg;
  double x[3 * GRID * GRID];
  int k;
  pthread_barrier_wait(r->start);
  for (k = 0; k < SHARED_CALLS; ++k) {
    embra_status st;
    if (k % 2 == 0) {
      st = embra_world_step(r->world);
    } else {
      st = embra_world_get_positions(r->world, x, 3 * GRID * GRID, 0, r->count);
    }
    if (st == EMBRA_OK)
      r->ok += k % 2 == 0;
    else if (st == EMBRA_ERROR_LOCKED)
      ++r->locked;
    else
      ++r->other;
  }
  return NULL;
}

static embra_world* small_cloth_world(int32_t iterations) {
  double xyz[3 * GRID * GRID];
  int32_t tris[3 * 2 * (GRID - 1) * (GRID - 1)];
  embra_world* w = NULL;
  embra_solver_def sd = embra_default_solver_def();
  embra_body_def bd = embra_default_body_def();
  embra_body_id body;
  int i, j, t = 0;
  for (i = 0; i < GRID; ++i)
    for (j = 0; j < GRID; ++j) {
      xyz[3 * (i * GRID + j)] = 0.2 * j;
      xyz[3 * (i * GRID + j) + 1] = 0.2 * i;
      xyz[3 * (i * GRID + j) + 2] = 0.0;
    }
  for (i = 0; i + 1 < GRID; ++i)
    for (j = 0; j + 1 < GRID; ++j) {
      const int32_t v = i * GRID + j;
      tris[t++] = v, tris[t++] = v + 1, tris[t++] = v + GRID + 1;
      tris[t++] = v, tris[t++] = v + GRID + 1, tris[t++] = v + GRID;
    }
  sd.iterations = iterations;
  if (embra_world_create(&w, &sd) != EMBRA_OK) return NULL;
  bd.vertex_count = GRID * GRID;
  bd.positions = xyz;
  bd.triangle_count = 2 * (GRID - 1) * (GRID - 1);
  bd.triangles = tris;
  bd.material.mass = 0.1;
  if (embra_body_create(w, &bd, &body, NULL) != EMBRA_OK) {
    embra_world_destroy(w);
    return NULL;
  }
  return w;
}

static void test_one_world_two_threads(void) {
  embra_world* w = small_cloth_world(20);
  shared_run runs[2];
  pthread_t threads[2];
  pthread_barrier_t start;
  embra_step_report report;
  int i, locked = 0;
  CHECK(w != NULL);
  if (w == NULL) return;
  pthread_barrier_init(&start, NULL, 2);
  memset(runs, 0, sizeof runs);
  for (i = 0; i < 2; ++i) {
    runs[i].world = w;
    runs[i].count = GRID * GRID;
    runs[i].start = &start;
    CHECK_INT(pthread_create(&threads[i], NULL, hammer, &runs[i]), 0);
  }
  for (i = 0; i < 2; ++i) CHECK_INT(pthread_join(threads[i], NULL), 0);
  for (i = 0; i < 2; ++i) {
    CAPI_CONTEXT("thread %d", i);
    CHECK_INT(runs[i].other, 0);
    locked += runs[i].locked;
  }
  CHECK_MSG(locked > 0, "no call met the lock in %d calls on two threads", 4 * SHARED_CALLS);
  CHECK_OK(embra_world_get_report(w, &report));
  CHECK_INT(report.frame, runs[0].ok + runs[1].ok);
  pthread_barrier_destroy(&start);
  embra_world_destroy(w);
}

/* --- cancelling a long step from another thread -----------------------------------------------
 * A step of 16 x 6,000 iterations (about a second) on one thread; the main thread cancels it once it
 * is under way: the step returns EMBRA_ERROR_CANCELLED well before it would have finished, and the
 * world saves to the same bytes as before the step. */

typedef struct {
  embra_world* world;
  embra_status status;
  int finished; /* read and written with __atomic builtins */
} long_step;

static void* step_once(void* arg) {
  long_step* r = (long_step*)arg;
  /* The other thread's get_report may hold the world for a moment as the step starts (the C ABI
   * refuses a second call at once rather than waiting): try again until the step has it. */
  do {
    r->status = embra_world_step(r->world);
  } while (r->status == EMBRA_ERROR_LOCKED);
  __atomic_store_n(&r->finished, 1, __ATOMIC_RELEASE);
  return NULL;
}

static char* saved(const embra_world* w) {
  int64_t n = 0;
  char* text = NULL;
  if (embra_world_save_json(w, NULL, 0, &n) != EMBRA_OK) return NULL;
  text = (char*)malloc((size_t)n);
  if (text != NULL && embra_world_save_json(w, text, n, &n) != EMBRA_OK) {
    free(text);
    text = NULL;
  }
  return text;
}

static void test_cancel_from_another_thread(void) {
  embra_world* w = small_cloth_world(6000);
  long_step r;
  pthread_t thread;
  char* before;
  char* after;
  embra_status st;
  CHECK(w != NULL);
  if (w == NULL) return;
  before = saved(w);
  memset(&r, 0, sizeof r);
  r.world = w;
  CHECK_INT(pthread_create(&thread, NULL, step_once, &r), 0);
  /* Until the step holds the world, a call from here gets EMBRA_OK; then the lock. */
  do {
    embra_step_report report;
    st = embra_world_get_report(w, &report);
    if (st == EMBRA_OK) sched_yield();
  } while (st == EMBRA_OK && !__atomic_load_n(&r.finished, __ATOMIC_ACQUIRE));
  CHECK_INT(st, EMBRA_ERROR_LOCKED);
  CHECK_OK(embra_world_cancel(w));
  CHECK_INT(pthread_join(thread, NULL), 0);
  CHECK_INT(r.status, EMBRA_ERROR_CANCELLED);
  after = saved(w);
  CHECK(before != NULL && after != NULL && strcmp(before, after) == 0);
  free(before);
  free(after);
  embra_world_destroy(w);
}

int main(void) {
  RUN(test_last_error_is_per_thread);
  RUN(test_worlds_in_parallel);
  RUN(test_one_world_two_threads);
  RUN(test_cancel_from_another_thread);
  return capi_test_finish();
}
