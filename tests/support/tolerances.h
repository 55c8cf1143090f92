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

// Inverse bind matrix x rest-pose joint matrix vs identity: the files store
// both in float after an exporter's own float products.
inline constexpr float kBindIdentityTol = 1e-4f;
// Skinned glTF vertices (metres) from two float evaluation paths compared
// with a double reference: float round-off over a ~20-joint chain.
inline constexpr double kSkinnedVertexTol = 1e-4;

}  // namespace testsupport
