#include "render/raster/rasterizer.h"

#include <algorithm>
#include <cmath>

#include "base/check.h"
#include "base/parallel.h"
#include "render/raster/internal/simd.h"
#include "render/raster/internal/tile_draw.h"

namespace render {
namespace {

// Largest |sample coordinate| a snapped vertex may have: 2^17 samples keeps
// fixed-point coordinates below 2^25, differences below 2^26 and edge-function
// products below 2^53, comfortably inside int64.
constexpr float kGuardLimitSamples = 131072.0f;
constexpr int kMaxRasterSize = 16384;
constexpr int kMaxClipVertices = 10;  // a triangle clipped by 6 planes has at most 9

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
  v.x = simd::RoundToInt(sx * static_cast<float>(kSubpixelScale));
  v.y = simd::RoundToInt(sy * static_cast<float>(kSubpixelScale));
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

namespace {

// Clears tile `tile`'s buffers and names its rectangle.
internal::TileTarget StartTile(const Rasterizer& raster, int tile, std::span<float> depth,
                               std::span<std::uint32_t> ids) {
  PATCHSKIN_CHECK(depth.size() >= kTileBufferSize && ids.size() >= kTileBufferSize);
  std::fill(depth.begin(), depth.begin() + kTileSize * kTileSize, 0.0f);
  std::fill(ids.begin(), ids.begin() + kTileSize * kTileSize, kNoTriangle);
  const int x0 = (tile % raster.tiles_x()) * kTileSize, y0 = (tile / raster.tiles_x()) * kTileSize;
  return {.x0 = x0,
          .y0 = y0,
          .x1 = std::min(x0 + kTileSize, raster.width()),
          .y1 = std::min(y0 + kTileSize, raster.height()),
          .depth = depth.data(),
          .ids = ids.data()};
}

}  // namespace

// The reference: the integer edge walk (exact, top-left rule) and a plain
// depth test per covered sample. The fast path must match it bit for bit, so
// the z formula and its float operation order are part of the contract.
void internal::DrawTriangleReference(const RasterTriangle& tri, std::uint32_t id, TileTarget tile) {
  const DepthFactors f = MakeDepthFactors(tri);
  Rasterizer::ForEachSample(
      tri, tile.x0, tile.y0, tile.x1, tile.y1, [&](int sx, int sy, const std::int64_t(&e)[3]) {
        const float z = static_cast<float>(e[0]) * f.z[0] + static_cast<float>(e[1]) * f.z[1] +
                        static_cast<float>(e[2]) * f.z[2];
        const std::size_t at = static_cast<std::size_t>(sy - tile.y0) * kTileSize +
                               static_cast<std::size_t>(sx - tile.x0);
        if (z > tile.depth[at]) {
          tile.depth[at] = z;
          tile.ids[at] = id;
        }
      });
}

void Rasterizer::RasterizeTile(int tile, std::span<float> depth,
                               std::span<std::uint32_t> ids) const {
  const internal::TileTarget target = StartTile(*this, tile, depth, ids);
  for (const std::uint32_t id : tile_triangles(tile))
    internal::DrawTriangleFast(triangle(id), id, target);
}

void Rasterizer::RasterizeTileReference(int tile, std::span<float> depth,
                                        std::span<std::uint32_t> ids) const {
  const internal::TileTarget target = StartTile(*this, tile, depth, ids);
  for (const std::uint32_t id : tile_triangles(tile))
    internal::DrawTriangleReference(triangle(id), id, target);
}

}  // namespace render
