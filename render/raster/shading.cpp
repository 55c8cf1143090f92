#include "render/raster/shading.h"

#include <algorithm>
#include <cmath>

#include "render/raster/internal/simd.h"

namespace render {

namespace {
glm::vec3 ToWorld(const glm::mat3& world_from_view, const glm::vec3& v) {
  const float len = glm::length(v);
  return len > 0.0f ? world_from_view * (v / len) : glm::vec3(0.0f, 0.0f, 1.0f);
}
}  // namespace

ShadingContext MakeShadingContext(const LightRig& rig, LightingModel model,
                                  const glm::mat4& view_from_world) {
  ShadingContext ctx;
  ctx.model = model;
  const glm::mat4 world_from_view = glm::inverse(view_from_world);
  ctx.eye = glm::vec3(world_from_view[3]);
  const glm::mat3 rotation(world_from_view);
  ctx.key_dir = ToWorld(rotation, rig.key.direction_view);
  ctx.fill_dir = ToWorld(rotation, rig.fill.direction_view);
  ctx.rim_dir = ToWorld(rotation, rig.rim.direction_view);
  ctx.key_radiance = rig.key.color * rig.key.intensity;
  ctx.fill_radiance = rig.fill.color * rig.fill.intensity;
  ctx.rim_radiance = rig.rim.color * rig.rim.intensity;
  ctx.ambient = rig.ambient;
  ctx.specular = rig.specular;
  ctx.shininess = rig.shininess;
  return ctx;
}

namespace {

// x^n by repeated squaring (n >= 1): a handful of multiplies instead of powf.
float PowInteger(float x, unsigned n) {
  float result = 1.0f;
  while (n != 0) {
    if ((n & 1u) != 0) result *= x;
    x *= x;
    n >>= 1;
  }
  return result;
}

}  // namespace

glm::vec3 ShadeSurface(const ShadingContext& ctx, const glm::vec3& albedo,
                       const glm::vec3& normal, const glm::vec3& position, float key_visibility) {
  switch (ctx.model) {
    case LightingModel::kUnlit:
      return albedo;
    case LightingModel::kLambert: {
      const float n_dot_l = std::max(glm::dot(normal, ctx.key_dir), 0.0f);
      return albedo * (ctx.ambient + ctx.key_radiance * key_visibility * n_dot_l);
    }
    case LightingModel::kBlinnPhong:
      break;
  }
  const glm::vec3 view = glm::normalize(ctx.eye - position);
  // Whole exponents (the default 32) by squaring; others through powf.
  const bool whole = ctx.shininess >= 1.0f && ctx.shininess <= 1024.0f &&
                     ctx.shininess == std::floor(ctx.shininess);
  const auto exponent = whole ? static_cast<unsigned>(ctx.shininess) : 0u;
  glm::vec3 diffuse = ctx.ambient;
  glm::vec3 spec(0.0f);
  const glm::vec3* dirs[3] = {&ctx.key_dir, &ctx.fill_dir, &ctx.rim_dir};
  const glm::vec3* radiance[3] = {&ctx.key_radiance, &ctx.fill_radiance, &ctx.rim_radiance};
  for (int i = 0; i < 3; ++i) {
    const float n_dot_l = glm::dot(normal, *dirs[i]);
    if (n_dot_l <= 0.0f) continue;
    const glm::vec3 rad = i == 0 ? *radiance[i] * key_visibility : *radiance[i];
    diffuse += rad * n_dot_l;
    if (ctx.specular > 0.0f) {
      const glm::vec3 half = glm::normalize(*dirs[i] + view);
      const float n_dot_h = glm::dot(normal, half);
      if (n_dot_h > 0.0f) {
        const float lobe = whole ? PowInteger(n_dot_h, exponent) : std::pow(n_dot_h, ctx.shininess);
        spec += rad * (ctx.specular * lobe);
      }
    }
  }
  return albedo * diffuse + spec;
}

namespace {

// |x - round(x)|, the distance to the nearest integer, without a libm call:
// rounding to nearest-even only differs from round() at ties, where the
// distance is 0.5 either way. Floats of magnitude >= 2^23 are integers.
float DistanceToInteger(float x) {
  if (!(std::abs(x) < 8388608.0f)) return 0.0f;
  return std::abs(x - static_cast<float>(simd::RoundToInt(x)));
}

}  // namespace

glm::vec3 GroundAlbedo(const GroundStyle& style, float grid_spacing, const glm::vec3& position,
                       const glm::vec3& eye) {
  if (!(grid_spacing > 0.0f)) return style.color;
  const float half_width = 0.5f * style.line_width;
  const float u = position.x / grid_spacing, v = position.z / grid_spacing;
  const float du = DistanceToInteger(u), dv = DistanceToInteger(v);
  // Soft-edged lines: full line colour inside the width, fading over the same width.
  const float d = std::min(du, dv);
  const float soft = std::max(half_width, 1e-6f);
  // Most of the ground is between lines: there (d - w) / soft >= 1, the line
  // weight below is exactly 0 and the colour exactly style.color.
  if (d - half_width >= soft) return style.color;
  float line = 1.0f - std::clamp((d - half_width) / soft, 0.0f, 1.0f);
  const float distance = glm::length(position - eye) / grid_spacing;
  const float fade_start = std::max(style.fade_start, 1e-3f);
  line *= 1.0f - std::clamp((distance - fade_start) / fade_start, 0.0f, 1.0f);
  return style.color + (style.line_color - style.color) * line;
}

float ContactShadowFactor(std::span<const ContactShadow> shadows, const glm::vec3& position) {
  float factor = 1.0f;
  for (const ContactShadow& s : shadows) {
    const glm::vec2 d = (glm::vec2(position.x, position.z) - s.centre_xz) / s.radius_xz;
    const float r2 = glm::dot(d, d);
    if (r2 < 9.0f) factor *= 1.0f - s.strength * std::exp(-2.0f * r2);
  }
  return factor;
}

ContactShadow ShadowUnder(const deform::Bounds& bounds, float ground_y, float strength) {
  ContactShadow shadow;
  if (bounds.empty()) {
    shadow.strength = 0.0f;
    return shadow;
  }
  const glm::vec3 size = bounds.size();
  shadow.centre_xz = glm::vec2(bounds.center().x, bounds.center().z);
  const float footprint = std::max(0.5f * std::max(size.x, size.z), 1e-4f);
  shadow.radius_xz = glm::max(0.6f * glm::vec2(size.x, size.z), glm::vec2(0.3f * footprint));
  // Fade with the gap between the object's lowest point and the ground.
  const float gap = std::max(bounds.min.y - ground_y, 0.0f);
  shadow.strength = strength / (1.0f + 4.0f * gap / footprint);
  return shadow;
}

glm::vec3 BackgroundColor(const Background& background, float t) {
  return background.top + (background.bottom - background.top) * std::clamp(t, 0.0f, 1.0f);
}

}  // namespace render
