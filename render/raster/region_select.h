#pragma once
// The paper's region sketch (ALGORITHMS.md 3.1): a rectangle drawn on the
// screen of a view selects the mesh vertices that project inside it, face the
// camera and are visible (their view depth within a tolerance of the
// rasterizer's z-buffer), restricted to the connected component (over the
// mesh's triangles, among the selected vertices) under the rectangle's centre.
// Setup work: renders one depth image and allocates.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "render/camera.h"

namespace render {

struct ScreenRegionQuery {
  glm::vec4 rect{0.0f};          // x0, y0, x1, y1 in [0,1] of the image, y down, x0 < x1, y0 < y1
  int width = 512;               // depth image size in pixels (camera.aspect should match)
  int height = 512;
  float depth_tol_rel = 0.01f;   // visible: view depth <= z-buffer x (1 + tol)
};

// `positions`, `normals` (#V, world space; normals unit, or empty to compute
// them) and `triangles` (#T) of the mesh as it is seen. Errors
// (kInvalidArgument): a bad rectangle or size, sizes that disagree; (kNotFound):
// no visible front-facing vertex inside the rectangle.
base::Result<std::vector<int>> SelectScreenRegion(const Camera& camera,
                                                  std::span<const glm::vec3> positions,
                                                  std::span<const glm::vec3> normals,
                                                  std::span<const glm::uvec3> triangles,
                                                  const ScreenRegionQuery& query);

}  // namespace render
