/* The `embra` command. Uses only the C ABI (embra.h), as any CAD host would.
 *
 *   embra version
 *   embra help
 *   embra validate SCENE.json [--allow-outside-paths]
 *   embra run SCENE.json [--frames N] [--out DIR] [--every K] [--threads T] [--until settled|tolerance]
 *             [--allow-outside-paths] [--force]
 *   embra demo tent [--frames N] [--out DIR] [--every K] [--n ROWS] [--force]
 *   embra sweep SWEEP.json [--scheduler ADDRESS] [--workers N] [--out DIR]
 *
 * `run` loads a scene (schemas/scene.schema.json), steps it N frames (default: the scene's own
 * "frames"; 0 loads and saves without stepping) and writes DIR/final.json (a complete scene to run
 * on), DIR/forces.json (reactions at the pins and colliders, member forces, N: write_forces), DIR/metrics.jsonl (one
 * JSON object per frame) and DIR/frame_NNNNN.obj every K frames; with panel meshes also their cut lists and, beside
 * each OBJ, the per-vertex error fields (frame_NNNNN.errors.json, final.errors.json) that the page's replay colours the
 * mesh by; and DIR/index.json: the files written and, per OBJ frame, its files and the colliders' poses. A DIR that
 * holds anything is refused (exit 1) unless --force, which writes into it.
 * --threads T steps on T threads (0: one per core; default: the scene's solver.threads): the same
 * bits at any T, and final.json keeps the scene's own setting. --until settled|tolerance steps with
 * embra_world_solve (N frames at most, 1000 by default) and prints why it stopped; it writes the
 * final files and one metrics record (the last frame).
 *
 * A scene's OBJ paths resolve against the scene file's folder and must stay inside it (no absolute
 * path, no ".." or symbolic link leading out: a scene file may come from anyone);
 * --allow-outside-paths lifts that for a scene you trust. Either way an OBJ file must be a regular
 * file of at most EMBRA_MAX_OBJ_BYTES.
 *
 * `demo tent` is the paper's Gaudi paradigm (section 3.2, figure 6): a triangular cloth pinned at
 * its three corners under reversed gravity. The membrane is elastic, so reversed gravity stretches
 * it into a doubly curved shell; the corner pins are drawn inwards to 90% of the span over the first
 * second (moving pin targets, as a designer would drag them), then held while the form settles.
 * It prints convergence as it goes and writes OBJ files of the shell.
 *
 * `sweep` is the Python package's design-space sweep on Dask (host_adapters/python/embra/sweeps.py):
 * it runs the command `embra-sweep` from PATH (the package's console script) with the same arguments,
 * and exits as it does; without it on PATH, exit 1 and how to get it.
 *
 * Exit codes: 0 ok, 1 usage (a non-empty DIR without --force too), 2 invalid input, 3 the simulation
 * failed (non-finite state), 4 --until: the world did not come to rest within tolerance. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
/* after windows.h */
#include <direct.h>
#include <io.h>
#include <process.h> /* execvp */
#include <shellapi.h>
#else
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

#include "embra/embra.h"

enum { EXIT_USAGE = 1, EXIT_INVALID = 2, EXIT_SIM = 3, EXIT_UNSETTLED = 4 };

/* --- The platform: files by UTF-8 names, folders, the clock, the terminal ----------------------
 * Every path is UTF-8, as embra.h takes it. Windows widens it to UTF-16 for its file calls (their
 * char versions read the ANSI code page); main() reads the command line as UTF-16 and makes it
 * UTF-8. Files are written in binary mode: the same bytes, "\n" line ends, on every platform. */

#ifdef _WIN32
/* UTF-8 to UTF-16 (malloc'd); NULL with errno EINVAL for bytes that are not UTF-8. */
static wchar_t* widen(const char* utf8) {
  const int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, utf8, -1, NULL, 0);
  wchar_t* w = n > 0 ? malloc(sizeof *w * (size_t)n) : NULL;
  if (w == NULL || MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, utf8, -1, w, n) != n) {
    free(w);
    errno = n > 0 ? ENOMEM : EINVAL;
    return NULL;
  }
  return w;
}

/* UTF-16 to UTF-8 (malloc'd), or NULL. */
static char* narrow(const wchar_t* w) {
  const int n = WideCharToMultiByte(CP_UTF8, 0, w, -1, NULL, 0, NULL, NULL);
  char* s = n > 0 ? malloc((size_t)n) : NULL;
  if (s != NULL && WideCharToMultiByte(CP_UTF8, 0, w, -1, s, n, NULL, NULL) != n) {
    free(s);
    s = NULL;
  }
  return s;
}

/* What Windows says of its last error, as one line (a static buffer). */
static const char* last_error_text(void) {
  static char text[256];
  const DWORD n = FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, NULL, GetLastError(),
                                 MAKELANGID(LANG_NEUTRAL, SUBLANG_DEFAULT), text, sizeof text, NULL);
  size_t len = n > 0 ? strlen(text) : 0;
  while (len > 0 && (text[len - 1] == '\n' || text[len - 1] == '\r' || text[len - 1] == '.')) text[--len] = 0;
  if (len == 0) snprintf(text, sizeof text, "Windows error %lu", (unsigned long)GetLastError());
  return text;
}
#endif

/* Whether `c` separates folders in a path. */
static int is_separator(char c) {
#ifdef _WIN32
  return c == '/' || c == '\\';
#else
  return c == '/';
#endif
}

/* Opens `path` for writing, in binary mode; NULL (errno set) on failure. */
static FILE* open_write(const char* path) {
#ifdef _WIN32
  wchar_t* w = widen(path);
  FILE* f = w ? _wfopen(w, L"wb") : NULL;
  free(w);
  return f;
#else
  return fopen(path, "wb");
#endif
}

/* Makes the folder `path` (its parent must exist); 0, or -1 with errno (EEXIST: it is there). */
static int make_one_dir(const char* path) {
#ifdef _WIN32
  wchar_t* w = widen(path);
  const int rc = w ? _wmkdir(w) : -1;
  free(w);
  return rc;
#else
  return mkdir(path, 0755);
#endif
}

/* Whether `path` is a folder with anything in it (a missing folder, or a file, is not). */
static int folder_has_entries(const char* path) {
#ifdef _WIN32
  const size_t n = strlen(path);
  char* pattern = malloc(n + 3);
  if (pattern == NULL) return 0;
  snprintf(pattern, n + 3, "%s%s*", path, n > 0 && is_separator(path[n - 1]) ? "" : "\\");
  wchar_t* w = widen(pattern);
  free(pattern);
  if (w == NULL) return 0;
  WIN32_FIND_DATAW entry;
  const HANDLE h = FindFirstFileW(w, &entry);
  free(w);
  if (h == INVALID_HANDLE_VALUE) return 0;
  int found = 0;
  do found = wcscmp(entry.cFileName, L".") != 0 && wcscmp(entry.cFileName, L"..") != 0;
  while (!found && FindNextFileW(h, &entry));
  FindClose(h);
  return found;
#else
  DIR* d = opendir(path);
  if (d == NULL) return 0;
  int found = 0;
  for (struct dirent* e; !found && (e = readdir(d)) != NULL;)
    found = strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
  closedir(d);
  return found;
#endif
}

/* Milliseconds on a monotonic clock. */
static double now_ms(void) {
#ifdef _WIN32
  LARGE_INTEGER count, frequency;
  QueryPerformanceCounter(&count);
  QueryPerformanceFrequency(&frequency);
  return (double)count.QuadPart * 1e3 / (double)frequency.QuadPart;
#else
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
#endif
}

static int stderr_is_terminal(void) {
#ifdef _WIN32
  return _isatty(_fileno(stderr));
#else
  return isatty(2);
#endif
}

/* Reads the scene file at `path` whole into *text (malloc'd, *length bytes): a regular file of at
 * most 2 GiB, opened without blocking (a pipe or device is refused before a byte is read). On
 * failure prints why and returns -1. */
static int read_scene_text(const char* path, char** text, size_t* length) {
  const int64_t max = (int64_t)1 << 31;
  *text = NULL;
  *length = 0;
#ifdef _WIN32
  wchar_t* w = widen(path);
  const HANDLE h = w ? CreateFileW(w, GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_WRITE, NULL, OPEN_EXISTING,
                                   FILE_FLAG_BACKUP_SEMANTICS, NULL)
                     : INVALID_HANDLE_VALUE;
  free(w);
  if (h == INVALID_HANDLE_VALUE) {
    fprintf(stderr, "embra: %s: %s\n", path, w ? last_error_text() : "the path is not UTF-8");
    return -1;
  }
  BY_HANDLE_FILE_INFORMATION info;
  int64_t size = 0;
  int ok = GetFileType(h) == FILE_TYPE_DISK && GetFileInformationByHandle(h, &info) &&
           !(info.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY);
  if (ok) size = (int64_t)(((uint64_t)info.nFileSizeHigh << 32) | info.nFileSizeLow);
  if (!ok || size > max) {
    fprintf(stderr, "embra: %s: not a regular file of at most 2 GiB\n", path);
    CloseHandle(h);
    return -1;
  }
  char* buffer = malloc((size_t)size + 1);
  size_t got = 0;
  DWORD n = 1;
  while (buffer != NULL && n > 0 && got <= (size_t)size)
    if (!ReadFile(h, buffer + got, (DWORD)((size_t)size + 1 - got), &n, NULL))
      break;
    else
      got += n;
  CloseHandle(h);
  const int failed = buffer == NULL || n != 0 || got != (size_t)size;
#else
  struct stat st;
  const int fd = open(path, O_RDONLY | O_NONBLOCK); /* a pipe does not block the open */
  FILE* f = fd >= 0 ? fdopen(fd, "rb") : NULL;
  if (f == NULL || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > max) {
    fprintf(stderr, "embra: %s: %s\n", path, f == NULL ? strerror(errno) : "not a regular file of at most 2 GiB");
    if (f)
      fclose(f);
    else if (fd >= 0)
      close(fd);
    return -1;
  }
  char* buffer = malloc((size_t)st.st_size + 1);
  const size_t got = buffer ? fread(buffer, 1, (size_t)st.st_size + 1, f) : 0;
  const int failed = buffer == NULL || ferror(f) || got != (size_t)st.st_size;
  fclose(f);
#endif
  if (failed) {
    fprintf(stderr, "embra: %s: cannot read it\n", path);
    free(buffer);
    return -1;
  }
  *text = buffer;
  *length = got;
  return 0;
}

/* Text that grows as it is printed to (the run's index). */
typedef struct text_buffer {
  char* text;
  size_t length, capacity;
  int failed;
} text_buffer;

static void text_printf(text_buffer* b, const char* format, ...) {
  va_list args;
  va_start(args, format);
  const int n = vsnprintf(NULL, 0, format, args);
  va_end(args);
  if (b->failed || n < 0) {
    b->failed = 1;
    return;
  }
  const size_t need = b->length + (size_t)n + 1;
  if (need > b->capacity) {
    size_t capacity = b->capacity > 0 ? b->capacity : 256;
    while (capacity < need) capacity *= 2;
    char* grown = realloc(b->text, capacity);
    if (grown == NULL) {
      b->failed = 1;
      return;
    }
    b->text = grown;
    b->capacity = capacity;
  }
  va_start(args, format);
  vsnprintf(b->text + b->length, (size_t)n + 1, format, args);
  va_end(args);
  b->length += (size_t)n;
}

static const char kUsage[] =
    "usage: embra version\n"
    "       embra help\n"
    "       embra validate SCENE.json [--allow-outside-paths]\n"
    "       embra run SCENE.json [--frames N] [--out DIR] [--every K] [--threads T] [--until settled|tolerance]\n"
    "                 [--allow-outside-paths] [--force]\n"
    "       embra demo tent [--frames N] [--out DIR] [--every K] [--n ROWS] [--force]\n"
    "       embra sweep SWEEP.json [--scheduler ADDRESS] [--workers N] [--out DIR]\n";

static int usage(void) {
  fputs(kUsage, stderr);
  return EXIT_USAGE;
}

/* A usage error that names what is wrong first, then the usage. */
static int bad_usage(const char* format, const char* a, const char* b) {
  fputs("embra: ", stderr);
  fprintf(stderr, format, a, b);
  fputs("\n", stderr);
  return usage();
}

static int help(void) {
  fputs(kUsage, stdout);
  fputs(
      "\n"
      "validate  loads SCENE.json (schemas/scene.schema.json) and builds its world; exit 0 if valid.\n"
      "run       steps the scene N frames (default: its own \"frames\"; 0: load and save only) and writes\n"
      "          DIR/final.json, DIR/forces.json (pin and collider reactions, member forces, N), DIR/metrics.jsonl,\n"
      "          DIR/index.json and DIR/frame_NNNNN.obj every K frames.\n"
      "          --threads T steps on T threads (0: one per core; default: the scene's solver.threads);\n"
      "          the results are the same bits at any T, and final.json keeps the scene's own setting.\n"
      "          --until settled|tolerance steps until the world is at rest (and, with tolerance, every\n"
      "          panel mesh within its tolerance targets and every kind's constraint residual within\n"
      "          EMBRA_SOLVE_RESIDUAL_TARGET_*) or N frames have passed, with embra_world_solve,\n"
      "          and says why it stopped: at rest within or out of tolerance (the worst metric and where),\n"
      "          or still moving, oscillating (with its period) or drifting. N defaults to 1000 there; the\n"
      "          per-frame lines and frame OBJs are not written, metrics.jsonl holds the last frame.\n"
      "          DIR defaults to ./out. OBJ files hold triangles as f lines, a net's edges as l lines.\n"
      "demo tent the paper's Gaudi tent: a triangular cloth under reversed gravity, as OBJ files\n"
      "          (DIR defaults to ./out/tent).\n"
      "sweep     runs embra-sweep (the Python package's sweeps on Dask: schemas/sweep.schema.json), the\n"
      "          variants of a scene on a LocalCluster of N workers or the Dask scheduler at ADDRESS.\n"
      "--force   run and demo tent refuse a DIR that holds anything (an earlier run's files are not\n"
      "          replaced silently); --force writes into it, replacing files of the same name.\n"
      "\n"
      "OBJ files a scene names: paths are relative to the scene file's folder and must stay inside it\n"
      "(an absolute path, or \"..\" or a symbolic link leading out, is refused: a scene file may come\n"
      "from anyone). --allow-outside-paths lifts that for a scene you trust. Either way an OBJ file must\n",
      stdout);
  printf("be a regular file (no folder, device or pipe) of at most %lld bytes (EMBRA_MAX_OBJ_BYTES).\n",
         (long long)EMBRA_MAX_OBJ_BYTES);
  fputs(
      "\nExit codes: 0 ok, 1 usage (a non-empty DIR without --force too), 2 invalid input, 3 the\n"
      "simulation failed (non-finite state), 4 --until: the world did not come to rest within tolerance.\n",
      stdout);
  return 0;
}

/* Loads the scene file at `path`: its OBJ paths relative to its folder and confined to it, unless
 * `allow_outside` (then through embra_world_load_json_with_options, the scene read here: a regular
 * file of at most 2 GiB). On failure prints why and returns EXIT_INVALID. */
static int load_scene_file(const char* path, int allow_outside, embra_world** world) {
  if (!allow_outside) {
    if (embra_world_load_file(world, path) == EMBRA_OK) return 0;
    fprintf(stderr, "embra: %s: %s\n", path, embra_last_error_message());
    return EXIT_INVALID;
  }
  char* text = NULL;
  size_t got = 0;
  if (read_scene_text(path, &text, &got) != 0) return EXIT_INVALID;
  /* The scene's folder, as embra_world_load_file finds it: "." for a bare name, "/" for a file at
   * the root; on Windows "\\" separates too and "C:\\" is a root. */
  char folder[4096];
  const char* slash = NULL;
  for (const char* p = path; *p; ++p)
    if (is_separator(*p)) slash = p;
  const int drive = is_separator('\\') && path[0] != 0 && path[1] == ':';
  if (slash == NULL)
    snprintf(folder, sizeof folder, "%.*s", drive ? 2 : 1, drive ? path : ".");
  else if (slash == path || (drive && slash == path + 2))
    snprintf(folder, sizeof folder, "%.*s", (int)(slash - path + 1), path);
  else
    snprintf(folder, sizeof folder, "%.*s", (int)(slash - path), path);
  embra_load_options options = embra_default_load_options();
  options.base_dir = folder;
  options.allow_paths_outside_base = 1;
  const embra_status s = embra_world_load_json_with_options(world, text, (int64_t)got, &options);
  free(text);
  if (s == EMBRA_OK) return 0;
  fprintf(stderr, "embra: %s: %s\n", path, embra_last_error_message());
  return EXIT_INVALID;
}

/* Parses a whole decimal integer in [lo, hi]; 0 on success. */
static int parse_int(const char* text, long lo, long hi, long* out) {
  char* end = NULL;
  errno = 0;
  const long v = strtol(text, &end, 10);
  if (errno != 0 || end == text || *end != 0 || v < lo || v > hi) return -1;
  *out = v;
  return 0;
}

/* The value of option `name` at argv[i + 1] as a whole number in [lo, hi] into *out; else names the
 * problem and returns the usage exit code (0 when fine). */
static int option_int(int argc, char** argv, int i, long lo, long hi, long* out) {
  if (i + 1 >= argc) return bad_usage("%s needs a value%s", argv[i], "");
  if (parse_int(argv[i + 1], lo, hi, out) != 0) {
    char range[96];
    snprintf(range, sizeof range, "a whole number from %ld to %ld, got '%%s'", lo, hi);
    char message[160];
    snprintf(message, sizeof message, "%%s: expected %s", range);
    return bad_usage(message, argv[i], argv[i + 1]);
  }
  return 0;
}

/* Makes the folder `path` with its parents; 0, or -1 with errno. */
static int make_dir(const char* path) {
  char buf[4096];
  if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) return -1;
  /* On Windows "C:\\" is a drive's root, not a folder to make. */
  const int drive = buf[0] != 0 && buf[1] == ':' && is_separator('\\');
  for (char* p = buf + 1; *p; ++p)
    if (is_separator(*p) && !(drive && p == buf + 2)) {
      const char separator = *p;
      *p = 0;
      if (make_one_dir(buf) != 0 && errno != EEXIST) return -1;
      *p = separator;
    }
  if (make_one_dir(buf) != 0 && errno != EEXIST) return -1;
  return 0;
}

/* The output folder: refused when it holds anything and `force` is not set (an earlier run's files
 * are not replaced silently); otherwise made with its parents. */
static int open_out_dir(const char* out, int force) {
  if (!force && folder_has_entries(out)) {
    fprintf(stderr,
            "embra: %s is not empty: pass --force to write into it (files of the same name are replaced), "
            "or --out another folder\n",
            out);
    return EXIT_USAGE;
  }
  if (make_dir(out) != 0) {
    fprintf(stderr, "embra: cannot create %s: %s\n", out, strerror(errno));
    return EXIT_INVALID;
  }
  return 0;
}

static int check(embra_status s, const char* what) {
  if (s == EMBRA_OK) return 0;
  fprintf(stderr, "embra: %s failed: %s (%s)\n", what, embra_last_error_message(), embra_status_name(s));
  return s == EMBRA_ERROR_NUMERICAL ? EXIT_SIM : EXIT_INVALID;
}

/* Writes the world as OBJ (embra_world_write_obj: triangles as `f`, a net's edges as `l` lines). */
static int write_world_obj(const char* path, const embra_world* world) {
  if (embra_world_write_obj(world, path) == EMBRA_OK) return 0;
  fprintf(stderr, "embra: %s\n", embra_last_error_message());
  return -1;
}

/* An equilateral triangle of side `side` (m) in the z = 0 plane, split into rows^2 triangles. */
static void triangle_mesh(int32_t rows, double side, double* xyz, int32_t* tri, int32_t corners[3]) {
  const double h = side * sqrt(3.0) / 2.0;
  int32_t v = 0, t = 0;
  for (int32_t r = 0; r <= rows; ++r)
    for (int32_t c = 0; c <= rows - r; ++c) {
      xyz[3 * v] = side * ((double)c + 0.5 * r) / rows - side / 2;
      xyz[3 * v + 1] = h * (double)r / rows - h / 3;
      xyz[3 * v + 2] = 0.0;
      ++v;
    }
    /* Index of vertex (r, c): rows before r hold sum_{k<r} (rows + 1 - k) vertices. */
#define IDX(r, c) ((r) * (rows + 1) - ((r) * ((r)-1)) / 2 + (c))
  for (int32_t r = 0; r < rows; ++r)
    for (int32_t c = 0; c < rows - r; ++c) {
      tri[3 * t] = IDX(r, c);
      tri[3 * t + 1] = IDX(r, c + 1);
      tri[3 * t + 2] = IDX(r + 1, c);
      ++t;
      if (c + 1 < rows - r) {
        tri[3 * t] = IDX(r, c + 1);
        tri[3 * t + 1] = IDX(r + 1, c + 1);
        tri[3 * t + 2] = IDX(r + 1, c);
        ++t;
      }
    }
  corners[0] = IDX(0, 0);
  corners[1] = IDX(0, rows);
  corners[2] = IDX(rows, 0);
#undef IDX
}

static int demo_tent(int argc, char** argv) {
  long frames = 600, every = 100, rows = 40;
  const char* out = "out/tent";
  int force = 0;
  for (int i = 0; i < argc; ++i) {
    int rc = 0;
    if (strcmp(argv[i], "--frames") == 0)
      rc = option_int(argc, argv, i++, 0, 100000000, &frames);
    else if (strcmp(argv[i], "--every") == 0)
      rc = option_int(argc, argv, i++, 1, 100000000, &every);
    else if (strcmp(argv[i], "--n") == 0)
      rc = option_int(argc, argv, i++, 2, 1000, &rows);
    else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
      out = argv[++i];
    else if (strcmp(argv[i], "--out") == 0)
      return bad_usage("%s needs a value%s", argv[i], "");
    else if (strcmp(argv[i], "--force") == 0)
      force = 1;
    else
      return bad_usage("unknown option '%s' for demo tent%s", argv[i], " (see embra help)");
    if (rc != 0) return rc;
  }
  const int opened = open_out_dir(out, force);
  if (opened != 0) return opened;

  const int32_t n = (rows + 1) * (rows + 2) / 2, t = rows * rows;
  double* xyz = malloc(sizeof(double) * 3 * (size_t)n);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * (size_t)t);
  if (!xyz || !tri) return EXIT_SIM;
  int32_t corners[3];
  triangle_mesh(rows, 1.0, xyz, tri, corners);

  int rc = 0;
  embra_world* world = NULL;
  embra_solver_def solver = embra_default_solver_def();
  solver.gravity[2] = +9.81; /* reversed: the hanging form, upside down, is the shell */
  solver.damping = 2.0;      /* 1/s: calms the membrane's waves so the form settles */
  solver.substeps = 20;
  solver.iterations = 4;
  solver.settle_speed = 1e-3;
  if ((rc = check(embra_world_create(&world, &solver), "embra_world_create"))) goto done;

  /* Two groups, in the paper's sense: stretch first and twice per pass (it matters most to the
   * form), bending after it. Each reports its own residual. */
  embra_group_id stretch, bend;
  embra_group_def group = embra_default_group_def();
  group.order = 0;
  group.weight = 2;
  if ((rc = check(embra_group_create(world, &group, &stretch), "embra_group_create"))) goto done;
  group.order = 1;
  group.weight = 1;
  if ((rc = check(embra_group_create(world, &group, &bend), "embra_group_create"))) goto done;

  embra_body_def body = embra_default_body_def();
  body.stretch_group = stretch;
  body.bend_group = bend;
  body.vertex_count = n;
  body.positions = xyz;
  body.triangle_count = t;
  body.triangles = tri;
  body.material.mass = 0.5;                /* kg */
  body.material.stretch_compliance = 1e-2; /* m/N: an elastic membrane, so it can take a double curvature */
  body.material.bend_compliance = 10.0;    /* soft fabric */
  embra_body_id cloth;
  int32_t first = 0;
  if ((rc = check(embra_body_create(world, &body, &cloth, &first), "embra_body_create"))) goto done;

  embra_pin_id pins[3];
  for (int k = 0; k < 3; ++k) {
    embra_pin_def pin = embra_default_pin_def();
    pin.particle = first + corners[k];
    memcpy(pin.target, &xyz[3 * corners[k]], sizeof pin.target);
    if ((rc = check(embra_pin_create(world, &pin, &pins[k]), "embra_pin_create"))) goto done;
  }

  printf("embra %s - Gaudi tent: %d particles, %d triangles, reversed gravity\n", embra_version_string(), n, t);
  printf("%6s %14s %14s %12s %12s %10s %8s\n", "frame", "stretch_res_m", "bend_res_rad", "kinetic_J", "max_speed_m/s",
         "apex_m", "settled");
  double* now = malloc(sizeof(double) * 3 * (size_t)n);
  if (!now) goto done;
  char path[4200];
  embra_step_report report;
  memset(&report, 0, sizeof report);
  for (int32_t f = 1; f <= frames; ++f) {
    const double draw = f < 60 ? (double)f / 60.0 : 1.0; /* corners travel inwards over 1 s */
    for (int k = 0; k < 3; ++k) {
      double target[3];
      for (int c = 0; c < 3; ++c) target[c] = xyz[3 * corners[k] + c] * (1.0 - 0.1 * draw);
      if ((rc = check(embra_pin_set_target(world, pins[k], target), "embra_pin_set_target"))) goto done_now;
    }
    if ((rc = check(embra_world_step(world), "embra_world_step"))) goto done_now;
    embra_world_get_report(world, &report);
    embra_group_report stretch_report, bend_report;
    embra_group_get_report(world, stretch, &stretch_report);
    embra_group_get_report(world, bend, &bend_report);
    if ((rc = check(embra_world_get_positions(world, now, 3 * (int64_t)n, first, n), "embra_world_get_positions")))
      goto done_now;
    double apex = -1e300;
    for (int32_t i = 0; i < n; ++i) apex = fmax(apex, now[3 * i + 2]);
    if (f % 30 == 0 || f == frames)
      printf("%6d %14.3e %14.3e %12.3e %12.3e %10.4f %8s\n", f, stretch_report.residual_max, bend_report.residual_max,
             report.kinetic_energy, report.max_speed, apex, report.settled ? "yes" : "no");
    if (f % every == 0 || f == frames) {
      snprintf(path, sizeof path, "%s/frame_%05d.obj", out, f);
      if (write_world_obj(path, world) != 0) {
        rc = EXIT_INVALID;
        goto done_now;
      }
    }
  }
  snprintf(path, sizeof path, "%s/final.obj", out);
  if (write_world_obj(path, world) != 0)
    rc = EXIT_INVALID;
  else
    printf("wrote %s (%ld frames, %.2f s simulated)\n", path, frames, report.time);
done_now:
  free(now);
done:
  embra_world_destroy(world);
  free(xyz);
  free(tri);
  return rc;
}

/* The ids of the world's bodies (malloc'd, *count of them; NULL on failure or none). */
static embra_body_id* world_bodies(const embra_world* world, int32_t* count) {
  *count = 0;
  int32_t n = 0;
  if (embra_world_get_bodies(world, NULL, 0, &n) != EMBRA_OK || n == 0) return NULL;
  embra_body_id* ids = malloc(sizeof *ids * (size_t)n);
  if (ids && embra_world_get_bodies(world, ids, n, &n) == EMBRA_OK) {
    *count = n;
    return ids;
  }
  free(ids);
  return NULL;
}

/* Panel meshes: the bodies of the world that are panel meshes (up to 64). */
#define MAX_PANEL_MESHES 64
static int find_panel_meshes(embra_world* world, embra_body_id* out) {
  int32_t body_count = 0;
  int n = 0;
  embra_body_id* bodies = world_bodies(world, &body_count);
  for (int32_t b = 0; b < body_count && n < MAX_PANEL_MESHES; ++b) {
    int32_t panels = 0;
    if (embra_panel_mesh_get_panel_count(world, bodies[b], &panels) == EMBRA_OK) out[n++] = bodies[b];
  }
  free(bodies);
  return n;
}

/* The worst of every panel mesh's metrics (and whether all are within tolerance). */
typedef struct panel_totals {
  double planarity, planarity_top, planarity_bottom, corner_distance, thickness, miter, conical, diagonal, corner_gap;
  int within;
} panel_totals;

static double max2(double a, double b) {
  return a > b ? a : b;
}

static int panel_totals_of(embra_world* world, const embra_body_id* bodies, int n, panel_totals* t) {
  memset(t, 0, sizeof *t);
  t->within = 1;
  for (int i = 0; i < n; ++i) {
    embra_panel_metrics m;
    embra_metric_summary gap;
    if (embra_panel_mesh_get_metrics(world, bodies[i], NULL, &m) != EMBRA_OK ||
        embra_panel_mesh_get_corner_gap(world, bodies[i], &gap) != EMBRA_OK)
      return -1;
    t->corner_gap = max2(t->corner_gap, gap.max);
    t->planarity_top = max2(t->planarity_top, m.planarity_top.max);
    t->planarity_bottom = max2(t->planarity_bottom, m.planarity_bottom.max);
    t->planarity = max2(t->planarity_top, t->planarity_bottom);
    t->corner_distance = max2(t->corner_distance, max2(m.corner_distance_top.max, m.corner_distance_bottom.max));
    t->diagonal = max2(t->diagonal, max2(m.diagonal_top.max, m.diagonal_bottom.max));
    t->thickness = max2(t->thickness, m.thickness.max);
    t->miter = max2(t->miter, m.miter.max);
    t->conical = max2(t->conical, m.conical.max);
    t->within = t->within && m.within_tolerance;
  }
  return 0;
}

/* Writes the per-vertex error fields beside an OBJ of the world (docs/live-protocol.md, "The replay
 * folder"): planarity, thickness and miter per world particle, null for particles of no panel mesh,
 * with the tolerances that colour them. */
static int write_error_fields(const char* path, embra_world* world, const embra_body_id* bodies, int n, long frame) {
  static const struct {
    const char* name;
    int32_t metric;
  } fields[3] = {{"planarity", EMBRA_PANEL_METRIC_PLANARITY},
                 {"thickness", EMBRA_PANEL_METRIC_THICKNESS},
                 {"miter", EMBRA_PANEL_METRIC_MITER}};
  embra_world_counts counts;
  embra_tolerances tol;
  if (embra_world_get_counts(world, &counts) != EMBRA_OK || embra_world_get_tolerances(world, &tol) != EMBRA_OK)
    return -1;
  const size_t np = (size_t)(counts.particles > 0 ? counts.particles : 1);
  double* value = malloc(sizeof(double) * np);
  unsigned char* measured = calloc(np, 1);
  FILE* f = value && measured ? open_write(path) : NULL;
  int rc = f ? 0 : -1;
  if (!f && value && measured) fprintf(stderr, "embra: cannot write %s: %s\n", path, strerror(errno));
  if (f) {
    fprintf(f,
            "{\"format\":\"embra-vertex-errors\",\"version\":1,\"frame\":%ld,\"particles\":%d,"
            "\"tolerances\":{\"unit_scale\":%.17g,\"planarity\":{\"target\":%.17g,\"max\":%.17g},"
            "\"thickness\":{\"target\":%.17g,\"max\":%.17g},\"miter\":{\"target\":%.17g,\"max\":%.17g}},"
            "\"fields\":{",
            frame, counts.particles, tol.unit_scale, tol.planarity.target, tol.planarity.max, tol.thickness.target,
            tol.thickness.max, tol.miter.target, tol.miter.max);
  }
  for (int k = 0; k < 3 && rc == 0; ++k) {
    memset(measured, 0, np);
    for (int i = 0; i < n && rc == 0; ++i) {
      int32_t first = 0, count = 0;
      int64_t got = 0;
      if (embra_body_get_particles(world, bodies[i], &first, &count) != EMBRA_OK ||
          embra_panel_mesh_get_vertex_errors(world, bodies[i], fields[k].metric, value + first, count, &got) !=
              EMBRA_OK) {
        rc = -1;
        break;
      }
      memset(measured + first, 1, (size_t)count);
    }
    fprintf(f, "%s\"%s\":[", k > 0 ? "," : "", fields[k].name);
    for (int32_t p = 0; p < counts.particles && rc == 0; ++p) {
      if (p > 0) fputc(',', f);
      if (measured[p] && isfinite(value[p]))
        fprintf(f, "%.9g", value[p]);
      else
        fputs("null", f);
    }
    fputc(']', f);
  }
  if (f) {
    fputs("}}\n", f);
    if (fclose(f) != 0) rc = -1;
  }
  free(value);
  free(measured);
  return rc;
}

/* Writes each panel mesh's cut list (JSON and CSV) into DIR. */
static int write_cuts(embra_world* world, const embra_body_id* bodies, int n, const char* dir) {
  for (int i = 0; i < n; ++i)
    for (int format = EMBRA_CUTS_JSON; format <= EMBRA_CUTS_CSV; ++format) {
      int64_t len = 0;
      if (embra_panel_mesh_export_cuts(world, bodies[i], format, NULL, 0, &len) != EMBRA_OK) return -1;
      char* text = malloc((size_t)len);
      if (!text) return -1;
      if (embra_panel_mesh_export_cuts(world, bodies[i], format, text, len, &len) != EMBRA_OK) {
        free(text);
        return -1;
      }
      char path[4200];
      snprintf(path, sizeof path, "%s/panels_%u.%s", dir, bodies[i].index, format == EMBRA_CUTS_JSON ? "json" : "csv");
      FILE* f = open_write(path);
      if (!f) {
        fprintf(stderr, "embra: cannot write %s: %s\n", path, strerror(errno));
        free(text);
        return -1;
      }
      fputs(text, f);
      free(text);
      if (fclose(f) != 0) return -1;
    }
  return 0;
}

static void print_tolerance_row(const char* name, double value, embra_tolerance tol, double unit_scale, int scaled) {
  if (scaled)
    printf("%-22s %12.3e %12.3e %10s %12.4f %12.4f\n", name, value, tol.target, value <= tol.target ? "yes" : "NO",
           value * unit_scale, tol.target * unit_scale);
  else
    printf("%-22s %12.3e %12.3e %10s %12s %12s\n", name, value, tol.target, value <= tol.target ? "yes" : "NO", "-",
           "-");
}

static int cmd_validate(int argc, char** argv) {
  const int allow_outside = argc == 2 && strcmp(argv[1], "--allow-outside-paths") == 0;
  if (argc != 1 + allow_outside) return usage();
  embra_world* world = NULL;
  const int rc = load_scene_file(argv[0], allow_outside, &world);
  if (rc != 0) return rc;
  embra_world_counts c;
  embra_world_get_counts(world, &c);
  printf("%s: valid (%d particles, %lld constraints, %d pins, %d colliders)\n", argv[0], c.particles,
         (long long)c.constraints, c.pins, c.colliders);
  embra_world_destroy(world);
  return 0;
}

/* The run's index (DIR/index.json): every file it wrote, and per OBJ frame its files and where each
 * collider was, so a replay shows the colliders where they were without re-running the scene. The
 * entries accumulate in memory streams and are written at the end. */
typedef struct run_index {
  text_buffer files, frames;
  int file_count, frame_count;
} run_index;

static void run_index_open(run_index* x) {
  memset(x, 0, sizeof *x);
}

/* Records a file written into DIR (its name only: every name embra writes is plain ASCII). */
static void run_index_file(run_index* x, const char* name) {
  text_printf(&x->files, "%s\"%s\"", x->file_count++ ? "," : "", name);
}

/* Records an OBJ frame: its files (errors: NULL for none) and every live collider's pose. */
static void run_index_frame(run_index* x, embra_world* world, long frame, const char* obj, const char* errors) {
  text_printf(&x->frames, "%s{\"frame\":%ld,\"obj\":\"%s\"", x->frame_count++ ? "," : "", frame, obj);
  if (errors) text_printf(&x->frames, ",\"errors\":\"%s\"", errors);
  text_printf(&x->frames, ",\"colliders\":[");
  int32_t n = 0;
  if (embra_world_get_colliders(world, NULL, 0, &n) == EMBRA_OK && n > 0) {
    embra_collider_id* ids = malloc(sizeof *ids * (size_t)n);
    if (ids && embra_world_get_colliders(world, ids, n, &n) == EMBRA_OK) {
      for (int32_t i = 0; i < n; ++i) {
        double p[3], q[4];
        if (embra_collider_get_transform(world, ids[i], p, q) != EMBRA_OK) continue;
        text_printf(&x->frames, "%s[%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g]", i ? "," : "", p[0], p[1], p[2], q[0],
                    q[1], q[2], q[3]);
      }
    }
    free(ids);
  }
  text_printf(&x->frames, "]}");
}

/* Writes DIR/forces.json: the last step's statics (embra_world_get_reactions,
 * embra_world_get_collider_reactions, embra_group_get_forces):
 * {"format": "embra-forces", "version": 1, "units": {"force": "N"},
 *  "reactions": [{"pin": [index, generation], "particle": p, "force": [x, y, z]}, ...],
 *  "reaction_sum": [x, y, z],
 *  "colliders": [{"collider": [index, generation], "contacts": c, "force": [x, y, z],
 *                 "moment": [x, y, z]}, ...],
 *  "collider_sum": [x, y, z], "total": [x, y, z],
 *  "groups": [{"group": [index, generation], "distance": [tension, ...], "tether": [...],
 *              "equal_length": [...]}, ...]}
 * the colliders' forces on the world (N) and moments about their positions (N m); "total" is the
 * pins' and colliders' sum, minus the total applied load at a static rest; a group's kinds listed
 * when it holds any, each constraint's tension (N, positive pulling its ends together) in the order
 * the constraints were added. */
static int write_forces(const char* path, const embra_world* world) {
  FILE* f = open_write(path);
  if (!f) {
    fprintf(stderr, "embra: cannot write %s: %s\n", path, strerror(errno));
    return -1;
  }
  int rc = 0;
  fputs("{\"format\":\"embra-forces\",\"version\":1,\"units\":{\"force\":\"N\",\"moment\":\"N m\"},\"reactions\":[", f);
  int32_t n = 0;
  double sum[3] = {0.0, 0.0, 0.0};
  if (embra_world_get_reactions(world, NULL, 0, &n) != EMBRA_OK) rc = -1;
  if (rc == 0 && n > 0) {
    embra_reaction* r = malloc(sizeof *r * (size_t)n);
    if (!r || embra_world_get_reactions(world, r, n, &n) != EMBRA_OK) rc = -1;
    for (int32_t i = 0; rc == 0 && i < n; ++i) {
      fprintf(f, "%s{\"pin\":[%u,%u],\"particle\":%d,\"force\":[%.17g,%.17g,%.17g]}", i ? "," : "", r[i].pin.index,
              r[i].pin.generation, r[i].particle, r[i].force[0], r[i].force[1], r[i].force[2]);
      for (int k = 0; k < 3; ++k) sum[k] += r[i].force[k];
    }
    free(r);
  }
  fprintf(f, "],\"reaction_sum\":[%.17g,%.17g,%.17g],\"colliders\":[", sum[0], sum[1], sum[2]);
  double csum[3] = {0.0, 0.0, 0.0};
  int32_t nc = 0;
  if (rc == 0 && embra_world_get_collider_reactions(world, NULL, 0, &nc) != EMBRA_OK) rc = -1;
  if (rc == 0 && nc > 0) {
    embra_collider_reaction* c = malloc(sizeof *c * (size_t)nc);
    if (!c || embra_world_get_collider_reactions(world, c, nc, &nc) != EMBRA_OK) rc = -1;
    for (int32_t i = 0; rc == 0 && i < nc; ++i) {
      fprintf(f,
              "%s{\"collider\":[%u,%u],\"contacts\":%lld,\"force\":[%.17g,%.17g,%.17g],\"moment\":[%.17g,%.17g,%.17g]}",
              i ? "," : "", c[i].collider.index, c[i].collider.generation, (long long)c[i].contacts, c[i].force[0],
              c[i].force[1], c[i].force[2], c[i].moment[0], c[i].moment[1], c[i].moment[2]);
      for (int k = 0; k < 3; ++k) csum[k] += c[i].force[k];
    }
    free(c);
  }
  fprintf(f, "],\"collider_sum\":[%.17g,%.17g,%.17g],\"total\":[%.17g,%.17g,%.17g],\"groups\":[", csum[0], csum[1],
          csum[2], sum[0] + csum[0], sum[1] + csum[1], sum[2] + csum[2]);
  int32_t groups = 0;
  if (rc == 0 && embra_world_get_groups(world, NULL, 0, &groups) != EMBRA_OK) rc = -1;
  embra_group_id* ids = groups > 0 ? malloc(sizeof *ids * (size_t)groups) : NULL;
  if (rc == 0 && groups > 0 && (!ids || embra_world_get_groups(world, ids, groups, &groups) != EMBRA_OK)) rc = -1;
  static const int32_t kinds[] = {EMBRA_CONSTRAINT_DISTANCE, EMBRA_CONSTRAINT_TETHER, EMBRA_CONSTRAINT_EQUAL_LENGTH};
  for (int32_t g = 0; rc == 0 && g < groups; ++g) {
    fprintf(f, "%s{\"group\":[%u,%u]", g ? "," : "", ids[g].index, ids[g].generation);
    for (size_t k = 0; rc == 0 && k < sizeof kinds / sizeof kinds[0]; ++k) {
      int64_t count = 0;
      if (embra_group_get_forces(world, ids[g], kinds[k], NULL, 0, &count) != EMBRA_OK) rc = -1;
      if (rc != 0 || count == 0) continue;
      double* v = malloc(sizeof *v * (size_t)count);
      if (!v || embra_group_get_forces(world, ids[g], kinds[k], v, count, &count) != EMBRA_OK) rc = -1;
      fprintf(f, ",\"%s\":[", embra_residual_name(kinds[k]));
      for (int64_t i = 0; rc == 0 && i < count; ++i) fprintf(f, "%s%.17g", i ? "," : "", v[i]);
      fputc(']', f);
      free(v);
    }
    fputc('}', f);
  }
  free(ids);
  fputs("]}\n", f);
  if (fclose(f) != 0) rc = -1;
  if (rc != 0) fprintf(stderr, "embra: cannot write %s: %s\n", path, embra_last_error_message());
  return rc;
}

/* Writes DIR/index.json and frees the index. */
static int run_index_write(run_index* x, const char* dir) {
  char path[4200];
  snprintf(path, sizeof path, "%s/index.json", dir);
  int rc = -1;
  if (x->files.failed || x->frames.failed) {
    fprintf(stderr, "embra: cannot write %s: out of memory\n", path);
  } else {
    FILE* f = open_write(path);
    if (f) {
      fprintf(f, "{\"format\":\"embra-run-index\",\"version\":1,\"files\":[%s,\"index.json\"],\"frames\":[%s]}\n",
              x->files.text ? x->files.text : "", x->frames.text ? x->frames.text : "");
      rc = fclose(f) == 0 ? 0 : -1;
    } else {
      fprintf(stderr, "embra: cannot write %s: %s\n", path, strerror(errno));
    }
  }
  free(x->files.text);
  free(x->frames.text);
  return rc;
}

static void progress(long done, long total, double ms) {
  const int width = 40;
  const int filled = total > 0 ? (int)(width * done / total) : width;
  fprintf(stderr, "\r[%.*s%*s] %ld/%ld frames  %.2f ms/frame", filled, "########################################",
          width - filled, "", done, total, done > 0 ? ms / (double)done : 0.0);
  fflush(stderr);
}

/* Sets the world's solver thread count (the rest of its solver settings as they are now); the
 * count it had goes to *before when before is not NULL. */
static int set_threads(embra_world* world, int32_t threads, int32_t* before) {
  embra_solver_def s;
  if (embra_world_get_solver(world, &s) != EMBRA_OK) return -1;
  if (before) *before = s.threads;
  s.threads = threads;
  return embra_world_set_solver(world, &s) == EMBRA_OK ? 0 : -1;
}

/* Reopens the metrics record just written (drops its closing "}\n") and adds the last step's
 * residuals by kind, each in its unit: "residuals": {"distance": {"unit": "m", "count": ..,
 * "max": .., "rms": ..}, ...}. */
static void write_residuals(FILE* metrics, const embra_world* world) {
  embra_kind_residual res[64];
  int32_t n = 0;
  if (embra_world_get_residuals(world, res, 64, &n) != EMBRA_OK) return;
  fseek(metrics, -2, SEEK_CUR);
  fputs(",\"residuals\":{", metrics);
  for (int32_t i = 0; i < n; ++i)
    fprintf(metrics, "%s\"%s\":{\"unit\":\"%s\",\"count\":%lld,\"max\":%.17g,\"rms\":%.17g}", i ? "," : "",
            embra_residual_name(res[i].kind), embra_residual_unit(res[i].kind), (long long)res[i].count, res[i].max,
            res[i].rms);
  fputs("}}\n", metrics);
}

/* The last step's residuals by kind, one line each, in each kind's unit, for a person. */
static void print_residuals(const embra_world* world) {
  embra_kind_residual res[64];
  int32_t n = 0;
  if (embra_world_get_residuals(world, res, 64, &n) != EMBRA_OK) return;
  for (int32_t i = 0; i < n; ++i)
    printf("%-18s %-13s %.3e %-3s max, %.3e rms over %lld\n", i == 0 ? "residual" : "",
           embra_residual_name(res[i].kind), res[i].max, embra_residual_unit(res[i].kind), res[i].rms,
           (long long)res[i].count);
}

/* What fights, for a person: the worst constraints (by violation x force) and the groups pulling
 * against each other, after a run that did not come to rest. */
/* Prints the constraints broken since the last read (embra_world_get_broken, which empties the
 * list): one "broke" line each, with its frame and strain. Returns how many. */
static int32_t print_broken(embra_world* world) {
  int32_t n = 0;
  if (embra_world_get_broken(world, NULL, 0, &n) != EMBRA_OK || n == 0) return 0;
  embra_broken_constraint* b = malloc(sizeof *b * (size_t)n);
  if (!b || embra_world_get_broken(world, b, n, &n) != EMBRA_OK) n = 0;
  for (int32_t i = 0; i < n; ++i)
    printf("%-18s %s %d of group %u (particles %d %d%s) in frame %lld at strain %.6g\n", "broke",
           embra_residual_name(b[i].kind), b[i].index, b[i].group.index, b[i].particles[0], b[i].particles[1],
           b[i].particles[2] >= 0 ? " ..." : "", (long long)b[i].frame, b[i].strain);
  free(b);
  return n;
}

static void print_fighting(const embra_world* world) {
  embra_constraint_residual worst[5];
  int32_t n = 0;
  if (embra_world_get_worst_constraints(world, worst, 5, &n) == EMBRA_OK)
    for (int32_t i = 0; i < n; ++i) {
      const embra_constraint_residual* c = &worst[i];
      char what[96];
      if (c->kind == EMBRA_RESIDUAL_PINS)
        snprintf(what, sizeof what, "pin %u on particle %d", c->pin.index, c->particles[0]);
      else
        snprintf(what, sizeof what, "%s %d (particles %d %d%s)", embra_residual_name(c->kind), c->index,
                 c->particles[0], c->particles[1], c->particles[2] >= 0 ? " ..." : "");
      const char* unit = embra_residual_unit(c->kind);
      /* The force's unit is the one conjugate to the value's: N for a length, N m for an angle. */
      const char* force_unit = strcmp(unit, "rad") == 0 ? "N m" : strcmp(unit, "m^3") == 0 ? "N/m^2" : "N";
      printf("%-18s %s of group %u: %.3e %s from rest, %.3e %s (residual %.3e)\n", i == 0 ? "fighting" : "", what,
             c->group.index, c->violation, unit, c->force, force_unit, c->residual);
    }
  if (embra_world_get_group_conflicts(world, NULL, 0, &n) != EMBRA_OK || n == 0) return;
  embra_group_conflict* all = malloc((size_t)n * sizeof *all);
  if (all && embra_world_get_group_conflicts(world, all, n, &n) == EMBRA_OK)
    for (int32_t i = 0; i < n && i < 3; ++i)
      printf("%-18s groups %u and %u pull against each other: %.3e N over %lld particles\n",
             i == 0 ? "groups fighting" : "", all[i].a.index, all[i].b.index, all[i].force,
             (long long)all[i].particles);
  free(all);
}

/* Why embra_world_solve stopped, for a person. */
static void print_solve_outcome(const embra_solve_result* s, const embra_world* world) {
  static const char* const metric_names[] = {"planarity", "thickness error", "miter twist", "corner off plane"};
  const char* metric = s->worst_metric >= 0 && s->worst_metric < 4 ? metric_names[s->worst_metric] : "";
  char where[200] = "";
  if (s->worst_metric == EMBRA_SOLVE_WORST_RESIDUAL) {
    const char* kind = embra_residual_name(s->worst_element);
    const char* unit = embra_residual_unit(s->worst_element);
    snprintf(where, sizeof where, "%s residual %.3e %s (target %.3e)", kind ? kind : "?", s->worst_value,
             unit ? unit : "", s->worst_target);
  } else if (s->worst_metric >= 0) {
    embra_tolerances tol;
    embra_world_get_tolerances(world, &tol);
    snprintf(where, sizeof where, "%s %.3e (target %.3e) at %s %d%s of panel mesh body %u", metric, s->worst_value,
             s->worst_target, s->worst_metric == EMBRA_PANEL_METRIC_MITER ? "joint" : "panel", s->worst_element,
             s->worst_layer == 0   ? " (top)"
             : s->worst_layer == 1 ? " (bottom)"
                                   : "",
             s->worst_body.index);
  }
  switch (s->outcome) {
    case EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE:
      printf("%-18s at rest and within tolerance after %d frames%s%s\n", "stopped", s->frames,
             s->worst_metric >= 0 ? "; closest to its target: " : "", where);
      break;
    case EMBRA_SOLVE_SETTLED_OUT_OF_TOLERANCE:
      printf("%-18s at rest after %d frames but out of tolerance: %s\n", "stopped", s->frames, where);
      break;
    case EMBRA_SOLVE_OSCILLATING:
      printf("%-18s still moving after %d frames: oscillating with a period of %.4g s\n", "stopped", s->frames,
             s->period);
      break;
    default:
      printf("%-18s still moving after %d frames: drifting (no period)\n", "stopped", s->frames);
      break;
  }
}

static int cmd_run(int argc, char** argv) {
  if (argc < 1) return usage();
  const char* scene = argv[0];
  const char* out = "out";
  long frames = -1, every = 0, threads = -1;
  int until = -1; /* EMBRA_SOLVE_UNTIL_*, or -1: step N frames */
  int allow_outside = 0, force = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--allow-outside-paths") == 0) {
      allow_outside = 1;
      continue;
    }
    if (strcmp(argv[i], "--force") == 0) {
      force = 1;
      continue;
    }
    int rc = 0;
    if (strcmp(argv[i], "--frames") == 0) {
      rc = option_int(argc, argv, i++, 0, 100000000, &frames);
    } else if (strcmp(argv[i], "--every") == 0) {
      rc = option_int(argc, argv, i++, 1, 100000000, &every);
    } else if (strcmp(argv[i], "--threads") == 0) {
      rc = option_int(argc, argv, i++, 0, EMBRA_MAX_THREADS, &threads);
    } else if (strcmp(argv[i], "--out") == 0 || strcmp(argv[i], "--until") == 0) {
      if (i + 1 >= argc) return bad_usage("%s needs a value%s", argv[i], "");
      if (strcmp(argv[i], "--out") == 0) {
        out = argv[++i];
      } else {
        ++i;
        if (strcmp(argv[i], "settled") == 0)
          until = EMBRA_SOLVE_UNTIL_SETTLED;
        else if (strcmp(argv[i], "tolerance") == 0)
          until = EMBRA_SOLVE_UNTIL_TOLERANCE;
        else
          return bad_usage("--until: expected settled or tolerance, got '%s'%s", argv[i], "");
      }
    } else {
      return bad_usage("unknown option '%s' for run%s", argv[i], " (see embra help)");
    }
    if (rc != 0) return rc;
  }
  embra_world* world = NULL;
  const int loaded = load_scene_file(scene, allow_outside, &world);
  if (loaded != 0) return loaded;
  /* --threads T steps on T threads (0: every core); final.json keeps the scene's own setting, so it
   * is the same file at any T (the solver's result does not depend on the thread count). */
  int32_t scene_threads = 1;
  if (threads >= 0 && set_threads(world, (int32_t)threads, &scene_threads) != 0) {
    fprintf(stderr, "embra: --threads %ld: %s\n", threads, embra_last_error_message());
    embra_world_destroy(world);
    return EXIT_INVALID;
  }
  embra_solve_def solve_def = embra_default_solve_def();
  embra_solve_result solved;
  memset(&solved, 0, sizeof solved);
  if (until >= 0) {
    solve_def.until = until;
    if (frames > 0) solve_def.max_frames = (int32_t)frames; /* --frames is at most 1e8 */
    frames = frames == 0 ? 0 : solve_def.max_frames;
  } else if (frames < 0) {
    int64_t f = 0;
    embra_world_get_scene_frames(world, &f);
    frames = (long)f;
  }
  /* --until: one call to embra_world_solve stands for the loop's frames. */
  const long calls = until >= 0 ? (frames > 0 ? 1 : 0) : frames;
  long stepped = 0;
  const int opened = open_out_dir(out, force);
  if (opened != 0) {
    embra_world_destroy(world);
    return opened;
  }
  char path[4200];
  snprintf(path, sizeof path, "%s/metrics.jsonl", out);
  FILE* metrics = open_write(path);
  if (!metrics) {
    fprintf(stderr, "embra: cannot write %s: %s\n", path, strerror(errno));
    embra_world_destroy(world);
    return EXIT_INVALID;
  }
  run_index index;
  run_index_open(&index);
  embra_body_id panel_bodies[MAX_PANEL_MESHES];
  const int panel_count = find_panel_meshes(world, panel_bodies);
  panel_totals pt;
  memset(&pt, 0, sizeof pt);
  long within_since = -1;
  const int tty = stderr_is_terminal();
  const long stride = calls >= 10 ? calls / 10 : 1;
  if (frames > 0)
    printf("%7s %9s %13s %13s %13s %13s %8s\n", "frame", "ms", "residual_max", "residual_rms", "kinetic_J", "max_speed",
           "settled");
  int rc = 0;
  double total_ms = 0.0;
  long settled_at = -1;
  embra_step_report r;
  memset(&r, 0, sizeof r);
  for (long f = 1; f <= calls; ++f) {
    const double t0 = now_ms();
    const embra_status s = until >= 0 ? embra_world_solve(world, &solve_def, &solved) : embra_world_step(world);
    const double ms = now_ms() - t0;
    total_ms += ms;
    stepped += until >= 0 ? solved.frames : 1;
    if (s != EMBRA_OK) {
      fprintf(stderr, "%sembra: frame %ld: %s\n", tty ? "\n" : "", stepped, embra_last_error_message());
      rc = s == EMBRA_ERROR_NUMERICAL ? EXIT_SIM : EXIT_INVALID;
      break;
    }
    embra_world_get_report(world, &r);
    print_broken(world);
    if (until >= 0) {
      settled_at =
          solved.outcome <= EMBRA_SOLVE_SETTLED_OUT_OF_TOLERANCE ? (long)r.frame - solve_def.hold_frames + 1 : -1;
    } else {
      if (r.settled && settled_at < 0) settled_at = (long)r.frame;
      if (!r.settled) settled_at = -1;
    }
    fprintf(metrics,
            "{\"frame\":%lld,\"time\":%.17g,\"ms\":%.6f,\"residual_max\":%.17g,\"residual_rms\":%.17g,"
            "\"kinetic_energy\":%.17g,\"max_speed\":%.17g,\"contacts\":%lld,\"settled\":%s}\n",
            (long long)r.frame, r.time, ms, r.residual_max, r.residual_rms, r.kinetic_energy, r.max_speed,
            (long long)r.contact_count, r.settled ? "true" : "false");
    if (panel_count > 0 && panel_totals_of(world, panel_bodies, panel_count, &pt) == 0) {
      fseek(metrics, -2, SEEK_CUR); /* reopen the record: drop "}\n" */
      fprintf(metrics,
              ",\"planarity_max\":%.17g,\"planarity_top_max\":%.17g,\"planarity_bottom_max\":%.17g,"
              "\"corner_distance_max\":%.17g,\"diagonal_max\":%.17g,\"thickness_error_max\":%.17g,"
              "\"miter_error_max\":%.17g,\"conical_defect_max\":%.17g,\"corner_gap_max\":%.17g,"
              "\"within_tolerance\":%s}\n",
              pt.planarity, pt.planarity_top, pt.planarity_bottom, pt.corner_distance, pt.diagonal, pt.thickness,
              pt.miter, pt.conical, pt.corner_gap, pt.within ? "true" : "false");
      if (pt.within && within_since < 0) within_since = (long)r.frame;
      if (!pt.within) within_since = -1;
    }
    write_residuals(metrics, world);
    if (f % stride == 0 || f == calls) {
      if (tty) fputs("\r\033[K", stderr); /* clear the progress bar's line */
      printf("%7lld %9.3f %13.3e %13.3e %13.3e %13.3e %8s\n", (long long)r.frame, ms, r.residual_max, r.residual_rms,
             r.kinetic_energy, r.max_speed, r.settled ? "yes" : "no");
      fflush(stdout);
    }
    if (until < 0 && every > 0 && f % every == 0) {
      snprintf(path, sizeof path, "%s/frame_%05ld.obj", out, f);
      if (write_world_obj(path, world) != 0) {
        rc = EXIT_INVALID;
        break;
      }
      snprintf(path, sizeof path, "%s/frame_%05ld.errors.json", out, f);
      if (panel_count > 0 && write_error_fields(path, world, panel_bodies, panel_count, f) != 0) {
        rc = EXIT_INVALID;
        break;
      }
      char obj_name[64], errors_name[64];
      snprintf(obj_name, sizeof obj_name, "frame_%05ld.obj", f);
      snprintf(errors_name, sizeof errors_name, "frame_%05ld.errors.json", f);
      run_index_file(&index, obj_name);
      if (panel_count > 0) run_index_file(&index, errors_name);
      run_index_frame(&index, world, f, obj_name, panel_count > 0 ? errors_name : NULL);
    }
    if (tty && until < 0 && (f % 10 == 0 || f == frames)) progress(f, frames, total_ms);
  }
  if (tty) fputc('\n', stderr);
  fclose(metrics);
  /* The state reached so far is kept whatever happened: a failed step restored the last good one. */
  snprintf(path, sizeof path, "%s/final.json", out);
  if ((threads >= 0 && set_threads(world, scene_threads, NULL) != 0) ||
      embra_world_save_file(world, path) != EMBRA_OK) {
    fprintf(stderr, "embra: %s\n", embra_last_error_message());
    if (rc == 0) rc = EXIT_INVALID;
  }
  snprintf(path, sizeof path, "%s/final.obj", out);
  if (write_world_obj(path, world) != 0 && rc == 0) rc = EXIT_INVALID;
  snprintf(path, sizeof path, "%s/final.errors.json", out);
  if (panel_count > 0 && write_error_fields(path, world, panel_bodies, panel_count, (long)r.frame) != 0 && rc == 0)
    rc = EXIT_INVALID;
  snprintf(path, sizeof path, "%s/forces.json", out);
  if (write_forces(path, world) != 0 && rc == 0) rc = EXIT_INVALID;
  run_index_file(&index, "final.json");
  run_index_file(&index, "forces.json");
  run_index_file(&index, "metrics.jsonl");
  run_index_file(&index, "final.obj");
  if (panel_count > 0) run_index_file(&index, "final.errors.json");
  run_index_frame(&index, world, (long)r.frame, "final.obj", panel_count > 0 ? "final.errors.json" : NULL);
  for (int i = 0; i < panel_count; ++i) {
    char name[64];
    snprintf(name, sizeof name, "panels_%u.json", panel_bodies[i].index);
    run_index_file(&index, name);
    snprintf(name, sizeof name, "panels_%u.csv", panel_bodies[i].index);
    run_index_file(&index, name);
  }
  if (run_index_write(&index, out) != 0 && rc == 0) rc = EXIT_INVALID;
  embra_world_counts c;
  embra_world_get_counts(world, &c);
  printf("%-18s %s\n", "scene", scene);
  printf("%-18s %d particles, %lld constraints, %d pins, %d colliders\n", "world", c.particles,
         (long long)c.constraints, c.pins, c.colliders);
  printf("%-18s %lld (%.3f s simulated)\n", "frames", (long long)r.frame, r.time);
  printf("%-18s %.3f total, %.3f per frame\n", "ms", total_ms, stepped > 0 ? total_ms / (double)stepped : 0.0);
  print_residuals(world);
  printf("%-18s %.3e J (max speed %.3e m/s)\n", "kinetic energy", r.kinetic_energy, r.max_speed);
  if (settled_at >= 0)
    printf("%-18s since frame %ld\n", "settled", settled_at);
  else
    printf("%-18s no\n", "settled");
  if (settled_at < 0 && r.frame > 0) print_fighting(world);
  if (until >= 0 && rc == 0) {
    print_solve_outcome(&solved, world);
    if (solved.outcome != EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE) rc = EXIT_UNSETTLED;
  }
  printf("%-18s %s/final.json, %s/forces.json, %s/metrics.jsonl\n", "wrote", out, out, out);
  if (panel_count > 0) {
    if (write_cuts(world, panel_bodies, panel_count, out) != 0 && rc == 0) rc = EXIT_INVALID;
    if (panel_count == 1)
      printf("%-18s %s/panels_%u.json, %s/panels_%u.csv (cut lists), %s/final.obj\n", "", out, panel_bodies[0].index,
             out, panel_bodies[0].index, out);
    else
      printf("%-18s %s/panels_<body>.json and .csv (cut lists, one per panel mesh), %s/final.obj\n", "", out, out);
    panel_totals_of(world, panel_bodies, panel_count, &pt);
    embra_tolerances tol;
    embra_world_get_tolerances(world, &tol);
    printf("\nfabrication metrics at frame %lld (%d panel mesh%s), unit scale %g mm per metre per unit\n",
           (long long)r.frame, panel_count, panel_count == 1 ? "" : "es", tol.unit_scale);
    printf("%-22s %12s %12s %10s %12s %12s\n", "metric", "max", "tolerance", "within", "max mm/m", "tol mm/m");
    print_tolerance_row("planarity top", pt.planarity_top, tol.planarity, 0.0, 0);
    print_tolerance_row("planarity bottom", pt.planarity_bottom, tol.planarity, 0.0, 0);
    print_tolerance_row("corner off plane", pt.corner_distance, tol.planarity_distance, tol.unit_scale, 1);
    print_tolerance_row("thickness error", pt.thickness, tol.thickness, tol.unit_scale, 1);
    print_tolerance_row("miter twist", pt.miter, tol.miter, tol.unit_scale, 1);
    printf("%-22s %12.3e %12s %10s\n", "diagonals / edge", pt.diagonal, "-", "-");
    printf("%-22s %12.3e %12s %10s\n", "conical defect (rad)", pt.conical, "-", "-");
    printf("%-22s %12.3e %12s %10s %12.4f\n", "corner gap (welds)", pt.corner_gap, "-", "-",
           pt.corner_gap * tol.unit_scale);
    if (within_since >= 0)
      printf("%-22s since frame %ld\n", "within tolerance", within_since);
    else
      printf("%-22s no\n", "within tolerance");
  }
  embra_world_destroy(world);
  return rc;
}

/* `embra sweep ARGS`: becomes `embra-sweep ARGS` (argv[0] "sweep" replaced); returns only when that
 * command cannot be started. */
static int cmd_sweep(char** argv) {
  argv[0] = "embra-sweep";
  fflush(NULL);
  execvp(argv[0], argv);
  fprintf(stderr,
          "embra: sweep runs the command embra-sweep (%s): install the Python package, e.g.\n"
          "  python3 -m venv --system-site-packages VENV  (Debian's python3-distributed for Dask)\n"
          "  VENV/bin/pip install --no-build-isolation --no-index host_adapters/python\n"
          "and put VENV/bin on PATH; or from a clone: PYTHONPATH=host_adapters/python "
          "EMBRA_LIBRARY=build/libembra.so python3 -m embra.sweeps ...\n",
          strerror(errno));
  return EXIT_USAGE;
}

static int run_main(int argc, char** argv) {
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) {
    fprintf(stderr, "embra: %s\n", embra_last_error_message());
    return EXIT_INVALID;
  }
  if (argc < 2) return usage();
  if (strcmp(argv[1], "help") == 0 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) return help();
  if (strcmp(argv[1], "version") == 0) {
    printf("embra %s (ABI %d)\n", embra_version_string(), embra_abi_version());
    return 0;
  }
  if (strcmp(argv[1], "validate") == 0) return cmd_validate(argc - 2, argv + 2);
  if (strcmp(argv[1], "run") == 0) return cmd_run(argc - 2, argv + 2);
  if (strcmp(argv[1], "demo") == 0 && argc >= 3 && strcmp(argv[2], "tent") == 0) return demo_tent(argc - 3, argv + 3);
  if (strcmp(argv[1], "sweep") == 0) return cmd_sweep(argv + 1);
  return bad_usage("unknown command '%s'%s", argv[1], " (see embra help)");
}

int main(int argc, char** argv) {
#ifdef _WIN32
  /* The arguments as UTF-8 (the C runtime's argv is in the ANSI code page), and UTF-8 on the console. */
  int wide_argc = 0;
  wchar_t** wide_argv = CommandLineToArgvW(GetCommandLineW(), &wide_argc);
  char** utf8_argv = wide_argv ? calloc((size_t)wide_argc + 1, sizeof *utf8_argv) : NULL;
  for (int i = 0; utf8_argv != NULL && i < wide_argc; ++i)
    if ((utf8_argv[i] = narrow(wide_argv[i])) == NULL) {
      fprintf(stderr, "embra: cannot read argument %d of the command line\n", i);
      return EXIT_USAGE;
    }
  if (wide_argv) LocalFree(wide_argv);
  if (utf8_argv == NULL) {
    fprintf(stderr, "embra: cannot read the command line\n");
    return EXIT_USAGE;
  }
  SetConsoleOutputCP(CP_UTF8);
  argc = wide_argc;
  argv = utf8_argv;
#endif
  return run_main(argc, argv);
}
