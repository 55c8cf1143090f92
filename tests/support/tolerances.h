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

// SWD: bind-pose rebuild error relative to the mesh size (ALGORITHMS.md 2.3 asks 1e-5).
inline constexpr float kSwdRebuildRelTol = 1e-5f;
// Area ratios of vertex rings compared with closed forms (float positions, double areas).
inline constexpr double kAreaRatioTol = 1e-4;
// Sweep centre-curve continuity: a step of kCurveStep in u moves c by about speed * step.
inline constexpr double kCurveStep = 1e-7;
inline constexpr double kCurveDirectionTol = 1e-5;  // radians between tangent directions

}  // namespace testsupport
