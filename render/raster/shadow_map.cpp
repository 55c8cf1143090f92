#include "render/raster/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace render {
namespace {

constexpr float kNoCaster = -std::numeric_limits<float>::infinity();
constexpr float kGoldenAngle = 2.39996322972865f;  // pi * (3 - sqrt(5))

}  // namespace

void ShadowMap::Build(const glm::vec3& light_dir, std::span<const ShadowCaster> casters,
                      const ShadowMapSettings& settings) {
  depth_.clear();
  block_max_.clear();
  size_ = 0;
  const float len = glm::length(light_dir);
  if (!(len > 0.0f)) return;
  axis_w_ = light_dir / len;
  // Any basis across the light will do; avoid the reference parallel to it.
  const glm::vec3 ref = std::abs(axis_w_.y) > 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  axis_u_ = glm::normalize(glm::cross(ref, axis_w_));
  axis_v_ = glm::cross(axis_w_, axis_u_);

  // Fit the map to the casters' light-space (u, v) bounds.
  glm::vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const ShadowCaster& c : casters) {
    for (const glm::vec3& p : c.positions) {
      const glm::vec2 uv(glm::dot(p, axis_u_), glm::dot(p, axis_v_));
      lo = glm::min(lo, uv);
      hi = glm::max(hi, uv);
    }
  }
  if (!(lo.x <= hi.x && lo.y <= hi.y)) return;
  const int size = std::clamp(settings.resolution, 16, 8192);
  radius_ = std::clamp(settings.filter_radius_texels, 0.0f, static_cast<float>(kBlock - 2));
  // A margin of the filter footprint keeps edge taps inside the map.
  const float margin_texels = radius_ + 2.0f;
  const float extent = std::max(std::max(hi.x - lo.x, hi.y - lo.y), 1e-6f);
  texel_ = extent / (static_cast<float>(size) - 2.0f * margin_texels);
  inv_texel_ = 1.0f / texel_;
  origin_ = 0.5f * (lo + hi) - glm::vec2(0.5f * static_cast<float>(size) * texel_);
  bias_ = std::max(settings.bias_texels, 0.0f) * texel_;
  for (int k = 0; k < kTaps; ++k) {
    const float r = radius_ * std::sqrt((static_cast<float>(k) + 0.5f) / kTaps);
    const float a = kGoldenAngle * static_cast<float>(k);
    taps_[static_cast<std::size_t>(k)] = {r * std::cos(a), r * std::sin(a)};
  }

  size_ = size;
  depth_.assign(static_cast<std::size_t>(size) * static_cast<std::size_t>(size), kNoCaster);
  for (const ShadowCaster& c : casters) {
    const std::size_t nv = c.positions.size();
    for (const glm::uvec3& t : c.triangles) {
      if (t.x >= nv || t.y >= nv || t.z >= nv) continue;
      glm::vec3 q[3];  // texel x, texel y, light depth
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& p = c.positions[t[k]];
        q[k] = {(glm::dot(p, axis_u_) - origin_.x) * inv_texel_,
                (glm::dot(p, axis_v_) - origin_.y) * inv_texel_, glm::dot(p, axis_w_)};
      }
      const float area = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
      if (!(std::abs(area) > 0.0f)) continue;  // edge-on to the light (or not finite)
      const float inv_area = 1.0f / area;
      const int x0 = std::max(static_cast<int>(std::floor(std::min({q[0].x, q[1].x, q[2].x}))), 0);
      const int x1 = std::min(static_cast<int>(std::ceil(std::max({q[0].x, q[1].x, q[2].x}))), size - 1);
      const int y0 = std::max(static_cast<int>(std::floor(std::min({q[0].y, q[1].y, q[2].y}))), 0);
      const int y1 = std::min(static_cast<int>(std::ceil(std::max({q[0].y, q[1].y, q[2].y}))), size - 1);
      for (int y = y0; y <= y1; ++y) {
        const float py = static_cast<float>(y) + 0.5f;
        float* row = depth_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(size);
        for (int x = x0; x <= x1; ++x) {
          const float px = static_cast<float>(x) + 0.5f;
          // Barycentric weights; both windings via the signed area. Texel
          // centres on a shared edge are filled by both triangles (max is fine).
          const float b0 = ((q[1].x - px) * (q[2].y - py) - (q[2].x - px) * (q[1].y - py)) * inv_area;
          const float b1 = ((q[2].x - px) * (q[0].y - py) - (q[0].x - px) * (q[2].y - py)) * inv_area;
          const float b2 = 1.0f - b0 - b1;
          if (b0 < 0.0f || b1 < 0.0f || b2 < 0.0f) continue;
          const float d = b0 * q[0].z + b1 * q[1].z + b2 * q[2].z;
          row[x] = std::max(row[x], d);
        }
      }
    }
  }

  // Coarse maxima: a block's own, then over its 3x3 neighbourhood, so one
  // read tells whether any tap of a point in the block can find an occluder.
  blocks_ = (size + kBlock - 1) / kBlock;
  std::vector<float> own(static_cast<std::size_t>(blocks_) * static_cast<std::size_t>(blocks_), kNoCaster);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float& m = own[static_cast<std::size_t>(y / kBlock) * static_cast<std::size_t>(blocks_) +
                     static_cast<std::size_t>(x / kBlock)];
      m = std::max(m, depth_[static_cast<std::size_t>(y) * static_cast<std::size_t>(size) +
                             static_cast<std::size_t>(x)]);
    }
  block_max_.assign(own.size(), kNoCaster);
  for (int by = 0; by < blocks_; ++by)
    for (int bx = 0; bx < blocks_; ++bx) {
      float m = kNoCaster;
      for (int j = std::max(by - 1, 0); j <= std::min(by + 1, blocks_ - 1); ++j)
        for (int i = std::max(bx - 1, 0); i <= std::min(bx + 1, blocks_ - 1); ++i)
          m = std::max(m, own[static_cast<std::size_t>(j) * static_cast<std::size_t>(blocks_) +
                              static_cast<std::size_t>(i)]);
      block_max_[static_cast<std::size_t>(by) * static_cast<std::size_t>(blocks_) +
                 static_cast<std::size_t>(bx)] = m;
    }
}

float ShadowMap::Texel(int i, int j) const {
  if (i < 0 || j < 0 || i >= size_ || j >= size_) return kNoCaster;
  return depth_[static_cast<std::size_t>(j) * static_cast<std::size_t>(size_) + static_cast<std::size_t>(i)];
}

float ShadowMap::LitBilinear(float x, float y, float depth) const {
  const float fx = x - 0.5f, fy = y - 0.5f;  // texel centres at integers
  const float ix = std::floor(fx), iy = std::floor(fy);
  const float tx = fx - ix, ty = fy - iy;
  const int i = static_cast<int>(ix), j = static_cast<int>(iy);
  auto lit = [&](int a, int b) { return Texel(a, b) <= depth ? 1.0f : 0.0f; };
  const float top = lit(i, j) + (lit(i + 1, j) - lit(i, j)) * tx;
  const float bottom = lit(i, j + 1) + (lit(i + 1, j + 1) - lit(i, j + 1)) * tx;
  return top + (bottom - top) * ty;
}

float ShadowMap::Visibility(const glm::vec3& p) const {
  if (size_ == 0) return 1.0f;
  const float x = (glm::dot(p, axis_u_) - origin_.x) * inv_texel_;
  const float y = (glm::dot(p, axis_v_) - origin_.y) * inv_texel_;
  const auto extent = static_cast<float>(size_);
  if (!(x >= 0.0f && y >= 0.0f && x < extent && y < extent)) return 1.0f;  // also NaN
  const float depth = glm::dot(p, axis_w_) + bias_;  // occluders must be nearer than this
  const int bx = static_cast<int>(x) / kBlock, by = static_cast<int>(y) / kBlock;
  if (block_max_[static_cast<std::size_t>(by) * static_cast<std::size_t>(blocks_) +
                 static_cast<std::size_t>(bx)] <= depth)
    return 1.0f;
  float sum = 0.0f;
  for (const glm::vec2& t : taps_) sum += LitBilinear(x + t.x, y + t.y, depth);
  return sum * (1.0f / kTaps);
}

}  // namespace render
