#pragma once
// Tiled triangle rasterizer core (after ssloy/tinyrenderer our_gl.cpp, tiled
// like pbrt-v4's ParallelFor2D).
//
// Pipeline: clip-space triangles -> Setup() (near-plane and guard-band
// clipping in homogeneous space, back-face culling, snapping to fixed point
// with kSubpixelBits fractional bits, binning into square tiles) ->
// RasterizeTile() per tile (integer edge functions with an exact top-left fill
// rule, z-buffer on 1/w) -> a visibility buffer (nearest triangle id per
// sample) that the caller shades (see Renderer).
//
// Coordinates: "samples" are the pixels of the (possibly supersampled) raster,
// row 0 at the top; sample (x, y) is tested at its centre (x + 0.5, y + 0.5).
// Front faces are counter-clockwise in NDC (OpenGL). Far-plane clipping is
// optional (RasterSettings::clip_far); without it geometry beyond the far plane
// is drawn.
//
// Determinism: each tile's bin lists its triangles in input order and a tile is
// rasterized by one thread, so the output is identical for any thread count.

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace render {

inline constexpr int kSubpixelBits = 8;                 // fixed-point fraction bits
inline constexpr int kSubpixelScale = 1 << kSubpixelBits;
inline constexpr int kTileSize = 64;                    // tile side, samples
// Size of the per-tile buffers RasterizeTile writes: kTileSize^2 samples plus
// padding for its 4-wide loop (the padding holds no data).
inline constexpr int kTileBufferSize = kTileSize * kTileSize + 4;
inline constexpr std::uint32_t kNoTriangle = 0xffffffffu;  // empty visibility-buffer entry

// One triangle list in homogeneous clip space.
struct ClipMesh {
  std::span<const glm::vec4> clip_positions;  // #V clip-space positions
  std::span<const glm::uvec3> triangles;      // #T vertex indices; out-of-range ones are skipped
};

// A screen-space triangle ready for edge walking (after clipping and culling).
// Its vertices are ordered so the doubled area in y-down sample space is > 0.
struct RasterTriangle {
  std::int32_t x[3];      // fixed-point sample-space x (kSubpixelBits fraction)
  std::int32_t y[3];      // fixed-point sample-space y, y down
  float inv_w[3];         // 1 / clip w (1 / view depth) at each vertex
  std::int32_t min_x, min_y, max_x, max_y;  // inclusive sample bounds, inside the viewport
  std::uint32_t mesh;     // index of the ClipMesh it came from
  std::uint32_t triangle; // index of the source triangle in that mesh
  std::int32_t clip_slot; // -1: vertex i is source corner order[i]; else row of corner weights
  std::uint8_t order[3];  // source corner of each vertex when clip_slot == -1
  bool back_facing;       // clockwise in NDC (only when culling is off)
};

struct RasterSettings {
  int width = 0;               // raster size in samples, 1..16384
  int height = 0;              // raster size in samples, 1..16384
  bool cull_back_faces = false;
  // Clip at the far plane (clip z <= w, i.e. view depth <= the camera's far
  // plane) as at the near plane: what lies beyond is not drawn, triangles
  // crossing it are cut. Off: the far plane limits nothing.
  bool clip_far = false;
  int threads = 1;             // >= 1; setup and binning split over this many threads
};

// Signed doubled area of a fixed-point triangle at sample (sx, sy)'s centre
// for edge a->b: (xb - xa)(py - ya) - (yb - ya)(px - xa), in 1/kSubpixelScale^2
// units. Positive inside a RasterTriangle.
inline std::int64_t EdgeValue(std::int32_t xa, std::int32_t ya, std::int32_t xb, std::int32_t yb,
                              int sx, int sy) {
  const std::int64_t px = std::int64_t{sx} * kSubpixelScale + kSubpixelScale / 2;
  const std::int64_t py = std::int64_t{sy} * kSubpixelScale + kSubpixelScale / 2;
  return std::int64_t{xb - xa} * (py - ya) - std::int64_t{yb - ya} * (px - xa);
}

// Where the edge walk over one triangle starts: its sample bounds cut to a
// rectangle, and the three edge functions there and per step. Edge i is
// opposite vertex i (from vertex i+1 to i+2). Every value is exact in int64
// (fixed-point coordinates < 2^25, see Setup's guard band).
struct EdgeStart {
  int bx0, by0, bx1, by1;  // inclusive samples to visit; none if bx0 > bx1 or by0 > by1
  std::int64_t row[3];     // E_i at (bx0, by0), less 1 where the fill rule does not own edge i
  std::int64_t step_x[3], step_y[3];  // change of E_i one sample right / one sample down
};

// Top-left rule: a sample exactly on an edge belongs to the triangle when the
// edge is a left edge (interior to its right, dy < 0) or a top edge (horizontal,
// interior below, dy == 0 and dx > 0). Biasing the other edges by -1 makes
// "E_i >= 0 for all i" the whole coverage test, so triangles sharing an edge
// cover each sample on it exactly once.
inline EdgeStart StartEdges(const RasterTriangle& tri, int x0, int y0, int x1, int y1) {
  EdgeStart s;
  s.bx0 = std::max(x0, tri.min_x);
  s.by0 = std::max(y0, tri.min_y);
  s.bx1 = std::min(x1 - 1, tri.max_x);
  s.by1 = std::min(y1 - 1, tri.max_y);
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    const std::int32_t dx = tri.x[b] - tri.x[a], dy = tri.y[b] - tri.y[a];
    const bool top_left = dy < 0 || (dy == 0 && dx > 0);
    s.row[i] = EdgeValue(tri.x[a], tri.y[a], tri.x[b], tri.y[b], s.bx0, s.by0) - (top_left ? 0 : 1);
    s.step_x[i] = -std::int64_t{dy} * kSubpixelScale;
    s.step_y[i] = std::int64_t{dx} * kSubpixelScale;
  }
  return s;
}

// Holds the per-frame triangle setup and tile bins; reuse one across frames so
// its buffers are not reallocated.
class Rasterizer {
 public:
  // Clips, culls, snaps and bins every triangle of `meshes`. Returns false and
  // sets up nothing when the settings are out of range.
  bool Setup(std::span<const ClipMesh> meshes, const RasterSettings& settings);

  int tiles_x() const { return tiles_x_; }
  int tiles_y() const { return tiles_y_; }
  int num_tiles() const { return tiles_x_ * tiles_y_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // Number of setup triangles (clipped pieces count separately).
  std::size_t num_triangles() const;

  // Number of triangles binned to `tile` (0 = the tile shows only background).
  std::uint32_t tile_triangle_count(int tile) const {
    const auto t = static_cast<std::size_t>(tile);
    return tile_offsets_[t + 1] - tile_offsets_[t];
  }
  // Visibility ids of the triangles binned to `tile`, in input order.
  std::span<const std::uint32_t> tile_triangles(int tile) const {
    const auto t = static_cast<std::size_t>(tile);
    return {bins_.data() + tile_offsets_[t], tile_triangle_count(tile)};
  }

  // Rasterizes tile `tile` (row-major over tiles_x() x tiles_y()) into
  // buffers of kTileBufferSize entries (row-major over the tile, row stride
  // kTileSize): `depth` gets the largest 1/w seen (0 = empty) and `ids` the id of
  // the nearest triangle (kNoTriangle = empty). Ties keep the earlier triangle.
  // Four samples per step with SSE2 (rasterize_tile_fast.cpp); the result is
  // bit for bit that of RasterizeTileReference.
  void RasterizeTile(int tile, std::span<float> depth, std::span<std::uint32_t> ids) const;
  // The same output from the scalar reference walk, one sample at a time:
  // ForEachSample's coverage, z = sum_i float(E_i) * inv_w_i / (doubled area),
  // summed in that order in float. The definition the fast path is tested
  // against; several times slower.
  void RasterizeTileReference(int tile, std::span<float> depth, std::span<std::uint32_t> ids) const;

  // The edge walk: calls fn(sx, sy, e) for every sample of `tri` inside
  // [x0,x1)x[y0,y1) that the fill rule assigns to it, row by row, left to
  // right, with e (const std::int64_t[3]) its biased edge values (StartEdges).
  // No depth test. Integer only, so it is exact for every triangle Setup emits.
  template <class Fn>
  static void ForEachSample(const RasterTriangle& tri, int x0, int y0, int x1, int y1, Fn&& fn);

  // The setup triangle with visibility id `id`.
  const RasterTriangle& triangle(std::uint32_t id) const {
    return per_thread_[id >> kThreadShift].triangles[id & kLocalMask];
  }

  // Source-corner weights of a clipped triangle's vertices (column i =
  // weights of vertex i), or nullptr when the triangle was not clipped.
  const glm::mat3* corner_weights(std::uint32_t id) const {
    const RasterTriangle& tri = triangle(id);
    return tri.clip_slot < 0 ? nullptr
                             : &per_thread_[id >> kThreadShift]
                                    .corner_weights[static_cast<std::size_t>(tri.clip_slot)];
  }

  // Visits every setup triangle in order (for tests).
  template <class Fn>
  void ForEachTriangle(Fn&& fn) const {
    for (const PerThread& part : per_thread_)
      for (const RasterTriangle& tri : part.triangles) fn(tri);
  }

 private:
  static constexpr int kThreadShift = 26;
  static constexpr std::uint32_t kLocalMask = (1u << kThreadShift) - 1u;
  struct PerThread {
    std::vector<RasterTriangle> triangles;
    std::vector<glm::mat3> corner_weights;  // column i: source-corner weights of vertex i
    std::vector<std::uint32_t> tile_counts;  // per tile
  };
  struct SnappedVertex {
    std::int32_t x, y;  // fixed-point sample coordinates
    float inv_w;        // 1 / clip w
  };
  bool Snap(const glm::vec4& clip, SnappedVertex& v) const;
  bool EmitSnapped(const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
                   const glm::mat3* weights, std::uint32_t mesh, std::uint32_t triangle,
                   PerThread& out) const;
  void SetupRange(std::span<const ClipMesh> meshes, std::size_t begin, std::size_t end,
                  PerThread& out) const;
  void EmitClipped(const glm::vec4 (&clip)[3], std::uint32_t mesh, std::uint32_t triangle,
                   PerThread& out) const;
  bool EmitTriangle(const glm::vec4 (&clip)[3], const glm::mat3* weights, std::uint32_t mesh,
                    std::uint32_t triangle, PerThread& out) const;

  int width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  bool cull_ = false;
  int num_planes_ = 5;  // clip planes in use: near, 4 guard-band planes, [far]
  float guard_ = 1.0f;  // NDC guard band: |x|,|y| <= guard_ * w keeps fixed point in range
  std::vector<PerThread> per_thread_;
  std::vector<std::size_t> vertex_offsets_;   // per mesh, into snapped_ / outcodes_
  std::vector<SnappedVertex> snapped_;        // per vertex, valid where its outcode is 0
  std::vector<std::uint8_t> outcodes_;        // per vertex: bit p set = outside clip plane p
  std::vector<std::uint32_t> tile_offsets_;  // num_tiles + 1
  std::vector<std::uint32_t> bins_;          // triangle ids grouped by tile
};

template <class Fn>
void Rasterizer::ForEachSample(const RasterTriangle& tri, int x0, int y0, int x1, int y1, Fn&& fn) {
  EdgeStart s = StartEdges(tri, x0, y0, x1, y1);
  for (int sy = s.by0; sy <= s.by1; ++sy) {
    std::int64_t e[3] = {s.row[0], s.row[1], s.row[2]};
    for (int sx = s.bx0; sx <= s.bx1; ++sx) {
      if ((e[0] | e[1] | e[2]) >= 0) fn(sx, sy, e);  // all three >= 0: inside
      for (int i = 0; i < 3; ++i) e[i] += s.step_x[i];
    }
    for (int i = 0; i < 3; ++i) s.row[i] += s.step_y[i];
  }
}

}  // namespace render
