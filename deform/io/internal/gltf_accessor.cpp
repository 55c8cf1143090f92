#include "deform/io/internal/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace deform::internal {
namespace {

constexpr int kByte = 5120;
constexpr int kUnsignedByte = 5121;
constexpr int kShort = 5122;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kFloat = 5126;

// Component c of element i as a double.
double Component(const AccessorView& v, std::size_t i, int c, bool normalize) {
  const unsigned char* p =
      v.data + i * v.stride + static_cast<std::size_t>(c * ComponentBytes(v.component_type));
  switch (v.component_type) {
    case kFloat: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case kUnsignedByte:
      return normalize ? p[0] / 255.0 : p[0];
    case kByte: {
      const auto x = static_cast<signed char>(p[0]);
      return normalize ? std::max(x / 127.0, -1.0) : x;
    }
    case kUnsignedShort: {
      std::uint16_t x;
      std::memcpy(&x, p, 2);
      return normalize ? x / 65535.0 : x;
    }
    case kShort: {
      std::int16_t x;
      std::memcpy(&x, p, 2);
      return normalize ? std::max(x / 32767.0, -1.0) : x;
    }
    case kUnsignedInt: {
      std::uint32_t x;
      std::memcpy(&x, p, 4);
      return x;
    }
    default:
      return 0.0;
  }
}

std::string AccessorField(int index) { return "accessors[" + std::to_string(index) + "]"; }

}  // namespace

int ComponentBytes(int component_type) {
  switch (component_type) {
    case kByte:
    case kUnsignedByte:
      return 1;
    case kShort:
    case kUnsignedShort:
      return 2;
    case kUnsignedInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

base::Result<std::vector<float>> ReadFloats(const AccessorView& v, bool normalize,
                                            const std::string& path) {
  const auto width = static_cast<std::size_t>(v.components);
  std::vector<float> out(v.count * width);
  for (std::size_t i = 0; i < v.count; ++i) {
    for (int c = 0; c < v.components; ++c) {
      const double x = Component(v, i, c, normalize);
      if (!std::isfinite(x)) {
        return base::MakeError(base::ErrorCode::kNonFinite, {path, 0, 0, AccessorField(v.index)},
                               "non-finite value at element " + std::to_string(i) + ", component " +
                                   std::to_string(c));
      }
      out[i * width + static_cast<std::size_t>(c)] = static_cast<float>(x);
    }
  }
  return out;
}

base::Result<std::vector<std::uint32_t>> ReadUints(const AccessorView& v, std::uint64_t limit,
                                                   const std::string& what,
                                                   const std::string& path) {
  const auto width = static_cast<std::size_t>(v.components);
  std::vector<std::uint32_t> out(v.count * width);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::size_t element = i / width;
    const auto x = static_cast<std::uint32_t>(Component(v, element, static_cast<int>(i % width), false));
    if (x >= limit) {
      return base::MakeError(base::ErrorCode::kCountMismatch, {path, 0, 0, AccessorField(v.index)},
                             what + " " + std::to_string(x) + " at element " +
                                 std::to_string(element) + " past the " + std::to_string(limit) +
                                 " " + (what == "joint index" ? "joints of the skin" : "vertices"));
    }
    out[i] = x;
  }
  return out;
}

}  // namespace deform::internal
