/* The `embra` command. Uses only the C ABI (embra.h), as any CAD host would.
 *
 *   embra version
 *   embra demo tent [--frames N] [--out DIR] [--every K] [--n ROWS]
 *
 * `demo tent` is the paper's Gaudi paradigm (section 3.2, figure 6): a triangular cloth pinned at
 * its three corners under reversed gravity. The membrane is elastic, so reversed gravity stretches
 * it into a doubly curved shell; the corner pins are drawn inwards to 90% of the span over the first
 * second (moving pin targets, as a designer would drag them), then held while the form settles.
 * It prints convergence as it goes and writes OBJ files of the shell.
 *
 * Exit codes: 0 ok, 1 usage, 2 invalid input, 3 the simulation failed (non-finite state). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "embra/embra.h"

enum { EXIT_USAGE = 1, EXIT_INVALID = 2, EXIT_SIM = 3 };

static int usage(void) {
  fprintf(stderr,
          "usage: embra version\n"
          "       embra demo tent [--frames N] [--out DIR] [--every K] [--n ROWS]\n");
  return EXIT_USAGE;
}

static int check(embra_status s, const char* what) {
  if (s == EMBRA_OK) return 0;
  fprintf(stderr, "embra: %s failed: %s (%s)\n", what, embra_last_error_message(), embra_status_name(s));
  return s == EMBRA_ERROR_NUMERICAL ? EXIT_SIM : EXIT_INVALID;
}

static int write_obj(const char* path, const double* xyz, int32_t n, const int32_t* tri, int32_t t) {
  FILE* f = fopen(path, "w");
  if (!f) {
    fprintf(stderr, "embra: cannot write %s: %s\n", path, strerror(errno));
    return -1;
  }
  fprintf(f, "# embra %s\n", embra_version_string());
  for (int32_t i = 0; i < n; ++i) fprintf(f, "v %.17g %.17g %.17g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  for (int32_t i = 0; i < t; ++i) fprintf(f, "f %d %d %d\n", tri[3 * i] + 1, tri[3 * i + 1] + 1, tri[3 * i + 2] + 1);
  fclose(f);
  return 0;
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
  int32_t frames = 600, every = 100, rows = 40;
  const char* out = "out/tent";
  for (int i = 0; i < argc; ++i) {
    if (i + 1 < argc && strcmp(argv[i], "--frames") == 0)
      frames = atoi(argv[++i]);
    else if (i + 1 < argc && strcmp(argv[i], "--out") == 0)
      out = argv[++i];
    else if (i + 1 < argc && strcmp(argv[i], "--every") == 0)
      every = atoi(argv[++i]);
    else if (i + 1 < argc && strcmp(argv[i], "--n") == 0)
      rows = atoi(argv[++i]);
    else
      return usage();
  }
  if (frames < 0 || every < 1 || rows < 2 || rows > 1000) return usage();
  if (mkdir(out, 0755) != 0 && errno != EEXIST) {
    /* create the parent once, for the default out/tent */
    char parent[4096];
    snprintf(parent, sizeof parent, "%s", out);
    char* slash = strrchr(parent, '/');
    if (slash) {
      *slash = 0;
      mkdir(parent, 0755);
    }
    if (mkdir(out, 0755) != 0 && errno != EEXIST) {
      fprintf(stderr, "embra: cannot create %s: %s\n", out, strerror(errno));
      return EXIT_INVALID;
    }
  }

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
      if (write_obj(path, now, n, tri, t) != 0) {
        rc = EXIT_INVALID;
        goto done_now;
      }
    }
  }
  snprintf(path, sizeof path, "%s/final.obj", out);
  if (write_obj(path, now, n, tri, t) != 0)
    rc = EXIT_INVALID;
  else
    printf("wrote %s (%d frames, %.2f s simulated)\n", path, frames, report.time);
done_now:
  free(now);
done:
  embra_world_destroy(world);
  free(xyz);
  free(tri);
  return rc;
}

int main(int argc, char** argv) {
  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) {
    fprintf(stderr, "embra: %s\n", embra_last_error_message());
    return EXIT_INVALID;
  }
  if (argc < 2) return usage();
  if (strcmp(argv[1], "version") == 0) {
    printf("embra %s (ABI %d)\n", embra_version_string(), embra_abi_version());
    return 0;
  }
  if (strcmp(argv[1], "demo") == 0 && argc >= 3 && strcmp(argv[2], "tent") == 0) return demo_tent(argc - 3, argv + 3);
  return usage();
}
