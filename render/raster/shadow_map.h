#pragma once
// ShadowMap: the key light's view of the scene's occluders, for cast shadows.
//
//   render::ShadowMap map;
//   map.Build(key_dir_world, casters, {.resolution = 1024, .threads = 2});
//   float lit = map.Visibility(ground_point);           // 1 lit ... 0 in shadow
//   float on_body = map.SurfaceVisibility(p, normal);   // a caster's own surface
//
// Build rasterizes every caster triangle (either winding) with an orthographic
// projection along the light direction, fitted to the casters' bounds, into a
// resolution x resolution buffer that keeps, per texel centre, the largest
// light-space depth dot(p, light_dir), i.e. the occluder nearest the light.
// Max is order-independent and every texel value is a pure function of the
// triangles, so the map is the same bytes however many threads build it (each
// fills its own band of rows). Cost: O(#T * bands + covered texels);
// a closed caster skips its triangles turned away from the light;
// resolution^2 floats (4 MB at 1024) plus coarse block bounds (1/32 of that).
//
// Visibility is percentage-closer filtering: the share of a disc of integer
// texel offsets around the point, each a bilinearly weighted depth comparison
// (lit where no occluder is nearer the light than the point minus a bias).
// The offsets are whole texels, so all taps share one pair of bilinear
// fractions: the comparisons of the footprint's texels become bit rows, and
// the filter is four popcounts of them against the disc (Sxy below).
//   Visibility         21 taps (5 x 5 without corners), for receivers such as
//                      the ground: a soft edge about 5 texels wide.
//   SurfaceVisibility  9 taps (3 x 3) at the point pushed along its normal,
//                      for the casters' own surfaces, where a narrower filter
//                      and the offset keep a lit surface from shadowing itself.
// Coarse blocks hold the depth range of their 3 x 3 neighbourhood, so a point
// with no occluder in reach is lit after one read, and one deep in the umbra
// is dark after the same read; SurfaceVisibility keeps a per-texel maximum
// instead (a lit surface has itself in every block): one read where lit. Points outside the map (or not finite) are lit.
// The soft edge is a fixed width (no blocker search): it reads as a soft light.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace render {

// One occluding triangle mesh, world space; spans are read only during Build.
struct ShadowCaster {
  std::span<const glm::vec3> positions{};   // #V
  std::span<const glm::uvec3> triangles{};  // #T; out-of-range indices are skipped
  // Closed and outward (counter-clockwise seen from outside): only its
  // triangles facing the light are drawn, half the work. Otherwise both windings.
  bool closed = false;
};

struct ShadowMapSettings {
  int resolution = 512;                // texels per side, 16 ... 8192
  float bias_texels = 1.5f;            // depth bias, in texel widths along the light
  float normal_offset_texels = 1.5f;   // SurfaceVisibility's push along the normal, texels
  int threads = 1;                     // bands built in parallel (the bytes do not depend on it)
};

class ShadowMap {
 public:
  // Rebuilds the map for `light_dir` (world, towards the light; normalized
  // here, must be non-zero). With no valid triangle the map is empty and
  // every point is lit.
  void Build(const glm::vec3& light_dir, std::span<const ShadowCaster> casters,
             const ShadowMapSettings& settings);

  // Fraction of the key light reaching world point `p`, in [0, 1] (21 taps).
  float Visibility(const glm::vec3& p) const;
  // Visibility of the points (x[k], y, z[k]), k = 0..3, bit for bit, the
  // coordinates of all four at once (a row of ground samples).
  void Visibility4(const float (&x)[4], float y, const float (&z)[4], float (&out)[4]) const;

  // The same for a point on a caster's surface with unit normal `n` (the side
  // it is seen from): 9 taps at p + n * normal offset. Only meaningful where
  // dot(n, light) > 0; callers skip the rest (the light does not reach them).
  float SurfaceVisibility(const glm::vec3& p, const glm::vec3& n) const;

  // For checks: a world point's texel coordinates (x, y; texel (i, j) spans
  // [i, i + 1) x [j, j + 1)) and light depth (z), and a texel's stored depth
  // (-inf where no caster covers its centre, and outside the map).
  glm::vec3 ToTexel(const glm::vec3& p) const {
    return {(glm::dot(p, axis_u_) - origin_.x) * inv_texel_, (glm::dot(p, axis_v_) - origin_.y) * inv_texel_,
            glm::dot(p, axis_w_)};
  }
  float Depth(int i, int j) const;


  // The map's square carried along the light onto the plane y = height: every
  // point of the plane the map can shadow lies inside these corners. False
  // (corners untouched) for an empty map or a light not above the plane's side.
  bool CornersOnPlane(float height, glm::vec3 (&corners)[4]) const;

  // SurfaceVisibility of lanes k = 0..3 with bit k of `lanes` set, bit for bit
  // ([component][lane] as in SurfacePoints4); other lanes get 1.
  void SurfaceVisibility4(const float (&p)[3][4], const float (&n)[3][4], int lanes,
                          float (&out)[4]) const;

  bool empty() const { return size_ == 0; }
  int resolution() const { return size_; }
  // World units per texel (the map is square in light space).
  float texel_size() const { return texel_; }
  // The half width of Visibility's soft edge, world units: points farther
  // than this from an occluder's outline are fully lit or fully dark.
  float soft_edge() const { return 3.5f * texel_; }

 private:
  static constexpr int kBlock = 8;  // texels per side of a coarse block
  static constexpr int kPad = 4;    // border texels around the map (no caster), so filters need no clamping
  struct Range {
    float lo, hi;  // min and max depth over a block's 3 x 3 neighbourhood
  };

  // The percentage-closer filter of a disc of `rows` bit rows (bit c of row r
  // is the tap at offset (c - half, r - half)) at texel coordinates (x, y).
  template <int kHalf>
  float Filter(float x, float y, float depth, const std::uint8_t (&disc)[2 * kHalf + 1]) const;
  // 1 or 0 when the block around (x, y) decides it alone, -1 otherwise.
  float BlockTest(float x, float y, float depth) const;
  void RasterBand(std::span<const std::vector<glm::vec3>> projected,
                  std::span<const ShadowCaster> casters, int row0, int row1);
  // Visibility and SurfaceVisibility after the point's texel coordinates and biased depth.
  float VisibilityAt(float x, float y, float depth) const;
  float SurfaceVisibilityAt(float x, float y, float depth) const;
  void BlockBounds(int block_row0, int block_row1, std::vector<Range>& own) const;
  void NarrowMaxima(int threads);  // fills narrow_max_
  const float* Row(int j) const { return depth_.data() + static_cast<std::size_t>(j + kPad) * stride_ + kPad; }
  float* Row(int j) { return depth_.data() + static_cast<std::size_t>(j + kPad) * stride_ + kPad; }

  glm::vec3 axis_u_{1, 0, 0}, axis_v_{0, 0, 1}, axis_w_{0, 1, 0};  // light space; w to the light
  glm::vec2 origin_{0.0f};        // light-space (u, v) of the map's corner
  float texel_ = 1.0f;            // world units per texel
  float inv_texel_ = 1.0f;
  float bias_ = 0.0f;             // world units
  float normal_offset_ = 0.0f;    // world units
  int size_ = 0;                  // texels per side (0: empty)
  std::size_t stride_ = 0;        // floats per stored row (size_ + 2 * kPad)
  int blocks_ = 0;                // coarse blocks per side
  std::vector<float> depth_;      // (size_ + 2 kPad)^2, row-major; -inf where no caster
  std::vector<Range> blocks3_;    // blocks_^2
  // Per cell (c, r) of two by two texels, c, r in [0, size_ / 2], at r * narrow_cells_ + c:
  // the largest depth of texels [2c - 2, 2c + 2] x [2r - 2, 2r + 2], which holds
  // the footprint of SurfaceVisibility's filter for any point whose
  // floor(x - 0.5) + 1 is 2c or 2c + 1 (same for y): an unoccluded point costs
  // one read of a grid a quarter of the map's size (it stays in cache).
  std::vector<float> narrow_max_;
  int narrow_cells_ = 0;
};

}  // namespace render
