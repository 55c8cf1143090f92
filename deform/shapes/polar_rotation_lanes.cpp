#include "deform/shapes/polar_rotation_lanes.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include <immintrin.h>

#include <glm/gtc/quaternion.hpp>

#include "deform/internal/cpu_features.h"
#include "deform/shapes/polar_rotation.h"

// The lane helpers pass vectors by value, but all are internal and always
// inlined into their callers, so no call crosses the ABI GCC warns about.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace deform {
namespace {

static_assert(sizeof(glm::dmat3) == 9 * sizeof(double), "dmat3 must be 9 packed doubles");

// Lane types built from GCC vectors: a base vector (2 or 4 doubles) or a Pair
// of them.
template <typename T>
struct Pair {
  T a, b;
};
template <typename T>
[[gnu::always_inline]] inline Pair<T> operator+(const Pair<T>& x, const Pair<T>& y) { return {x.a + y.a, x.b + y.b}; }
template <typename T>
[[gnu::always_inline]] inline Pair<T> operator-(const Pair<T>& x, const Pair<T>& y) { return {x.a - y.a, x.b - y.b}; }
template <typename T>
[[gnu::always_inline]] inline Pair<T> operator*(const Pair<T>& x, const Pair<T>& y) { return {x.a * y.a, x.b * y.b}; }
template <typename T>
[[gnu::always_inline]] inline Pair<T> operator/(const Pair<T>& x, const Pair<T>& y) { return {x.a / y.a, x.b / y.b}; }
template <typename T>
[[gnu::always_inline]] inline auto operator<(const Pair<T>& x, const Pair<T>& y) {
  return Pair<decltype(x.a < y.a)>{x.a < y.a, x.b < y.b};
}
template <typename T>
[[gnu::always_inline]] inline auto operator>(const Pair<T>& x, const Pair<T>& y) {
  return Pair<decltype(x.a > y.a)>{x.a > y.a, x.b > y.b};
}
template <typename T>
[[gnu::always_inline]] inline auto operator==(const Pair<T>& x, const Pair<T>& y) {
  return Pair<decltype(x.a == y.a)>{x.a == y.a, x.b == y.b};
}
template <typename T>
[[gnu::always_inline]] inline auto operator!=(const Pair<T>& x, const Pair<T>& y) {
  return Pair<decltype(x.a != y.a)>{x.a != y.a, x.b != y.b};
}
template <typename T>
[[gnu::always_inline]] inline Pair<T> operator|(const Pair<T>& x, const Pair<T>& y) { return {x.a | y.a, x.b | y.b}; }
template <typename T>
[[gnu::always_inline]] inline Pair<T> operator&(const Pair<T>& x, const Pair<T>& y) { return {x.a & y.a, x.b & y.b}; }
template <typename T>
[[gnu::always_inline]] inline T AndNot(const T& x, const T& y) { return x & ~y; }
template <typename T>
[[gnu::always_inline]] inline Pair<T> AndNot(const Pair<T>& x, const Pair<T>& y) {
  return {AndNot(x.a, y.a), AndNot(x.b, y.b)};
}

template <typename T>
inline constexpr int kWidth = static_cast<int>(sizeof(T) / sizeof(T{}[0]));  // lanes of a GCC vector

template <typename V, typename E>
[[gnu::always_inline]] inline V Splat(E x) {
  if constexpr (requires(V v) { v.a; }) {
    using T = decltype(V{}.a);
    return {Splat<T>(x), Splat<T>(x)};
  } else {
    return x + V{};  // x + (+0) is x for every x but -0, which is never splat
  }
}
template <typename V, typename E>
[[gnu::always_inline]] inline V Load(const E* p) {
  if constexpr (requires(V v) { v.a; }) {
    using T = decltype(V{}.a);
    return {Load<T>(p), Load<T>(p + kWidth<T>)};
  } else {
    V v;
    for (int l = 0; l < kWidth<V>; ++l) v[l] = p[l];
    return v;
  }
}
template <typename V>
[[gnu::always_inline]] inline auto Lane(const V& v, int l) {
  if constexpr (requires { v.a; }) {
    constexpr int h = kWidth<decltype(v.a)>;
    return l < h ? Lane(v.a, l) : Lane(v.b, l - h);
  } else {
    return v[l];
  }
}
template <typename M, typename V>
[[gnu::always_inline]] inline V Select(const M& m, const V& x, const V& y) {
  if constexpr (requires { m.a; }) {
    return {Select(m.a, x.a, y.a), Select(m.b, x.b, y.b)};
  } else {
    return m ? x : y;
  }
}

constexpr double kInf = std::numeric_limits<double>::infinity();

// SSE2 (the x86-64 baseline): 4 doubles as two 2-double registers.
namespace sse2 {
using E = double;
constexpr double kMinDet = kPolarNewtonMinDet, kMaxDet = kInf;
constexpr double kStop2 = kPolarNewtonStop * kPolarNewtonStop;
typedef double V2 __attribute__((vector_size(16)));
[[gnu::always_inline]] inline Pair<V2> Sqrt(const Pair<V2>& v) {
  return {V2(_mm_sqrt_pd(__m128d(v.a))), V2(_mm_sqrt_pd(__m128d(v.b)))};
}
using V = Pair<V2>;
using M = decltype(V{} < V{});
[[gnu::always_inline]] inline int Bits(const M& m) {
  return _mm_movemask_pd(__m128d(m.a)) | (_mm_movemask_pd(__m128d(m.b)) << 2);
}
#include "deform/shapes/internal/polar_lanes_kernel.inc"
}  // namespace sse2

// SSE: 4 floats in one register.
namespace sse2_float {
using E = float;
constexpr double kMinDet = kPolarFloatMinDet, kMaxDet = kPolarFloatMaxDet;
constexpr double kStop2 = kPolarFloatStop * kPolarFloatStop;
typedef float V __attribute__((vector_size(16)));
[[gnu::always_inline]] inline V Sqrt(const V& v) { return V(_mm_sqrt_ps(__m128(v))); }
using M = decltype(V{} < V{});
[[gnu::always_inline]] inline int Bits(const M& m) { return _mm_movemask_ps(__m128(m)); }
#include "deform/shapes/internal/polar_lanes_kernel.inc"
}  // namespace sse2_float

void NewtonSse2(const double* in, double* out, glm::quat* quats, std::uint8_t* ok,
                std::size_t count) {
  sse2::NewtonAll(in, out, quats, ok, count);
}
void NewtonSse2Float(const double* in, glm::quat* quats, std::uint8_t* ok, std::size_t count) {
  sse2_float::NewtonAll(in, nullptr, quats, ok, count);
}
void NewtonSse2FloatRows(const float* rows, std::size_t stride, glm::quat* quats, std::uint8_t* ok,
                         std::size_t count) {
  sse2_float::NewtonAllRows(rows, stride, quats, ok, count);
}

// AVX: 4 doubles, or 8 floats, in one register.
#pragma GCC push_options
#pragma GCC target("avx")
namespace avx {
using E = double;
constexpr double kMinDet = kPolarNewtonMinDet, kMaxDet = kInf;
constexpr double kStop2 = kPolarNewtonStop * kPolarNewtonStop;
typedef double V __attribute__((vector_size(32)));
[[gnu::always_inline]] inline V Sqrt(const V& v) { return V(_mm256_sqrt_pd(__m256d(v))); }
using M = decltype(V{} < V{});
[[gnu::always_inline]] inline int Bits(const M& m) { return _mm256_movemask_pd(__m256d(m)); }
#include "deform/shapes/internal/polar_lanes_kernel.inc"
}  // namespace avx

namespace avx_float {
using E = float;
constexpr double kMinDet = kPolarFloatMinDet, kMaxDet = kPolarFloatMaxDet;
constexpr double kStop2 = kPolarFloatStop * kPolarFloatStop;
typedef float V __attribute__((vector_size(32)));
[[gnu::always_inline]] inline V Sqrt(const V& v) { return V(_mm256_sqrt_ps(__m256(v))); }
using M = decltype(V{} < V{});
[[gnu::always_inline]] inline int Bits(const M& m) { return _mm256_movemask_ps(__m256(m)); }
#include "deform/shapes/internal/polar_lanes_kernel.inc"
}  // namespace avx_float

void NewtonAvx(const double* in, double* out, glm::quat* quats, std::uint8_t* ok,
               std::size_t count) {
  avx::NewtonAll(in, out, quats, ok, count);
}
void NewtonAvxFloat(const double* in, glm::quat* quats, std::uint8_t* ok, std::size_t count) {
  avx_float::NewtonAll(in, nullptr, quats, ok, count);
}
void NewtonAvxFloatRows(const float* rows, std::size_t stride, glm::quat* quats, std::uint8_t* ok,
                        std::size_t count) {
  avx_float::NewtonAllRows(rows, stride, quats, ok, count);
}
#pragma GCC pop_options

}  // namespace

bool PolarLanesAvxAvailable() { return internal::CpuHasAvx(); }

namespace {

// kAuto made concrete (AVX where the CPU has it, else SSE2); AVX asked for on a
// CPU without it refused, and the scalar path where the caller has none.
mocap::JobStatus ResolvePath(PolarLanesPath& path, bool has_scalar) {
  if (path == PolarLanesPath::kAuto) {
    path = PolarLanesAvxAvailable() ? PolarLanesPath::kAvx : PolarLanesPath::kSse2;
  }
  if (path == PolarLanesPath::kAvx && !PolarLanesAvxAvailable()) {
    return {mocap::JobStatus::kOutOfRange, "this CPU has no AVX"};
  }
  if (path == PolarLanesPath::kScalar && !has_scalar) {
    return {mocap::JobStatus::kOutOfRange, "the float iteration has no scalar path"};
  }
  return mocap::kJobOk;
}

}  // namespace

mocap::JobStatus PolarRotationsNewton(std::span<const glm::dmat3> blends,
                                      std::span<glm::dmat3> rotations,
                                      std::span<std::uint8_t> converged, PolarLanesPath path,
                                      std::span<glm::quat> quats) {
  const std::size_t n = blends.size();
  if ((!rotations.empty() && rotations.size() != n) || converged.size() != n ||
      (!quats.empty() && quats.size() != n)) {
    return {mocap::JobStatus::kSizeMismatch,
            "converged must be #N like blends, rotations and quats #N or empty"};
  }
  if (const mocap::JobStatus status = ResolvePath(path, true); !status) return status;
  if (n == 0) return mocap::kJobOk;
  if (path == PolarLanesPath::kScalar) {
    for (std::size_t i = 0; i < n; ++i) {
      glm::dmat3 r;
      converged[i] = PolarRotationNewton(blends[i], r) ? 1 : 0;
      if (!converged[i]) continue;
      if (!rotations.empty()) rotations[i] = r;
      if (!quats.empty()) quats[i] = glm::normalize(glm::quat(glm::quat_cast(r)));
    }
    return mocap::kJobOk;
  }
  const double* in = &blends[0][0][0];
  double* out = rotations.empty() ? nullptr : &rotations[0][0][0];
  glm::quat* q = quats.empty() ? nullptr : quats.data();
  if (path == PolarLanesPath::kAvx) {
    NewtonAvx(in, out, q, converged.data(), n);
  } else {
    NewtonSse2(in, out, q, converged.data(), n);
  }
  return mocap::kJobOk;
}

}  // namespace deform

namespace deform {

mocap::JobStatus PolarRotationsNewtonFloat(std::span<const glm::dmat3> blends,
                                           std::span<glm::quat> quats,
                                           std::span<std::uint8_t> converged, PolarLanesPath path) {
  const std::size_t n = blends.size();
  if (quats.size() != n || converged.size() != n) {
    return {mocap::JobStatus::kSizeMismatch, "quats and converged must be #N like blends"};
  }
  if (const mocap::JobStatus status = ResolvePath(path, false); !status) return status;
  if (n == 0) return mocap::kJobOk;
  if (path == PolarLanesPath::kAvx) {
    NewtonAvxFloat(&blends[0][0][0], quats.data(), converged.data(), n);
  } else {
    NewtonSse2Float(&blends[0][0][0], quats.data(), converged.data(), n);
  }
  return mocap::kJobOk;
}

}  // namespace deform

namespace deform {

mocap::JobStatus PolarRotationsNewtonFloatRows(std::span<const float> rows,
                                               std::span<glm::quat> quats,
                                               std::span<std::uint8_t> converged,
                                               PolarLanesPath path) {
  const std::size_t n = quats.size(), stride = rows.size() / 9;
  if (converged.size() != n || rows.size() % 9 != 0 || stride < n) {
    return {mocap::JobStatus::kSizeMismatch,
            "converged must be #N like quats, rows 9 x stride with stride >= #N"};
  }
  if (const mocap::JobStatus status = ResolvePath(path, false); !status) return status;
  if (n == 0) return mocap::kJobOk;
  if (path == PolarLanesPath::kAvx) {
    NewtonAvxFloatRows(rows.data(), stride, quats.data(), converged.data(), n);
  } else {
    NewtonSse2FloatRows(rows.data(), stride, quats.data(), converged.data(), n);
  }
  return mocap::kJobOk;
}

}  // namespace deform
