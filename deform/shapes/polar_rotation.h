#pragma once
// The rotation of a blend of rotations, fast (ALGORITHMS.md 4.3): the
// orthogonal polar factor of M = sum_b w_b R_b, computed per control point
// and per frame for the example shapes' frames A (SSD with three or more
// bones; one and two bones have a closed form in example_shapes.cpp).
//
//   Newton's iteration for the polar factor (Higham 1986, "Computing the polar
//   decomposition - with applications", SIAM J. Sci. Stat. Comput. 7(4)):
//     X_0 = M,   X_{k+1} = (g_k X_k + X_k^-T / g_k) / 2
//   converges quadratically to U (M = U P, U orthogonal, P symmetric positive
//   definite) for any nonsingular M. X^-T is cof(X) / det(X), whose columns
//   are the cross products of X's columns (no general inverse). g_k is
//   Higham's Frobenius-norm scaling, g = sqrt(|X^-1|_F / |X|_F), applied only
//   while det X_k is outside [1/8, 8] (far from orthogonal: a nearly singular
//   blend, or the first iterates after one); elsewhere g = 1, since for
//   blends of rotations (singular values in (0, 1]) the scaling saves less
//   than its two square roots and division cost (random blends of 3-4 bones
//   up to 150 degrees apart: 3-7 iterations, 4 on average).
//   Stopping rule: near U the error after a step is about half the square of
//   that step's length |X_{k+1} - X_k|_F (relative to the smallest singular
//   value, which is 1 there), so stopping once the step is below
//   kPolarNewtonStop leaves an error of about 1e-13, far below float.
//
// Only matrices with det M > kPolarNewtonMinDet are taken: det <= 0 (a blend
// that reflects, or a singular one) has no proper-rotation polar factor and
// needs the SVD's sign fix (PolarRotation / PolarRotationSvd), and a nearly
// singular blend is left to it as well. Callers fall back when this returns
// false.

#include <glm/glm.hpp>

namespace deform {

// Step length |X_{k+1} - X_k|_F below which the iteration stops.
inline constexpr double kPolarNewtonStop = 1e-6;
// Smallest det M the iteration accepts (for |M|_2 <= 1, as for convex blends
// of rotations, this bounds the smallest singular value below by this value).
inline constexpr double kPolarNewtonMinDet = 1e-6;
// Higham's scaling is applied while det X_k is below the first or above the
// second of these (far from orthogonal); elsewhere g = 1.
inline constexpr double kPolarNewtonScaleBelowDet = 0.125;
inline constexpr double kPolarNewtonScaleAboveDet = 8.0;
// Most iterations before giving up (never reached for det M >
// kPolarNewtonMinDet in tests; a safety net against NaN input).
inline constexpr int kPolarNewtonMaxIterations = 20;

// The orthogonal polar factor of `m` by the scaled Newton iteration above.
// Returns false (and leaves `rotation` unspecified) when det m <=
// kPolarNewtonMinDet, m is not finite, or the iteration did not converge in
// kPolarNewtonMaxIterations; `iterations` (optional) receives the count.
// Never allocates.
[[nodiscard]] bool PolarRotationNewton(const glm::dmat3& m, glm::dmat3& rotation,
                                       int* iterations = nullptr);

}  // namespace deform
