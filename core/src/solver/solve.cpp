// Solve to tolerance: see solve.hpp.
//
// Still moving at the end: the motion is watched through three fixed random projections of the
// movable particles' positions, s_k(t) = sum_i r_ik . x_i(t) (r_ik in [-1, 1]^3 from a hash of i and
// k, the same every run), recorded once a frame. Over the last three quarters of the frames stepped,
// the projection that varies most, less its straight-line trend, is cut where it rises through zero
// (a crossing counts once the signal has been below -b and then above +b, b a quarter of its
// standard deviation, so jitter does not count); the crossing time is interpolated between frames.
// At least three crossings whose intervals all lie within 10 % of their mean make the motion
// oscillating, with the mean interval as its period; anything else is drifting.
#include "embra/core/solve.hpp"

#include "common/check.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string_view>
#include <vector>

namespace embra {

namespace {

/// A weight in [-1, 1] for particle i, projection k, coordinate c (splitmix64 of the three).
double weight(size_t i, int k, int c) {
  uint64_t z =
      static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(3 * k + c + 1) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

constexpr int kProjections = 3;

/// How far a metric is over its target (value / target; with a zero target, infinite when above it).
double over_target(double value, double target) {
  return target > 0.0 ? value / target : (value > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
}

/// The period in frames of an oscillating signal, or 0.
double period_of(const std::vector<double>& s) {
  const size_t n = s.size();
  if (n < 8) return 0.0;
  // Least-squares line a + b t, removed.
  double st = 0.0, ss = 0.0, stt = 0.0, sts = 0.0;
  for (size_t t = 0; t < n; ++t) {
    const double td = static_cast<double>(t);
    st += td, ss += s[t], stt += td * td, sts += td * s[t];
  }
  const double nd = static_cast<double>(n);
  const double den = nd * stt - st * st;
  const double b = den != 0.0 ? (nd * sts - st * ss) / den : 0.0;
  const double a = (ss - b * st) / nd;
  std::vector<double> d(n);
  double var = 0.0;
  for (size_t t = 0; t < n; ++t) {
    d[t] = s[t] - (a + b * static_cast<double>(t));
    var += d[t] * d[t];
  }
  const double band = 0.25 * std::sqrt(var / nd);
  if (!(band > 0.0)) return 0.0;
  std::vector<double> up;  // upward zero crossings, in frames
  bool below = false;
  double last_rise = -1.0;
  for (size_t t = 1; t < n; ++t) {
    if (d[t - 1] < 0.0 && d[t] >= 0.0) last_rise = static_cast<double>(t - 1) + d[t - 1] / (d[t - 1] - d[t]);
    if (d[t] < -band) below = true;
    if (d[t] > band && below && last_rise >= 0.0) {
      up.push_back(last_rise);
      below = false;
    }
  }
  if (up.size() < 3) return 0.0;
  const double mean = (up.back() - up.front()) / static_cast<double>(up.size() - 1);
  for (size_t k = 1; k < up.size(); ++k)
    if (std::abs((up[k] - up[k - 1]) - mean) > 0.1 * mean) return 0.0;
  return mean;
}

}  // namespace

double residual_target(int kind) {
  if (kind < 0 || kind >= kResidualKinds) invalid("residual_target: no such residual kind");
  if (kind >= kKindCount) return kResidualTargetLength;  // pins, contacts: m
  const std::string_view unit = kKinds[kind].unit;
  return unit == "rad" ? kResidualTargetAngle : unit == "m^3" ? kResidualTargetVolume : kResidualTargetLength;
}

WorstMetric worst_metric(const World& world, const Tolerances& tolerances) {
  WorstMetric worst;
  double worst_ratio = -1.0;
  const auto consider = [&](const PanelLayout& l, PanelMetric metric, int32_t layer, const std::vector<double>& values,
                            double target) {
    for (size_t e = 0; e < values.size(); ++e) {
      const double v = values[e];
      const double ratio = over_target(v, target);
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = WorstMetric{static_cast<int32_t>(metric), l.body, static_cast<int32_t>(e), layer, v, target};
      }
    }
  };
  for (const PanelLayout& l : world.panel_layouts()) {
    const PanelErrors e = measure_panels(l, world.positions());
    consider(l, PanelMetric::planarity, 0, e.planarity_top, tolerances.planarity.target);
    consider(l, PanelMetric::planarity, 1, e.planarity_bottom, tolerances.planarity.target);
    consider(l, PanelMetric::corner_distance, 0, e.corner_distance_top, tolerances.planarity_distance.target);
    consider(l, PanelMetric::corner_distance, 1, e.corner_distance_bottom, tolerances.planarity_distance.target);
    consider(l, PanelMetric::thickness, -1, e.thickness, tolerances.thickness.target);
    consider(l, PanelMetric::miter, -1, e.miter, tolerances.miter.target);
  }
  // The constraints' residuals, each kind in its own unit against its target: only above it, so that
  // a world within tolerance names its panel metric closest to its target (or none).
  const StepReport& report = world.report();
  for (int k = 0; k < kResidualKinds; ++k) {
    const KindResidual& r = report.by_kind[k];
    const double target = residual_target(k);
    if (r.count == 0 || !(r.max > target)) continue;
    const double ratio = r.max / target;
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      // The C numbering of the residual kinds: the constraint kinds, then -1 pins, -2 contacts.
      const int32_t kind = k < kKindCount ? k : (k == kResidualPins ? -1 : -2);
      worst = WorstMetric{kWorstResidual, Id{}, kind, -1, r.max, target};
    }
  }
  return worst;
}

SolveResult solve(World& world, const SolveSettings& settings, const Tolerances& tolerances,
                  const StepControl& control) {
  if (settings.until != SolveUntil::settled && settings.until != SolveUntil::tolerance)
    invalid("solve: until must be 0 (settled) or 1 (tolerance)");
  if (settings.max_frames < 1) invalid("solve: max_frames must be >= 1");
  if (settings.hold_frames < 1) invalid("solve: hold_frames must be >= 1");
  check_non_negative(settings.max_seconds, "solve: max_seconds");
  const auto start = std::chrono::steady_clock::now();
  const auto out_of_time = [&] {
    return settings.max_seconds > 0.0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= settings.max_seconds;
  };
  const auto ratio = [](const WorstMetric& w) { return w.metric < 0 ? 0.0 : over_target(w.value, w.target); };
  SolveResult result;
  std::array<std::vector<double>, kProjections> signal;
  int32_t at_rest = 0;
  double ratio_then = std::numeric_limits<double>::infinity();  // the worst ratio hold_frames frames ago at rest
  while (result.frames < settings.max_frames) {
    world.step(control);
    ++result.frames;
    const std::vector<Vec3>& x = world.positions();
    const std::vector<double>& inv_mass = world.inverse_masses();
    for (int k = 0; k < kProjections; ++k) {
      double sum = 0.0;
      for (size_t i = 0; i < x.size(); ++i)
        if (inv_mass[i] > 0.0)
          sum += weight(i, k, 0) * x[i].x() + weight(i, k, 1) * x[i].y() + weight(i, k, 2) * x[i].z();
      signal[k].push_back(sum);
    }
    at_rest = world.report().settled && world.report().frame >= settings.rest_from_frame ? at_rest + 1 : 0;
    if (at_rest == 0) ratio_then = std::numeric_limits<double>::infinity();
    if (at_rest >= settings.hold_frames) {
      result.worst = worst_metric(world, tolerances);
      const double now = ratio(result.worst);
      if (settings.until == SolveUntil::settled || now <= 1.0) {
        result.outcome = now <= 1.0 ? SolveOutcome::settled_within_tolerance : SolveOutcome::settled_out_of_tolerance;
        return result;
      }
      // At rest, out of tolerance: on while the worst metric still falls by 1 % per hold_frames.
      if ((at_rest - settings.hold_frames) % settings.hold_frames == 0) {
        if (!(now < 0.99 * ratio_then)) {
          result.outcome = SolveOutcome::settled_out_of_tolerance;
          return result;
        }
        ratio_then = now;
      }
    }
    if (out_of_time()) break;
  }
  result.worst = worst_metric(world, tolerances);
  if (at_rest >= settings.hold_frames) {
    result.outcome =
        ratio(result.worst) <= 1.0 ? SolveOutcome::settled_within_tolerance : SolveOutcome::settled_out_of_tolerance;
    return result;
  }
  // Still moving: oscillating or drifting (the file's comment).
  const size_t skip = signal[0].size() / 4;
  int best = 0;
  double best_var = -1.0;
  for (int k = 0; k < kProjections; ++k) {
    double mean = 0.0, var = 0.0;
    const size_t n = signal[k].size() - skip;
    for (size_t t = skip; t < signal[k].size(); ++t) mean += signal[k][t] / static_cast<double>(n);
    for (size_t t = skip; t < signal[k].size(); ++t) var += (signal[k][t] - mean) * (signal[k][t] - mean);
    if (var > best_var) best_var = var, best = k;
  }
  const std::vector<double> window(signal[best].begin() + static_cast<std::ptrdiff_t>(skip), signal[best].end());
  const double frames = period_of(window);
  result.outcome = frames > 0.0 ? SolveOutcome::oscillating : SolveOutcome::drifting;
  result.period = frames * world.settings().dt;
  return result;
}

}  // namespace embra
