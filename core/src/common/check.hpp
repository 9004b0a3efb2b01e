// Argument checks shared by every core file that validates input: the ranges of limits.hpp, one
// message per kind of refusal. Each throws embra::Error(invalid_argument) before anything changes.
#pragma once

#include "embra/core/limits.hpp"
#include "embra/core/world.hpp"

#include <cmath>
#include <string>
#include <string_view>

namespace embra {

[[noreturn]] inline void invalid(const std::string& message) {
  throw Error(ErrorCode::invalid_argument, message);
}

/// A number any door accepts: finite and within +-limits::kMaxAbsValue.
inline bool in_range(double value) {
  return std::abs(value) <= limits::kMaxAbsValue;  // false for NaN
}

inline void check_finite(double value, std::string_view what) {
  if (!in_range(value)) invalid(std::string(what) + " must be finite, within +-1e300");
}

inline void check_non_negative(double value, std::string_view what) {
  check_finite(value, what);
  if (value < 0.0) invalid(std::string(what) + " must be >= 0");
}

/// A value whose inverse is taken (a mass, a length divided by): 0 or at least limits::kMinPositive.
inline void check_zero_or_positive(double value, std::string_view what) {
  check_non_negative(value, what);
  if (value != 0.0 && value < limits::kMinPositive) invalid(std::string(what) + " must be 0 or >= 1e-300");
}

inline void check_positive(double value, std::string_view what) {
  check_finite(value, what);
  if (!(value >= limits::kMinPositive)) invalid(std::string(what) + " must be >= 1e-300");
}

}  // namespace embra
