// What the fuzz targets share: the trace of calls printed with a finding, saving a world, the
// finite-state check and the bound on a step's work. Through embra.h only.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "embra/embra.h"

namespace fuzz {

/// The calls made for the current input, printed with a finding.
inline std::string& trace() {
  static std::string t;
  return t;
}

inline void note(const std::string& line) {
  static const bool to_stderr = std::getenv("EMBRA_FUZZ_TRACE") != nullptr;
  trace() += "  " + line + "\n";
  if (to_stderr) std::fprintf(stderr, "  %s\n", line.c_str());
}

/// A finding: prints the calls and the check that failed, then aborts so libFuzzer keeps the input.
[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "embra fuzz: calls made:\n%s", trace().c_str());
  std::fprintf(stderr, "embra fuzz: FAILED: %s\n  last error: %s\n", what.c_str(), embra_last_error_message());
  std::abort();
}

/// Where two saved worlds first differ, with some text of each around it (for a finding's message).
inline std::string difference(const std::string& a, const std::string& b) {
  size_t i = 0;
  while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
  const size_t from = i > 120 ? i - 120 : 0;
  return "first difference at byte " + std::to_string(i) + ":\n    " + a.substr(from, 240) + "\n  against\n    " +
         b.substr(from, 240);
}

inline std::string fmt(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

/// The world as scene JSON (two-call pattern, checked); a world that cannot be saved is a finding.
inline std::string save(const embra_world* w, const std::string& when) {
  int64_t length = 0;
  if (embra_world_save_json(w, nullptr, 0, &length) != EMBRA_OK) fail("the world cannot be saved " + when);
  if (length < 1) fail("embra_world_save_json gave a length below 1");
  std::string text(static_cast<size_t>(length), '\x7f');
  int64_t written = 0;
  if (embra_world_save_json(w, text.data(), length, &written) != EMBRA_OK)
    fail("the world cannot be saved into a buffer of the length asked " + when);
  if (written != length || text[static_cast<size_t>(length - 1)] != '\0' ||
      std::strlen(text.c_str()) != static_cast<size_t>(length - 1))
    fail("embra_world_save_json wrote other than the NUL-terminated length it announced");
  text.pop_back();
  return text;
}

inline void check_finite(const double* v, int64_t n, const std::string& what) {
  for (int64_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) fail(what + "[" + std::to_string(i) + "] is " + fmt(v[i]));
}

/// Every position and velocity of the world is finite.
inline void check_state(const embra_world* w, const std::string& when) {
  embra_world_counts c{};
  if (embra_world_get_counts(w, &c) != EMBRA_OK) fail("embra_world_get_counts refused " + when);
  const int64_t n = 3 * int64_t{c.particles};
  std::vector<double> xyz(static_cast<size_t>(n) + 1);
  if (embra_world_get_positions(w, xyz.data(), n, 0, c.particles) != EMBRA_OK)
    fail("embra_world_get_positions of every particle refused " + when);
  check_finite(xyz.data(), n, "position " + when);
  if (embra_world_get_velocities(w, xyz.data(), n, 0, c.particles) != EMBRA_OK)
    fail("embra_world_get_velocities of every particle refused " + when);
  check_finite(xyz.data(), n, "velocity " + when);
}

/// Whether one step of `w` is within `max_work` passes x (particles + constraints): the targets
/// step only such worlds, so no input takes long.
inline bool small_step(const embra_world* w, int64_t max_work) {
  embra_solver_def s{};
  embra_world_counts c{};
  if (embra_world_get_solver(w, &s) != EMBRA_OK || embra_world_get_counts(w, &c) != EMBRA_OK) return false;
  const int64_t passes = int64_t{s.substeps} * s.iterations * (1 + int64_t{s.realign_passes});
  // Self-collision costs a broad and narrow phase a substep, about 16 projections' worth per particle
  // (a 21,000-particle self-colliding cloth at 10 substeps took 87 s a frame under the sanitizers).
  const int64_t weight = s.self_collision ? 16 : 1;
  return weight * passes * (int64_t{c.particles} + c.constraints + 1) <= max_work;
}

}  // namespace fuzz
