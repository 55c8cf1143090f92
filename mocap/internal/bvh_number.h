#pragma once
// Number conversion shared by the BVH hierarchy parser and the motion hot loop.
// fast_float does the conversion (correctly rounded, no locale); this wrapper
// adds what BVH files need and fast_float 3.9 does not do: an optional leading
// '+', and rejection of NaN, infinity and out-of-range values.

#include <cmath>
#include <system_error>

#include <fast_float/fast_float.h>

namespace mocap::internal {

enum class NumberStatus { kOk, kBadNumber, kNonFinite };

// Converts the number starting at `first`; on success stores it in `value` and
// the first byte after it in `*next`. Does not check what follows the number:
// the caller decides whether that byte ends the token.
template <typename T>
inline NumberStatus ParseBvhNumber(const char* first, const char* last, T& value,
                                   const char** next) {
  if (first != last && *first == '+') {
    ++first;
    if (first != last && (*first == '-' || *first == '+')) return NumberStatus::kBadNumber;
  }
  const fast_float::from_chars_result r = fast_float::from_chars(first, last, value);
  if (r.ec == std::errc::result_out_of_range) return NumberStatus::kNonFinite;
  if (r.ec != std::errc()) return NumberStatus::kBadNumber;
  *next = r.ptr;
  if (!std::isfinite(value)) return NumberStatus::kNonFinite;
  return NumberStatus::kOk;
}

}  // namespace mocap::internal
