#pragma once
// The elastic layer's per-stage-time forcing (deform/elastic/mass_spring.h) as the
// modal step's coefficient matrices (internal/mass_spring_modal.h), for one
// driving frame at a time (the scalar reference) or for four or eight at a time,
// one per SSE2 or AVX lane, with the same IEEE operations in the same order per
// lane: the same bits (the build has -ffp-contract=off;
// tests/deform/stage_forcing_test.cpp). A 30 fps output frame (8 RK4 steps) has
// 17 stage times; the first is the previous frame's last (internal/modal_run.h),
// so 16 are new: two groups of eight.
//
// The frames given here are already checked: MassSpringStepJob replaces a
// non-finite frame by the bind frame and clamps |a| before this point.

#include <span>

#include <glm/glm.hpp>

#include "deform/elastic/internal/mass_spring_modal.h"
#include "deform/elastic/mass_spring.h"

namespace deform::internal {

// What the forcing adds besides the frame, fixed for a run.
struct ForcingConstants {
  float gain = 1.0f;                    // gam (MassSpringParams::gain)
  glm::vec3 user_acceleration{0.0f};    // u, model units/s^2 in the driving frame
  bool gravity = true;                  // add R^T g - R_bind^T g
  glm::vec3 gravity_model{0.0f};        // g in model space, model units/s^2
  glm::vec3 gravity_bind{0.0f};         // R_bind^T g
};

// The scalar formulation, written as glm evaluates it:
//   common = -gam a + u (+ conj(normalize(R)) g - R_bind^T g with gravity),
//   mx = -gam ([al]x + [w]x^2) with [w]x^2 = w w^T - |w|^2 I, mv = -2 gam [w]x.
StageCoefficients StageCoefficientsOf(const DrivingFrame& frame, const ForcingConstants& k);

// The same for frames.size() frames (any count): eight at a time in AVX lanes
// when allowed and the CPU has AVX, the rest four at a time in SSE2 lanes; out[i]
// has the bits of StageCoefficientsOf(frames[i], k) either way. out.size() ==
// frames.size(); nothing outside frames[i] and out[i] is read or written.
void StageCoefficientsOfEach(std::span<const DrivingFrame> frames, const ForcingConstants& k,
                             std::span<StageCoefficients> out, bool allow_avx = true);

// The quick test of CheckedDriving (internal/checked_driving.h) on a frame's
// floats: the frame passes when every float is finite, some |q_i| >= min_abs_q,
// every |q_i| <= max_abs_q and |a_x|, |a_y|, |a_z| <= max_abs_a; a frame that
// fails may need the exact checks.
struct QuickTestBounds {
  float min_abs_q = 0.0f;
  float max_abs_q = 0.0f;
  float max_abs_a = 0.0f;
};

// Eight frames at once, in the AVX lanes of StageCoefficientsOfEach (needs a
// CPU with AVX): the quick test on each first; if every frame passes, out[0..7]
// get StageCoefficientsOf(frames[l], k)'s bits and 0 is returned; else nothing
// is written and bit l of the result is set for each frame l that failed.
unsigned QuickTestedCoefficientsOfEight(const DrivingFrame* frames, const ForcingConstants& k,
                                        const QuickTestBounds& bounds, StageCoefficients* out);

}  // namespace deform::internal
