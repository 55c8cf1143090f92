// RasterizeTile's fast path: the reference edge walk (rasterizer.cpp), four
// samples per step in SSE2 lanes. Two variants, by triangle size:
//  - small triangles (most of a body mesh): the edge values fit in int32, so
//    they step in int32 lanes and convert to float exactly as the int64 ones;
//  - large ones (the ground's two cover most tiles): the edge values step in
//    double lanes, exact since every |E| < 2^53; converting them to float rounds
//    once, as the int64 -> float cast does.
// So z, the depth test and the result are the reference's, bit for bit.

#include <algorithm>
#include <cstddef>

#include "render/raster/internal/simd.h"
#include "render/raster/internal/tile_draw.h"

namespace render::internal {

#if defined(__SSE2__)
namespace {

// Lanes (r, r + s, r + 2s, r + 3s): an edge value at four consecutive samples.
__m128i FourSamples(std::int32_t r, std::int32_t s) {
  return _mm_setr_epi32(r, r + s, r + 2 * s, r + 3 * s);
}

// z = (f0 * z0 + f1 * z1) + f2 * z2 per lane, the reference's order.
__m128 InterpolateDepth(__m128 f0, __m128 f1, __m128 f2, const __m128 (&z)[3]) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(f0, z[0]), _mm_mul_ps(f1, z[1])), _mm_mul_ps(f2, z[2]));
}

// Depth test and store of four samples at d / ids for the lanes in `inside`:
// a larger z wins; ties and the other lanes keep what is stored.
void DepthTestAndStore(float* d, std::uint32_t* ids, __m128 z, __m128 inside, __m128i id4) {
  const __m128 old_z = _mm_loadu_ps(d);
  const __m128 pass = _mm_and_ps(inside, _mm_cmpgt_ps(z, old_z));
  _mm_storeu_ps(d, simd::Select(pass, z, old_z));
  simd::StoreU(ids, simd::Select(_mm_castps_si128(pass), id4, simd::LoadU(ids)));
}

// The tile's buffers at sample (bx, sy).
std::size_t TileOffset(const TileTarget& tile, int bx, int sy) {
  return static_cast<std::size_t>(sy - tile.y0) * kTileSize +
         static_cast<std::size_t>(bx - tile.x0);
}

// Small triangle: edge values in int32 lanes. The edge values of a row's
// first four samples step down a row with one add each; the group reaching
// past the bounds (the last one, when the row's length is not a multiple of 4)
// masks off its extra lanes.
void DrawSmall(const EdgeStart& s, const DepthFactors& f, std::uint32_t id,
               const TileTarget& tile) {
  __m128i row[3], down[3], step[3];
  for (int i = 0; i < 3; ++i) {
    const auto r = static_cast<std::int32_t>(s.row[i]), sx = static_cast<std::int32_t>(s.step_x[i]);
    row[i] = FourSamples(r, sx);
    down[i] = _mm_set1_epi32(static_cast<std::int32_t>(s.step_y[i]));
    step[i] = _mm_set1_epi32(4 * sx);
  }
  const __m128 z[3] = {_mm_set1_ps(f.z[0]), _mm_set1_ps(f.z[1]), _mm_set1_ps(f.z[2])};
  const __m128i minus_one = _mm_set1_epi32(-1);
  const __m128i id4 = _mm_set1_epi32(static_cast<int>(id));
  const int n = s.bx1 - s.bx0 + 1;
  const int full = n & ~3;  // samples in whole groups
  const __m128i tail = _mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(n - full));
  for (int sy = s.by0; sy <= s.by1; ++sy) {
    const std::size_t at = TileOffset(tile, s.bx0, sy);
    float* d = tile.depth + at;
    std::uint32_t* out = tile.ids + at;
    __m128i e[3] = {row[0], row[1], row[2]};
    const auto inside = [&] {  // all three edge values >= 0
      return _mm_cmpgt_epi32(_mm_or_si128(_mm_or_si128(e[0], e[1]), e[2]), minus_one);
    };
    const auto depth = [&] {
      return InterpolateDepth(_mm_cvtepi32_ps(e[0]), _mm_cvtepi32_ps(e[1]), _mm_cvtepi32_ps(e[2]),
                              z);
    };
    int i = 0;
    for (; i < full; i += 4) {
      // No test for an empty group: about half of a small triangle's
      // bounding box lies outside it, in no predictable pattern, and the
      // mispredicted branch cost more than the masked depth test and
      // stores it saved (RasterizeTile ~12 % faster without it, against
      // SampleShader::Load in alternating perf profiles).
      DepthTestAndStore(d + i, out + i, depth(), _mm_castsi128_ps(inside()), id4);
      for (int k = 0; k < 3; ++k) e[k] = _mm_add_epi32(e[k], step[k]);
    }
    if (i < n) {
      const __m128i in_tail = _mm_and_si128(inside(), tail);
      if (simd::Any(in_tail))
        DepthTestAndStore(d + i, out + i, depth(), _mm_castsi128_ps(in_tail), id4);
    }
    for (int k = 0; k < 3; ++k) row[k] = _mm_add_epi32(row[k], down[k]);
  }
}

// Large triangle: edge values in double lanes, samples (0, 1) of a group in
// `lo` and (2, 3) in `hi`; lanes past the row's end are masked off.
void DrawLarge(EdgeStart s, const DepthFactors& f, std::uint32_t id, const TileTarget& tile) {
  const int n = s.bx1 - s.bx0 + 1;
  const __m128d zero = _mm_setzero_pd();
  const __m128 z[3] = {_mm_set1_ps(f.z[0]), _mm_set1_ps(f.z[1]), _mm_set1_ps(f.z[2])};
  const __m128i count = _mm_set1_epi32(n), four = _mm_set1_epi32(4);
  const __m128i id4 = _mm_set1_epi32(static_cast<int>(id));
  __m128d step4[3];
  for (int i = 0; i < 3; ++i) step4[i] = _mm_set1_pd(static_cast<double>(4 * s.step_x[i]));
  for (int sy = s.by0; sy <= s.by1; ++sy) {
    const std::size_t at = TileOffset(tile, s.bx0, sy);
    float* d = tile.depth + at;
    std::uint32_t* out = tile.ids + at;
    __m128d lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      const auto r = static_cast<double>(s.row[i]), st = static_cast<double>(s.step_x[i]);
      lo[i] = _mm_setr_pd(r, r + st);
      hi[i] = _mm_setr_pd(r + 2.0 * st, r + 3.0 * st);
    }
    __m128i lane = _mm_setr_epi32(0, 1, 2, 3);
    for (int i = 0; i < n; i += 4) {
      const __m128d in_lo =
          _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(lo[0], zero), _mm_cmpge_pd(lo[1], zero)),
                     _mm_cmpge_pd(lo[2], zero));
      const __m128d in_hi =
          _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(hi[0], zero), _mm_cmpge_pd(hi[1], zero)),
                     _mm_cmpge_pd(hi[2], zero));
      const __m128 inside = _mm_and_ps(
          _mm_shuffle_ps(_mm_castpd_ps(in_lo), _mm_castpd_ps(in_hi), _MM_SHUFFLE(2, 0, 2, 0)),
          _mm_castsi128_ps(_mm_cmplt_epi32(lane, count)));
      __m128 e[3];
      for (int j = 0; j < 3; ++j) e[j] = _mm_movelh_ps(_mm_cvtpd_ps(lo[j]), _mm_cvtpd_ps(hi[j]));
      for (int j = 0; j < 3; ++j) {
        lo[j] = _mm_add_pd(lo[j], step4[j]);
        hi[j] = _mm_add_pd(hi[j], step4[j]);
      }
      lane = _mm_add_epi32(lane, four);
      if (!simd::Any(inside)) continue;
      DepthTestAndStore(d + i, out + i, InterpolateDepth(e[0], e[1], e[2], z), inside, id4);
    }
    for (int k = 0; k < 3; ++k) s.row[k] += s.step_y[k];
  }
}

}  // namespace

void DrawTriangleFast(const RasterTriangle& tri, std::uint32_t id, TileTarget tile) {
  const EdgeStart s = StartEdges(tri, tile.x0, tile.y0, tile.x1, tile.y1);
  const DepthFactors f = MakeDepthFactors(tri);
  const std::int32_t extent_x =
      std::max({tri.x[0], tri.x[1], tri.x[2]}) - std::min({tri.x[0], tri.x[1], tri.x[2]});
  const std::int32_t extent_y =
      std::max({tri.y[0], tri.y[1], tri.y[2]}) - std::min({tri.y[0], tri.y[1], tri.y[2]});
  if (extent_x < kSmallTriangleExtent && extent_y < kSmallTriangleExtent) {
    DrawSmall(s, f, id, tile);
  } else {
    DrawLarge(s, f, id, tile);
  }
}

#else  // no SSE2: the reference

void DrawTriangleFast(const RasterTriangle& tri, std::uint32_t id, TileTarget tile) {
  DrawTriangleReference(tri, id, tile);
}

#endif

}  // namespace render::internal
