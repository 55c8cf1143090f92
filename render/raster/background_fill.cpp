#include "render/raster/background_fill.h"

#include <algorithm>
#include <limits>

#include "render/raster/internal/simd.h"

namespace render {
namespace {

// Non-temporal stores (the image is not read back by this thread): no
// read-for-ownership of the destination lines. 16-byte stores throughout:
// four-byte ones (movnti) fill the write-combining buffers far more slowly.
void StreamRow(glm::vec4* dst, int n, const glm::vec4& v) {
  int i = 0;
#if defined(__SSE2__)
  if ((reinterpret_cast<std::uintptr_t>(dst) & 15u) == 0) {
    const __m128 x = simd::Set(v);
    for (; i + 4 <= n; i += 4) {  // a cache line per step
      float* p = reinterpret_cast<float*>(dst + i);
      _mm_stream_ps(p, x);
      _mm_stream_ps(p + 4, x);
      _mm_stream_ps(p + 8, x);
      _mm_stream_ps(p + 12, x);
    }
    for (; i < n; ++i) _mm_stream_ps(reinterpret_cast<float*>(dst + i), x);
  }
#endif
  for (; i < n; ++i) dst[i] = v;
}

void StreamRow(float* dst, int n, float v) {
  int i = 0;
#if defined(__SSE2__)
  for (; i < n && (reinterpret_cast<std::uintptr_t>(dst + i) & 15u) != 0; ++i) dst[i] = v;
  const __m128 x = _mm_set1_ps(v);
  for (; i + 16 <= n; i += 16) {  // a cache line per step
    _mm_stream_ps(dst + i, x);
    _mm_stream_ps(dst + i + 4, x);
    _mm_stream_ps(dst + i + 8, x);
    _mm_stream_ps(dst + i + 12, x);
  }
  for (; i + 4 <= n; i += 4) _mm_stream_ps(dst + i, x);
#endif
  for (; i < n; ++i) dst[i] = v;
}

}  // namespace

void BackgroundFill::Plan(const Rasterizer& raster, int supersample,
                          std::span<const glm::vec3> sample_rows, bool transparent, int width,
                          int height, std::atomic<std::size_t>& cursor) {
  const int ss = supersample, per_tile = kTileSize / ss;
  units_.clear();
  for (int ty = 0; ty < raster.tiles_y(); ++ty) {
    const int y0 = ty * per_tile, y1 = std::min(y0 + per_tile, height);
    for (int y = y0; y < y1; ++y) {
      for (int tx = 0; tx < raster.tiles_x();) {
        if (raster.tile_triangle_count(ty * raster.tiles_x() + tx) != 0) {
          ++tx;
          continue;
        }
        const int run0 = tx;
        while (tx < raster.tiles_x() && raster.tile_triangle_count(ty * raster.tiles_x() + tx) == 0)
          ++tx;
        const int x0 = run0 * per_tile, x1 = std::min(tx * per_tile, width);
        if (x0 < x1) units_.push_back({y, x0, x1});
      }
    }
  }
  row_colors_.assign(static_cast<std::size_t>(height), glm::vec4(0.0f));
  if (!transparent) {
    const float inv_n = 1.0f / static_cast<float>(ss * ss);
    for (int oy = 0; oy < height; ++oy) {
      glm::vec4& color = row_colors_[static_cast<std::size_t>(oy)];
      if (ss == 1) {
        color = glm::vec4(sample_rows[static_cast<std::size_t>(oy)], 1.0f);
        continue;
      }
      // Sum in the order ShadeTile accumulates: sample rows, then columns.
      glm::vec4 acc(0.0f);
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i)
          acc += glm::vec4(sample_rows[static_cast<std::size_t>(oy * ss + j)], 0.0f);
      color = glm::vec4(glm::vec3(acc) * inv_n, 1.0f);
    }
  }
  cursor_ = &cursor;
  cursor_->store(0, std::memory_order_relaxed);
}

void BackgroundFill::WriteUnit(std::size_t u, Image& image) const {
  const Unit& unit = units_[u];
  const int n = unit.x1 - unit.x0;
  StreamRow(image.rgba.data() + image.index(unit.x0, unit.y), n,
            row_colors_[static_cast<std::size_t>(unit.y)]);
  if (!image.depth.empty())
    StreamRow(image.depth.data() + image.index(unit.x0, unit.y), n,
              std::numeric_limits<float>::infinity());
}

std::size_t BackgroundFill::Drain(std::size_t n, Image& image) const {
  std::size_t written = 0;
  for (; written < n; ++written) {
    const std::size_t u = cursor_->fetch_add(1, std::memory_order_relaxed);
    if (u >= units_.size()) break;
    WriteUnit(u, image);
  }
#if defined(__SSE2__)
  if (written > 0) _mm_sfence();
#endif
  return written;
}

}  // namespace render
