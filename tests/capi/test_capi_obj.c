/* embra_world_export_obj and embra_world_write_obj: the OBJ every adapter and the `embra` command
 * write. Read back: the `v` lines are the world's positions bit for bit, triangles are `f` lines,
 * and a body without triangles (a hanging net) has its edges, with the distance constraints added
 * between its particles, as `l` lines, each pair once; every refused argument changes nothing. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, fdopen */
#include "capi_test.h"

#define NET 3 /* a NET x NET net of 0.1 m links */

typedef struct parsed {
  int v, f, l, g;
  double xyz[3 * 64];
  int faces[3 * 64];
  int lines[2 * 64];
} parsed;

/* Counts and reads the v, f, l and g lines of OBJ text (at most 64 of each). */
static int parse(const char* text, parsed* p) {
  memset(p, 0, sizeof *p);
  for (const char* s = text; *s; s = strchr(s, '\n') ? strchr(s, '\n') + 1 : s + strlen(s)) {
    if (strncmp(s, "v ", 2) == 0) {
      if (p->v >= 64) return -1;
      char* end = (char*)s + 2;
      for (int c = 0; c < 3; ++c) p->xyz[3 * p->v + c] = strtod(end, &end);
      ++p->v;
    } else if (strncmp(s, "f ", 2) == 0) {
      if (p->f >= 64 ||
          sscanf(s, "f %d %d %d", &p->faces[3 * p->f], &p->faces[3 * p->f + 1], &p->faces[3 * p->f + 2]) != 3)
        return -1;
      ++p->f;
    } else if (strncmp(s, "l ", 2) == 0) {
      if (p->l >= 64 || sscanf(s, "l %d %d", &p->lines[2 * p->l], &p->lines[2 * p->l + 1]) != 2) return -1;
      ++p->l;
    } else if (strncmp(s, "g ", 2) == 0) {
      ++p->g;
    }
  }
  return 0;
}

static char* export_obj(const embra_world* w) {
  int64_t n = 0;
  if (embra_world_export_obj(w, NULL, 0, &n) != EMBRA_OK) return NULL;
  char* text = (char*)malloc((size_t)n);
  if (text && embra_world_export_obj(w, text, n, &n) != EMBRA_OK) {
    free(text);
    return NULL;
  }
  return text;
}

/* A NET x NET net: particles on a grid in z = 0, edges along rows and columns, no triangles. */
static embra_body_id make_net(embra_world* w, int32_t* first) {
  double xyz[3 * NET * NET];
  int32_t edges[2 * 2 * NET * (NET - 1)];
  int e = 0;
  for (int j = 0; j < NET; ++j)
    for (int i = 0; i < NET; ++i) {
      const int k = j * NET + i;
      xyz[3 * k] = 0.1 * i;
      xyz[3 * k + 1] = 0.1 * j;
      xyz[3 * k + 2] = 0.0;
      if (i + 1 < NET) edges[2 * e] = k, edges[2 * e + 1] = k + 1, ++e;
      if (j + 1 < NET) edges[2 * e] = k, edges[2 * e + 1] = k + NET, ++e;
    }
  embra_body_def def = embra_default_body_def();
  def.vertex_count = NET * NET;
  def.positions = xyz;
  def.edge_count = e;
  def.edges = edges;
  def.generate = EMBRA_GENERATE_STRETCH;
  embra_body_id body = {0, 0};
  CHECK_OK(embra_body_create(w, &def, &body, first));
  return body;
}

static void test_net_as_lines(void) {
  embra_world* w = NULL;
  CHECK_OK(embra_world_create(&w, NULL));
  int32_t first = -1;
  make_net(w, &first);
  /* A diagonal and a repeat of an edge, added by the host: the diagonal is a line, the repeat not. */
  embra_constraint_def c = embra_default_constraint_def();
  c.kind = EMBRA_CONSTRAINT_DISTANCE;
  c.particles[0] = first + 4, c.particles[1] = first + 0;
  CHECK_OK(embra_constraint_add(w, &c));
  c.particles[0] = first + 1, c.particles[1] = first + 0;
  CHECK_OK(embra_constraint_add(w, &c));
  for (int f = 0; f < 30; ++f) CHECK_OK(embra_world_step(w)); /* it falls: positions off the grid */

  char* text = export_obj(w);
  CHECK(text != NULL);
  if (!text) return;
  CHECK(strncmp(text, "# embra ", 8) == 0);
  parsed p;
  CHECK_INT(parse(text, &p), 0);
  CHECK_INT(p.v, NET * NET);
  CHECK_INT(p.f, 0);
  CHECK_INT(p.g, 1);
  double x[3 * NET * NET];
  CHECK_OK(embra_world_get_positions(w, x, 3 * NET * NET, 0, NET * NET));
  CHECK(memcmp(x, p.xyz, sizeof x) == 0); /* %.17g: every double exactly */
  CHECK(x[3 * 4 + 2] < -1e-3);            /* and it has fallen */
  /* 12 grid edges and the added diagonal 1-5 (1-based), sorted, lower first. */
  int expected[2 * 13];
  int n = 0;
  for (int a = 0; a < NET * NET; ++a)
    for (int b = a + 1; b < NET * NET; ++b) {
      const int grid = (b == a + 1 && a % NET + 1 < NET) || b == a + NET;
      if (grid || (a == 0 && b == 4)) expected[2 * n] = a + 1, expected[2 * n + 1] = b + 1, ++n;
    }
  CHECK_INT(n, 13);
  CHECK_INT(p.l, 13);
  CHECK(memcmp(p.lines, expected, sizeof expected) == 0);
  free(text);
  embra_world_destroy(w);
}

static void test_triangles_beside_a_net(void) {
  embra_world* w = NULL;
  CHECK_OK(embra_world_create(&w, NULL));
  const double tri_xyz[] = {0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
  const int32_t tris[] = {0, 1, 2, 1, 3, 2};
  embra_body_def def = embra_default_body_def();
  def.vertex_count = 4;
  def.positions = tri_xyz;
  def.triangle_count = 2;
  def.triangles = tris;
  embra_body_id sheet;
  int32_t sheet_first = -1, net_first = -1;
  CHECK_OK(embra_body_create(w, &def, &sheet, &sheet_first));
  const embra_body_id net = make_net(w, &net_first);
  def = embra_default_body_def();
  def.vertex_count = 1;
  def.positions = tri_xyz;
  embra_body_id loose;
  int32_t loose_first = -1;
  CHECK_OK(embra_body_create(w, &def, &loose, &loose_first)); /* one particle: no group */

  char* text = export_obj(w);
  parsed p;
  CHECK(text != NULL && parse(text, &p) == 0);
  if (!text) return;
  CHECK_INT(p.v, 4 + NET * NET + 1);
  CHECK_INT(p.g, 2);
  CHECK(strstr(text, "g body_0\nf 1 2 3\nf 2 4 3\ng body_1\nl ") != NULL);
  char group[32];
  snprintf(group, sizeof group, "g body_%u\n", net.index);
  CHECK(strstr(text, group) != NULL);
  CHECK_INT(p.f, 2);
  CHECK_INT(p.l, 2 * NET * (NET - 1)); /* the sheet's edges are not lines; the net's are */
  for (int k = 0; k < 2 * p.l; ++k) CHECK(p.lines[k] > net_first && p.lines[k] <= net_first + NET * NET);
  free(text);
  embra_world_destroy(w);
}

static void test_file_and_refusals(void) {
  embra_world* w = NULL;
  CHECK_OK(embra_world_create(&w, NULL));
  int32_t first = -1;
  make_net(w, &first);
  char* before = capi_test_save(w);
  char* text = export_obj(w);
  CHECK(before != NULL && text != NULL);
  if (!before || !text) return;
  const int64_t size = (int64_t)strlen(text) + 1;

  /* The file holds the same text. */
  char path[] = "/tmp/embra_obj_XXXXXX";
  const int fd = mkstemp(path);
  CHECK(fd >= 0);
  if (fd >= 0) fclose(fdopen(fd, "w"));
  CHECK_OK(embra_world_write_obj(w, path));
  FILE* f = fopen(path, "rb");
  char* back = (char*)calloc((size_t)size + 1, 1);
  CHECK(f != NULL && back != NULL);
  if (f && back) {
    CHECK_INT((int64_t)fread(back, 1, (size_t)size, f), size - 1);
    CHECK(strcmp(back, text) == 0);
  }
  if (f) fclose(f);
  free(back);
  remove(path);

  /* Refusals: the status, a message naming the argument, and nothing written. */
  int64_t n = -7;
  CHECK_STATUS(embra_world_export_obj(NULL, NULL, 0, &n), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_INT(n, -7);
  CHECK_STATUS(embra_world_export_obj(w, NULL, 0, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(embra_last_error_message(), "out_length") != NULL);
  CHECK_STATUS(embra_world_export_obj(w, NULL, 16, &n), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(embra_last_error_message(), "out") != NULL);
  char small[16];
  memset(small, 'x', sizeof small);
  CHECK_STATUS(embra_world_export_obj(w, small, (int64_t)sizeof small, &n), EMBRA_ERROR_BUFFER_TOO_SMALL);
  CHECK_INT(n, size);
  CHECK(small[0] == 'x' && small[15] == 'x');
  CHECK_STATUS(embra_world_write_obj(NULL, path), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(embra_world_write_obj(w, NULL), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(embra_last_error_message(), "path") != NULL);
  CHECK_STATUS(embra_world_write_obj(w, "/nonexistent-embra-folder/net.obj"), EMBRA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(embra_last_error_message(), "/nonexistent-embra-folder/net.obj") != NULL);
  FILE* none = fopen("/nonexistent-embra-folder/net.obj", "r");
  CHECK(none == NULL);
  if (none) fclose(none);
  char* after = capi_test_save(w);
  CHECK(after != NULL && strcmp(before, after) == 0);
  free(after);
  free(before);
  free(text);
  embra_world_destroy(w);
}

int main(void) {
  RUN(test_net_as_lines);
  RUN(test_triangles_beside_a_net);
  RUN(test_file_and_refusals);
  return capi_test_finish();
}
