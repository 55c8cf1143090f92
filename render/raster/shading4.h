#pragma once
// ShadeSurface for four surface points at once (SSE2), for the renderer's
// row passes. Each lane runs the operations of ShadeSurface in the same order
// (glm's dot, normalize = v * (1 / sqrt(v . v)), the whole-exponent squaring),
// with skipped terms replaced by adding zero, so every colour is bit-identical
// to ShadeSurface's for the same inputs (tests/render/shading_test.cpp).

#include "render/raster/shading.h"

namespace render {

// Four surface points, structure of arrays: [component][lane].
struct SurfacePoints4 {
  alignas(16) float albedo[3][4];    // linear RGB
  alignas(16) float normal[3][4];    // unit world-space normals, facing the lit side
  alignas(16) float position[3][4];  // world-space positions (for the view vector)
  alignas(16) float key_visibility[4];  // the key light's unshadowed share, 0..1
  // For the renderer, not read here: the side of the surface its shadow map is
  // read from (outward normal = side * normal), or 0 where it is not read.
  alignas(16) float shadow_side[4];
};

// out[c][k] = ShadeSurface(ctx, albedo_k, normal_k, position_k, key_visibility_k)[c] for k = 0..3.
// Lanes not in use may hold anything finite or not; they do not affect the others.
void ShadeSurface4(const ShadingContext& ctx, const SurfacePoints4& in, float (&out)[3][4]);

}  // namespace render
