#include "render/raster/shadow_map.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "base/parallel.h"
#include "render/raster/internal/simd.h"

namespace render {
namespace {

constexpr float kNoCaster = -std::numeric_limits<float>::infinity();
// Tap discs as bit rows (bit c: offset c - half): 5 x 5 without its corners, and 3 x 3.
constexpr std::uint8_t kWideDisc[5] = {0b01110, 0b11111, 0b11111, 0b11111, 0b01110};
constexpr std::uint8_t kNarrowDisc[3] = {0b111, 0b111, 0b111};
// Set bits of a 6-bit row (the widest footprint), by table: the baseline
// x86-64 target has no popcount instruction, and the library call costs more.
constexpr auto kRowBits = [] {
  std::array<std::uint8_t, 64> bits{};
  for (unsigned v = 0; v < 64; ++v) bits[v] = static_cast<std::uint8_t>(std::popcount(v));
  return bits;
}();
// Texel-centre spans are widened by this much (texels) so that a centre on an
// edge shared by two triangles cannot fall between their spans by rounding.
constexpr float kSpanSlack = 1e-3f;

// [lo, hi] (whole numbers as floats) intersected with [min, max]; false when
// empty or not a number.
bool ClampSpan(float lo, float hi, int min, int max, int& out_lo, int& out_hi) {
  if (!(lo <= hi) || hi < static_cast<float>(min) || lo > static_cast<float>(max)) return false;
  out_lo = lo > static_cast<float>(min) ? static_cast<int>(lo) : min;
  out_hi = hi < static_cast<float>(max) ? static_cast<int>(hi) : max;
  return true;
}

}  // namespace

void ShadowMap::Build(const glm::vec3& light_dir, std::span<const ShadowCaster> casters,
                      const ShadowMapSettings& settings) {
  depth_.clear();
  blocks3_.clear();
  narrow_max_.clear();
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
  // A margin of the wide filter's reach keeps the soft edge inside the map.
  constexpr float kMarginTexels = 4.0f;
  const float extent = std::max(std::max(hi.x - lo.x, hi.y - lo.y), 1e-6f);
  texel_ = extent / (static_cast<float>(size) - 2.0f * kMarginTexels);
  inv_texel_ = 1.0f / texel_;
  origin_ = 0.5f * (lo + hi) - glm::vec2(0.5f * static_cast<float>(size) * texel_);
  bias_ = std::max(settings.bias_texels, 0.0f) * texel_;
  normal_offset_ = std::max(settings.normal_offset_texels, 0.0f) * texel_;

  // Every vertex in texel coordinates (x, y) and light depth (z), once.
  std::vector<std::vector<glm::vec3>> projected(casters.size());
  for (std::size_t m = 0; m < casters.size(); ++m) {
    projected[m].reserve(casters[m].positions.size());
    for (const glm::vec3& p : casters[m].positions) projected[m].push_back(ToTexel(p));
  }

  size_ = size;
  stride_ = static_cast<std::size_t>(size + 2 * kPad);
  depth_.assign(stride_ * stride_, kNoCaster);
  blocks_ = (size + kBlock - 1) / kBlock;
  std::vector<Range> own(static_cast<std::size_t>(blocks_) * static_cast<std::size_t>(blocks_));
  // Bands of whole block rows: each thread fills its rows, then their block bounds.
  const int bands = std::clamp(settings.threads, 1, blocks_);
  base::RunOnThreads(bands, [&](int band) {
    const int b0 = blocks_ * band / bands, b1 = blocks_ * (band + 1) / bands;
    RasterBand(projected, casters, b0 * kBlock, std::min(b1 * kBlock, size));
    BlockBounds(b0, b1, own);
  });
  narrow_cells_ = size / 2 + 1;
  NarrowMaxima(bands);

  // Each block's range over its 3 x 3 neighbourhood, which holds every
  // footprint of a point inside it; beyond the map counts as no caster.
  blocks3_.assign(own.size(), {});
  for (int by = 0; by < blocks_; ++by)
    for (int bx = 0; bx < blocks_; ++bx) {
      Range r{std::numeric_limits<float>::infinity(), kNoCaster};
      for (int j = by - 1; j <= by + 1; ++j)
        for (int i = bx - 1; i <= bx + 1; ++i) {
          if (i < 0 || j < 0 || i >= blocks_ || j >= blocks_) {
            r.lo = kNoCaster;
            continue;
          }
          const Range& o = own[static_cast<std::size_t>(j) * static_cast<std::size_t>(blocks_) +
                               static_cast<std::size_t>(i)];
          r.lo = std::min(r.lo, o.lo);
          r.hi = std::max(r.hi, o.hi);
        }
      blocks3_[static_cast<std::size_t>(by) * static_cast<std::size_t>(blocks_) +
               static_cast<std::size_t>(bx)] = r;
    }
}

// Fills rows [row0, row1) from every triangle: per row, the span of texel
// centres inside the triangle (from its three edge functions, linear in x)
// and the depth plane along it.
void ShadowMap::RasterBand(std::span<const std::vector<glm::vec3>> projected,
                           std::span<const ShadowCaster> casters, int row0, int row1) {
  for (std::size_t m = 0; m < casters.size(); ++m) {
    const std::vector<glm::vec3>& q = projected[m];
    const bool closed = casters[m].closed;
    const std::size_t nv = q.size();
    for (const glm::uvec3& t : casters[m].triangles) {
      if (t.x >= nv || t.y >= nv || t.z >= nv) continue;
      const glm::vec3 a = q[t.x], b = q[t.y], c = q[t.z];
      const float ymin = std::min({a.y, b.y, c.y}), ymax = std::max({a.y, b.y, c.y});
      // Rows whose centre y + 0.5 lies in [ymin, ymax], within the band
      // (compared as floats first: a huge or NaN bound must not reach a cast).
      int y0 = 0, y1 = 0;
      if (!ClampSpan(std::ceil(ymin - 0.5f), std::floor(ymax - 0.5f), row0, row1 - 1, y0, y1)) continue;
      // Edges and depth relative to vertex a, so that values stay small.
      const glm::vec2 e1(b.x - a.x, b.y - a.y), e2(c.x - a.x, c.y - a.y);
      const float area = e1.x * e2.y - e2.x * e1.y;
      if (!(std::abs(area) > 0.0f)) continue;  // edge-on to the light (or not finite)
      // A closed, outward surface is first met by the light on triangles that
      // face it (positive area in light space): the others never hold a texel's max.
      if (closed && !(area > 0.0f)) continue;
      const float inv = 1.0f / area;
      // The depth plane z = a.z + gx (x - a.x) + gy (y - a.y).
      const float dz1 = b.z - a.z, dz2 = c.z - a.z;
      const float gx = (dz1 * e2.y - dz2 * e1.y) * inv, gy = (dz2 * e1.x - dz1 * e2.x) * inv;
      // Each edge's inside half-plane, s * (x - a.x) + t * (y - a.y) + r >= 0
      // (the barycentric weight opposite it, times the area's sign: both
      // windings), bounds x on a row as x - a.x >= or <= -(r + t (y - a.y)) / s.
      const float sign = area > 0.0f ? 1.0f : -1.0f;
      const float es[3] = {sign * (e1.y - e2.y), sign * e2.y, -sign * e1.y};
      const float et[3] = {sign * (e2.x - e1.x), -sign * e2.x, sign * e1.x};
      const float er[3] = {sign * area, 0.0f, 0.0f};
      float lo0 = std::min({0.0f, e1.x, e2.x}) - kSpanSlack, hi0 = std::max({0.0f, e1.x, e2.x}) + kSpanSlack;
      float lo_c[3] = {}, lo_t[3] = {}, hi_c[3] = {}, hi_t[3] = {};  // per row: c + t * (y - a.y)
      int n_lo = 0, n_hi = 0;
      bool parallel_outside_at_any_row = false;
      for (int k = 0; k < 3; ++k) {
        if (es[k] > 0.0f) {
          lo_c[n_lo] = -er[k] / es[k] - kSpanSlack;
          lo_t[n_lo++] = -et[k] / es[k];
        } else if (es[k] < 0.0f) {
          hi_c[n_hi] = -er[k] / es[k] + kSpanSlack;
          hi_t[n_hi++] = -et[k] / es[k];
        } else {
          parallel_outside_at_any_row = true;  // checked per row below (rare)
        }
      }
      const float zmin = std::min({a.z, b.z, c.z}), zmax = std::max({a.z, b.z, c.z});
      for (int y = y0; y <= y1; ++y) {
        const float ry = static_cast<float>(y) + 0.5f - a.y;
        float lo = lo0, hi = hi0;  // relative to a.x
        for (int k = 0; k < n_lo; ++k) lo = std::max(lo, lo_c[k] + lo_t[k] * ry);
        for (int k = 0; k < n_hi; ++k) hi = std::min(hi, hi_c[k] + hi_t[k] * ry);
        if (parallel_outside_at_any_row) {
          for (int k = 0; k < 3; ++k)
            if (es[k] == 0.0f && er[k] + et[k] * ry < 0.0f) hi = lo - 1.0f;  // parallel to the row, outside
        }
        int x0 = 0, x1 = 0;
        if (!ClampSpan(std::ceil(lo + a.x - 0.5f), std::floor(hi + a.x - 0.5f), 0, size_ - 1, x0, x1)) continue;
        const float zrow = a.z + gy * ry;
        float* row = Row(y);
        // Clamped to the triangle's own depths: the slack never extrapolates past them.
        for (int x = x0; x <= x1; ++x)
          row[x] = std::max(row[x], std::clamp(zrow + gx * (static_cast<float>(x) + 0.5f - a.x), zmin, zmax));
      }
    }
  }
}

// Two separable passes of a 5-wide max at every other texel: along rows into
// `across` (rows -3 .. size_ + 2), then down its columns into narrow_max_.
void ShadowMap::NarrowMaxima(int threads) {
  const int n = narrow_cells_;
  const int rows = size_ + 6;
  std::vector<float> across(static_cast<std::size_t>(rows) * static_cast<std::size_t>(n));
  narrow_max_.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  base::RunOnThreads(threads, [&](int t) {
    for (int j = -3 + rows * t / threads; j < -3 + rows * (t + 1) / threads; ++j) {
      const float* row = Row(j);
      float* out = across.data() + static_cast<std::size_t>(j + 3) * static_cast<std::size_t>(n);
      for (int c = 0; c < n; ++c) {
        const float* w = row + 2 * c - 2;  // texels 2c - 2 .. 2c + 2
        out[c] = std::max(std::max(std::max(w[0], w[1]), std::max(w[2], w[3])), w[4]);
      }
    }
  });
  base::RunOnThreads(threads, [&](int t) {
    for (int c = n * t / threads; c < n * (t + 1) / threads; ++c) {
      float* out = narrow_max_.data() + static_cast<std::size_t>(c) * static_cast<std::size_t>(n);
      const std::size_t step = static_cast<std::size_t>(n);
      const float* up = across.data() + static_cast<std::size_t>(2 * c + 1) * step;  // row 2c - 2
      for (int i = 0; i < n; ++i)
        out[i] = std::max(std::max(std::max(up[i], up[step + i]), std::max(up[2 * step + i], up[3 * step + i])),
                          up[4 * step + i]);
    }
  });
}

// Min and max depth of each block in block rows [block_row0, block_row1).
// Blocks that reach past the map's edge include its no-caster border.
void ShadowMap::BlockBounds(int block_row0, int block_row1, std::vector<Range>& own) const {
  for (int by = block_row0; by < block_row1; ++by)
    for (int bx = 0; bx < blocks_; ++bx) {
      Range r{std::numeric_limits<float>::infinity(), kNoCaster};
      const int x0 = bx * kBlock, x1 = std::min(x0 + kBlock, size_);
      const int y0 = by * kBlock, y1 = std::min(y0 + kBlock, size_);
      if (x1 - x0 < kBlock || y1 - y0 < kBlock) r.lo = kNoCaster;
      for (int y = y0; y < y1; ++y) {
        const float* row = Row(y);
        for (int x = x0; x < x1; ++x) {
          r.lo = std::min(r.lo, row[x]);
          r.hi = std::max(r.hi, row[x]);
        }
      }
      own[static_cast<std::size_t>(by) * static_cast<std::size_t>(blocks_) +
          static_cast<std::size_t>(bx)] = r;
    }
}

float ShadowMap::Depth(int i, int j) const {
  if (i < 0 || j < 0 || i >= size_ || j >= size_) return kNoCaster;
  return Row(j)[i];
}

bool ShadowMap::CornersOnPlane(float height, glm::vec3 (&corners)[4]) const {
  if (size_ == 0 || !(axis_w_.y > 1e-3f)) return false;
  const float extent = static_cast<float>(size_) * texel_;
  for (int k = 0; k < 4; ++k) {
    const float u = origin_.x + ((k & 1) != 0 ? extent : 0.0f);
    const float v = origin_.y + ((k & 2) != 0 ? extent : 0.0f);
    // u * axis_u + v * axis_v + t * axis_w, with t putting it on the plane.
    const float t = (height - u * axis_u_.y - v * axis_v_.y) / axis_w_.y;
    corners[k] = u * axis_u_ + v * axis_v_ + t * axis_w_;
  }
  return true;
}

float ShadowMap::BlockTest(float x, float y, float depth) const {
  const int bx = static_cast<int>(x) / kBlock, by = static_cast<int>(y) / kBlock;
  const Range& r = blocks3_[static_cast<std::size_t>(by) * static_cast<std::size_t>(blocks_) +
                            static_cast<std::size_t>(bx)];
  if (r.hi <= depth) return 1.0f;  // nothing in reach is nearer the light
  if (r.lo > depth) return 0.0f;   // everything in reach is
  return -1.0f;
}

// With lit(i, j) = [texel (i, j) <= depth] and (ix, tx) the integer and
// fraction of x - 0.5 (texel centres at integers), a tap at whole offset
// (i, j) is the bilinear blend of lit over texels (ix + i + {0, 1}, iy + j + {0, 1}).
// Summing over the disc: (1-tx)(1-ty) S00 + tx(1-ty) S10 + (1-tx) ty S01 + tx ty S11,
// where Sxy counts the lit texels of the disc shifted by (x, y).
template <int kHalf>
float ShadowMap::Filter(float x, float y, float depth, const std::uint8_t (&disc)[2 * kHalf + 1]) const {
  constexpr int kRows = 2 * kHalf + 1, kWindow = kRows + 1;
  // floor(x - 0.5) for x >= 0 without a libm call (the baseline target has no SSE4.1 round).
  const int ix = static_cast<int>(x + 0.5f) - 1, iy = static_cast<int>(y + 0.5f) - 1;
  const float tx = x - 0.5f - static_cast<float>(ix), ty = y - 0.5f - static_cast<float>(iy);
  const int i0 = ix - kHalf, j0 = iy - kHalf;
  unsigned lit[kWindow];
#if defined(__SSE2__)
  // Four comparisons per instruction; a 6-wide row as two overlapping fours.
  const __m128 d4 = _mm_set1_ps(depth);
  for (int r = 0; r < kWindow; ++r) {
    const float* row = Row(j0 + r) + i0;
    unsigned bits = static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(_mm_loadu_ps(row), d4)));
    if constexpr (kWindow > 4)
      bits |= static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(_mm_loadu_ps(row + kWindow - 4), d4)))
              << (kWindow - 4);
    lit[r] = bits;
  }
#else
  for (int r = 0; r < kWindow; ++r) {
    const float* row = Row(j0 + r) + i0;
    unsigned bits = 0;
    for (int c = 0; c < kWindow; ++c) bits |= (row[c] <= depth ? 1u : 0u) << c;
    lit[r] = bits;
  }
#endif
  int s00 = 0, s10 = 0, s01 = 0, s11 = 0, taps = 0;
  for (int r = 0; r < kRows; ++r) {
    const unsigned d = disc[r], d1 = d << 1;
    s00 += kRowBits[lit[r] & d];
    s10 += kRowBits[lit[r] & d1];
    s01 += kRowBits[lit[r + 1] & d];
    s11 += kRowBits[lit[r + 1] & d1];
    taps += kRowBits[d];
  }
  const auto f = [](int s) { return static_cast<float>(s); };
  const float top = f(s00) + (f(s10) - f(s00)) * tx;
  const float bottom = f(s01) + (f(s11) - f(s01)) * tx;
  return (top + (bottom - top) * ty) / f(taps);
}

float ShadowMap::Visibility(const glm::vec3& p) const {
  if (size_ == 0) return 1.0f;
  const glm::vec3 t = ToTexel(p);
  const auto extent = static_cast<float>(size_);
  if (!(t.x >= 0.0f && t.y >= 0.0f && t.x < extent && t.y < extent)) return 1.0f;  // also NaN
  return VisibilityAt(t.x, t.y, t.z + bias_);  // occluders must be nearer than that
}

float ShadowMap::VisibilityAt(float x, float y, float depth) const {
  const float block = BlockTest(x, y, depth);
  return block >= 0.0f ? block : Filter<2>(x, y, depth, kWideDisc);
}

void ShadowMap::Visibility4(const float (&x)[4], float y, const float (&z)[4], float (&out)[4]) const {
  if (size_ == 0) {
    for (float& o : out) o = 1.0f;
    return;
  }
#if defined(__SSE2__)
  // glm::dot's order, (x * a.x + y * a.y) + z * a.z, so each lane is Visibility's value.
  const __m128 px = _mm_loadu_ps(x), pz = _mm_loadu_ps(z), py = _mm_set1_ps(y);
  const __m128 inv = _mm_set1_ps(inv_texel_);
  const __m128 tx =
      _mm_mul_ps(_mm_sub_ps(simd::Dot(px, py, pz, axis_u_), _mm_set1_ps(origin_.x)), inv);
  const __m128 ty =
      _mm_mul_ps(_mm_sub_ps(simd::Dot(px, py, pz, axis_v_), _mm_set1_ps(origin_.y)), inv);
  const __m128 zero = _mm_setzero_ps(), extent = _mm_set1_ps(static_cast<float>(size_));
  const int inside = _mm_movemask_ps(_mm_and_ps(
      _mm_and_ps(_mm_cmpge_ps(tx, zero), _mm_cmpge_ps(ty, zero)),
      _mm_and_ps(_mm_cmplt_ps(tx, extent), _mm_cmplt_ps(ty, extent))));
  for (float& o : out) o = 1.0f;
  if (inside == 0) return;  // most of a ground row: nothing to read
  alignas(16) float fx[4], fy[4], depth[4];
  _mm_store_ps(fx, tx);
  _mm_store_ps(fy, ty);
  _mm_store_ps(depth, _mm_add_ps(simd::Dot(px, py, pz, axis_w_), _mm_set1_ps(bias_)));
  for (int k = 0; k < 4; ++k)
    if ((inside >> k) & 1) out[k] = VisibilityAt(fx[k], fy[k], depth[k]);
#else
  for (int k = 0; k < 4; ++k) out[k] = Visibility({x[k], y, z[k]});
#endif
}

float ShadowMap::SurfaceVisibility(const glm::vec3& p, const glm::vec3& n) const {
  if (size_ == 0) return 1.0f;
  // The push grows as the light grazes the surface (sine of its angle to the
  // normal), where a texel spans the most depth along the surface.
  const float cos_l = std::clamp(glm::dot(n, axis_w_), -1.0f, 1.0f);
  const float push = normal_offset_ * (1.0f + 2.0f * std::sqrt(1.0f - cos_l * cos_l));
  const glm::vec3 t = ToTexel(p + n * push);
  return SurfaceVisibilityAt(t.x, t.y, t.z + bias_);
}

float ShadowMap::SurfaceVisibilityAt(float x, float y, float depth) const {
  const auto extent = static_cast<float>(size_);
  if (!(x >= 0.0f && y >= 0.0f && x < extent && y < extent)) return 1.0f;  // also NaN
  // No occluder in reach of the filter decides it exactly: the filter reads
  // texels floor(x - 0.5) - 1 .. + 2, and floor(x - 0.5) + 1 = (int)(x + 0.5)
  // for x >= 0, so a cell of two texels covers them all.
  const int i = static_cast<int>(x + 0.5f) >> 1, j = static_cast<int>(y + 0.5f) >> 1;
  if (narrow_max_[static_cast<std::size_t>(j) * static_cast<std::size_t>(narrow_cells_) +
                  static_cast<std::size_t>(i)] <= depth)
    return 1.0f;
  return Filter<1>(x, y, depth, kNarrowDisc);
}

void ShadowMap::SurfaceVisibility4(const float (&p)[3][4], const float (&n)[3][4], int lanes,
                                   float (&out)[4]) const {
  for (float& o : out) o = 1.0f;
  if (size_ == 0 || lanes == 0) return;
#if defined(__SSE2__)
  // SurfaceVisibility's operations in its order, four lanes at a time.
  const __m128 nx = _mm_loadu_ps(n[0]), ny = _mm_loadu_ps(n[1]), nz = _mm_loadu_ps(n[2]);
  const __m128 one = _mm_set1_ps(1.0f);
  const __m128 cos_l =
      _mm_min_ps(_mm_max_ps(simd::Dot(nx, ny, nz, axis_w_), _mm_set1_ps(-1.0f)), one);
  const __m128 sine = _mm_sqrt_ps(_mm_sub_ps(one, _mm_mul_ps(cos_l, cos_l)));
  const __m128 push =
      _mm_mul_ps(_mm_set1_ps(normal_offset_), _mm_add_ps(one, _mm_mul_ps(_mm_set1_ps(2.0f), sine)));
  const __m128 qx = _mm_add_ps(_mm_loadu_ps(p[0]), _mm_mul_ps(nx, push));
  const __m128 qy = _mm_add_ps(_mm_loadu_ps(p[1]), _mm_mul_ps(ny, push));
  const __m128 qz = _mm_add_ps(_mm_loadu_ps(p[2]), _mm_mul_ps(nz, push));
  const __m128 inv = _mm_set1_ps(inv_texel_);
  alignas(16) float x[4], y[4], depth[4];
  _mm_store_ps(x,
               _mm_mul_ps(_mm_sub_ps(simd::Dot(qx, qy, qz, axis_u_), _mm_set1_ps(origin_.x)), inv));
  _mm_store_ps(y,
               _mm_mul_ps(_mm_sub_ps(simd::Dot(qx, qy, qz, axis_v_), _mm_set1_ps(origin_.y)), inv));
  _mm_store_ps(depth, _mm_add_ps(simd::Dot(qx, qy, qz, axis_w_), _mm_set1_ps(bias_)));
  for (int k = 0; k < 4; ++k)
    if ((lanes >> k) & 1) out[k] = SurfaceVisibilityAt(x[k], y[k], depth[k]);
#else
  for (int k = 0; k < 4; ++k)
    if ((lanes >> k) & 1)
      out[k] = SurfaceVisibility({p[0][k], p[1][k], p[2][k]}, {n[0][k], n[1][k], n[2][k]});
#endif
}

}  // namespace render
