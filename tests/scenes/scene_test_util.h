/* scene_test_util.h - helpers shared by the JSON scene tests (strict C99 plus POSIX file calls).
 *
 * Include after capi_test.h. Everything here goes through embra.h only. */
#ifndef EMBRA_TESTS_SCENES_SCENE_TEST_UTIL_H
#define EMBRA_TESTS_SCENES_SCENE_TEST_UTIL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "embra/embra.h"

/* The whole file as a NUL-terminated buffer (the NUL not counted in *out_length); NULL if it cannot
 * be read. Free with free(). */
static inline char* scene_read_file(const char* path, int64_t* out_length) {
  FILE* f = fopen(path, "rb");
  char* text = NULL;
  size_t size = 0, capacity = 0, got;
  if (f == NULL) return NULL;
  for (;;) {
    if (capacity - size < 65536) {
      char* bigger;
      capacity = capacity == 0 ? 131072 : 2 * capacity;
      bigger = (char*)realloc(text, capacity + 1);
      if (bigger == NULL) {
        free(text);
        fclose(f);
        return NULL;
      }
      text = bigger;
    }
    got = fread(text + size, 1, capacity - size, f);
    size += got;
    if (got == 0) break;
  }
  if (ferror(f)) {
    free(text);
    fclose(f);
    return NULL;
  }
  fclose(f);
  text[size] = '\0';
  *out_length = (int64_t)size;
  return text;
}

/* The world saved as scene JSON (NUL-terminated; length without the NUL in *out_length), or NULL.
 * Free with free(). */
static inline char* scene_save(const embra_world* world, int64_t* out_length) {
  int64_t needed = 0, written = 0;
  char* text;
  if (embra_world_save_json(world, NULL, 0, &needed) != EMBRA_OK || needed < 1) return NULL;
  text = (char*)malloc((size_t)needed);
  if (text == NULL) return NULL;
  if (embra_world_save_json(world, text, needed, &written) != EMBRA_OK || written != needed ||
      text[needed - 1] != '\0') {
    free(text);
    return NULL;
  }
  if (out_length) *out_length = needed - 1;
  return text;
}

/* The folder part of a path ("." for none) into out. */
static inline void scene_folder_of(const char* path, char* out, size_t capacity) {
  const char* slash = strrchr(path, '/');
  if (slash == NULL) {
    snprintf(out, capacity, ".");
  } else if (slash == path) {
    snprintf(out, capacity, "/");
  } else {
    snprintf(out, capacity, "%.*s", (int)(slash - path), path);
  }
}

/* 1 when the bytes are valid UTF-8 (RFC 3629: no overlongs, no surrogates, at most U+10FFFF). */
static inline int scene_valid_utf8(const char* text) {
  const unsigned char* s = (const unsigned char*)text;
  while (*s) {
    unsigned cp;
    int n, k;
    if (s[0] < 0x80) {
      ++s;
      continue;
    }
    if ((s[0] & 0xE0) == 0xC0) {
      n = 1;
      cp = s[0] & 0x1Fu;
    } else if ((s[0] & 0xF0) == 0xE0) {
      n = 2;
      cp = s[0] & 0x0Fu;
    } else if ((s[0] & 0xF8) == 0xF0) {
      n = 3;
      cp = s[0] & 0x07u;
    } else {
      return 0;
    }
    for (k = 1; k <= n; ++k) {
      if ((s[k] & 0xC0) != 0x80) return 0;
      cp = (cp << 6) | (s[k] & 0x3Fu);
    }
    if ((n == 1 && cp < 0x80) || (n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) || cp > 0x10FFFF ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return 0;
    s += n + 1;
  }
  return 1;
}

#endif /* EMBRA_TESTS_SCENES_SCENE_TEST_UTIL_H */
