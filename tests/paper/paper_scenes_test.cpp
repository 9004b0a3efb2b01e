// The paper's section 3 scenes from examples/, each checked against something physical.
#include "scene_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace embra::paper {
namespace {

// --- Flag in wind ------------------------------------------------------------------------------
// The flag hangs in the x-z plane from a pole along its edge at x = 0; the air flows along +x. A
// flag that flaps moves its free corner across the plane (along y) back and forth: after the
// start-up, the corner's y about its mean crosses zero regularly, and the signal's
// autocorrelation has a clear peak at a non-zero lag (the period). The energy stays bounded: the
// kinetic energy of the last third of the run is no larger than twice that of the middle third
// (no runaway), and never more than the work the wind could do on the whole flag moving with the
// air (0.5 m v^2, the flag's mass at the wind speed).
TEST(PaperScenes, FlagFlapsPeriodicallyWithBoundedEnergy) {
  Scene s = load_example("flag_wind.json");
  World& w = *s.world;
  const BodyInfo& flag = w.body(body_named(s, "flag"));
  const int32_t tip = flag.first_particle + flag.particle_count - 1;  // the free top corner
  const int frames = 900;                                             // 15 s, the scene's own length
  std::vector<double> y, ke;
  for (int f = 0; f < frames; ++f) {
    s.step();
    y.push_back(w.positions()[tip].y());
    ke.push_back(w.report().kinetic_energy);
  }
  // Signal after 2 s of start-up.
  const size_t start = 120;
  std::vector<double> sig(y.begin() + start, y.end());
  const double mean = std::accumulate(sig.begin(), sig.end(), 0.0) / static_cast<double>(sig.size());
  for (double& v : sig) v -= mean;
  double amplitude = 0.0;
  for (double v : sig) amplitude = std::max(amplitude, std::abs(v));
  // Crossings with hysteresis: from below -a/4 to above +a/4 and back, so jitter near zero does not count.
  int crossings = 0, side = 0;
  for (double v : sig) {
    const int now = v > 0.25 * amplitude ? 1 : v < -0.25 * amplitude ? -1 : 0;
    if (now != 0 && now != side) {
      if (side != 0) ++crossings;
      side = now;
    }
  }
  const double var = std::inner_product(sig.begin(), sig.end(), sig.begin(), 0.0);
  double best = -1.0;
  size_t best_lag = 0;
  bool left_first_peak = false;
  for (size_t lag = 1; lag < sig.size() / 2; ++lag) {  // lags up to 6.5 s
    double c = 0.0;
    for (size_t i = 0; i + lag < sig.size(); ++i) c += sig[i] * sig[i + lag];
    c /= var * static_cast<double>(sig.size() - lag) / static_cast<double>(sig.size());
    if (c < 0.0) left_first_peak = true;  // past the zero lag's lobe
    if (left_first_peak && c > best) {
      best = c;
      best_lag = lag;
    }
  }
  const auto max_of = [&](size_t a, size_t b) { return *std::max_element(ke.begin() + a, ke.begin() + b); };
  const double middle = max_of(frames / 3, 2 * frames / 3), last = max_of(2 * frames / 3, frames);
  double mass = 0.0;
  for (int32_t i = 0; i < flag.particle_count; ++i) mass += flag.masses[i];
  const double bound = 0.5 * mass * 8.0 * 8.0;
  std::printf(
      "flag: %d zero crossings in %zu frames, period %zu frames, autocorrelation %.3f, amplitude %.3f m, "
      "max KE middle %.4f J, last %.4f J, bound %.4f J\n",
      crossings, sig.size(), best_lag, best, amplitude, middle, last, bound);
  RecordProperty("autocorrelation", std::to_string(best));
  EXPECT_GE(crossings, 8);        // at least four full flaps in 13 s
  EXPECT_GT(amplitude, 0.05);     // a visible flap, not numerical noise
  EXPECT_GT(best, 0.5);           // periodic
  EXPECT_LE(last, 2.0 * middle);  // no runaway
  EXPECT_LT(*std::max_element(ke.begin(), ke.end()), bound);
}

}  // namespace
}  // namespace embra::paper
