#pragma once
// ShadowMap: the key light's view of the scene's occluders, for cast shadows.
//
//   render::ShadowMap map;
//   map.Build(key_dir_world, casters, {.resolution = 1024});
//   float lit = map.Visibility(ground_point);   // 1 lit ... 0 in shadow
//
// Build rasterizes every caster triangle (either winding) with an orthographic
// projection along the light direction, fitted to the casters' bounds, into a
// resolution x resolution buffer that keeps, per texel centre, the largest
// light-space depth dot(p, light_dir), i.e. the occluder nearest the light.
// Max is order-independent and every texel value is a pure function of the
// triangles, so the map is the same bytes however it is built or read.
// Cost: O(#T + covered texels) on the caller's thread; resolution^2 floats
// (4 MB at 1024) plus a coarse block maximum (1/64 of that).
//
// Visibility is percentage-closer filtering: the fraction of a fixed disc of
// kTaps taps (a golden-angle spiral of radius filter_radius_texels) whose
// bilinearly weighted depth comparisons find no occluder nearer the light than
// the point minus `bias_texels` texel widths. Points outside the map (or not
// finite) are lit (1). A block maximum rejects most lit points after one read.
// It does not model penumbrae widening with distance: the soft edge is a
// fixed width, which reads as a soft light without a blocker search.

#include <array>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace render {

// One occluding triangle mesh, world space; spans are read only during Build.
struct ShadowCaster {
  std::span<const glm::vec3> positions{};   // #V
  std::span<const glm::uvec3> triangles{};  // #T; out-of-range indices are skipped
};

struct ShadowMapSettings {
  int resolution = 1024;               // texels per side, 16 ... 8192
  float filter_radius_texels = 2.5f;   // PCF disc radius (the soft edge is about twice this)
  float bias_texels = 1.5f;            // depth bias, in texel widths along the light
};

class ShadowMap {
 public:
  static constexpr int kTaps = 16;

  // Rebuilds the map for `light_dir` (world, towards the light; normalized
  // here, must be non-zero). With no valid triangle the map is empty and
  // every point is lit.
  void Build(const glm::vec3& light_dir, std::span<const ShadowCaster> casters,
             const ShadowMapSettings& settings);

  // Fraction of the key light reaching world point `p`, in [0, 1].
  float Visibility(const glm::vec3& p) const;

  bool empty() const { return depth_.empty(); }
  int resolution() const { return size_; }
  // World units per texel (the map is square in light space).
  float texel_size() const { return texel_; }

 private:
  static constexpr int kBlock = 8;  // texels per side of a coarse block
  // The lit fraction of a bilinear depth test at texel coordinates (x, y)
  // (texel centres at i + 0.5) for a point at light depth `depth`.
  float LitBilinear(float x, float y, float depth) const;
  float Texel(int i, int j) const;  // -inf outside the map

  glm::vec3 axis_u_{1, 0, 0}, axis_v_{0, 0, 1}, axis_w_{0, 1, 0};  // light space; w to the light
  glm::vec2 origin_{0.0f};        // light-space (u, v) of the map's corner
  float texel_ = 1.0f;            // world units per texel
  float inv_texel_ = 1.0f;
  float bias_ = 0.0f;             // world units
  float radius_ = 0.0f;           // PCF radius, texels
  int size_ = 0;                  // texels per side (0: empty)
  int blocks_ = 0;                // coarse blocks per side
  std::vector<float> depth_;      // size_^2, row-major; -inf where no caster
  std::vector<float> block_max_;  // blocks_^2: max depth of the block and its 8 neighbours
  std::array<glm::vec2, kTaps> taps_{};  // PCF offsets, texels
};

}  // namespace render
