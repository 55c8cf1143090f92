#include "render/raster/rasterizer.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "base/check.h"
#include "base/parallel.h"

namespace render {
namespace {

// Largest |sample coordinate| a snapped vertex may have: 2^17 samples keeps
// fixed-point coordinates below 2^25, differences below 2^26 and edge-function
// products below 2^53, comfortably inside int64.
constexpr float kGuardLimitSamples = 131072.0f;
constexpr int kMaxRasterSize = 16384;
constexpr int kMaxClipVertices = 10;  // a triangle clipped by 6 planes has at most 9
// Triangles whose vertices span less than this (fixed point) use the int32 loop.
constexpr std::int32_t kSmallTriangleExtent = 48 * kSubpixelScale;

// Round to nearest (ties to even), as lrint in the default rounding mode.
std::int32_t RoundToInt(float x) {
#if defined(__SSE2__)
  return _mm_cvtss_si32(_mm_set_ss(x));
#else
  return static_cast<std::int32_t>(std::lrint(x));
#endif
}

// Floor division for a possibly negative numerator and positive divisor.
std::int32_t FloorDiv(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b;
  if ((a % b != 0) && (a < 0)) --q;
  return static_cast<std::int32_t>(q);
}

struct ClipVertex {
  glm::vec4 clip;
  glm::vec3 weights;  // barycentric weights of the source triangle's corners
};

// Signed distance to clip plane `p` (>= 0 inside): 0 near (z >= -w), then the
// guard band x <= g w, x >= -g w, y <= g w, y >= -g w, then 5 far (z <= w).
float PlaneDistance(const glm::vec4& c, int p, float guard) {
  switch (p) {
    case 0: return c.z + c.w;
    case 1: return guard * c.w - c.x;
    case 2: return guard * c.w + c.x;
    case 3: return guard * c.w - c.y;
    case 4: return guard * c.w + c.y;
    default: return c.w - c.z;
  }
}

}  // namespace

std::size_t Rasterizer::num_triangles() const {
  std::size_t n = 0;
  for (const PerThread& part : per_thread_) n += part.triangles.size();
  return n;
}

bool Rasterizer::Snap(const glm::vec4& clip, SnappedVertex& v) const {
  if (!(clip.w > 0.0f)) return false;
  const float inv_w = 1.0f / clip.w;
  const float sx = (clip.x * inv_w + 1.0f) * (0.5f * static_cast<float>(width_));
  const float sy = (1.0f - clip.y * inv_w) * (0.5f * static_cast<float>(height_));
  if (!(std::abs(sx) <= kGuardLimitSamples && std::abs(sy) <= kGuardLimitSamples)) return false;
  v.x = RoundToInt(sx * static_cast<float>(kSubpixelScale));
  v.y = RoundToInt(sy * static_cast<float>(kSubpixelScale));
  v.inv_w = inv_w;
  return true;
}

bool Rasterizer::EmitTriangle(const glm::vec4 (&clip)[3], const glm::mat3* weights,
                              std::uint32_t mesh, std::uint32_t triangle, PerThread& out) const {
  SnappedVertex v[3];
  for (int i = 0; i < 3; ++i)
    if (!Snap(clip[i], v[i])) return false;
  return EmitSnapped(v[0], v[1], v[2], weights, mesh, triangle, out);
}

bool Rasterizer::EmitSnapped(const SnappedVertex& v0, const SnappedVertex& v1,
                             const SnappedVertex& v2, const glm::mat3* weights, std::uint32_t mesh,
                             std::uint32_t triangle, PerThread& out) const {
  RasterTriangle tri;
  const SnappedVertex* v[3] = {&v0, &v1, &v2};
  for (int i = 0; i < 3; ++i) {
    tri.x[i] = v[i]->x;
    tri.y[i] = v[i]->y;
    tri.inv_w[i] = v[i]->inv_w;
    tri.order[i] = static_cast<std::uint8_t>(i);
  }
  const std::int64_t area2 = std::int64_t{tri.x[1] - tri.x[0]} * (tri.y[2] - tri.y[0]) -
                             std::int64_t{tri.y[1] - tri.y[0]} * (tri.x[2] - tri.x[0]);
  if (area2 == 0) return false;
  // y points down in sample space, so counter-clockwise in NDC has area2 < 0.
  tri.back_facing = area2 > 0;
  if (tri.back_facing && cull_) return false;
  glm::mat3 w = weights != nullptr ? *weights : glm::mat3(1.0f);
  if (area2 < 0) {
    std::swap(tri.x[1], tri.x[2]);
    std::swap(tri.y[1], tri.y[2]);
    std::swap(tri.inv_w[1], tri.inv_w[2]);
    std::swap(tri.order[1], tri.order[2]);
    std::swap(w[1], w[2]);
  }
  const std::int32_t min_fx = std::min({tri.x[0], tri.x[1], tri.x[2]});
  const std::int32_t max_fx = std::max({tri.x[0], tri.x[1], tri.x[2]});
  const std::int32_t min_fy = std::min({tri.y[0], tri.y[1], tri.y[2]});
  const std::int32_t max_fy = std::max({tri.y[0], tri.y[1], tri.y[2]});
  // Sample s is a candidate when its centre s*S + S/2 lies inside [min, max].
  constexpr std::int32_t kHalf = kSubpixelScale / 2;
  tri.min_x = std::max(0, -FloorDiv(-(min_fx - kHalf), kSubpixelScale));
  tri.min_y = std::max(0, -FloorDiv(-(min_fy - kHalf), kSubpixelScale));
  tri.max_x = std::min(width_ - 1, FloorDiv(max_fx - kHalf, kSubpixelScale));
  tri.max_y = std::min(height_ - 1, FloorDiv(max_fy - kHalf, kSubpixelScale));
  if (tri.min_x > tri.max_x || tri.min_y > tri.max_y) return false;
  tri.mesh = mesh;
  tri.triangle = triangle;
  tri.clip_slot = -1;
  if (weights != nullptr) {
    tri.clip_slot = static_cast<std::int32_t>(out.corner_weights.size());
    out.corner_weights.push_back(w);
  }
  for (int ty = tri.min_y / kTileSize; ty <= tri.max_y / kTileSize; ++ty)
    for (int tx = tri.min_x / kTileSize; tx <= tri.max_x / kTileSize; ++tx)
      ++out.tile_counts[static_cast<std::size_t>(ty * tiles_x_ + tx)];
  out.triangles.push_back(tri);
  return true;
}

void Rasterizer::EmitClipped(const glm::vec4 (&clip)[3], std::uint32_t mesh,
                             std::uint32_t triangle, PerThread& out) const {
  ClipVertex buffers[2][kMaxClipVertices];
  int count = 3;
  for (int i = 0; i < 3; ++i) {
    buffers[0][i].clip = clip[i];
    buffers[0][i].weights = glm::vec3(0.0f);
    buffers[0][i].weights[i] = 1.0f;
  }
  int src = 0;
  for (int plane = 0; plane < num_planes_ && count > 0; ++plane) {
    const ClipVertex* in = buffers[src];
    ClipVertex* result = buffers[1 - src];
    int n = 0;
    bool all_inside = true;
    for (int i = 0; i < count; ++i) all_inside &= PlaneDistance(in[i].clip, plane, guard_) >= 0.0f;
    if (all_inside) continue;
    for (int i = 0; i < count; ++i) {
      const ClipVertex& a = in[i];
      const ClipVertex& b = in[(i + 1) % count];
      const float da = PlaneDistance(a.clip, plane, guard_);
      const float db = PlaneDistance(b.clip, plane, guard_);
      if (da >= 0.0f) result[n++] = a;
      if ((da >= 0.0f) != (db >= 0.0f)) {
        // Interpolate from the inside vertex so a shared edge clips to the same
        // point in both of its triangles.
        const ClipVertex& inside = da >= 0.0f ? a : b;
        const ClipVertex& outside = da >= 0.0f ? b : a;
        const float d_in = da >= 0.0f ? da : db;
        const float d_out = da >= 0.0f ? db : da;
        const float t = d_in / (d_in - d_out);
        result[n].clip = inside.clip + t * (outside.clip - inside.clip);
        result[n].weights = inside.weights + t * (outside.weights - inside.weights);
        ++n;
      }
    }
    count = n;
    src = 1 - src;
  }
  if (count < 3) return;
  const ClipVertex* poly = buffers[src];
  for (int i = 1; i + 1 < count; ++i) {
    const glm::vec4 piece[3] = {poly[0].clip, poly[i].clip, poly[i + 1].clip};
    const glm::mat3 weights(poly[0].weights, poly[i].weights, poly[i + 1].weights);
    EmitTriangle(piece, &weights, mesh, triangle, out);
  }
}

void Rasterizer::SetupRange(std::span<const ClipMesh> meshes, std::size_t begin, std::size_t end,
                            PerThread& out) const {
  out.triangles.clear();
  out.corner_weights.clear();
  out.tile_counts.assign(static_cast<std::size_t>(num_tiles()), 0u);
  std::size_t first = 0;  // global index of the current mesh's triangle 0
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const ClipMesh& mesh = meshes[m];
    const std::size_t n = mesh.triangles.size();
    const std::size_t lo = std::max(begin, first), hi = std::min(end, first + n);
    const std::size_t num_vertices = mesh.clip_positions.size();
    const SnappedVertex* snapped = snapped_.data() + vertex_offsets_[m];
    const std::uint8_t* outcodes = outcodes_.data() + vertex_offsets_[m];
    for (std::size_t g = lo; g < hi; ++g) {
      const std::size_t t = g - first;
      const glm::uvec3 idx = mesh.triangles[t];
      if (idx.x >= num_vertices || idx.y >= num_vertices || idx.z >= num_vertices) continue;
      const unsigned o0 = outcodes[idx.x], o1 = outcodes[idx.y], o2 = outcodes[idx.z];
      if ((o0 & o1 & o2) != 0) continue;  // all beyond one plane
      const auto mi = static_cast<std::uint32_t>(m), ti = static_cast<std::uint32_t>(t);
      if ((o0 | o1 | o2) == 0) {
        EmitSnapped(snapped[idx.x], snapped[idx.y], snapped[idx.z], nullptr, mi, ti, out);
      } else {
        const glm::vec4 clip[3] = {mesh.clip_positions[idx.x], mesh.clip_positions[idx.y],
                                   mesh.clip_positions[idx.z]};
        EmitClipped(clip, mi, ti, out);
      }
    }
    first += n;
  }
}

bool Rasterizer::Setup(std::span<const ClipMesh> meshes, const RasterSettings& settings) {
  if (settings.width < 1 || settings.height < 1 || settings.width > kMaxRasterSize ||
      settings.height > kMaxRasterSize || settings.threads < 1 ||
      settings.threads >= (1 << (32 - kThreadShift)))
    return false;
  width_ = settings.width;
  height_ = settings.height;
  cull_ = settings.cull_back_faces;
  num_planes_ = settings.clip_far ? 6 : 5;
  tiles_x_ = (width_ + kTileSize - 1) / kTileSize;
  tiles_y_ = (height_ + kTileSize - 1) / kTileSize;
  // Clip to half the limit so vertices created on a guard plane, after
  // round-off, stay well inside what EmitTriangle accepts.
  guard_ = kGuardLimitSamples / static_cast<float>(std::max(width_, height_)) - 1.0f;
  std::size_t total = 0;
  for (const ClipMesh& mesh : meshes) total += mesh.triangles.size();
  // Outcodes and snapped positions once per vertex; a triangle inside every
  // plane reuses them, so shared vertices snap identically by construction.
  vertex_offsets_.assign(meshes.size() + 1, 0);
  for (std::size_t m = 0; m < meshes.size(); ++m)
    vertex_offsets_[m + 1] = vertex_offsets_[m] + meshes[m].clip_positions.size();
  snapped_.resize(vertex_offsets_.back());
  outcodes_.resize(vertex_offsets_.back());
  const int vertex_threads = vertex_offsets_.back() > 16384 ? settings.threads : 1;
  base::RunOnThreads(vertex_threads, [&](int t) {
    for (std::size_t m = 0; m < meshes.size(); ++m) {
      const std::span<const glm::vec4> clip = meshes[m].clip_positions;
      const std::size_t begin = clip.size() * static_cast<std::size_t>(t) / static_cast<std::size_t>(vertex_threads);
      const std::size_t end = clip.size() * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(vertex_threads);
      for (std::size_t i = begin; i < end; ++i) {
        unsigned code = 0;
        for (int p = 0; p < num_planes_; ++p)
          if (!(PlaneDistance(clip[i], p, guard_) >= 0.0f)) code |= 1u << p;
        SnappedVertex& v = snapped_[vertex_offsets_[m] + i];
        // Inside every plane yet not snappable cannot happen; be safe anyway.
        if (code == 0 && !Snap(clip[i], v)) code = 1u;
        outcodes_[vertex_offsets_[m] + i] = static_cast<std::uint8_t>(code);
      }
    }
  });
  const int threads = static_cast<int>(
      std::max<std::size_t>(1, std::min<std::size_t>(static_cast<std::size_t>(settings.threads),
                                                      total / 1024 + 1)));
  per_thread_.resize(static_cast<std::size_t>(threads));
  base::RunOnThreads(threads, [&](int t) {
    const std::size_t begin = total * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
    const std::size_t end =
        total * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(threads);
    SetupRange(meshes, begin, end, per_thread_[static_cast<std::size_t>(t)]);
  });
  // Tile offsets; each thread's counts become its write cursors, so every
  // bin lists thread 0's triangles first, then thread 1's: input order.
  const auto tiles = static_cast<std::size_t>(num_tiles());
  tile_offsets_.assign(tiles + 1, 0u);
  std::uint32_t running = 0;
  for (std::size_t tile = 0; tile < tiles; ++tile) {
    tile_offsets_[tile] = running;
    for (PerThread& part : per_thread_) {
      const std::uint32_t c = part.tile_counts[tile];
      part.tile_counts[tile] = running;
      running += c;
    }
  }
  tile_offsets_[tiles] = running;
  bins_.resize(running);
  base::RunOnThreads(threads, [&](int t) {
    PerThread& part = per_thread_[static_cast<std::size_t>(t)];
    const std::uint32_t base = static_cast<std::uint32_t>(t) << kThreadShift;
    for (std::size_t i = 0; i < part.triangles.size(); ++i) {
      const RasterTriangle& tri = part.triangles[i];
      for (int ty = tri.min_y / kTileSize; ty <= tri.max_y / kTileSize; ++ty)
        for (int tx = tri.min_x / kTileSize; tx <= tri.max_x / kTileSize; ++tx)
          bins_[part.tile_counts[static_cast<std::size_t>(ty * tiles_x_ + tx)]++] =
              base | static_cast<std::uint32_t>(i);
    }
  });
  return true;
}

void Rasterizer::RasterizeTile(int tile, std::span<float> depth,
                               std::span<std::uint32_t> ids) const {
  PATCHSKIN_CHECK(depth.size() >= kTileBufferSize && ids.size() >= kTileBufferSize);
  std::fill(depth.begin(), depth.begin() + kTileSize * kTileSize, 0.0f);
  std::fill(ids.begin(), ids.begin() + kTileSize * kTileSize, kNoTriangle);
  const int x0 = (tile % tiles_x_) * kTileSize, y0 = (tile / tiles_x_) * kTileSize;
  const int x1 = std::min(x0 + kTileSize, width_), y1 = std::min(y0 + kTileSize, height_);
  const auto t = static_cast<std::size_t>(tile);
  for (std::uint32_t k = tile_offsets_[t]; k < tile_offsets_[t + 1]; ++k) {
    const std::uint32_t id = bins_[k];
    const RasterTriangle& tri = triangle(id);
    const int bx0 = std::max(x0, tri.min_x), by0 = std::max(y0, tri.min_y);
    const int bx1 = std::min(x1 - 1, tri.max_x), by1 = std::min(y1 - 1, tri.max_y);
    std::int64_t row[3], step_x[3], step_y[3];
    for (int i = 0; i < 3; ++i) {
      const int a = (i + 1) % 3, b = (i + 2) % 3;
      const std::int32_t dx = tri.x[b] - tri.x[a], dy = tri.y[b] - tri.y[a];
      const bool top_left = dy < 0 || (dy == 0 && dx > 0);
      row[i] = EdgeValue(tri.x[a], tri.y[a], tri.x[b], tri.y[b], bx0, by0) - (top_left ? 0 : 1);
      step_x[i] = -std::int64_t{dy} * kSubpixelScale;
      step_y[i] = std::int64_t{dx} * kSubpixelScale;
    }
    const std::int64_t area2 = std::int64_t{tri.x[1] - tri.x[0]} * (tri.y[2] - tri.y[0]) -
                               std::int64_t{tri.y[1] - tri.y[0]} * (tri.x[2] - tri.x[0]);
    const float inv_area = 1.0f / static_cast<float>(area2);
    const float z0 = tri.inv_w[0] * inv_area, z1 = tri.inv_w[1] * inv_area,
                z2 = tri.inv_w[2] * inv_area;
    const std::int32_t extent_x = std::max({tri.x[0], tri.x[1], tri.x[2]}) - std::min({tri.x[0], tri.x[1], tri.x[2]});
    const std::int32_t extent_y = std::max({tri.y[0], tri.y[1], tri.y[2]}) - std::min({tri.y[0], tri.y[1], tri.y[2]});
    if (extent_x < kSmallTriangleExtent && extent_y < kSmallTriangleExtent) {
      // Small triangle: every edge value inside its bounds fits in 32 bits
      // (|dx|, |dy| < 2^14 fixed-point units, so |E| < 2^30), so the loop can
      // run on int32 lanes without branches.
      std::int32_t row32[3], sx32[3], sy32[3];
      for (int i = 0; i < 3; ++i) {
        row32[i] = static_cast<std::int32_t>(row[i]);
        sx32[i] = static_cast<std::int32_t>(step_x[i]);
        sy32[i] = static_cast<std::int32_t>(step_y[i]);
      }
      const int n = bx1 - bx0 + 1;
#if defined(__SSE2__)
      // Four samples per step. The edge values of a row's first four samples
      // are kept in lanes and stepped down a row with one add each; the group
      // reaching past the bounds (the last one, when n is not a multiple of
      // 4) masks off its extra lanes, which may read and rewrite, unchanged,
      // the next row or the buffer padding.
      __m128i row0 = _mm_setr_epi32(row32[0], row32[0] + sx32[0], row32[0] + 2 * sx32[0], row32[0] + 3 * sx32[0]);
      __m128i row1 = _mm_setr_epi32(row32[1], row32[1] + sx32[1], row32[1] + 2 * sx32[1], row32[1] + 3 * sx32[1]);
      __m128i row2 = _mm_setr_epi32(row32[2], row32[2] + sx32[2], row32[2] + 2 * sx32[2], row32[2] + 3 * sx32[2]);
      const __m128i down0 = _mm_set1_epi32(sy32[0]), down1 = _mm_set1_epi32(sy32[1]),
                    down2 = _mm_set1_epi32(sy32[2]);
      const __m128i step0 = _mm_set1_epi32(4 * sx32[0]), step1 = _mm_set1_epi32(4 * sx32[1]),
                    step2 = _mm_set1_epi32(4 * sx32[2]);
      const __m128 zz0 = _mm_set1_ps(z0), zz1 = _mm_set1_ps(z1), zz2 = _mm_set1_ps(z2);
      const __m128i minus_one = _mm_set1_epi32(-1);
      const __m128i id4 = _mm_set1_epi32(static_cast<int>(id));
      const int full = n & ~3;  // samples in whole groups
      const __m128i tail = _mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(n - full));
      for (int sy = by0; sy <= by1; ++sy) {
        float* d = depth.data() + static_cast<std::size_t>(sy - y0) * kTileSize +
                   static_cast<std::size_t>(bx0 - x0);
        std::uint32_t* out = ids.data() + (d - depth.data());
        __m128i e0 = row0, e1 = row1, e2 = row2;
        // Depth test and store of the group at i for the lanes in `inside`.
        const auto group = [&](int i, __m128i inside) {
          const __m128 z = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_cvtepi32_ps(e0), zz0),
                                                 _mm_mul_ps(_mm_cvtepi32_ps(e1), zz1)),
                                      _mm_mul_ps(_mm_cvtepi32_ps(e2), zz2));
          const __m128 old_z = _mm_loadu_ps(d + i);
          const __m128 pass = _mm_and_ps(_mm_castsi128_ps(inside), _mm_cmpgt_ps(z, old_z));
          _mm_storeu_ps(d + i, _mm_or_ps(_mm_and_ps(pass, z), _mm_andnot_ps(pass, old_z)));
          const __m128i old_id = _mm_loadu_si128(reinterpret_cast<const __m128i*>(out + i));
          const __m128i pass_i = _mm_castps_si128(pass);
          _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                           _mm_or_si128(_mm_and_si128(pass_i, id4), _mm_andnot_si128(pass_i, old_id)));
        };
        int i = 0;
        for (; i < full; i += 4) {
          const __m128i inside =
              _mm_cmpgt_epi32(_mm_or_si128(_mm_or_si128(e0, e1), e2), minus_one);
          // No test for an empty group: about half of a small triangle's
          // bounding box lies outside it, in no predictable pattern, and the
          // mispredicted branch cost more than the masked depth test and
          // stores it saved (RasterizeTile ~12 % faster without it, against
          // SampleShader::Load in alternating perf profiles).
          group(i, inside);
          e0 = _mm_add_epi32(e0, step0);
          e1 = _mm_add_epi32(e1, step1);
          e2 = _mm_add_epi32(e2, step2);
        }
        if (i < n) {
          const __m128i inside = _mm_and_si128(
              _mm_cmpgt_epi32(_mm_or_si128(_mm_or_si128(e0, e1), e2), minus_one), tail);
          if (_mm_movemask_epi8(inside) != 0) group(i, inside);
        }
        row0 = _mm_add_epi32(row0, down0);
        row1 = _mm_add_epi32(row1, down1);
        row2 = _mm_add_epi32(row2, down2);
      }
#else
      for (int sy = by0; sy <= by1; ++sy) {
        float* d = depth.data() + static_cast<std::size_t>(sy - y0) * kTileSize +
                   static_cast<std::size_t>(bx0 - x0);
        std::uint32_t* out = ids.data() + (d - depth.data());
        std::int32_t e0 = row32[0], e1 = row32[1], e2 = row32[2];
        for (int i = 0; i < n; ++i) {
          const float z = static_cast<float>(e0) * z0 + static_cast<float>(e1) * z1 +
                          static_cast<float>(e2) * z2;
          const bool pass = ((e0 | e1 | e2) >= 0) & (z > d[i]);
          d[i] = pass ? z : d[i];
          out[i] = pass ? id : out[i];
          e0 += sx32[0];
          e1 += sx32[1];
          e2 += sx32[2];
        }
        row32[0] += sy32[0];
        row32[1] += sy32[1];
        row32[2] += sy32[2];
      }
#endif
      continue;
    }
#if defined(__SSE2__)
    // Large triangle (the ground's two cover most tiles): the same edge values
    // in double lanes, exact since every |E| < 2^53, four samples per step;
    // converting them to float rounds once, as the int64 -> float cast does,
    // so z and the result are those of the scalar loop below.
    {
      const int n = bx1 - bx0 + 1;
      const __m128d zero = _mm_setzero_pd();
      const __m128 zz0 = _mm_set1_ps(z0), zz1 = _mm_set1_ps(z1), zz2 = _mm_set1_ps(z2);
      const __m128i count = _mm_set1_epi32(n), four = _mm_set1_epi32(4);
      const __m128i id4 = _mm_set1_epi32(static_cast<int>(id));
      __m128d step4[3];
      for (int i = 0; i < 3; ++i) step4[i] = _mm_set1_pd(static_cast<double>(4 * step_x[i]));
      for (int sy = by0; sy <= by1; ++sy) {
        float* d = depth.data() + static_cast<std::size_t>(sy - y0) * kTileSize +
                   static_cast<std::size_t>(bx0 - x0);
        std::uint32_t* out = ids.data() + (d - depth.data());
        __m128d lo[3], hi[3];  // samples (0, 1) and (2, 3) of the group
        for (int i = 0; i < 3; ++i) {
          const auto r = static_cast<double>(row[i]), st = static_cast<double>(step_x[i]);
          lo[i] = _mm_setr_pd(r, r + st);
          hi[i] = _mm_setr_pd(r + 2.0 * st, r + 3.0 * st);
        }
        __m128i lane = _mm_setr_epi32(0, 1, 2, 3);
        for (int i = 0; i < n; i += 4) {
          const __m128d in_lo = _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(lo[0], zero), _mm_cmpge_pd(lo[1], zero)),
                                           _mm_cmpge_pd(lo[2], zero));
          const __m128d in_hi = _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(hi[0], zero), _mm_cmpge_pd(hi[1], zero)),
                                           _mm_cmpge_pd(hi[2], zero));
          const __m128 inside = _mm_and_ps(
              _mm_shuffle_ps(_mm_castpd_ps(in_lo), _mm_castpd_ps(in_hi), _MM_SHUFFLE(2, 0, 2, 0)),
              _mm_castsi128_ps(_mm_cmplt_epi32(lane, count)));
          __m128 f[3];
          for (int j = 0; j < 3; ++j) f[j] = _mm_movelh_ps(_mm_cvtpd_ps(lo[j]), _mm_cvtpd_ps(hi[j]));
          for (int j = 0; j < 3; ++j) {
            lo[j] = _mm_add_pd(lo[j], step4[j]);
            hi[j] = _mm_add_pd(hi[j], step4[j]);
          }
          lane = _mm_add_epi32(lane, four);
          if (_mm_movemask_ps(inside) == 0) continue;
          const __m128 z = _mm_add_ps(_mm_add_ps(_mm_mul_ps(f[0], zz0), _mm_mul_ps(f[1], zz1)),
                                      _mm_mul_ps(f[2], zz2));
          const __m128 old_z = _mm_loadu_ps(d + i);
          const __m128 pass = _mm_and_ps(inside, _mm_cmpgt_ps(z, old_z));
          _mm_storeu_ps(d + i, _mm_or_ps(_mm_and_ps(pass, z), _mm_andnot_ps(pass, old_z)));
          const __m128i old_id = _mm_loadu_si128(reinterpret_cast<const __m128i*>(out + i));
          const __m128i pass_i = _mm_castps_si128(pass);
          _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                           _mm_or_si128(_mm_and_si128(pass_i, id4), _mm_andnot_si128(pass_i, old_id)));
        }
        row[0] += step_y[0];
        row[1] += step_y[1];
        row[2] += step_y[2];
      }
      continue;
    }
#endif
    for (int sy = by0; sy <= by1; ++sy) {
      std::int64_t e0 = row[0], e1 = row[1], e2 = row[2];
      const std::size_t base = static_cast<std::size_t>(sy - y0) * kTileSize;
      for (int sx = bx0; sx <= bx1; ++sx) {
        if ((e0 | e1 | e2) >= 0) {
          const float z = static_cast<float>(e0) * z0 + static_cast<float>(e1) * z1 +
                          static_cast<float>(e2) * z2;
          const std::size_t at = base + static_cast<std::size_t>(sx - x0);
          if (z > depth[at]) {
            depth[at] = z;
            ids[at] = id;
          }
        }
        e0 += step_x[0];
        e1 += step_x[1];
        e2 += step_x[2];
      }
      row[0] += step_y[0];
      row[1] += step_y[1];
      row[2] += step_y[2];
    }
  }
}

}  // namespace render
