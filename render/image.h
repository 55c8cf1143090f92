#pragma once
// Image: the framebuffer the rasterizer resolves into and the image I/O writes.
// Colour is linear RGBA float (premultiplied alpha is NOT used: alpha is
// coverage, colour is straight); conversion to sRGB 8-bit happens on writing.
// Optional depth holds camera-space distance along the view axis (+inf = empty).

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace render {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> rgba;  // width x height, row 0 at the top
  std::vector<float> depth;     // width x height, or empty

  Image() = default;
  Image(int w, int h, glm::vec4 fill = glm::vec4(0.0f))
      : width(w), height(h), rgba(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}

  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  }
  glm::vec4& at(int x, int y) { return rgba[index(x, y)]; }
  const glm::vec4& at(int x, int y) const { return rgba[index(x, y)]; }
};

// A frame as 8-bit files store it: sRGB-encoded colour and straight alpha,
// 4 bytes per pixel (R, G, B, A), row 0 at the top. Made once per frame by
// render::EncodeSrgb8 (render/output/image_io.h) and shared by the frame file,
// the preview video and the contact sheet, which would each convert it again.
struct Srgb8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // 4 * width * height bytes
};

}  // namespace render
