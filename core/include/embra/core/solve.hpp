// Solve to tolerance: step until the world is settled (and every panel mesh within its tolerance
// targets), or a frame or time budget runs out, and say why it stopped.
#pragma once

#include "embra/core/panels.hpp"
#include "embra/core/world.hpp"

#include <cstdint>

namespace embra {

enum class SolveUntil : int32_t {
  settled = 0,    // at rest (Settings::settle_speed) for hold_frames frames in a row
  tolerance = 1,  // and every panel mesh's planarity, corner distance, thickness and miter at or
                  // below their targets, and every kind's constraint residual at or below its
                  // residual target (residual_target); at rest but out of them, the stepping goes on
                  // while the worst of them still falls by 1 % over hold_frames frames
};

/// The residual targets of "within tolerance", by the unit of a kind's residual (KindInfo::unit;
/// pins and contacts: m): the largest XPBD residual |C + alpha~ lambda| of a kind over the last step
/// (StepReport::by_kind) must be at or below them. A constraint that is not satisfied (a stretched
/// inextensible link, a pin off its target, a particle inside a collider) or a compliant one whose
/// implicit step has not converged keeps a world out of tolerance however still it stands.
/// embra.h states them as EMBRA_SOLVE_RESIDUAL_TARGET_M, _RAD and _M3 (checked where it is compiled).
constexpr double kResidualTargetLength = 1e-4;  // m: 0.1 mm
constexpr double kResidualTargetAngle = 1e-3;   // rad
constexpr double kResidualTargetVolume = 1e-9;  // m^3: a cube of 1 mm
/// The target for StepReport::by_kind[kind] (a Kind, kResidualPins or kResidualContacts).
double residual_target(int kind);

/// WorstMetric::metric for a kind's residual (above its target), beside the PanelMetric values.
constexpr int32_t kWorstResidual = 16;

struct SolveSettings {
  SolveUntil until = SolveUntil::tolerance;
  int32_t max_frames = 1000;    // frame budget, >= 1
  int32_t hold_frames = 10;     // frames in a row at rest that count as settled, >= 1
  double max_seconds = 0.0;     // wall-clock budget (>= 0; 0 = none). With one, where the stepping stops
                                // depends on the machine's speed; each frame is the same bits anyway.
  int64_t rest_from_frame = 0;  // at rest counts only from this frame on (World::report().frame): a
                                // scene's scheduled actions still drive the world before their last key
};

enum class SolveOutcome : int32_t {
  settled_within_tolerance = 0,  // at rest and every panel mesh within its targets (or none)
  settled_out_of_tolerance = 1,  // at rest, a metric above its target: `worst` says which and where
  oscillating = 2,               // still moving, back and forth with `period`
  drifting = 3,                  // still moving, with no period
};

/// The metric furthest above its target (by value / target), where it is.
struct WorstMetric {
  int32_t metric = -1;   // PanelMetric (planarity, corner distance, thickness, miter), kWorstResidual; -1: none
  Id body;               // the panel mesh (none for a residual)
  int32_t element = -1;  // panel (planarity, corner distance, thickness) or joint (miter, panel_joints order);
                         // for kWorstResidual the kind (a Kind, or -1 pins, -2 contacts as in embra.h)
  int32_t layer = -1;    // 0 top, 1 bottom (planarity, corner distance); -1 otherwise
  double value = 0.0;    // in the metric's unit
  double target = 0.0;
};

struct SolveResult {
  SolveOutcome outcome = SolveOutcome::drifting;
  int32_t frames = 0;   // frames stepped by this call
  double period = 0.0;  // s, oscillating: the period of the motion; else 0
  WorstMetric worst;    // the worst metric at the end (also when within tolerance: the closest)
};

/// Steps `world` (with `control` each frame) until `settings.until` holds or a budget runs out.
/// Errors of a step pass on as from World::step (the failing frame undone, the frames before it
/// stepped). Throws Error(invalid_argument) for settings out of range, before any step.
SolveResult solve(World& world, const SolveSettings& settings, const Tolerances& tolerances,
                  const StepControl& control = {});

/// The worst metric of every panel mesh of `world` at its current positions (value / target
/// largest; metrics with a zero target rank by value); a kind whose residual in the last step report
/// is above its residual_target takes its place when further above.
WorstMetric worst_metric(const World& world, const Tolerances& tolerances);

}  // namespace embra
