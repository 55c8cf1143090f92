#include "render/raster/texture.h"

#include <algorithm>
#include <cmath>

namespace render {
namespace {

using deform::TextureWrap;

// Texel index i wrapped into [0, n). Indices within one period of the range
// (what SampleLevel passes) take the branches; others the general modulo.
[[gnu::always_inline]] inline int WrapIndex(int i, int n, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kClampToEdge:
      return std::clamp(i, 0, n - 1);
    case TextureWrap::kMirroredRepeat: {
      const int period = 2 * n;
      const int m = i >= 0 && i < period ? i : ((i % period) + period) % period;
      return m < n ? m : period - 1 - m;
    }
    case TextureWrap::kRepeat:
    default:
      if (i >= 0 && i < n) return i;
      if (i < 0 && i >= -n) return i + n;
      if (i >= n && i < 2 * n) return i - n;
      return ((i % n) + n) % n;
  }
}

// A coordinate brought near [0, 1] before it is scaled to texels, so huge
// values cannot overflow the integer texel index; the wrap is unchanged by it.
[[gnu::always_inline]] inline float Reduce(float t, TextureWrap wrap) {
  if (!std::isfinite(t)) return 0.0f;
  switch (wrap) {
    case TextureWrap::kClampToEdge:
      return std::clamp(t, -1.0f, 2.0f);
    case TextureWrap::kMirroredRepeat:
      return t - 2.0f * std::floor(0.5f * t);  // [0, 2): one mirrored period
    case TextureWrap::kRepeat:
    default:
      return t - std::floor(t);
  }
}

}  // namespace

Texture::Texture(int width, int height, std::span<const float> rgb, TextureWrap wrap_s, TextureWrap wrap_t)
    : wrap_s_(wrap_s), wrap_t_(wrap_t) {
  Level base;
  if (width < 1 || height < 1 ||
      rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3) {
    base.width = base.height = 1;
    base.texels.assign(1, glm::vec3(0.5f));
  } else {
    base.width = width;
    base.height = height;
    base.texels.resize(rgb.size() / 3);
    for (std::size_t t = 0; t < base.texels.size(); ++t)
      base.texels[t] = glm::vec3(rgb[3 * t], rgb[3 * t + 1], rgb[3 * t + 2]);
  }
  levels_.push_back(std::move(base));
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const Level& src = levels_.back();
    Level next;
    next.width = std::max(1, src.width / 2);
    next.height = std::max(1, src.height / 2);
    next.texels.resize(static_cast<std::size_t>(next.width) * static_cast<std::size_t>(next.height));
    for (int y = 0; y < next.height; ++y) {
      const int y0 = std::min(2 * y, src.height - 1), y1 = std::min(2 * y + 1, src.height - 1);
      for (int x = 0; x < next.width; ++x) {
        const int x0 = std::min(2 * x, src.width - 1), x1 = std::min(2 * x + 1, src.width - 1);
        auto at = [&](int xx, int yy) {
          return src.texels[static_cast<std::size_t>(yy) * static_cast<std::size_t>(src.width) +
                            static_cast<std::size_t>(xx)];
        };
        next.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(next.width) +
                    static_cast<std::size_t>(x)] = 0.25f * (at(x0, y0) + at(x1, y0) + at(x0, y1) + at(x1, y1));
      }
    }
    levels_.push_back(std::move(next));
  }
}

glm::vec3 Texture::Texel(int level, int x, int y) const {
  const Level& l = levels_[static_cast<std::size_t>(std::clamp(level, 0, num_levels() - 1))];
  x = WrapIndex(x, l.width, wrap_s_);
  y = WrapIndex(y, l.height, wrap_t_);
  return l.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(l.width) + static_cast<std::size_t>(x)];
}

glm::vec3 Texture::SampleLevel(glm::vec2 uv, int level) const {
  if (levels_.empty()) return glm::vec3(0.5f);
  level = std::clamp(level, 0, num_levels() - 1);
  const Level& l = levels_[static_cast<std::size_t>(level)];
  const float x = Reduce(uv.x, wrap_s_) * static_cast<float>(l.width) - 0.5f;
  const float y = Reduce(uv.y, wrap_t_) * static_cast<float>(l.height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  // Reduce() bounds the coordinates, so the wrap of the two columns and rows
  // is one or two comparisons each (WrapIndex for the mirrored period).
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int c0 = WrapIndex(x0, l.width, wrap_s_), c1 = WrapIndex(x0 + 1, l.width, wrap_s_);
  const int r0 = WrapIndex(y0, l.height, wrap_t_), r1 = WrapIndex(y0 + 1, l.height, wrap_t_);
  const glm::vec3* row0 = l.texels.data() + static_cast<std::size_t>(r0) * static_cast<std::size_t>(l.width);
  const glm::vec3* row1 = l.texels.data() + static_cast<std::size_t>(r1) * static_cast<std::size_t>(l.width);
  const glm::vec3 top = glm::mix(row0[c0], row0[c1], ax);
  const glm::vec3 bottom = glm::mix(row1[c0], row1[c1], ax);
  return glm::mix(top, bottom, ay);
}

glm::vec3 Texture::Sample(glm::vec2 uv, float lod) const {
  if (levels_.empty()) return glm::vec3(0.5f);
  const float max_lod = static_cast<float>(num_levels() - 1);
  lod = std::isfinite(lod) ? std::clamp(lod, 0.0f, max_lod) : (lod > 0.0f ? max_lod : 0.0f);
  const int level = static_cast<int>(lod);
  const float blend = lod - static_cast<float>(level);
  const glm::vec3 fine = SampleLevel(uv, level);
  if (blend <= 0.0f) return fine;
  return glm::mix(fine, SampleLevel(uv, level + 1), blend);
}

float Texture::Lod(glm::vec2 duv_dx, glm::vec2 duv_dy) const {
  const glm::vec2 size(static_cast<float>(width()), static_cast<float>(height()));
  const glm::vec2 dx = duv_dx * size, dy = duv_dy * size;
  const float rho2 = std::max(glm::dot(dx, dx), glm::dot(dy, dy));
  // Magnified (rho <= 1): level 0 whatever the exact negative lod, without the log.
  if (rho2 <= 1.0f) return rho2 == 1.0f ? 0.0f : -1.0f;
  if (!(rho2 < 1e30f)) return static_cast<float>(num_levels());  // inf / NaN: the coarsest
  // log2 from the float's exponent and a quadratic in its mantissa 1 + x,
  // x in [0, 1): log2(1 + x) ~ x (1.3466 - 0.3466 x) (exact at both ends, off
  // by < 0.008 between): finer than the level blend needs, without libm's log2.
  int exponent = 0;
  const float x = 2.0f * std::frexp(rho2, &exponent) - 1.0f;  // rho2 = (1 + x) 2^(exponent - 1)
  return 0.5f * (static_cast<float>(exponent - 1) + x * (1.3466f - 0.3466f * x));
}

}  // namespace render
