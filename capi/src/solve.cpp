// Solve to tolerance: embra_world_solve (embra/core/solve.hpp).
#include "copy.hpp"
#include "guard.hpp"

#include "embra/core/solve.hpp"
#include "embra/io/scene.hpp"

#include <algorithm>

using namespace embra::capi;

namespace {

constexpr std::tuple kSolveCopies{Copy{&embra_solve_def::max_frames, &embra::SolveSettings::max_frames},
                                  Copy{&embra_solve_def::hold_frames, &embra::SolveSettings::hold_frames},
                                  Copy{&embra_solve_def::max_seconds, &embra::SolveSettings::max_seconds}};

static_assert(embra::kResidualTargetLength == EMBRA_SOLVE_RESIDUAL_TARGET_M, "embra.h states the targets");
static_assert(embra::kResidualTargetAngle == EMBRA_SOLVE_RESIDUAL_TARGET_RAD, "embra.h states the targets");
static_assert(embra::kResidualTargetVolume == EMBRA_SOLVE_RESIDUAL_TARGET_M3, "embra.h states the targets");
static_assert(embra::kWorstResidual == EMBRA_SOLVE_WORST_RESIDUAL, "embra.h states the metric's number");

}  // namespace

extern "C" {

embra_solve_def embra_default_solve_def(void) {
  const embra::SolveSettings s;
  embra_solve_def d{};
  d.version = EMBRA_SOLVE_DEF_VERSION;
  d.until = static_cast<int32_t>(s.until);
  to_c(kSolveCopies, s, d);
  return d;
}

embra_status embra_world_solve(embra_world* world, const embra_solve_def* def, embra_solve_result* out_result) {
  embra::SolveResult r;
  const embra_status status = guard("embra_world_solve", world, [&] {
    need(out_result, "out_result");
    *out_result = embra_solve_result{};
    out_result->worst_metric = out_result->worst_layer = out_result->worst_element = -1;
    const embra_solve_def d = def ? *def : embra_default_solve_def();
    need_version(d.version, EMBRA_SOLVE_DEF_VERSION, "embra_solve_def");
    if (d.until != EMBRA_SOLVE_UNTIL_SETTLED && d.until != EMBRA_SOLVE_UNTIL_TOLERANCE)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.until must be EMBRA_SOLVE_UNTIL_SETTLED (0) or _TOLERANCE (1)");
    embra::SolveSettings s;
    s.until = static_cast<embra::SolveUntil>(d.until);
    to_core(kSolveCopies, d, s);
    // A scene's actions (pins drawn in, a collider moved) are part of the problem: at rest before
    // their last key is not the end.
    for (const embra::io::Action& a : world->meta.actions)
      for (int64_t f : a.frames) s.rest_from_frame = std::max(s.rest_from_frame, f);
    const embra::StepControl control = frame_control(world);
    const embra::Tolerances tolerances = embra::io::parse_tolerances(world->meta.tolerances);
    const int64_t frame_before = world->world.report().frame;
    try {
      r = embra::solve(world->world, s, tolerances, control);
    } catch (...) {
      out_result->frames = static_cast<int32_t>(world->world.report().frame - frame_before);
      throw;
    }
    embra_solve_result o{};
    o.outcome = static_cast<int32_t>(r.outcome);
    o.frames = r.frames;
    o.period = r.period;
    o.worst_metric = r.worst.metric;
    o.worst_layer = r.worst.layer;
    o.worst_body = from_id<embra_body_id>(r.worst.body);
    o.worst_element = r.worst.element;
    o.worst_value = r.worst.value;
    o.worst_target = r.worst.target;
    *out_result = o;
  });
  consume_cancel(world, status);
  return status;
}

}  // extern "C"
