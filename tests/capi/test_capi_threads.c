/* Threading, as embra.h states it: the last-error message is per thread, and different worlds
 * may be used from different threads at once (each giving what it gives on one thread). */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
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

int main(void) {
  RUN(test_last_error_is_per_thread);
  RUN(test_worlds_in_parallel);
  return capi_test_finish();
}
