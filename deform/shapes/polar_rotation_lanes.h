#pragma once
// PolarRotationNewton (polar_rotation.h) on many blends at once, in groups of
// SIMD lanes: the per-frame rotations A of the example shapes (ALGORITHMS.md
// 4.3) for the control points that blend three or more bones: groups of 4
// blends, in one 4-double AVX register or two 2-double SSE2 registers (the
// x86-64 baseline). Groups of 8 (two AVX registers) were measured slower on
// the shoulder patch: more spills, and a group waits for its slowest lane.
//
// Each lane does exactly the scalar iteration's IEEE operations in the same
// order (the build has -ffp-contract=off and no FMA is used), and a lane's
// result is its iterate at the step where *it* converged; lanes that
// converged earlier keep being computed with the group but are no longer
// read. So every result, its success flag included, is bit for bit
// PolarRotationNewton's, whatever the grouping, the path (AVX, SSE2, scalar)
// or the number of blends (the last group is padded with the identity, which
// converges in one step). A group costs the iterations of its slowest lane.
// The optional quaternion output is glm::quat_cast done in the lanes (the
// same candidates, comparisons and arithmetic), then glm::normalize of its
// float cast: again bit for bit the scalar expression.
// Higham's scaling (det X outside [1/8, 8]) takes two scalar square roots in
// the lanes that need it; it is rare for blends of rotations.
//
// PolarRotationsNewtonFloat (below) runs the same kernel in float, 8 lanes
// per AVX register, on well-conditioned blends only: a first try that
// PatchControlRotations makes before these double lanes (and the SVD).

#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mocap/error.h"

namespace deform {

enum class PolarLanesPath : std::uint8_t {
  kAuto,    // kAvx when the CPU has AVX, else kSse2
  kScalar,  // PolarRotationNewton once per blend
  kSse2,    // 4 lanes in two 2-double registers (x86-64 baseline)
  kAvx,     // 4 lanes in one 4-double AVX register (CPUs with AVX only)
};

// Whether this CPU (and OS) can run the kAvx path.
bool PolarLanesAvxAvailable();

// For every i of the #N `blends` (any N, 0 included): where
// PolarRotationNewton(blends[i], R) returns true, converged[i] = 1,
// rotations[i] = R and quats[i] = glm::normalize(glm::quat(glm::quat_cast(R)))
// (a unit float quaternion, its largest double component positive), all bit
// for bit; otherwise (det <= kPolarNewtonMinDet, not finite, or no
// convergence in kPolarNewtonMaxIterations) converged[i] = 0 and rotations[i],
// quats[i] are left as they were: the caller falls back to PolarRotation (SVD).
// `converged` #N; `rotations` and `quats` #N or empty (not wanted).
// kSizeMismatch on other sizes; kOutOfRange for kAvx on a CPU without AVX.
// Never allocates; thread-safe.
[[nodiscard]] mocap::JobStatus PolarRotationsNewton(std::span<const glm::dmat3> blends,
                                                    std::span<glm::dmat3> rotations,
                                                    std::span<std::uint8_t> converged,
                                                    PolarLanesPath path = PolarLanesPath::kAuto,
                                                    std::span<glm::quat> quats = {});

// The same iteration in float lanes (8 with AVX, 4 with SSE), for
// well-conditioned blends only, as a faster first try: every lane whose
// det X leaves (kPolarFloatMinDet, kPolarFloatMaxDet] at any step is refused
// (converged[i] = 0, quats[i] left alone) and goes to PolarRotationsNewton,
// so the float iteration never needs Higham's scaling. A lane stops after
// the step shorter than kPolarFloatStop: near U the error after a step is
// about half its squared length (5e-9), below float round-off. The result
// differs from the double iteration's by float round-off magnified by the
// blend's conditioning, 1 / (sigma_i + sigma_j) <= 4 here: measured below
// kPolarFloatTol (tests/support/tolerances.h) on random blends, against
// kRotationTolRad = 1e-5 for the rotations' users. Each lane's result
// depends on that lane's blend only (any grouping, count or path gives the
// same bits). `blends`, `quats`, `converged` all #N; kSizeMismatch
// otherwise; kOutOfRange for kScalar, or kAvx without AVX.
inline constexpr double kPolarFloatMinDet = 0.125;
inline constexpr double kPolarFloatMaxDet = 8.0;
inline constexpr double kPolarFloatStop = 1e-4;
[[nodiscard]] mocap::JobStatus PolarRotationsNewtonFloat(std::span<const glm::dmat3> blends,
                                                         std::span<glm::quat> quats,
                                                         std::span<std::uint8_t> converged,
                                                         PolarLanesPath path = PolarLanesPath::kAuto);

// PolarRotationsNewtonFloat on blends already rounded to float and laid out
// as the lanes load them (structure of arrays), so a caller that builds the
// blends can write them straight into the iteration's input: `rows` holds 9
// rows of stride = rows.size() / 9 floats, entry (column c, row r) of blend
// i at rows[(3 c + r) * stride + i] (glm's column-major order), for i < #N;
// entries at i >= #N never change a result (they may be loaded with a whole
// group of lanes, then replaced by the identity). quats[i], converged[i] are bit for bit
// PolarRotationsNewtonFloat's on a blend whose double entries round to these
// floats (the same lanes, the same operations). `quats`, `converged` #N;
// kSizeMismatch unless rows.size() is 9 x stride with stride >= #N;
// kOutOfRange for kScalar, or kAvx without AVX. Never allocates.
[[nodiscard]] mocap::JobStatus PolarRotationsNewtonFloatRows(
    std::span<const float> rows, std::span<glm::quat> quats, std::span<std::uint8_t> converged,
    PolarLanesPath path = PolarLanesPath::kAuto);

}  // namespace deform
