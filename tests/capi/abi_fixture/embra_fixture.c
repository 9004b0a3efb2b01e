/* The implementation of embra_fixture.h; see there. Built by check_abi_selftest.sh only. */
#include "embra_fixture.h"

#include <stdlib.h>
#include <string.h>

struct embra_world {
  int64_t frame;
  double positions[8];
#ifdef FIXTURE_PRIVATE
  double velocities[8]; /* private: hosts only hold pointers */
  int32_t pins;
#endif
};

embra_pin_def embra_default_pin_def(void) {
  embra_pin_def d;
  memset(&d, 0, sizeof d);
  d.version = 1;
  return d;
}

embra_status embra_world_create(embra_world** out_world) {
  *out_world = calloc(1, sizeof(embra_world));
  return *out_world ? 0 : -8;
}

void embra_world_destroy(embra_world* world) {
  free(world);
}

embra_status embra_pin_create(embra_world* world, const embra_pin_def* def, embra_pin_id* out_pin) {
  if (!world || !def || !out_pin) return -1;
  out_pin->index = (uint32_t)def->particle;
  out_pin->generation = 1;
  return 0;
}

#ifdef FIXTURE_PARAMETER
embra_status embra_world_step(embra_world* world, int64_t frames) {
#else
embra_status embra_world_step(embra_world* world, int32_t frames) {
#endif
  if (!world) return -1;
  world->frame += frames;
  return 0;
}

embra_status embra_world_get_report(const embra_world* world, embra_step_report* out_report) {
  if (!world || !out_report) return -1;
  memset(out_report, 0, sizeof *out_report);
  out_report->frame = world->frame;
  return 0;
}

#ifndef FIXTURE_REMOVED
embra_status embra_pin_destroy(embra_world* world, embra_pin_id pin) {
  return world && pin.generation ? 0 : -2;
}
#endif

#ifdef FIXTURE_ADDED
embra_status embra_pin_set_compliance(embra_world* world, embra_pin_id pin, double compliance) {
  return world && pin.generation && compliance >= 0 ? 0 : -1;
}
#endif
