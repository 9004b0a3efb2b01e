// The projection kernels: tight loops over the raw xyz array for the bulk of every cloth and panel
// mesh (distance, tether, dihedral, quad planarity, plane offset), the automatic tethers' runs, the
// chain pass (Settings::chain_solve) and the value passes of the residual measurement. Each is
// compiled for every lane width this machine may run (lanes.hpp): all give the same bits.
#pragma once

#include "common/pool.hpp"
#include "embra/core/world.hpp"

#include <vector>

namespace embra {

class ChainTrack;  // solver/pin_track.hpp

/// The coordinates of a position array as one array of doubles (x0 y0 z0 x1 ...); null when empty.
inline double* coords(std::vector<Vec3>& x) {
  return x.empty() ? nullptr : x.front().data();
}
inline const double* coords(const std::vector<Vec3>& x) {
  return x.empty() ? nullptr : x.front().data();
}

static_assert(sizeof(Vec3) == 3 * sizeof(double), "positions are packed xyz triples");

/// One instruction set's kernels, each over a range of one solver array. A projection kernel takes
/// one Gauss-Seidel pass of XPBD (alpha~ = compliance * inv_h2) over the constraints [begin, end) of
/// one colour, writing positions x (xyz) of particles with inverse mass w != 0: in blocks of lanes
/// with `in_lanes`, else one at a time in order (a shared tail, whose constraints may overlap).
struct Kernels {
  using Pass = void (*)(SolverArray&, size_t begin, size_t end, bool in_lanes, double inv_h2, double* x,
                        const double* w);
  using Values = void (*)(const SolverArray&, size_t begin, size_t end, const double* x, double* out);
  Pass distance, tether, dihedral, planarity, plane_offset;
  /// The chains [begin, end) of one colour (Settings::chain_solve); scratch: World::kChainScratch
  /// doubles per link of the longest chain, plus as many again.
  void (*chain)(SolverArray&, size_t begin, size_t end, bool in_lanes, double inv_h2, double* x, const double* w,
                double* scratch);
  /// The function values of constraints [begin, end) into out[begin .. end).
  Values distance_values, dihedral_values;
  /// The automatic tethers' runs pair_runs[begin .. end), or other_runs[begin .. end) with `others`.
  void (*tether_runs)(const SolverArray&, size_t begin, size_t end, bool others, double* x, const double* w);
  /// The island items [begin, end) of `plan`; rows: the group's distance, planarity and plane-offset
  /// arrays. `ends` (IslandEnds): whether the rows' multipliers are first taken from the arrays into
  /// the islands' own (IslandPlan::Shape::lambda), and afterwards given back.
  void (*islands)(const IslandPlan& plan, size_t begin, size_t end, SolverArray* const* rows, double inv_h2, double* x,
                  const double* w, int ends);
  const char* name;
};

/// Kernels::islands' `ends`: a pass's first projection of a group takes the islands' multipliers
/// from the arrays (where a global solve or an earlier pass set them; World::reset_multipliers
/// zeroes both), its last gives them back, so between them each thread writes the multipliers
/// of its own items only, on cache lines of their own (a row's place in its array colour does not
/// follow the threads' cut). Every other reader of the arrays comes after a pass's last projection:
/// a realignment (Settings::realign_passes) within the substep, else only what reads the frame's
/// last substep (the reactions, the fights, the constraints' forces), so the multipliers are given
/// back in that substep alone unless a realignment follows (World::solve).
enum IslandEnds : int { kIslandsTake = 1, kIslandsGive = 2 };

/// Calls f(kind, row) for each row of the island items [begin, end) of `plan`, island by island in
/// the islands' order (kind: 0 distance, 1 planarity, 2 plane offset; row: the index into that
/// kind's solver array).
template <class F>
void each_island_row(const IslandPlan& plan, size_t begin, size_t end, F&& f) {
  for (size_t i = begin; i < end; ++i) {
    const IslandPlan::Item& item = plan.items[i];
    const IslandPlan::Shape& shape = plan.shapes[static_cast<size_t>(item.shape)];
    const size_t steps = static_cast<size_t>(shape.steps);
    for (int32_t island = item.first; island < item.first + item.count; ++island)
      for (size_t step = 0; step < steps; ++step)
        f(static_cast<int>(shape.kind[step]),
          static_cast<size_t>(shape.row[static_cast<size_t>(island) * steps + step]));
  }
}

/// The kernels for this machine. Every set computes the same bits (lanes.hpp); EMBRA_KERNELS=scalar,
/// vec2 or avx2 forces one, to check exactly that.
const Kernels& kernels();

namespace passes {

// Items per thread below which a range is not split: a part must outweigh the hand-over (about a
// microsecond where the cores share a cache, a few where they do not). A constraint costs tens of
// nanoseconds, a chain a few links' worth each.
inline constexpr size_t kGrain = 256;
inline constexpr size_t kChainGrain = 16;
inline constexpr size_t kAlign = 4;  // parts start on a block of the widest lanes

/// Calls run(begin, end, in_lanes, part) for each colour [starts[c], starts[c + 1]) in order: split
/// over the pool's threads in blocks of lanes, except a shared tail (the last colour, when
/// `shared_tail`: its items may overlap), which runs whole on the caller, one item at a time.
template <class F>
void each_colour(ThreadPool& pool, const std::vector<int32_t>& starts, bool shared_tail, size_t grain, F&& run) {
  const size_t colours = starts.empty() ? 0 : starts.size() - 1;
  for (size_t c = 0; c < colours; ++c) {
    const size_t begin = static_cast<size_t>(starts[c]), end = static_cast<size_t>(starts[c + 1]);
    if (shared_tail && c + 1 == colours)
      run(begin, end, false, 0);
    else
      pool.run(begin, end, kAlign, grain, [&](size_t b, size_t e, int part) { run(b, e, true, part); });
  }
}

/// each_colour with `track.before(begin, end)` and `track.after(begin, end)` around every run of
/// items: each colour whole, a shared tail one tracked item at a time (`track.next(i)`: the first
/// tracked item at or after i, or SIZE_MAX) with the runs between them whole. What `before` reads
/// is then what each item's projection starts from: items of a colour share no movable particle.
/// The items run in the same order and lanes as each_colour's, so the result has the same bits.
template <class F, class Track>
void each_colour_tracked(ThreadPool& pool, const std::vector<int32_t>& starts, bool shared_tail, size_t grain, F&& run,
                         Track& track) {
  const size_t colours = starts.empty() ? 0 : starts.size() - 1;
  for (size_t c = 0; c < colours; ++c) {
    const size_t begin = static_cast<size_t>(starts[c]), end = static_cast<size_t>(starts[c + 1]);
    if (shared_tail && c + 1 == colours) {
      for (size_t i = begin; i < end;) {
        const size_t t = track.next(i);
        if (t >= end) {
          run(i, end, false, 0);
          break;
        }
        if (t > i) run(i, t, false, 0);
        track.before(t, t + 1);
        run(t, t + 1, false, 0);
        track.after(t, t + 1);
        i = t + 1;
      }
    } else {
      track.before(begin, end);
      pool.run(begin, end, kAlign, grain, [&](size_t b, size_t e, int part) { run(b, e, true, part); });
      track.after(begin, end);
    }
  }
}

/// Calls project(i) for every constraint i of `a`, colour by colour, each colour's constraints
/// split over the pool's threads (a shared tail in order on the caller): for the kinds projected
/// one constraint at a time. Constraints of one colour share no particle, so every split gives the
/// bits of the serial pass in colour order.
template <class F>
void each_constraint(ThreadPool& pool, const SolverArray& a, F&& project) {
  each_colour(pool, a.colour_start, a.shared_tail, kGrain, [&](size_t b, size_t e, bool, int) {
    for (size_t i = b; i < e; ++i) project(i);
  });
}

}  // namespace passes

// Whole passes, colour by colour, each colour's items split over the pool's threads. Items of one
// colour share no movable particle and every kernel gives an item the same bits in a block or alone,
// so the result does not depend on the thread count.

/// One pass of `kernel` over every constraint of `a`.
void project_pass(ThreadPool& pool, Kernels::Pass kernel, SolverArray& a, double inv_h2, double* x, const double* w);
/// The chain pass over every chain of `a`; `scratch` holds one equal share per thread of the pool.
/// With `track`, the hard pins' shares are tracked around every run (ChainTrack, pin_track.hpp).
void chain_pass(ThreadPool& pool, SolverArray& a, double inv_h2, double* x, const double* w,
                std::vector<double>& scratch, ChainTrack* track = nullptr);
/// Every automatic tether run of `t` (runs share no particle).
void tether_runs_pass(ThreadPool& pool, const SolverArray& t, double* x, const double* w);
/// The rest values and compliances over h^2 (inv_h2 = 1 / h^2) of the rows of `plan`'s islands in
/// single precision, from the arrays into IslandPlan::Shape::rest_single and alpha_single, rounded
/// to floats (World::step, once a frame: the arrays change between frames only).
void island_operands(const IslandPlan& plan, SolverArray* const* rows, double inv_h2);

/// The distance, planarity and plane-offset rows of a group, island by island (IslandPlan), colour
/// by colour, each colour's items split over the pool's threads (its islands share no particle).
void islands_pass(ThreadPool& pool, IslandPlan& plan, SolverArray* const* rows, double inv_h2, double* x,
                  const double* w, int ends);
/// Colour `colour` of islands_pass alone, without the items flagged in `skip` (one flag per item of
/// the plan; null: none skipped), which the caller projects itself.
void islands_colour(ThreadPool& pool, IslandPlan& plan, size_t colour, SolverArray* const* rows, double inv_h2,
                    double* x, const double* w, const uint8_t* skip, int ends);
/// The function values of every constraint of `a` into out[0 .. a.size()).
void values_pass(ThreadPool& pool, Kernels::Values kernel, const SolverArray& a, const double* x, double* out);

}  // namespace embra
