#pragma once
// Bit-for-bit equality of two arrays of trivially copyable values (no float
// comparison: -0 differs from +0, and a NaN equals the same NaN).

#include <cstring>
#include <span>
#include <type_traits>
#include <vector>

namespace testsupport {

template <typename T>
requires std::is_trivially_copyable_v<T>
bool SameBits(std::span<const T> a, std::span<const T> b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size_bytes()) == 0);
}

template <typename T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return SameBits(std::span<const T>(a), std::span<const T>(b));
}

}  // namespace testsupport
