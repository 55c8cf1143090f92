#include "render/raster/ground_shader.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "render/raster/internal/simd.h"

namespace render {
namespace {

// 2^f = sum c_k f^k (Taylor coefficients ln(2)^k / k!), |f| <= 1/2: relative
// error below 2.5e-7 in float.
constexpr float kExp2C1 = 0.693147180559945f, kExp2C2 = 0.240226506959101f,
                kExp2C3 = 0.0555041086648216f, kExp2C4 = 0.00961812910762848f,
                kExp2C5 = 0.00133335581464284f, kExp2C6 = 0.000154035303933816f;
constexpr float kLog2E = 1.44269504088896f;
constexpr float kIntegerFloat = 8388608.0f;  // 2^23: floats this large are integers
constexpr float kShadowCutR2 = 9.0f;        // ContactShadowFactor's cut (3 radii)

// The sample-space bounding box of the ground the shadow map can darken: its
// corners on the ground, projected. The whole raster when a corner is behind
// the eye (its projection says nothing) or the map does not reach the ground.
glm::ivec4 ShadowedSampleBox(const ShadowMap& map, const GroundShaderParams& params) {
  const glm::ivec4 all(0, 0, params.raster_width - 1, params.raster_height - 1);
  glm::vec3 corners[4];
  if (!map.CornersOnPlane(params.ground_y, corners)) return all;
  glm::vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const glm::vec3& c : corners) {
    const glm::vec4 clip = params.clip_from_world * glm::vec4(c, 1.0f);
    if (!(clip.w > 1e-6f)) return all;
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    const glm::vec2 s((ndc.x + 1.0f) * 0.5f * static_cast<float>(params.raster_width),
                      (1.0f - ndc.y) * 0.5f * static_cast<float>(params.raster_height));
    lo = glm::min(lo, s);
    hi = glm::max(hi, s);
  }
  // A sample of margin for rounding; clamped to the raster (also when outside it).
  const glm::vec2 max_xy(static_cast<float>(params.raster_width), static_cast<float>(params.raster_height));
  lo = glm::clamp(lo - 1.0f, glm::vec2(-1.0f), max_xy);
  hi = glm::clamp(hi + 1.0f, glm::vec2(-1.0f), max_xy);
  return {static_cast<int>(lo.x), static_cast<int>(lo.y), static_cast<int>(hi.x), static_cast<int>(hi.y)};
}

}  // namespace

GroundShader GroundShader::Create(const GroundShaderParams& params) {
  GroundShader g;
  // Ray through NDC (x, y): h = world_from_clip * (x, y, 0, 1) lies on it, so
  // d = h.xyz - eye * h.w points along it (any scale or sign serves: p below
  // divides by d.y). h is linear in (x, y), and so in the sample coordinates.
  const glm::dmat4 inv = glm::inverse(glm::dmat4(params.clip_from_world));
  const glm::dvec3 eye(params.eye);
  auto along = [&](const glm::dvec4& h) { return glm::dvec3(h) - eye * h.w; };
  const glm::dvec3 d0 = along(inv[3]), dx = along(inv[0]), dy = along(inv[1]);
  const double w = std::max(params.raster_width, 1), h = std::max(params.raster_height, 1);
  // ndc_x = (sx + 0.5) * 2 / w - 1, ndc_y = 1 - (sy + 0.5) * 2 / h.
  g.ray_x_ = glm::vec3(dx * (2.0 / w));
  g.ray_y_ = glm::vec3(dy * (-2.0 / h));
  g.ray_c_ = glm::vec3(d0 + dx * (1.0 / w - 1.0) + dy * (1.0 - 1.0 / h));
  g.eye_ = params.eye;
  g.height_ = params.ground_y - params.eye.y;
  g.ground_y_ = params.ground_y;
  const GroundStyle& style = params.style;
  g.grid_ = params.grid_spacing > 0.0f;
  g.inv_spacing_ = g.grid_ ? 1.0f / params.grid_spacing : 1.0f;
  g.half_width_ = 0.5f * style.line_width;
  g.soft_ = std::max(g.half_width_, 1e-6f);
  g.inv_soft_ = 1.0f / g.soft_;
  // The line profile is 1 up to half_width from a line, falls linearly to 0
  // over soft, and is cut at half a spacing: twice its integral from 0 to 1/2.
  {
    const float q = std::clamp(0.5f - g.half_width_, 0.0f, g.soft_);
    g.line_area_ = 2.0f * (std::min(0.5f, g.half_width_) + q - q * q * 0.5f * g.inv_soft_);
  }
  g.inv_fade_ = 1.0f / std::max(style.fade_start, 1e-3f);
  g.color_ = style.color;
  g.line_delta_ = style.line_color - style.color;
  g.light_ = params.light;
  g.shadow_map_ = params.shadow_map != nullptr && !params.shadow_map->empty() ? params.shadow_map
                                                                                 : nullptr;
  g.key_light_ = params.key_light;
  if (g.shadow_map_ != nullptr) g.map_box_ = ShadowedSampleBox(*g.shadow_map_, params);
  g.shadows_.clear();
  for (const ContactShadow& s : params.shadows) {
    if (!(s.strength > 0.0f)) continue;  // a factor of exactly 1
    g.shadows_.push_back({s.centre_xz.x, s.centre_xz.y, 1.0f / s.radius_xz.x,
                          1.0f / s.radius_xz.y, s.strength});
  }
  return g;
}

#if defined(__SSE2__)

namespace {

inline __m128 Abs(__m128 x) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), x); }

// |x - nearest integer|, 0 where |x| >= 2^23 (or x is not finite), as
// DistanceToInteger in shading.cpp.
inline __m128 DistanceToInteger4(__m128 x) {
  const __m128 small = _mm_cmplt_ps(Abs(x), _mm_set1_ps(kIntegerFloat));
  const __m128 nearest = _mm_cvtepi32_ps(_mm_cvtps_epi32(x));
  return _mm_and_ps(small, Abs(_mm_sub_ps(x, nearest)));
}

inline __m128 Clamp01(__m128 x) {
  return _mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), _mm_set1_ps(1.0f));
}

// exp(x) for x in [-126 ln 2, 0].
inline __m128 ExpNonPositive4(__m128 x) {
  const __m128 y = _mm_max_ps(_mm_mul_ps(x, _mm_set1_ps(kLog2E)), _mm_set1_ps(-126.0f));
  const __m128i k = _mm_cvtps_epi32(y);  // nearest integer
  const __m128 f = _mm_sub_ps(y, _mm_cvtepi32_ps(k));
  __m128 p = _mm_set1_ps(kExp2C6);
  p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(kExp2C5));
  p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(kExp2C4));
  p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(kExp2C3));
  p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(kExp2C2));
  p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(kExp2C1));
  p = _mm_add_ps(_mm_mul_ps(p, f), _mm_set1_ps(1.0f));
  // Times 2^k: add k to the exponent field (p is in [0.7, 1.5], k >= -126).
  return _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(p), _mm_slli_epi32(k, 23)));
}

// floor(x) for |x| < 2^31.
inline __m128 Floor4(__m128 x) {
  const __m128 t = _mm_cvtepi32_ps(_mm_cvttps_epi32(x));
  return _mm_sub_ps(t, _mm_and_ps(_mm_cmpgt_ps(t, x), _mm_set1_ps(1.0f)));
}

// The grid line profile along one axis, in spacings: 1 within half_width of
// an integer, falling linearly to 0 over soft, cut at half a spacing.
struct LineProfile {
  float half_width, soft, inv_soft, area;  // area: its integral over one spacing
};

// The profile's integral from 0 to u: whole spacings times the area, plus the
// closed form over the last part (by symmetry about 1/2).
inline __m128 LineIntegral4(__m128 u, const LineProfile& p) {
  const __m128 k = Floor4(u);
  const __m128 t = _mm_sub_ps(u, k);  // [0, 1)
  const __m128 upper = _mm_cmpgt_ps(t, _mm_set1_ps(0.5f));
  const __m128 s = simd::Select(upper, _mm_sub_ps(_mm_set1_ps(1.0f), t), t);  // [0, 1/2]
  const __m128 q = _mm_min_ps(
      _mm_max_ps(_mm_sub_ps(s, _mm_set1_ps(p.half_width)), _mm_setzero_ps()), _mm_set1_ps(p.soft));
  const __m128 g = _mm_sub_ps(_mm_add_ps(_mm_min_ps(s, _mm_set1_ps(p.half_width)), q),
                              _mm_mul_ps(_mm_mul_ps(q, q), _mm_set1_ps(0.5f * p.inv_soft)));
  const __m128 area = _mm_set1_ps(p.area);
  return _mm_add_ps(_mm_mul_ps(k, area), simd::Select(upper, _mm_sub_ps(area, g), g));
}

// The profile's mean over [u - w/2, u + w/2]: u is first taken to its offset
// from the nearest line (0 where |u| >= 2^23 or u is not finite, as
// DistanceToInteger4), w is kept in [1e-4, 1e4] spacings.
inline __m128 FilteredLine4(__m128 u, __m128 w, const LineProfile& p) {
  const __m128 small = _mm_cmplt_ps(Abs(u), _mm_set1_ps(kIntegerFloat));
  u = _mm_and_ps(small, _mm_sub_ps(u, _mm_cvtepi32_ps(_mm_cvtps_epi32(u))));
  w = _mm_min_ps(_mm_max_ps(w, _mm_set1_ps(1e-4f)), _mm_set1_ps(1e4f));  // NaN: 1e-4
  const __m128 half = _mm_mul_ps(w, _mm_set1_ps(0.5f));
  const __m128 mean = _mm_div_ps(
      _mm_sub_ps(LineIntegral4(_mm_add_ps(u, half), p), LineIntegral4(_mm_sub_ps(u, half), p)), w);
  return Clamp01(mean);
}

// The rays through sample positions (x[k], y) and where they meet the ground:
// d = ray_c + ray_x x + ray_y y, p = eye + t d with t = height / d.y.
struct GroundHits4 {
  __m128 dx, dy, dz;  // the ray directions (unnormalized)
  __m128 t;           // the ray parameter of the ground
  __m128 ox, oz;      // p - eye, xz
  __m128 px, pz;      // p, xz
};

inline GroundHits4 HitGround4(const glm::vec3& ray_c, const glm::vec3& ray_x,
                              const glm::vec3& ray_y, const glm::vec3& eye, float height, __m128 x,
                              float y) {
  const glm::vec3 c = ray_c + ray_y * y;  // the row's part of the ray
  GroundHits4 h;
  h.dx = _mm_add_ps(_mm_set1_ps(c.x), _mm_mul_ps(_mm_set1_ps(ray_x.x), x));
  h.dy = _mm_add_ps(_mm_set1_ps(c.y), _mm_mul_ps(_mm_set1_ps(ray_x.y), x));
  h.dz = _mm_add_ps(_mm_set1_ps(c.z), _mm_mul_ps(_mm_set1_ps(ray_x.z), x));
  h.t = _mm_div_ps(_mm_set1_ps(height), h.dy);
  h.ox = _mm_mul_ps(h.dx, h.t);
  h.oz = _mm_mul_ps(h.dz, h.t);
  h.px = _mm_add_ps(_mm_set1_ps(eye.x), h.ox);
  h.pz = _mm_add_ps(_mm_set1_ps(eye.z), h.oz);
  return h;
}

// The grid lines' fade with the eye distance |(ox, height, oz)|, in spacings:
// 1 up to fade_start spacings, 0 from twice that.
inline __m128 LineFade4(__m128 ox, __m128 oz, float height, __m128 inv_spacing, float inv_fade) {
  const __m128 one = _mm_set1_ps(1.0f);
  const __m128 dist2 =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(ox, ox), _mm_mul_ps(oz, oz)), _mm_set1_ps(height * height));
  const __m128 spacings = _mm_mul_ps(_mm_sqrt_ps(dist2), inv_spacing);
  return _mm_sub_ps(one, Clamp01(_mm_sub_ps(_mm_mul_ps(spacings, _mm_set1_ps(inv_fade)), one)));
}

}  // namespace

template <>
void GroundShader::Finish4(__m128 px, __m128 pz, __m128 line, const float* visibility, float* r,
                           float* g, float* b) const {
  __m128 shadow = _mm_set1_ps(1.0f);
  for (const Shadow& s : shadows_) {
    const __m128 ux = _mm_mul_ps(_mm_sub_ps(px, _mm_set1_ps(s.cx)), _mm_set1_ps(s.inv_rx));
    const __m128 uz = _mm_mul_ps(_mm_sub_ps(pz, _mm_set1_ps(s.cz)), _mm_set1_ps(s.inv_rz));
    const __m128 r2 = _mm_add_ps(_mm_mul_ps(ux, ux), _mm_mul_ps(uz, uz));
    const __m128 inside = _mm_cmplt_ps(r2, _mm_set1_ps(kShadowCutR2));
    if (!simd::Any(inside)) continue;
    const __m128 e = ExpNonPositive4(_mm_mul_ps(_mm_set1_ps(-2.0f), _mm_and_ps(inside, r2)));
    const __m128 f = _mm_sub_ps(_mm_set1_ps(1.0f), _mm_mul_ps(_mm_set1_ps(s.strength), e));
    shadow = _mm_mul_ps(shadow, simd::Select(inside, f, _mm_set1_ps(1.0f)));
  }

  // 1 - visibility of the key light per lane (exactly 0 where lit).
  __m128 occluded = _mm_setzero_ps();
  if (visibility != nullptr) occluded = _mm_sub_ps(_mm_set1_ps(1.0f), _mm_loadu_ps(visibility));
  auto channel = [&](float base, float delta, float light, float key, float* out) {
    const __m128 albedo = _mm_add_ps(_mm_set1_ps(base), _mm_mul_ps(_mm_set1_ps(delta), line));
    const __m128 lit = _mm_sub_ps(_mm_set1_ps(light), _mm_mul_ps(_mm_set1_ps(key), occluded));
    _mm_storeu_ps(out, _mm_mul_ps(_mm_mul_ps(albedo, lit), shadow));
  };
  channel(color_.x, line_delta_.x, light_.x, key_light_.x, r);
  channel(color_.y, line_delta_.y, light_.y, key_light_.y, g);
  channel(color_.z, line_delta_.z, light_.z, key_light_.z, b);
}

void GroundShader::Shade4(int sx, int sy, float* r, float* g, float* b) const {
  const __m128 x = _mm_add_ps(_mm_set1_ps(static_cast<float>(sx)), _mm_setr_ps(0, 1, 2, 3));
  const GroundHits4 h =
      HitGround4(ray_c_, ray_x_, ray_y_, eye_, height_, x, static_cast<float>(sy));
  const __m128 px = h.px, pz = h.pz;

  __m128 line = _mm_setzero_ps();  // grid line weight, 0..1
  if (grid_) {
    const __m128 inv_spacing = _mm_set1_ps(inv_spacing_);
    const __m128 d = _mm_min_ps(DistanceToInteger4(_mm_mul_ps(px, inv_spacing)),
                                DistanceToInteger4(_mm_mul_ps(pz, inv_spacing)));
    const __m128 from_edge = _mm_sub_ps(d, _mm_set1_ps(half_width_));
    // Between lines (from_edge >= soft) the weight is exactly 0.
    const __m128 near = _mm_cmplt_ps(from_edge, _mm_set1_ps(soft_));
    if (simd::Any(near)) {
      const __m128 one = _mm_set1_ps(1.0f);
      line = _mm_sub_ps(one, Clamp01(_mm_mul_ps(from_edge, _mm_set1_ps(inv_soft_))));
      const __m128 fade = LineFade4(h.ox, h.oz, height_, inv_spacing, inv_fade_);
      line = _mm_and_ps(near, _mm_mul_ps(line, fade));
    }
  }

  const bool read_map = shadow_map_ != nullptr && sy >= map_box_.y && sy <= map_box_.w &&
                        sx + 3 >= map_box_.x && sx <= map_box_.z;
  alignas(16) float v4[4];
  if (read_map) {
    alignas(16) float x4[4], z4[4];
    _mm_store_ps(x4, px);
    _mm_store_ps(z4, pz);
    shadow_map_->Visibility4(x4, ground_y_, z4, v4);
  }
  Finish4(px, pz, line, read_map ? v4 : nullptr, r, g, b);
}

void GroundShader::ShadePixels4(int sx, int sy, int ss, float* r, float* g, float* b) const {
  // The pixels' centres in sample coordinates (a sample's centre is at its index).
  const float centre = 0.5f * static_cast<float>(ss - 1);
  const auto step = static_cast<float>(ss);
  const __m128 x = _mm_add_ps(_mm_set1_ps(static_cast<float>(sx) + centre),
                              _mm_mul_ps(_mm_set1_ps(step), _mm_setr_ps(0, 1, 2, 3)));
  const GroundHits4 h =
      HitGround4(ray_c_, ray_x_, ray_y_, eye_, height_, x, static_cast<float>(sy) + centre);
  const __m128 dx = h.dx, dy = h.dy, dz = h.dz, t = h.t, px = h.px, pz = h.pz;

  __m128 line = _mm_setzero_ps();
  if (grid_) {
    // The pixel's edges on the ground: p = eye + t d with t = height / d.y,
    // so dp/ds = t (ray_s - d ray_s.y / d.y) per sample step s; times ss.
    const __m128 inv_dy = _mm_div_ps(_mm_set1_ps(1.0f), dy);
    auto edge = [&](const glm::vec3& ray, __m128 d_axis, float ray_axis) {
      const __m128 along = _mm_mul_ps(_mm_set1_ps(ray.y), inv_dy);
      return _mm_mul_ps(_mm_mul_ps(t, _mm_set1_ps(step * inv_spacing_)),
                        _mm_sub_ps(_mm_set1_ps(ray_axis), _mm_mul_ps(d_axis, along)));
    };
    const __m128 ux = edge(ray_x_, dx, ray_x_.x), uy = edge(ray_y_, dx, ray_y_.x);
    const __m128 vx = edge(ray_x_, dz, ray_x_.z), vy = edge(ray_y_, dz, ray_y_.z);
    // One box per axis with the variance of the footprint's projection onto it
    // (two boxes convolved, widths |ux| and |uy|).
    const __m128 wu = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(ux, ux), _mm_mul_ps(uy, uy)));
    const __m128 wv = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(vx, vx), _mm_mul_ps(vy, vy)));
    const __m128 inv_spacing = _mm_set1_ps(inv_spacing_);
    const __m128 u = _mm_mul_ps(px, inv_spacing), v = _mm_mul_ps(pz, inv_spacing);
    // A lane is off every line when its box ends before the profile starts.
    const __m128 reach = _mm_set1_ps(half_width_ + soft_);
    const __m128 half = _mm_set1_ps(0.5f);
    const __m128 near =
        _mm_or_ps(_mm_cmplt_ps(_mm_sub_ps(DistanceToInteger4(u), _mm_mul_ps(half, wu)), reach),
                  _mm_cmplt_ps(_mm_sub_ps(DistanceToInteger4(v), _mm_mul_ps(half, wv)), reach));
    if (simd::Any(near)) {
      const LineProfile profile{half_width_, soft_, inv_soft_, line_area_};
      const __m128 one = _mm_set1_ps(1.0f);
      const __m128 lu = FilteredLine4(u, wu, profile), lv = FilteredLine4(v, wv, profile);
      // Either line: the union of the two axes' coverages.
      line = _mm_sub_ps(one, _mm_mul_ps(_mm_sub_ps(one, lu), _mm_sub_ps(one, lv)));
      const __m128 fade = LineFade4(h.ox, h.oz, height_, inv_spacing, inv_fade_);
      line = _mm_and_ps(near, _mm_mul_ps(line, fade));
    }
  }
  const int last = sx + 4 * ss - 1;
  const bool read_map = shadow_map_ != nullptr && sy + ss - 1 >= map_box_.y && sy <= map_box_.w &&
                        last >= map_box_.x && sx <= map_box_.z;
  alignas(16) float visibility[4];
  if (read_map) PixelVisibility4(sx, sy, ss, visibility);
  Finish4(px, pz, line, read_map ? visibility : nullptr, r, g, b);
}

void GroundShader::PixelVisibility4(int sx, int sy, int ss, float* visibility) const {
  // Sample (i, j) of the four pixels sits ss samples apart in x.
  __m128 sum = _mm_setzero_ps();
  for (int j = 0; j < ss; ++j) {
    for (int i = 0; i < ss; ++i) {
      const __m128 x =
          _mm_add_ps(_mm_set1_ps(static_cast<float>(sx + i)),
                     _mm_mul_ps(_mm_set1_ps(static_cast<float>(ss)), _mm_setr_ps(0, 1, 2, 3)));
      const GroundHits4 h =
          HitGround4(ray_c_, ray_x_, ray_y_, eye_, height_, x, static_cast<float>(sy + j));
      alignas(16) float x4[4], z4[4], v4[4];
      _mm_store_ps(x4, h.px);
      _mm_store_ps(z4, h.pz);
      shadow_map_->Visibility4(x4, ground_y_, z4, v4);
      sum = _mm_add_ps(sum, _mm_load_ps(v4));
    }
  }
  _mm_storeu_ps(visibility, _mm_mul_ps(sum, _mm_set1_ps(1.0f / static_cast<float>(ss * ss))));
}

#else  // the same operations, one lane at a time

namespace {

float DistanceToInteger1(float x) {
  if (!(std::abs(x) < kIntegerFloat)) return 0.0f;
  return std::abs(x - std::nearbyint(x));
}

float ExpNonPositive1(float x) {
  const float y = std::max(x * kLog2E, -126.0f);
  const float k = std::nearbyint(y);
  const float f = y - k;
  float p = kExp2C6;
  for (float c : {kExp2C5, kExp2C4, kExp2C3, kExp2C2, kExp2C1, 1.0f}) p = p * f + c;
  return std::ldexp(p, static_cast<int>(k));
}

// The profile's integral from 0 to u (see the SSE version).
float LineIntegral1(float u, float hw, float soft, float inv_soft, float area) {
  const float k = std::floor(u), t = u - k;
  const bool upper = t > 0.5f;
  const float s = upper ? 1.0f - t : t;
  const float q = std::min(std::max(s - hw, 0.0f), soft);
  const float g = std::min(s, hw) + q - q * q * (0.5f * inv_soft);
  return k * area + (upper ? area - g : g);
}

}  // namespace

template <>
void GroundShader::Finish4(const float* px, const float* pz, const float* line,
                           const float* visibility, float* r, float* g, float* b) const {
  for (int k = 0; k < 4; ++k) {
    float shadow = 1.0f;
    for (const Shadow& s : shadows_) {
      const float ux = (px[k] - s.cx) * s.inv_rx, uz = (pz[k] - s.cz) * s.inv_rz;
      const float r2 = ux * ux + uz * uz;
      if (r2 < kShadowCutR2) shadow *= 1.0f - s.strength * ExpNonPositive1(-2.0f * r2);
    }
    const float occluded = visibility != nullptr ? 1.0f - visibility[k] : 0.0f;
    const glm::vec3 lit = light_ - key_light_ * occluded;
    const glm::vec3 albedo = color_ + line_delta_ * line[k];
    r[k] = albedo.x * lit.x * shadow;
    g[k] = albedo.y * lit.y * shadow;
    b[k] = albedo.z * lit.z * shadow;
  }
}

void GroundShader::Shade4(int sx, int sy, float* r, float* g, float* b) const {
  const glm::vec3 c = ray_c_ + ray_y_ * static_cast<float>(sy);
  float px[4], pz[4], line[4];
  for (int k = 0; k < 4; ++k) {
    const float x = static_cast<float>(sx) + static_cast<float>(k);
    const float dx = c.x + ray_x_.x * x, dy = c.y + ray_x_.y * x, dz = c.z + ray_x_.z * x;
    const float t = height_ / dy;
    const float ox = dx * t, oz = dz * t;
    px[k] = eye_.x + ox;
    pz[k] = eye_.z + oz;
    line[k] = 0.0f;
    if (grid_) {
      const float d = std::min(DistanceToInteger1(px[k] * inv_spacing_),
                               DistanceToInteger1(pz[k] * inv_spacing_));
      const float from_edge = d - half_width_;
      if (from_edge < soft_) {
        line[k] = 1.0f - std::clamp(from_edge * inv_soft_, 0.0f, 1.0f);
        const float spacings = std::sqrt(ox * ox + oz * oz + height_ * height_) * inv_spacing_;
        line[k] *= 1.0f - std::clamp(spacings * inv_fade_ - 1.0f, 0.0f, 1.0f);
      }
    }
  }
  float visibility[4];
  for (int k = 0; k < 4 && shadow_map_ != nullptr; ++k)
    visibility[k] = shadow_map_->Visibility({px[k], ground_y_, pz[k]});
  Finish4<const float*>(px, pz, line, shadow_map_ != nullptr ? visibility : nullptr, r, g, b);
}

void GroundShader::ShadePixels4(int sx, int sy, int ss, float* r, float* g, float* b) const {
  const float centre = 0.5f * static_cast<float>(ss - 1), step = static_cast<float>(ss);
  const glm::vec3 c = ray_c_ + ray_y_ * (static_cast<float>(sy) + centre);
  float px[4], pz[4], line[4];
  for (int k = 0; k < 4; ++k) {
    const float x = static_cast<float>(sx) + centre + step * static_cast<float>(k);
    const glm::vec3 d = c + ray_x_ * x;
    const float t = height_ / d.y;
    const float ox = d.x * t, oz = d.z * t;
    px[k] = eye_.x + ox;
    pz[k] = eye_.z + oz;
    line[k] = 0.0f;
    if (!grid_) continue;
    const glm::vec3 ex = t * (ray_x_ - d * (ray_x_.y / d.y)) * (step * inv_spacing_);
    const glm::vec3 ey = t * (ray_y_ - d * (ray_y_.y / d.y)) * (step * inv_spacing_);
    auto filtered = [&](float u, float w) {
      u = std::abs(u) < kIntegerFloat ? u - std::nearbyint(u) : 0.0f;
      w = std::isnan(w) ? 1e-4f : std::clamp(w, 1e-4f, 1e4f);
      const float mean = (LineIntegral1(u + 0.5f * w, half_width_, soft_, inv_soft_, line_area_) -
                          LineIntegral1(u - 0.5f * w, half_width_, soft_, inv_soft_, line_area_)) /
                         w;
      return std::clamp(mean, 0.0f, 1.0f);
    };
    const float lu = filtered(px[k] * inv_spacing_, std::hypot(ex.x, ey.x));
    const float lv = filtered(pz[k] * inv_spacing_, std::hypot(ex.z, ey.z));
    const float spacings = std::sqrt(ox * ox + oz * oz + height_ * height_) * inv_spacing_;
    line[k] = (1.0f - (1.0f - lu) * (1.0f - lv)) *
              (1.0f - std::clamp(spacings * inv_fade_ - 1.0f, 0.0f, 1.0f));
  }
  float visibility[4];
  if (shadow_map_ != nullptr) PixelVisibility4(sx, sy, ss, visibility);
  Finish4<const float*>(px, pz, line, shadow_map_ != nullptr ? visibility : nullptr, r, g, b);
}

void GroundShader::PixelVisibility4(int sx, int sy, int ss, float* visibility) const {
  for (int k = 0; k < 4; ++k) {
    float sum = 0.0f;
    for (int j = 0; j < ss; ++j) {
      for (int i = 0; i < ss; ++i) {
        const glm::vec3 d = ray_c_ + ray_y_ * static_cast<float>(sy + j) +
                            ray_x_ * static_cast<float>(sx + ss * k + i);
        const float t = height_ / d.y;
        sum += shadow_map_->Visibility({eye_.x + d.x * t, ground_y_, eye_.z + d.z * t});
      }
    }
    visibility[k] = sum / static_cast<float>(ss * ss);
  }
}

#endif

glm::vec3 GroundShader::Shade(int sx, int sy) const {
  float r[4], g[4], b[4];
  Shade4(sx, sy, r, g, b);
  return {r[0], g[0], b[0]};
}

}  // namespace render
