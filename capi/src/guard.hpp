// What every file of the C ABI shares: the world handle, guard() (every exported function runs
// inside it: exceptions become a status code and a thread-local message; nothing unwinds into the
// host), refuse() and the argument checks (need, need_version, need_count, view, fits), and the
// conversions between C ids and vectors and the core's.
#pragma once

#include "embra/embra.h"

#include "embra/core/panels.hpp"
#include "embra/core/world.hpp"
#include "embra/io/scene.hpp"

#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

struct embra_world {
  embra::World world;
  embra::io::SceneMeta meta;  // names, actions and tolerances of a scene; empty for an API-built world
  /// Held by the call in progress (guard): a second concurrent call gets EMBRA_ERROR_LOCKED.
  mutable std::atomic<bool> busy{false};
  /// embra_world_cancel: set by any thread, consumed by the step that sees it.
  std::atomic<bool> cancel{false};
  /// The last panel mesh measured (embra_panel_mesh_get_metrics, _get_vertex_errors,
  /// _get_corner_gap), kept while its particles' positions are bit for bit the same: a host that
  /// reads a frame's metrics and several error fields measures the mesh once. A world's layouts are
  /// only ever appended, never changed, so the body and its layout's address name the layout.
  struct PanelMeasure {
    bool valid = false;
    embra::Id body;
    const embra::PanelLayout* layout = nullptr;
    std::vector<embra::Vec3> x;  // the layout's particles, first_particle onwards
    embra::PanelErrors errors;
  };
  mutable PanelMeasure panel_measure{};
};

namespace embra::capi {

/// Decimal text of an integer. Not std::to_string: its libstdc++ implementation has function-local
/// statics of default visibility (std::__detail::__to_chars_10_impl<...>::__digits) that would be
/// exported from libembra.so beside the embra_ functions.
std::string num(int64_t value);

struct Refused {
  embra_status status;
  std::string message;
};

[[noreturn]] inline void refuse(embra_status status, const std::string& message) {
  throw Refused{status, message};
}

/// The status of the exception in flight (called from a catch block), with the thread's
/// last-error message set to "<function>: <what happened>".
embra_status failed(const char* function) noexcept;

/// Runs `body`, turning every exception into a status and the thread's last-error message.
template <class F>
embra_status guard(const char* function, F&& body) noexcept {
  try {
    body();
    return EMBRA_OK;
  } catch (...) {
    return failed(function);
  }
}

template <class T>
void need(const T* p, const char* name) {
  if (p == nullptr) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(name) + " is NULL");
}

/// One call at a time on a world: held for the call's duration, refused (never waited for) when
/// another call holds it.
class WorldLock {
 public:
  explicit WorldLock(const embra_world& world) : busy_(world.busy) {
    if (busy_.exchange(true, std::memory_order_acquire))
      refuse(EMBRA_ERROR_LOCKED, "the world is in use by a call in progress on another thread (one call at a time)");
  }
  ~WorldLock() { busy_.store(false, std::memory_order_release); }
  WorldLock(const WorldLock&) = delete;
  WorldLock& operator=(const WorldLock&) = delete;

 private:
  std::atomic<bool>& busy_;
};

/// guard() for a call on a world: the world must be non-null and not in use by another call.
template <class W, class F>
embra_status guard(const char* function, W* world, F&& body) noexcept {
  return guard(function, [&] {
    need(world, "world");
    const WorldLock lock(*world);
    body();
  });
}

/// A def's version field against the version this library reads.
void need_version(int32_t got, int32_t want, const char* def);

inline void need_count(int64_t count, const char* name) {
  if (count < 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(name) + " is negative");
}

/// A boolean of a def: 0 or 1.
inline void need_flag(int32_t value, const char* name) {
  if (value != 0 && value != 1) refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(name) + " must be 0 or 1");
}

/// `n` values at `p` (which may be NULL when n is 0).
template <class T>
std::span<const T> view(const T* p, int64_t n, const char* name) {
  if (n == 0) return {};
  need(p, name);
  return {p, static_cast<size_t>(n)};
}

/// The two-call protocol of an output buffer: false when the host only asks for the size (out NULL
/// and capacity 0); else true, once `out` is known to hold the `n` values (`what`) needed.
template <class T>
bool fits(const T* out, int64_t capacity, int64_t n, const char* what) {
  if (out == nullptr && capacity == 0) return false;
  need(out, "out");
  if (capacity < n)
    refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " " + what + ", " + num(n) + " needed");
  return true;
}

/// `text` and its terminating NUL into `out` (the two-call protocol; *out_length is the size
/// needed, set also when the buffer is too small).
void write_text(const std::string& text, char* out, int64_t capacity, int64_t* out_length);

/// What a frame stepped through the C ABI reads: the scene's actions for the frame, and the world's
/// cancel flag (capi/src/world.cpp).
embra::StepControl frame_control(embra_world* world);
/// After a call that stepped: a cancel request is consumed by the step it stopped.
void consume_cancel(embra_world* world, embra_status status);

template <class T>
embra::Id to_id(T id) {
  return embra::Id{id.index, id.generation};
}
template <class T>
T from_id(embra::Id id) {
  return T{id.index, id.generation};
}

inline embra::Vec3 vec(const double* p) {
  return embra::Vec3(p[0], p[1], p[2]);
}

/// A host-owned rotation [w, x, y, z].
inline Eigen::Quaterniond quat(const double* wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}

/// A scene action that drives a destroyed pin or collider goes with it.
void drop_actions(embra::io::SceneMeta& meta, embra::io::Action::Type type, embra::Id id);

}  // namespace embra::capi
