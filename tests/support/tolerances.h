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

}  // namespace testsupport

namespace testsupport {

// Skinning with a rigid palette: positions of order 1..10 after one blended
// 3x4 transform (edge lengths, rigid-map comparisons).
inline constexpr float kSkinningTol = 1e-4f;
// Smallest triangle area accepted in a generated mesh, as a fraction of the
// body size squared (a 24-vertex ring at 0.004 S radius makes ~1e-6 S^2 cells).
inline constexpr float kMinTriangleAreaFraction = 1e-9f;
// How far the mannequin's height along the up axis may differ from the
// skeleton's joint-and-end-site height (head and foot soles add thickness).
inline constexpr float kMannequinHeightTolFraction = 0.25f;
// Cross-section area ratios of a 64-gon ring (polygon vs analytic shrink).
inline constexpr float kAreaRatioTol = 0.01f;

}  // namespace testsupport
