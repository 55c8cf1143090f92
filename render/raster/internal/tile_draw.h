#pragma once
// Drawing one setup triangle into one tile's depth and id buffers: the scalar
// reference (rasterizer.cpp) and the SSE2 fast path (rasterize_tile_fast.cpp)
// that Rasterizer::RasterizeTile uses. Both give the same bits, sample for
// sample; tests/render/raster/rasterizer_test.cpp checks it.

#include <cstdint>

#include "render/raster/rasterizer.h"

namespace render::internal {

// Triangles spanning less than this in x and in y (fixed point) take the fast
// path's int32 lanes: |dx|, |dy| < 2^14 fixed-point units, so every edge value
// inside their bounds is below 2^30 in magnitude.
inline constexpr std::int32_t kSmallTriangleExtent = 48 * kSubpixelScale;

// One tile: its rectangle of samples and its buffers (kTileBufferSize entries,
// row-major over the tile, row stride kTileSize; see RasterizeTile). Passed by
// value: a copy the id stores cannot alias stays in registers (by reference,
// its fields were reloaded after every store, about 7 % more instructions).
struct TileTarget {
  int x0, y0;  // the tile's first sample
  int x1, y1;  // one past its last sample, clipped to the raster
  float* depth;
  std::uint32_t* ids;
};

// Per-vertex factors of the depth plane: z = sum_i float(E_i) * z[i] is 1/w
// interpolated at a sample with biased edge values E_i.
struct DepthFactors {
  float z[3];  // inv_w[i] / (doubled area), in float
};
inline DepthFactors MakeDepthFactors(const RasterTriangle& tri) {
  const std::int64_t area2 = std::int64_t{tri.x[1] - tri.x[0]} * (tri.y[2] - tri.y[0]) -
                             std::int64_t{tri.y[1] - tri.y[0]} * (tri.x[2] - tri.x[0]);
  const float inv_area = 1.0f / static_cast<float>(area2);
  return {{tri.inv_w[0] * inv_area, tri.inv_w[1] * inv_area, tri.inv_w[2] * inv_area}};
}

// Depth-tests every sample of `tri` inside the tile: where its z is larger
// than the stored one, stores z and `id` (ties keep the earlier triangle).
// The reference: Rasterizer::ForEachSample plus the test, one sample at a time.
void DrawTriangleReference(const RasterTriangle& tri, std::uint32_t id, TileTarget tile);
// The same result, four samples per step with SSE2 (the reference without
// SSE2). May read and rewrite, unchanged, up to 3 entries past a row's last
// sample (the next row, or the buffers' padding).
void DrawTriangleFast(const RasterTriangle& tri, std::uint32_t id, TileTarget tile);

}  // namespace render::internal
