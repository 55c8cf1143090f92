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
