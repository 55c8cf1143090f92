#pragma once
// Placing test geometry on the rasterizer's sample grid.

#include <glm/glm.hpp>

namespace testsupport {

// The clip-space point (w = 1) that lands exactly on sample-space (sx, sy) of
// a width x height sample grid (y down).
inline glm::vec4 AtSample(float sx, float sy, int width, int height) {
  return {sx / static_cast<float>(width) * 2.0f - 1.0f,
          1.0f - sy / static_cast<float>(height) * 2.0f, 0.0f, 1.0f};
}

}  // namespace testsupport
