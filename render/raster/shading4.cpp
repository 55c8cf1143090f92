#include "render/raster/shading4.h"

#include <cmath>

#include "render/raster/internal/simd.h"

namespace render {

#if defined(__SSE2__)

namespace {

struct Vec4x3 {
  __m128 x, y, z;
};

inline Vec4x3 Load(const float (&v)[3][4]) {
  return {_mm_load_ps(v[0]), _mm_load_ps(v[1]), _mm_load_ps(v[2])};
}
// glm::dot for vec3: (a.x * b.x + a.y * b.y) + a.z * b.z.
inline __m128 Dot(const Vec4x3& a, const Vec4x3& b) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_mul_ps(a.y, b.y)), _mm_mul_ps(a.z, b.z));
}
// glm::normalize: v * (1 / sqrt(dot(v, v))).
inline Vec4x3 Normalize(const Vec4x3& v) {
  const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(Dot(v, v)));
  return {_mm_mul_ps(v.x, inv), _mm_mul_ps(v.y, inv), _mm_mul_ps(v.z, inv)};
}
inline Vec4x3 Splat(const glm::vec3& v) {
  return {_mm_set1_ps(v.x), _mm_set1_ps(v.y), _mm_set1_ps(v.z)};
}

}  // namespace

void ShadeSurface4(const ShadingContext& ctx, const SurfacePoints4& in, float (&out)[3][4]) {
  if (ctx.model != LightingModel::kBlinnPhong) {
    for (int k = 0; k < 4; ++k) {
      const glm::vec3 c = ShadeSurface(
          ctx, {in.albedo[0][k], in.albedo[1][k], in.albedo[2][k]},
          {in.normal[0][k], in.normal[1][k], in.normal[2][k]},
          {in.position[0][k], in.position[1][k], in.position[2][k]}, in.key_visibility[k]);
      for (int ch = 0; ch < 3; ++ch) out[ch][k] = c[ch];
    }
    return;
  }
  const Vec4x3 n = Load(in.normal), p = Load(in.position);
  const Vec4x3 eye = Splat(ctx.eye);
  const Vec4x3 view = Normalize({_mm_sub_ps(eye.x, p.x), _mm_sub_ps(eye.y, p.y), _mm_sub_ps(eye.z, p.z)});
  const bool whole = ctx.shininess >= 1.0f && ctx.shininess <= 1024.0f &&
                     ctx.shininess == std::floor(ctx.shininess);
  const auto exponent = whole ? static_cast<unsigned>(ctx.shininess) : 0u;
  Vec4x3 diffuse = Splat(ctx.ambient);
  Vec4x3 spec{_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
  const glm::vec3* dirs[3] = {&ctx.key_dir, &ctx.fill_dir, &ctx.rim_dir};
  const glm::vec3* radiance[3] = {&ctx.key_radiance, &ctx.fill_radiance, &ctx.rim_radiance};
  const __m128 zero = _mm_setzero_ps();
  for (int i = 0; i < 3; ++i) {
    const Vec4x3 l = Splat(*dirs[i]);
    const __m128 n_dot_l = Dot(n, l);
    const __m128 lit = _mm_cmpgt_ps(n_dot_l, zero);
    if (!simd::Any(lit)) continue;
    Vec4x3 rad = Splat(*radiance[i]);
    if (i == 0) {  // the key light, less its shadowed share
      const __m128 v = _mm_load_ps(in.key_visibility);
      rad = {_mm_mul_ps(rad.x, v), _mm_mul_ps(rad.y, v), _mm_mul_ps(rad.z, v)};
    }
    // Unlit lanes add +0, which leaves their (non-negative) sums unchanged.
    diffuse.x = _mm_add_ps(diffuse.x, _mm_and_ps(lit, _mm_mul_ps(rad.x, n_dot_l)));
    diffuse.y = _mm_add_ps(diffuse.y, _mm_and_ps(lit, _mm_mul_ps(rad.y, n_dot_l)));
    diffuse.z = _mm_add_ps(diffuse.z, _mm_and_ps(lit, _mm_mul_ps(rad.z, n_dot_l)));
    if (!(ctx.specular > 0.0f)) continue;
    const Vec4x3 half =
        Normalize({_mm_add_ps(l.x, view.x), _mm_add_ps(l.y, view.y), _mm_add_ps(l.z, view.z)});
    const __m128 n_dot_h = Dot(n, half);
    const __m128 shine = _mm_and_ps(lit, _mm_cmpgt_ps(n_dot_h, zero));
    if (!simd::Any(shine)) continue;
    __m128 lobe;
    if (whole) {
      // PowInteger: result = 1, times x for each set bit while x is squared.
      __m128 x = n_dot_h, result = _mm_set1_ps(1.0f);
      for (unsigned e = exponent; e != 0; e >>= 1) {
        if ((e & 1u) != 0) result = _mm_mul_ps(result, x);
        x = _mm_mul_ps(x, x);
      }
      lobe = result;
    } else {
      alignas(16) float h[4], r[4];
      _mm_store_ps(h, n_dot_h);
      for (int k = 0; k < 4; ++k) r[k] = h[k] > 0.0f ? std::pow(h[k], ctx.shininess) : 0.0f;
      lobe = _mm_load_ps(r);
    }
    const __m128 weight = _mm_and_ps(shine, _mm_mul_ps(_mm_set1_ps(ctx.specular), lobe));
    spec.x = _mm_add_ps(spec.x, _mm_and_ps(shine, _mm_mul_ps(rad.x, weight)));
    spec.y = _mm_add_ps(spec.y, _mm_and_ps(shine, _mm_mul_ps(rad.y, weight)));
    spec.z = _mm_add_ps(spec.z, _mm_and_ps(shine, _mm_mul_ps(rad.z, weight)));
  }
  const Vec4x3 albedo = Load(in.albedo);
  _mm_store_ps(out[0], _mm_add_ps(_mm_mul_ps(albedo.x, diffuse.x), spec.x));
  _mm_store_ps(out[1], _mm_add_ps(_mm_mul_ps(albedo.y, diffuse.y), spec.y));
  _mm_store_ps(out[2], _mm_add_ps(_mm_mul_ps(albedo.z, diffuse.z), spec.z));
}

#else

void ShadeSurface4(const ShadingContext& ctx, const SurfacePoints4& in, float (&out)[3][4]) {
  for (int k = 0; k < 4; ++k) {
    const glm::vec3 c = ShadeSurface(ctx, {in.albedo[0][k], in.albedo[1][k], in.albedo[2][k]},
                                     {in.normal[0][k], in.normal[1][k], in.normal[2][k]},
                                     {in.position[0][k], in.position[1][k], in.position[2][k]},
                                     in.key_visibility[k]);
    for (int ch = 0; ch < 3; ++ch) out[ch][k] = c[ch];
  }
}

#endif

}  // namespace render
