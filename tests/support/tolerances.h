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

// B-spline identities in double (partition of unity, Cox-de Boor agreement).
inline constexpr double kSplineTol = 1e-12;
// Central finite differences of B-spline derivatives (step 1e-6 in parameter).
inline constexpr double kFiniteDiffTol = 1e-5;
// Knot insertion and refinement keep the surface (ALGORITHMS.md 7).
inline constexpr double kKnotInsertionTol = 1e-6;
// Rest rebuild of bound vertices, relative to the patch size (ALGORITHMS.md 3.5).
inline constexpr double kRebuildRelTol = 1e-4;
// Projection recovering known (u,v,d) (Newton stops at 1e-7 x diagonal).
inline constexpr double kProjectionTol = 1e-6;

}  // namespace testsupport
