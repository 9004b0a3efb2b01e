/* A host built against the installed package (find_package(embra) or pkg-config): checks the ABI,
 * drops one particle for 30 frames and compares it with the closed form of symplectic Euler over
 * N substeps of h: z = z0 - g h^2 N (N + 1) / 2. Prints "consumer ok" and exits 0 when it agrees. */
#include <math.h>
#include <stdio.h>

#include <embra/embra.h>

int main(void) {
  embra_world* world = NULL;
  embra_solver_def solver = embra_default_solver_def();
  embra_body_def body = embra_default_body_def();
  const double start[3] = {0.0, 0.0, 5.0};
  double now[3] = {0.0, 0.0, 0.0};
  int32_t first = -1;
  embra_body_id id;
  const int frames = 30, substeps = 10, n = frames * substeps;
  const double h = (1.0 / 60.0) / substeps;
  double expected, error;

  if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) {
    fprintf(stderr, "consumer: %s\n", embra_last_error_message());
    return 1;
  }
  solver.substeps = substeps;
  body.vertex_count = 1;
  body.positions = start;
  body.material.mass = 1.0;
  if (embra_world_create(&world, &solver) != EMBRA_OK || embra_body_create(world, &body, &id, &first) != EMBRA_OK) {
    fprintf(stderr, "consumer: %s\n", embra_last_error_message());
    embra_world_destroy(world);
    return 1;
  }
  for (int f = 0; f < frames; ++f) embra_world_step(world);
  embra_world_get_positions(world, now, 3, first, 1);
  embra_world_destroy(world);
  expected = 5.0 - 9.81 * h * h * n * (n + 1) / 2.0;
  error = fabs(now[2] - expected);
  printf("embra %s (ABI %d): z = %.15f, closed form %.15f, error %.2e\n", embra_version_string(),
         (int)embra_abi_version(), now[2], expected, error);
  if (!(error < 1e-10) || now[0] != 0.0 || now[1] != 0.0) return 1;
  printf("consumer ok\n");
  return 0;
}
