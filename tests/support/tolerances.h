#pragma once
// Named tolerances for tests: never a bare literal in an assertion.

namespace testsupport {

// Float round-off of a few operations on values of order 1..100.
inline constexpr float kFloatTol = 1e-5f;
// Positions after a chain of float transforms in file units (cm-scale skeletons).
inline constexpr float kPositionTol = 1e-3f;
// Angles compared in degrees after Euler/quaternion round trips.
inline constexpr float kAngleTolDeg = 1e-3f;
// Double-precision solves (fits, RBF, projections).
inline constexpr double kDoubleTol = 1e-9;

// Rendered colour against an analytic value where only float round-off and
// 1/256-pixel vertex snapping differ (perspective-correct interpolation).
inline constexpr float kRenderTol = 2e-3f;
// Shading of a tessellated sphere against the analytic sphere's N.L (the
// interpolated normal of a 64x128 UV sphere is off by well under 1 degree).
inline constexpr float kTessellatedShadingTol = 5e-3f;
// A smoothly varying shaded value read at the pixel containing a projected
// point rather than at the point itself.
inline constexpr float kPixelFootprintTol = 2e-2f;

}  // namespace testsupport
