#pragma once
// The modal RK4 step of the elastic layer (deform/elastic/mass_spring.h) on padded
// structure-of-arrays mode data: modes in groups of 8 lanes, and a last mode
// left over (a 5x5 or 7x7 grid has 8 k + 1 modes) as (x, y, z, unused) in one
// 4-float register (beside the group when there is one, by itself before the
// groups when there are several). One template compiled three times,
// chosen at run time:
//  - SSE2 (baseline x86-64, pairs of registers) and AVX: the same IEEE
//    operations in the same order, the scalar formulation below (the build uses
//    -ffp-contract=off), so a trajectory has the same bits on either, on any
//    x86-64 machine ("exact");
//  - AVX2 + FMA: a * b + c contracted, one rounding instead of two; faster, and
//    equal to the exact paths up to float round-off (a damped linear system:
//    differences stay at round-off level, mass_spring_simd_test).
// Each is deterministic: same inputs, same bits, whatever the thread count.
//
// Scalar formulation: per mode k (omega2, damping, sum, rest: its mode_lanes
// entries) and component c, with a(c) < b(c) the other two axes
// ((1, 2), (0, 2), (0, 1)) and e = rest + x, the acceleration at one stage
// time (StageCoefficients s) is, evaluated in exactly this order,
//   acc_c(s, x, v) = ((sum s.common_c + s.mx_c0 e_x) + (s.mx_c1 e_y + s.mx_c2 e_z))
//                  + ((s.mv_ca v_a + s.mv_cb v_b) - (omega2 x_c + damping v_c))
// (mv = -2 gam [w]x is skew: its diagonal is zero and never read), and the RK4
// step (ALGORITHMS.md 6, with x' = v) is
//   k1 = acc(s0, x, v)
//   v2 = v + h/2 k1,  k2 = acc(sm, x + h/2 v,  v2)
//   v3 = v + h/2 k2,  k3 = acc(sm, x + h/2 v2, v3)
//   v4 = v + h k3,    k4 = acc(s1, x + h v3,   v4)
//   x+ = x + h/6 ((v + v4) + 2 (v2 + v3))
//   v+ = v + h/6 ((k1 + 2 (k2 + k3)) + k4)
// with h/2 and h/6 rounded to float once.
//
// Layout: a modal vector field (displacement eta or velocity eta') is 3 rows of
// MassSpringNetwork::mode_stride floats, x row, y row, z row: component c of
// mode k at [c * stride + k]. Padding lanes (k >= #free) hold 0 and stay 0.

#include <cstddef>

#include "deform/elastic/mass_spring.h"

namespace deform::internal {

// Floats per SIMD lane group; MassSpringNetwork::mode_stride is a multiple of it.
inline constexpr int kModeLanes = 8;
// Largest mode_stride: (16 - 2)^2 = 196 free points, rounded up to 200.
inline constexpr int kMaxModeStride = 200;

// Rows of MassSpringNetwork::mode_lanes.
enum ModeLaneField : int {
  kLaneOmega2 = 0,   // (2 pi f_k)^2
  kLaneDamping = 1,  // c_k / m
  kLaneSum = 2,      // sum_a U[a, k]
  kLaneRestX = 3,    // sum_a U[a, k] k_a, x
  kLaneRestY = 4,
  kLaneRestZ = 5,
  kLaneMaxAbs = 6,   // max_a |U[a, k]|
};

// The moving-frame terms of one RK4 stage time, per unit mass, as matrices
// acting on all modes alike:
//   eta_k'' = sum_k common + mx (rest_k + eta_k) + mv eta_k' - omega2_k eta_k - damping_k eta_k'
// with mx = -gam ([al]x + [w]x^2), mv = -2 gam [w]x (skew: only its
// off-diagonal entries are kept) and common = -gam a + gravity + push; the
// order of evaluation is the scalar formulation above. Stored as the four-float
// columns a lone mode multiplies by (x, y, z) (the 4th float 0), so that it
// reads them as they are; a lane group broadcasts single entries from them.
struct alignas(16) StageCoefficients {
  float common[4] = {};     // (common_x, common_y, common_z, 0)
  float mx_col[3][4] = {};  // mx_col[j] = column j of mx, (mx[0][j], mx[1][j], mx[2][j], 0)
  float mv_a[4] = {};       // mv[c][a(c)]: (mv[0][1], mv[1][0], mv[2][0], 0)
  float mv_b[4] = {};       // mv[c][b(c)]: (mv[0][2], mv[1][2], mv[2][1], 0)

  // Entry (r, c) of mx, and of mv off its diagonal (r != c).
  float& Mx(int r, int c) { return mx_col[c][r]; }
  float& Mv(int r, int c) { return c == (r == 0 ? 1 : 0) ? mv_a[r] : mv_b[r]; }
};

// Sums of the new state the limit check needs (ALGORITHMS.md 6 limits); the
// exact paths add the terms in the same order (per mode (x^2 + y^2) + z^2, the
// 8 lanes of the groups in a fixed tree, then the lone mode):
struct ModalStepSums {
  float sum_x = 0.0f;  // sum_k |eta_k|^2 (>= |e_a|^2 for every point: U orthonormal)
  float sum_v = 0.0f;  // sum_k |eta'_k|^2
};

// One RK4 step of every mode, from (x, v) at t to (x_out, v_out) at t + h, with
// the coefficients at t, t + h/2 and t + h. Arrays: 3 x mode_stride each (see the
// layout above); outputs must not alias inputs.
using ModalStepFn = ModalStepSums (*)(const MassSpringNetwork& network,
                                      const StageCoefficients& s0, const StageCoefficients& sm,
                                      const StageCoefficients& s1, float h, const float* x,
                                      const float* v, float* x_out, float* v_out);

// The runner's four modal fields: the newest step's displacement and velocity
// (x, v) and the step's before (prev_x, prev_v), each 3 x mode_stride.
struct ModalBuffers {
  float* x;
  float* v;
  float* prev_x;
  float* prev_v;
};

// Up to `count` (>= 1) RK4 steps one after another, step i with the
// coefficients c[2 i], c[2 i + 1], c[2 i + 2] (its start, middle and end; so
// 2 count + 1 of them): each step goes from (b.x, b.v) into (b.prev_x,
// b.prev_v), then the two pairs are swapped, so that b.x, b.v hold the newest
// step and b.prev_x, b.prev_v the one before, as after `count` calls of the
// ModalStepFn. Stops early after a step the limits could change: either sum is
// not finite, or neither of ModalDisplacementLimit's cheap exits holds, with
// e_max the network's max_displacement (sum_x <= e_max^2; in the exact kernels
// also ModeBound <= e_max). Returns the number
// of steps taken, with that last step's sums in `sums`. Each step has the bits
// of the ModalStepFn of the same kernel. The input padding lanes must hold 0;
// the four arrays must not overlap.
using ModalStepsFn = int (*)(const MassSpringNetwork& network, const StageCoefficients* c,
                             int count, float h, ModalBuffers& b, ModalStepSums& sums);

enum class ModalKernel {
  kFastest,   // AVX2 + FMA when the CPU has both, else AVX, else SSE2
  kExactAvx,  // AVX when the CPU has it, else SSE2 (same bits either way)
  kPortable,  // SSE2
};
ModalStepFn SelectModalStep(ModalKernel kernel);
// MassSpringStepJob's switches: allow_avx and allow_fma -> kFastest, allow_avx
// alone -> kExactAvx (the default: the same bits on every x86-64 CPU), neither ->
// kPortable.
ModalStepFn SelectModalStep(bool allow_avx, bool allow_fma);

ModalStepsFn SelectModalSteps(ModalKernel kernel);
// The several-step kernel for MassSpringStepJob's switches (as SelectModalStep),
// and whether it is one of the exact kernels, which test ModeBound before they
// stop early (the FMA one tests sum_x alone).
struct ModalStepsChoice {
  ModalStepsFn steps;
  bool tests_mode_bound;
};
ModalStepsChoice ChooseModalSteps(bool allow_avx, bool allow_fma);

// Point-space field e_a = sum_k U[a, k] eta_k of a modal field (both 3 x stride;
// k summed in ascending order from 0, as the scalar code does).
void ModalToPoints(const MassSpringNetwork& network, const float* modal, float* points,
                   bool allow_avx);

// The inverse, eta_k = sum_a U[a, k] e_a (a ascending from 0, as the scalar code).
void PointsToModal(const MassSpringNetwork& network, const float* points, float* modal,
                   bool allow_avx);

// sum_k max_a |U[a, k]| |x_k| for a modal displacement x (3 x stride, padding
// lanes 0): an upper bound on every |(U x)_a|, the same bits on every path
// (the exact several-step kernels test it too).
float ModeBound(const MassSpringNetwork& network, const float* x, bool allow_avx);

// The displacement limit's two products (internal/modal_run.h), the same bits
// on every path. PointVelocities: velocities[3 j + c] = (U v)_{points[j]}, row
// c, for j < count. AddPointChanges: x_k += sum_j U[points[j], k] dx[3 j + c]
// and v_k += sum_j U[points[j], k] dv[3 j + c] for every row c and mode k, the
// products added one at a time, j ascending.
void PointVelocities(const MassSpringNetwork& network, const std::size_t* points, int count,
                     const float* v, float* velocities, bool allow_avx);
void AddPointChanges(const MassSpringNetwork& network, const std::size_t* points, int count,
                     const float* dx, const float* dv, float* x, float* v, bool allow_avx);

}  // namespace deform::internal
