/* A miniature of embra.h's shapes (an opaque world, a versioned def returned by value, value ids,
 * status-returning functions) in variants, to show what capi/abi/check_abi.sh accepts and refuses:
 *   (none)               the baseline
 *   FIXTURE_ADDED        a new function                      -> compatible
 *   FIXTURE_PRIVATE      the opaque world's private layout   -> compatible
 *   FIXTURE_REMOVED      a function removed                  -> incompatible
 *   FIXTURE_GROWN_DEF    a field appended to a def           -> incompatible (returned by value)
 *   FIXTURE_PARAMETER    a parameter's type changed          -> incompatible
 *   FIXTURE_GROWN_REPORT a field appended to an output struct -> incompatible (written by the library
 *                        into a host's buffer of the old size) */
#ifndef EMBRA_FIXTURE_H
#define EMBRA_FIXTURE_H
#include <stdint.h>

#define EMBRA_API __attribute__((visibility("default")))

typedef int32_t embra_status;
typedef struct embra_world embra_world;
typedef struct embra_pin_id {
  uint32_t index;
  uint32_t generation;
} embra_pin_id;

typedef struct embra_pin_def {
  int32_t version;
  int32_t particle;
  double target[3];
  double compliance;
#ifdef FIXTURE_GROWN_DEF
  double damping;
#endif
} embra_pin_def;

typedef struct embra_step_report {
  int64_t frame;
  double kinetic_energy;
#ifdef FIXTURE_GROWN_REPORT
  double residual_max;
#endif
} embra_step_report;

EMBRA_API embra_pin_def embra_default_pin_def(void);
EMBRA_API embra_status embra_world_get_report(const embra_world* world, embra_step_report* out_report);
EMBRA_API embra_status embra_world_create(embra_world** out_world);
EMBRA_API void embra_world_destroy(embra_world* world);
EMBRA_API embra_status embra_pin_create(embra_world* world, const embra_pin_def* def, embra_pin_id* out_pin);
#ifdef FIXTURE_PARAMETER
EMBRA_API embra_status embra_world_step(embra_world* world, int64_t frames);
#else
EMBRA_API embra_status embra_world_step(embra_world* world, int32_t frames);
#endif
#ifndef FIXTURE_REMOVED
EMBRA_API embra_status embra_pin_destroy(embra_world* world, embra_pin_id pin);
#endif
#ifdef FIXTURE_ADDED
EMBRA_API embra_status embra_pin_set_compliance(embra_world* world, embra_pin_id pin, double compliance);
#endif

#endif
