/* capi_test.h - a tiny assertion harness for embra's C-ABI tests (strict C99, no dependencies).
 *
 * Each CHECK counts one check. A failed check prints where it is, what it checked and, for
 * status checks, the status names and embra_last_error_message(). A test program runs its
 * tests with RUN(fn) and ends with `return capi_test_finish();`, which prints the final line
 * "N passed, N failed" and returns non-zero when any check failed.
 *
 * CAPI_CONTEXT(fmt, ...) names the case a loop is on ("positions[4] = nan"), printed with any
 * failure until the next CAPI_CONTEXT or RUN. */
#ifndef EMBRA_TESTS_CAPI_TEST_H
#define EMBRA_TESTS_CAPI_TEST_H

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "embra/embra.h"

static int capi_test_passed = 0;
static int capi_test_failed = 0;
static const char* capi_test_name = "";
static char capi_test_context[256] = "";

/* Records one check; prints the failure. Returns `ok` so callers can stop on a failed check. */
static inline int capi_test_record(int ok, const char* file, int line, const char* what) {
  if (ok) {
    ++capi_test_passed;
  } else {
    ++capi_test_failed;
    fprintf(stderr, "%s:%d: FAILED in %s%s%s: %s\n", file, line, capi_test_name, capi_test_context[0] ? " | " : "",
            capi_test_context, what);
  }
  return ok;
}

/* The world as scene JSON (malloc'd; NULL on failure). */
static inline char* capi_test_save(const embra_world* w) {
  int64_t n = 0;
  char* text;
  if (embra_world_save_json(w, NULL, 0, &n) != EMBRA_OK) return NULL;
  text = (char*)malloc((size_t)n);
  if (text == NULL) return NULL;
  if (embra_world_save_json(w, text, n, &n) != EMBRA_OK) {
    free(text);
    return NULL;
  }
  return text;
}

#define CAPI_CONTEXT(...) snprintf(capi_test_context, sizeof capi_test_context, __VA_ARGS__)

#define CHECK(cond) capi_test_record((cond) ? 1 : 0, __FILE__, __LINE__, #cond)

#define CHECK_MSG(cond, ...)                                            \
  do {                                                                  \
    if (!capi_test_record((cond) ? 1 : 0, __FILE__, __LINE__, #cond)) { \
      fprintf(stderr, "    ");                                          \
      fprintf(stderr, __VA_ARGS__);                                     \
      fprintf(stderr, "\n");                                            \
    }                                                                   \
  } while (0)

#define CHECK_INT(actual, expected)                                                          \
  do {                                                                                       \
    const long long capi_a_ = (long long)(actual), capi_e_ = (long long)(expected);          \
    if (!capi_test_record(capi_a_ == capi_e_, __FILE__, __LINE__, #actual " == " #expected)) \
      fprintf(stderr, "    got %lld, expected %lld\n", capi_a_, capi_e_);                    \
  } while (0)

/* |actual - expected| <= tol. */
#define CHECK_NEAR(actual, expected, tol)                                                                         \
  do {                                                                                                            \
    const double capi_a_ = (actual), capi_e_ = (expected), capi_t_ = (tol);                                       \
    if (!capi_test_record(fabs(capi_a_ - capi_e_) <= capi_t_, __FILE__, __LINE__, #actual " ~= " #expected))      \
      fprintf(stderr, "    got %.17g, expected %.17g (tolerance %.3g, off by %.3g)\n", capi_a_, capi_e_, capi_t_, \
              capi_a_ - capi_e_);                                                                                 \
  } while (0)

/* Bit-identical doubles (the same value, not merely close). */
#define CHECK_SAME_DOUBLE(actual, expected)                                                    \
  do {                                                                                         \
    const double capi_a_ = (actual), capi_e_ = (expected);                                     \
    if (!capi_test_record(memcmp(&capi_a_, &capi_e_, sizeof capi_a_) == 0, __FILE__, __LINE__, \
                          #actual " is bit-identical to " #expected))                          \
      fprintf(stderr, "    got %.17g, expected %.17g\n", capi_a_, capi_e_);                    \
  } while (0)

#define CHECK_STR(actual, expected)                                                                \
  do {                                                                                             \
    const char* capi_a_ = (actual);                                                                \
    const char* capi_e_ = (expected);                                                              \
    if (!capi_test_record(capi_a_ != NULL && strcmp(capi_a_, capi_e_) == 0, __FILE__, __LINE__,    \
                          #actual " equals \"" #expected "\""))                                    \
      fprintf(stderr, "    got \"%s\", expected \"%s\"\n", capi_a_ ? capi_a_ : "(NULL)", capi_e_); \
  } while (0)

/* An embra call returns the expected status. */
#define CHECK_STATUS(call, expected)                                                            \
  do {                                                                                          \
    const embra_status capi_s_ = (call);                                                        \
    const embra_status capi_x_ = (expected);                                                    \
    if (!capi_test_record(capi_s_ == capi_x_, __FILE__, __LINE__, #call " returns " #expected)) \
      fprintf(stderr, "    got %s (%d): \"%s\"\n", embra_status_name(capi_s_), (int)capi_s_,    \
              embra_last_error_message());                                                      \
  } while (0)

#define CHECK_OK(call) CHECK_STATUS(call, EMBRA_OK)

/* Case-insensitive strstr. */
static inline int capi_test_contains(const char* haystack, const char* needle) {
  size_t n = strlen(needle), i, k;
  if (haystack == NULL) return 0;
  for (i = 0; haystack[i] != '\0'; ++i) {
    for (k = 0; k < n && haystack[i + k] != '\0'; ++k)
      if (tolower((unsigned char)haystack[i + k]) != tolower((unsigned char)needle[k])) break;
    if (k == n) return 1;
  }
  return n == 0;
}

#define CHECK_CONTAINS(text, needle)                                                                              \
  do {                                                                                                            \
    const char* capi_t_ = (text);                                                                                 \
    if (!capi_test_record(capi_test_contains(capi_t_, (needle)), __FILE__, __LINE__, #text " mentions " #needle)) \
      fprintf(stderr, "    text is \"%s\"\n", capi_t_ ? capi_t_ : "(NULL)");                                      \
  } while (0)

#define RUN(fn)                  \
  do {                           \
    capi_test_name = #fn;        \
    capi_test_context[0] = '\0'; \
    fn();                        \
  } while (0)

static inline int capi_test_finish(void) {
  printf("%d passed, %d failed\n", capi_test_passed, capi_test_failed);
  fflush(stdout);
  return capi_test_failed == 0 ? 0 : 1;
}

#endif /* EMBRA_TESTS_CAPI_TEST_H */
