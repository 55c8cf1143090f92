#include "deform/elastic/internal/mass_spring_modal.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>

#include <emmintrin.h>

#include "deform/internal/cpu_features.h"

// The 8-lane helpers pass vectors by value, but all of them are internal and
// always inlined into their callers, so no call crosses the ABI GCC warns about.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace deform::internal {
namespace {

// Eight floats as one GCC vector: an AVX register in the target("avx"...)
// functions below (GCC lowers it through memory where AVX is off).
namespace native {
inline constexpr bool kPairGroups = true;  // matrix products: 16-lane groups (two registers)
typedef float V8 __attribute__((vector_size(32)));
typedef float V4 __attribute__((vector_size(16)));
typedef float V8Unaligned __attribute__((vector_size(32), aligned(4)));
[[gnu::always_inline]] inline V8 SplatV8(float x) { return x - V8{}; }  // x - (+0) is x, even -0
// A float in memory to all lanes: vbroadcastss. (AVX has no register-to-register
// broadcast, and from SplatV8 of a value it has loaded GCC makes a scalar load,
// four inserts and a lane copy: in the matrix products, six shuffles per
// multiply-add pair where one load does.) Only ever inlined into AVX functions.
[[gnu::always_inline]] inline V8 BroadcastV8(const float* p) {
  V8 r;
  asm("vbroadcastss %1, %0" : "=x"(r) : "m"(*p));
  return r;
}
// The same, not before `after` is computed.
[[gnu::always_inline]] inline V8 BroadcastAfter(const float* p, const V8& after) {
  V8 r;
  asm("vbroadcastss %1, %0" : "=x"(r) : "m"(*p), "x"(after));
  return r;
}
// Each lane's square root (vsqrtps, correctly rounded as sqrtps is).
[[gnu::always_inline]] inline V8 SqrtV8(const V8& v) {
  V8 r;
  asm("vsqrtps %1, %0" : "=x"(r) : "x"(v));
  return r;
}
[[gnu::always_inline]] inline V8 LoadV8(const float* p) { return *reinterpret_cast<const V8Unaligned*>(p); }
[[gnu::always_inline]] inline void StoreV8(float* p, const V8& v) { *reinterpret_cast<V8Unaligned*>(p) = v; }
[[gnu::always_inline]] inline void HalvesV8(const V8& v, V4& lo, V4& hi) {
  lo = __builtin_shufflevector(v, v, 0, 1, 2, 3);
  hi = __builtin_shufflevector(v, v, 4, 5, 6, 7);
}
}  // namespace native

// Eight floats as two SSE2 registers, for the baseline path.
namespace sse2 {
inline constexpr bool kPairGroups = false;  // matrix products: 8 lanes, already two registers
typedef float V4 __attribute__((vector_size(16)));
typedef float V4Unaligned __attribute__((vector_size(16), aligned(4)));
struct V8 {
  V4 lo, hi;
};
[[gnu::always_inline]] inline V8 operator+(const V8& a, const V8& b) { return {a.lo + b.lo, a.hi + b.hi}; }
[[gnu::always_inline]] inline V8 operator-(const V8& a, const V8& b) { return {a.lo - b.lo, a.hi - b.hi}; }
[[gnu::always_inline]] inline V8 operator*(const V8& a, const V8& b) { return {a.lo * b.lo, a.hi * b.hi}; }
[[gnu::always_inline]] inline V8 SplatV8(float x) {
  const V4 b = x - V4{};
  return {b, b};
}
[[gnu::always_inline]] inline V8 LoadV8(const float* p) {
  return {*reinterpret_cast<const V4Unaligned*>(p), *reinterpret_cast<const V4Unaligned*>(p + 4)};
}
[[gnu::always_inline]] inline V8 BroadcastV8(const float* p) { return SplatV8(*p); }
[[gnu::always_inline]] inline V8 SqrtV8(const V8& v) {
  return {reinterpret_cast<V4>(_mm_sqrt_ps(reinterpret_cast<__m128>(v.lo))),
          reinterpret_cast<V4>(_mm_sqrt_ps(reinterpret_cast<__m128>(v.hi)))};
}
[[gnu::always_inline]] inline V8 BroadcastAfter(const float* p, const V8&) { return SplatV8(*p); }
[[gnu::always_inline]] inline void StoreV8(float* p, const V8& v) {
  *reinterpret_cast<V4Unaligned*>(p) = v.lo;
  *reinterpret_cast<V4Unaligned*>(p + 4) = v.hi;
}
[[gnu::always_inline]] inline void HalvesV8(const V8& v, V4& lo, V4& hi) {
  lo = v.lo;
  hi = v.hi;
}
}  // namespace sse2

// As written: the same IEEE operations as the scalar formulation (the build
// has -ffp-contract=off).
namespace exact_sse2 {
using namespace sse2;
inline constexpr bool kContracted = false;
#include "deform/elastic/internal/mass_spring_modal_kernel.inc"
}  // namespace exact_sse2

namespace exact_avx {
using namespace native;
inline constexpr bool kContracted = false;
#include "deform/elastic/internal/mass_spring_modal_kernel.inc"
}  // namespace exact_avx

// AVX2 with a * b + c contracted into FMA: fewer instructions and shorter
// dependency chains, with one rounding where the scalar formulation has two.
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#pragma GCC optimize("fp-contract=fast")
namespace fused {
using namespace native;
inline constexpr bool kContracted = true;
#include "deform/elastic/internal/mass_spring_modal_kernel.inc"
}  // namespace fused

ModalStepSums StepFma(const MassSpringNetwork& net, const StageCoefficients& s0,
                      const StageCoefficients& sm, const StageCoefficients& s1, float h,
                      const float* x, const float* v, float* x_out, float* v_out) {
  return fused::StepBody(net, s0, sm, s1, h, x, v, x_out, v_out);
}

int StepsFma(const MassSpringNetwork& net, const StageCoefficients* c, int count, float h,
             ModalBuffers& b, ModalStepSums& sums) {
  return fused::StepsBody(net, c, count, h, b, sums);
}
#pragma GCC pop_options

ModalStepSums StepSse(const MassSpringNetwork& net, const StageCoefficients& s0,
                      const StageCoefficients& sm, const StageCoefficients& s1, float h,
                      const float* x, const float* v, float* x_out, float* v_out) {
  return exact_sse2::StepBody(net, s0, sm, s1, h, x, v, x_out, v_out);
}

[[gnu::target("avx")]] ModalStepSums StepAvx(const MassSpringNetwork& net,
                                             const StageCoefficients& s0,
                                             const StageCoefficients& sm,
                                             const StageCoefficients& s1, float h, const float* x,
                                             const float* v, float* x_out, float* v_out) {
  return exact_avx::StepBody(net, s0, sm, s1, h, x, v, x_out, v_out);
}

int StepsSse(const MassSpringNetwork& net, const StageCoefficients* c, int count, float h,
             ModalBuffers& b, ModalStepSums& sums) {
  return exact_sse2::StepsBody(net, c, count, h, b, sums);
}

[[gnu::target("avx")]] int StepsAvx(const MassSpringNetwork& net, const StageCoefficients* c,
                                    int count, float h, ModalBuffers& b, ModalStepSums& sums) {
  return exact_avx::StepsBody(net, c, count, h, b, sums);
}

void MatrixSse(const MassSpringNetwork& net, const float* m, const float* in, float* out) {
  exact_sse2::MatrixBody(net, m, in, out);
}

[[gnu::target("avx")]] void MatrixAvx(const MassSpringNetwork& net, const float* m,
                                      const float* in, float* out) {
  exact_avx::MatrixBody(net, m, in, out);
}

float ModeBoundSse(const MassSpringNetwork& net, const float* x) {
  return exact_sse2::ModeBoundBody(net, x);
}

[[gnu::target("avx")]] float ModeBoundAvx(const MassSpringNetwork& net, const float* x) {
  return exact_avx::ModeBoundBody(net, x);
}

void PointVelocitiesSse(const MassSpringNetwork& net, const std::size_t* points, int count,
                        const float* v, float* vel) {
  exact_sse2::PointVelocitiesBody(net, points, count, v, vel);
}

[[gnu::target("avx")]] void PointVelocitiesAvx(const MassSpringNetwork& net,
                                               const std::size_t* points, int count,
                                               const float* v, float* vel) {
  exact_avx::PointVelocitiesBody(net, points, count, v, vel);
}

void AddPointChangesSse(const MassSpringNetwork& net, const std::size_t* points, int count,
                        const float* dx, const float* dv, float* x, float* v) {
  exact_sse2::AddPointChangesBody(net, points, count, dx, dv, x, v);
}

[[gnu::target("avx")]] void AddPointChangesAvx(const MassSpringNetwork& net,
                                               const std::size_t* points, int count,
                                               const float* dx, const float* dv, float* x,
                                               float* v) {
  exact_avx::AddPointChangesBody(net, points, count, dx, dv, x, v);
}

// The kernel `kernel` asks for, among the three compilations of one function.
template <typename Fn>
Fn Pick(ModalKernel kernel, Fn fma, Fn avx, Fn sse) {
  if (kernel == ModalKernel::kFastest && CpuHasAvx2Fma()) return fma;
  if (kernel != ModalKernel::kPortable && CpuHasAvx()) return avx;
  return sse;
}

ModalKernel KernelFor(bool allow_avx, bool allow_fma) {
  if (!allow_avx) return ModalKernel::kPortable;
  return allow_fma ? ModalKernel::kFastest : ModalKernel::kExactAvx;
}

}  // namespace

ModalStepFn SelectModalStep(ModalKernel kernel) { return Pick(kernel, &StepFma, &StepAvx, &StepSse); }

ModalStepFn SelectModalStep(bool allow_avx, bool allow_fma) {
  return SelectModalStep(KernelFor(allow_avx, allow_fma));
}

ModalStepsFn SelectModalSteps(ModalKernel kernel) {
  return Pick(kernel, &StepsFma, &StepsAvx, &StepsSse);
}

ModalStepsChoice ChooseModalSteps(bool allow_avx, bool allow_fma) {
  const ModalKernel kernel = KernelFor(allow_avx, allow_fma);
  return {SelectModalSteps(kernel), Pick(kernel, false, true, true)};
}

void ModalToPoints(const MassSpringNetwork& network, const float* modal, float* points,
                   bool allow_avx) {
  const float* m = network.modes_by_mode.data();
  (allow_avx && CpuHasAvx() ? MatrixAvx : MatrixSse)(network, m, modal, points);
}

void PointsToModal(const MassSpringNetwork& network, const float* points, float* modal,
                   bool allow_avx) {
  const float* m = network.modes_by_point.data();
  (allow_avx && CpuHasAvx() ? MatrixAvx : MatrixSse)(network, m, points, modal);
}

float ModeBound(const MassSpringNetwork& network, const float* x, bool allow_avx) {
  return (allow_avx && CpuHasAvx() ? ModeBoundAvx : ModeBoundSse)(network, x);
}

void PointVelocities(const MassSpringNetwork& network, const std::size_t* points, int count,
                     const float* v, float* velocities, bool allow_avx) {
  (allow_avx && CpuHasAvx() ? PointVelocitiesAvx : PointVelocitiesSse)(network, points, count, v,
                                                                       velocities);
}

void AddPointChanges(const MassSpringNetwork& network, const std::size_t* points, int count,
                     const float* dx, const float* dv, float* x, float* v, bool allow_avx) {
  (allow_avx && CpuHasAvx() ? AddPointChangesAvx : AddPointChangesSse)(network, points, count, dx,
                                                                       dv, x, v);
}

}  // namespace deform::internal
