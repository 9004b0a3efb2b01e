// Statuses, the last-error message, versions, and the helpers of guard.hpp that are not templates.
#include "enum_pins_generated.hpp"  // the C enums cast to the core's, every value pinned
#include "guard.hpp"

#include "embra/core/limits.hpp"

#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <new>

namespace embra::capi {

namespace {

// The message, in a fixed buffer of plain chars: a thread_local with a destructor is torn down at
// thread exit by MinGW's libstdc++ in an order that can free its storage first (a host thread that
// called embra and ended could corrupt the heap: msys2/MINGW-packages#2519, #7096), so nothing here
// has one. Zero-initialised: "" until a call fails.
thread_local char g_last_error[EMBRA_MAX_ERROR_MESSAGE];

/// Sets the message to the parts one after the other, cut at a UTF-8 character boundary to what
/// the buffer holds.
void set_last_error(std::initializer_list<const char*> parts) noexcept {
  char* out = g_last_error;
  const size_t room = sizeof g_last_error - 1;
  size_t n = 0;
  unsigned char next = 0;  // the first byte left out, if any
  for (const char* part : parts) {
    for (; *part != '\0' && n < room; ++part) out[n++] = *part;
    if (*part != '\0') {
      next = static_cast<unsigned char>(*part);
      break;
    }
  }
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(out[k]); };
  if ((next & 0xc0) == 0x80) {  // the cut falls inside a character: leave all of it out
    while (n > 0 && (byte(n - 1) & 0xc0) == 0x80) --n;
    if (n > 0 && (byte(n - 1) & 0xc0) == 0xc0) --n;
  }
  out[n] = '\0';
}

embra_status map(embra::ErrorCode code) {
  switch (code) {
    case embra::ErrorCode::invalid_argument:
      return EMBRA_ERROR_INVALID_ARGUMENT;
    case embra::ErrorCode::stale_id:
      return EMBRA_ERROR_STALE_ID;
    case embra::ErrorCode::buffer_too_small:
      return EMBRA_ERROR_BUFFER_TOO_SMALL;
    case embra::ErrorCode::numerical:
      return EMBRA_ERROR_NUMERICAL;
    case embra::ErrorCode::internal:
      return EMBRA_ERROR_INTERNAL;
    case embra::ErrorCode::cancelled:
      return EMBRA_ERROR_CANCELLED;
  }
  return EMBRA_ERROR_INTERNAL;
}

}  // namespace

std::string num(int64_t value) {
  char text[24];
  std::snprintf(text, sizeof text, "%lld", static_cast<long long>(value));
  return text;
}

embra_status failed(const char* function) noexcept {
  try {
    throw;
  } catch (const Refused& r) {
    set_last_error({function, ": ", r.message.c_str()});
    return r.status;
  } catch (const embra::io::SceneError& e) {
    set_last_error({function, ": ", e.what()});
    return EMBRA_ERROR_SCHEMA;
  } catch (const embra::Error& e) {
    set_last_error({function, ": ", e.what()});
    return map(e.code());
  } catch (const std::bad_alloc&) {
    set_last_error({function, ": out of memory"});
    return EMBRA_ERROR_INTERNAL;
  } catch (const std::exception& e) {
    set_last_error({function, ": internal error: ", e.what()});
    return EMBRA_ERROR_INTERNAL;
  } catch (...) {
    set_last_error({function, ": internal error"});
    return EMBRA_ERROR_INTERNAL;
  }
}

void need_version(int32_t got, int32_t want, const char* def) {
  if (got != want)
    refuse(EMBRA_ERROR_VERSION, std::string(def) + ".version is " + num(got) + ", this library reads " + num(want) +
                                    " (start from its embra_default_ function)");
}

void write_text(const std::string& text, char* out, int64_t capacity, int64_t* out_length) {
  const int64_t n = static_cast<int64_t>(text.size()) + 1;
  if (out == nullptr && capacity == 0) {
    *out_length = n;
    return;
  }
  need(out, "out");
  if (capacity < n) {
    *out_length = n;
    refuse(EMBRA_ERROR_BUFFER_TOO_SMALL, "buffer holds " + num(capacity) + " bytes, " + num(n) + " needed");
  }
  std::memcpy(out, text.c_str(), static_cast<size_t>(n));
  *out_length = n;
}

void drop_actions(embra::io::SceneMeta& meta, embra::io::Action::Type type, embra::Id id) {
  std::erase_if(meta.actions, [&](const embra::io::Action& a) { return a.type == type && a.target == id; });
}

}  // namespace embra::capi

using embra::capi::guard;
using embra::capi::num;
using embra::capi::refuse;

// The header's numbers are the core's (limits.hpp): a drift is a compile error.
static_assert(EMBRA_MAX_ABS_VALUE == embra::limits::kMaxAbsValue);
static_assert(EMBRA_MIN_POSITIVE == embra::limits::kMinPositive);
static_assert(EMBRA_MAX_DT == embra::limits::kMaxDt);
static_assert(EMBRA_MAX_UNIT_SCALE == embra::limits::kMaxUnitScale);
static_assert(EMBRA_MAX_PARTICLES == embra::limits::kMaxParticles);
static_assert(EMBRA_MAX_CONSTRAINTS == embra::limits::kMaxConstraints);
static_assert(EMBRA_MAX_PASSES_PER_STEP == embra::limits::kMaxPassesPerStep);
static_assert(EMBRA_MAX_OBJ_BYTES == embra::limits::kMaxObjBytes);
static_assert(EMBRA_MAX_THREADS == embra::limits::kMaxThreads);
static_assert(EMBRA_GLOBAL_SOLVE_AUTO == embra::kGlobalSolveAuto);
static_assert(EMBRA_GLOBAL_SOLVE_AUTO_LIMIT == embra::kGlobalSolveAutoLimit);

extern "C" {

const char* embra_last_error_message(void) {
  return embra::capi::g_last_error;
}

const char* embra_status_name(embra_status status) {
  switch (status) {
    case EMBRA_OK:
      return "EMBRA_OK";
    case EMBRA_ERROR_INVALID_ARGUMENT:
      return "EMBRA_ERROR_INVALID_ARGUMENT";
    case EMBRA_ERROR_STALE_ID:
      return "EMBRA_ERROR_STALE_ID";
    case EMBRA_ERROR_BUFFER_TOO_SMALL:
      return "EMBRA_ERROR_BUFFER_TOO_SMALL";
    case EMBRA_ERROR_SCHEMA:
      return "EMBRA_ERROR_SCHEMA";
    case EMBRA_ERROR_VERSION:
      return "EMBRA_ERROR_VERSION";
    case EMBRA_ERROR_LOCKED:
      return "EMBRA_ERROR_LOCKED";
    case EMBRA_ERROR_NUMERICAL:
      return "EMBRA_ERROR_NUMERICAL";
    case EMBRA_ERROR_INTERNAL:
      return "EMBRA_ERROR_INTERNAL";
    case EMBRA_ERROR_CANCELLED:
      return "EMBRA_ERROR_CANCELLED";
    default:
      return "EMBRA_UNKNOWN_STATUS";
  }
}

int32_t embra_version(void) {
  return EMBRA_VERSION_MAJOR * 10000 + EMBRA_VERSION_MINOR * 100 + EMBRA_VERSION_PATCH;
}
const char* embra_version_string(void) {
  return EMBRA_VERSION_STRING;
}
int32_t embra_abi_version(void) {
  return EMBRA_ABI_VERSION;
}

embra_status embra_check_abi(int32_t header_abi_version) {
  return guard("embra_check_abi", [&] {
    if (header_abi_version != EMBRA_ABI_VERSION)
      refuse(EMBRA_ERROR_VERSION, "the host was compiled against ABI " + num(header_abi_version) +
                                      ", this library is ABI " + num(EMBRA_ABI_VERSION));
  });
}

}  // extern "C"
