#pragma once
// MassSpringStepJob::Run for the modal solver (deform/elastic/mass_spring.h): whole RK4
// steps of every mode up to the output time, the displacement limit after each
// step, and the output displacement interpolated between the last two steps.
//
// The modes stay in the state in the padded structure-of-arrays layout of the
// SIMD step (MassSpringState::modal, internal/mass_spring_modal.h) and are
// stepped there; the output is blended and taken to point space from them. The
// stage coefficients of up to 8 steps are computed together before the steps
// (internal/stage_forcing.h), and the run's first stage time, the previous run's
// last, comes from MassSpringState::last_stage when it matches. The results are
// the bits of stepping one step at a time with every stage time sampled
// (tests/deform/stage_forcing_test.cpp, modal_run_test.cpp).

#include <glm/glm.hpp>

#include "deform/elastic/mass_spring.h"

namespace deform::internal {

// Steps the modal state (job.state, already reset if the run resets) while its
// step time is below `until_s`, then writes job.displacements (if not empty) at
// job.time_s. `job` has passed Validate() and uses the modal solver.
void RunModal(const MassSpringStepJob& job, double until_s);

// The displacement limit (ALGORITHMS.md 6) on a modal state x, v (3 x
// mode_stride rows each, 32-byte aligned, padding lanes 0) whose sum_k |x_k|^2
// is sum_x: every free point a with |e_a| > e_max, e = U x, is clamped by
// ClampDisplacement with its velocity (U v)_a, and the changes d_a taken back
// to the modes together as x_k += sum_a U[a, k] d_a, a ascending (the same for
// v: U is orthonormal, so every other point keeps its displacement and
// velocity up to float rounding). Each point's e and velocity are computed
// from the state before any clamp (a clamp at a changes no other point, in
// exact arithmetic), the velocities of the candidates only
// (internal/mass_spring_modal.h: PointVelocities, AddPointChanges).
// Cheap exits first: sum_x <= e_max^2, or ModeBound(x) = sum_k max_a |U[a, k]|
// |x_k| <= e_max; a caller that has seen both fail for this x (an exact
// several-step kernel that stopped early) says so with `exits_failed`. (The
// exits only save work: ClampDisplacement decides, so no bit depends on them.)
// Returns the number of points clamped.
int ModalDisplacementLimit(const MassSpringNetwork& network, float sum_x, float* x, float* v,
                           bool allow_avx, bool exits_failed = false);

// Rest: a state whose displacements' squares and whose velocities' squares each
// sum below this (every point or mode under 1e-12 model units and units/s) is
// set to exactly 0, by the modal run after each batch of steps and by the
// point-space run after each step. Left alone, a patch whose drive has stopped
// decays on into the subnormal floats, where every operation costs a microcode
// assist (a 5x5 patch at rest measured about half again slower per frame than
// a moving one); at 0 with no drive it stays exactly 0.
inline constexpr float kRestSumOfSquares = 1e-24f;

// The displacement limit of one point (ALGORITHMS.md 6): e longer than e_max is
// projected back onto the sphere of radius e_max and the outward part of v
// removed. Returns whether it clamped. Shared by the modal and point-space runs.
inline bool ClampDisplacement(glm::vec3& e, glm::vec3& v, float e_max) {
  const float len = glm::length(e);
  if (len <= e_max) return false;
  const glm::vec3 dir = e / len;
  e = dir * e_max;
  const float outward = glm::dot(v, dir);
  if (outward > 0.0f) v -= outward * dir;
  return true;
}

}  // namespace deform::internal
