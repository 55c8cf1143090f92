#pragma once
// The SSE2 lane helpers the render kernels share: four float or int32 lanes
// per __m128 / __m128i. A mask is a lane of all ones (true) or all zeros
// (false), as the SSE compares return.
//
// Only SSE2 (the x86-64 baseline): no -march flag is needed, and golden images
// rely on none (STYLE.md section 8). Every helper is one or two instructions
// and does exactly what its scalar reading says, in that order, so a kernel
// using it gives the same bits as before. Without SSE2 only RoundToInt is
// defined; the kernels keep their scalar `#else` branches.

#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/glm.hpp>

namespace render::simd {

// Nearest integer, ties to even (lrint in the default rounding mode), without
// a libm call.
inline std::int32_t RoundToInt(float x) {
#if defined(__SSE2__)
  return _mm_cvtss_si32(_mm_set_ss(x));
#else
  return static_cast<std::int32_t>(std::lrint(x));
#endif
}

#if defined(__SSE2__)

// Per lane: mask ? a : b.
inline __m128 Select(__m128 mask, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
inline __m128i Select(__m128i mask, __m128i a, __m128i b) {
  return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
}

// Whether any lane of the mask is set.
inline bool Any(__m128 mask) { return _mm_movemask_ps(mask) != 0; }
inline bool Any(__m128i mask) { return _mm_movemask_epi8(mask) != 0; }

// Four uint32 from / to p (no alignment needed).
inline __m128i LoadU(const std::uint32_t* p) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
}
inline void StoreU(std::uint32_t* p, __m128i v) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v);
}

// Lanes (v.x, v.y, v.z, v.w).
inline __m128 Set(const glm::vec4& v) { return _mm_setr_ps(v.x, v.y, v.z, v.w); }

// Per lane: x * a.x + y * a.y + z * a.z, summed left to right, no fused
// multiply-add: four points (x, y, z) dotted with one vector a.
inline __m128 Dot(__m128 x, __m128 y, __m128 z, const glm::vec3& a) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, _mm_set1_ps(a.x)), _mm_mul_ps(y, _mm_set1_ps(a.y))),
                    _mm_mul_ps(z, _mm_set1_ps(a.z)));
}

#endif  // __SSE2__

}  // namespace render::simd
