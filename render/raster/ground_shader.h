#pragma once
// GroundShader: the lit colour of the ground plane four samples at a time.
//
// The ground is most of a typical frame (80% of the demo's samples), so its
// per-sample work is reduced to what cannot be shared:
//  - the world point comes from the ray through the sample centre, whose
//    direction d = d0 + dx * sx + dy * sy is linear in the sample position:
//    p = eye + (ground_y - eye.y) / d.y * d (one reciprocal per sample, no
//    perspective-weight interpolation);
//  - grid lines and their fade as GroundAlbedo computes them, with the
//    reciprocals of the spacing, line softness and fade distance hoisted, and
//    the square root (the eye distance) only for lanes near a line;
//  - contact shadows as ContactShadowFactor, with the reciprocal radii
//    hoisted and exp(-2 r^2) from a degree-6 polynomial of 2^f, f in
//    [-1/2, 1/2] (relative error below 3e-7, about 10^4 times finer than one
//    8-bit step), evaluated only when a lane is inside a shadow's 3-radius cut;
//  - the light on the (upward-facing) ground, one colour per frame, less the
//    key light's share where the shadow map (when given) finds an occluder:
//    light - key_light * (1 - visibility); lit lanes keep `light` exactly.
// Every lane runs the same IEEE operations, so a sample's colour does not
// depend on its neighbours, on which lanes are asked for, or on thread count.
// The colour agrees with GroundAlbedo * ContactShadowFactor * light to about
// 1e-5 (tests/render/ground_shader_test.cpp); it is not bit-identical to them.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "render/raster/shading.h"
#include "render/raster/shadow_map.h"

namespace render {

struct GroundShaderParams {
  glm::mat4 clip_from_world{1.0f};  // the camera's projection * view
  glm::vec3 eye{0.0f};              // world-space centre of projection
  int raster_width = 1;             // sample raster size (output size * supersample), >= 1
  int raster_height = 1;            // >= 1
  float ground_y = 0.0f;            // world height of the ground plane
  float grid_spacing = 1.0f;        // world units between lines; <= 0: no lines
  GroundStyle style;                // colours, line width, fade distance
  std::span<const ContactShadow> shadows;  // copied by Create; may be empty
  glm::vec3 light{1.0f};            // multiplies albedo * shadow (1 for unlit renders)
  // The key light's cast shadow: the map (borrowed; must outlive the shader),
  // or null for none, and the part of `light` it takes away where fully shadowed.
  const ShadowMap* shadow_map = nullptr;
  glm::vec3 key_light{0.0f};
};

class GroundShader {
 public:
  // Precomputes the per-frame constants. The ground must not pass through the
  // eye (eye.y != ground_y) for the colours to mean anything; they stay finite.
  static GroundShader Create(const GroundShaderParams& params);

  // Linear RGB of samples (sx + k, sy), k = 0..3, in r[k], g[k], b[k]
  // (sample coordinates: the sample's centre is (sx + k + 0.5, sy + 0.5)).
  void Shade4(int sx, int sy, float* r, float* g, float* b) const;

  // The colour of one sample: lane 0 of Shade4.
  glm::vec3 Shade(int sx, int sy) const;

  // Multisampling: linear RGB of four whole pixels of ss x ss samples, the
  // pixels whose first samples are (sx + ss * k, sy), k = 0..3, shaded once
  // at their centres. The grid lines there are box-filtered over the pixel's
  // footprint on the ground (the pixel's two edge vectors projected, the
  // trapezoid profile integrated in closed form), so a line thinner than a
  // pixel is not lost between samples; contact shadows are smooth and read at
  // the centre. The cast shadow's edge is sharper than a pixel: its
  // visibility is the mean over the pixel's samples, as supersampling's.
  void ShadePixels4(int sx, int sy, int ss, float* r, float* g, float* b) const;

 private:
  // Shade4's and ShadePixels4's common end, four lanes of type V: contact
  // shadows, the key light's visibility (null: fully lit) and the albedo of
  // line weight `line`, stored in r, g, b.
  template <class V>
  void Finish4(V px, V pz, V line, const float* visibility, float* r, float* g, float* b) const;

  // The key light's visibility of four pixels (as ShadePixels4), each the mean
  // over its ss x ss samples.
  void PixelVisibility4(int sx, int sy, int ss, float* visibility) const;

  struct Shadow {
    float cx, cz;        // centre, world xz
    float inv_rx, inv_rz;  // 1 / half-axes
    float strength;      // 0..1
  };
  // Ray direction (unnormalized, world) = ray_c + ray_x * sx + ray_y * sy at sample centres.
  glm::vec3 ray_c_{0.0f}, ray_x_{0.0f}, ray_y_{0.0f};
  glm::vec3 eye_{0.0f};
  float height_ = 0.0f;          // ground_y - eye.y
  float ground_y_ = 0.0f;
  bool grid_ = false;            // grid lines drawn
  float inv_spacing_ = 1.0f;     // 1 / grid spacing
  float half_width_ = 0.0f;      // half the line width, in spacings
  float inv_soft_ = 1.0f;        // 1 / soft edge width (spacings)
  float soft_ = 1.0f;            // soft edge width (spacings)
  float inv_fade_ = 1.0f;        // 1 / fade start (spacings)
  glm::vec3 color_{0.0f}, line_delta_{0.0f};  // albedo between lines, line - between
  glm::vec3 light_{1.0f};
  float line_area_ = 0.0f;  // the line profile's integral over one spacing
  const ShadowMap* shadow_map_ = nullptr;
  glm::ivec4 map_box_{0};  // samples (x0, y0, x1, y1), inclusive, the map can darken
  glm::vec3 key_light_{0.0f};
  std::vector<Shadow> shadows_;
};

}  // namespace render
