#pragma once
// A base colour texture for the renderer: a linear RGB mip pyramid, built once
// per image (not per frame), sampled trilinearly.
//
// Level 0 is the image; level k+1 has max(1, floor(size / 2)) texels a side,
// each the mean of the 2 x 2 texels of level k it covers (an odd last row or
// column is dropped), down to 1 x 1. Building costs 4/3 of the image's texels
// in memory (12 bytes each) and one pass over them.
//
// Coordinates follow glTF: u right, v down the image rows; texel (x, y) of a
// level of size w x h has its centre at ((x + 0.5) / w, (y + 0.5) / h).
// Outside [0, 1] the wrap mode of each axis applies (repeat, clamp to the edge
// texel, mirrored repeat), per texel of the bilinear footprint.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/mesh.h"

namespace render {

class Texture {
 public:
  Texture() = default;
  // rgb: width x height x 3 linear values, row-major, row 0 at v = 0. An empty
  // or mis-sized image gives a 1 x 1 texture of the mean grey 0.5 (never used
  // by the importers, which refuse such images).
  Texture(int width, int height, std::span<const float> rgb, deform::TextureWrap wrap_s,
          deform::TextureWrap wrap_t);
  Texture(const deform::TextureImage& image, deform::TextureWrap wrap_s, deform::TextureWrap wrap_t)
      : Texture(image.width, image.height, image.rgb, wrap_s, wrap_t) {}

  int width() const { return levels_.empty() ? 0 : levels_[0].width; }
  int height() const { return levels_.empty() ? 0 : levels_[0].height; }
  int num_levels() const { return static_cast<int>(levels_.size()); }

  // Texel (x, y) of `level` (wrapped as the sampler would).
  glm::vec3 Texel(int level, int x, int y) const;
  // Bilinear filtering of one level.
  glm::vec3 SampleLevel(glm::vec2 uv, int level) const;
  // Trilinear: bilinear on levels floor(lod) and floor(lod) + 1, blended by the
  // fraction; lod is clamped to [0, num_levels - 1].
  glm::vec3 Sample(glm::vec2 uv, float lod) const;
  // The level of detail of a footprint given by the screen derivatives of uv
  // (per sample step in x and in y): log2 of the longer one in level-0 texels
  // (as OpenGL's scale factor rho, its log2 approximated within 0.008); -1 for
  // any footprint under one texel (magnified: level 0 either way).
  float Lod(glm::vec2 duv_dx, glm::vec2 duv_dy) const;

 private:
  struct Level {
    int width = 0, height = 0;
    std::vector<glm::vec3> texels;  // width x height, row-major
  };
  std::vector<Level> levels_;
  deform::TextureWrap wrap_s_ = deform::TextureWrap::kRepeat;
  deform::TextureWrap wrap_t_ = deform::TextureWrap::kRepeat;
};

}  // namespace render
