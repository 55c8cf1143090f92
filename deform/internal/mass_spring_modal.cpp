#include "deform/internal/mass_spring_modal.h"

#include <cmath>

// The 8-lane helpers pass vectors by value, but all of them are internal and
// always inlined into their callers, so no call crosses the ABI GCC warns about.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace deform::internal {
namespace {

// Eight floats: one AVX register in target("avx") functions, two SSE2 registers
// elsewhere; four floats: one SSE2 register (the last group of a mode count that
// is not a multiple of 8). Element-wise IEEE arithmetic either way.
typedef float V8 __attribute__((vector_size(32)));
typedef float V8Unaligned __attribute__((vector_size(32), aligned(4)));

// Sixteen floats as two V8 (GCC lowers a 64-byte vector type through memory).
struct V16 {
  V8 lo, hi;
};
[[gnu::always_inline]] inline V16 operator+(const V16& a, const V16& b) { return {a.lo + b.lo, a.hi + b.hi}; }
[[gnu::always_inline]] inline V16 operator-(const V16& a, const V16& b) { return {a.lo - b.lo, a.hi - b.hi}; }
[[gnu::always_inline]] inline V16 operator*(const V16& a, const V16& b) { return {a.lo * b.lo, a.hi * b.hi}; }

template <typename V>
inline constexpr int kWidth = static_cast<int>(sizeof(V) / sizeof(float));

template <typename V>
[[gnu::always_inline]] inline V Splat(float x) {
  if constexpr (sizeof(V) == 64) {
    const V8 b = x - V8{};
    return {b, b};
  } else {
    return x - V8{};  // vector - scalar broadcasts; x - (+0) is x, even for -0
  }
}

template <typename V>
[[gnu::always_inline]] inline V Load(const float* p) {
  if constexpr (sizeof(V) == 64) {
    return {*reinterpret_cast<const V8Unaligned*>(p), *reinterpret_cast<const V8Unaligned*>(p + 8)};
  } else {
    return *reinterpret_cast<const V8Unaligned*>(p);
  }
}

template <typename V>
[[gnu::always_inline]] inline void Store(float* p, const V& v) {
  if constexpr (sizeof(V) == 64) {
    *reinterpret_cast<V8Unaligned*>(p) = v.lo;
    *reinterpret_cast<V8Unaligned*>(p + 8) = v.hi;
  } else {
    *reinterpret_cast<V8Unaligned*>(p) = v;
  }
}

// Lanes added in order: the same sum on both paths.
[[gnu::always_inline]] inline float SumLanes(const V8& v) {
  float s = v[0];
  for (int l = 1; l < 8; ++l) s += v[l];
  return s;
}
[[gnu::always_inline]] inline float SumLanes(const V16& v) { return SumLanes(v.lo) + SumLanes(v.hi); }

// The per-mode constants of one group of modes.
template <typename V>
struct ModeGroup {
  V omega2, damping, sum, rest[3];
};

// eta'' of a group of modes: the expression (and its evaluation order) of the
// scalar formulation, sum * common + mx (rest + x) + mv v - omega2 x_c - damping v_c.
// The coefficients are broadcast where they are used (a load-port operation)
// rather than held in registers across the group.
template <typename V>
[[gnu::always_inline]] inline void Accelerations(const StageCoefficients& s, const ModeGroup<V>& g,
                                                 const V (&x)[3], const V (&v)[3], V (&acc)[3]) {
  const V ex = g.rest[0] + x[0], ey = g.rest[1] + x[1], ez = g.rest[2] + x[2];
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
    acc[c] = g.sum * Splat<V>(s.common[c]) + Splat<V>(s.mx[c][0]) * ex +
             Splat<V>(s.mx[c][1]) * ey + Splat<V>(s.mx[c][2]) * ez + Splat<V>(s.mv[c][0]) * v[0] +
             Splat<V>(s.mv[c][1]) * v[1] + Splat<V>(s.mv[c][2]) * v[2] - g.omega2 * x[c] -
             g.damping * v[c];
  }
}

// Everything one step of a group needs besides its lanes.
struct StepArgs {
  const float* lanes;  // MassSpringNetwork::mode_lanes
  std::size_t stride;  // mode_stride
  const StageCoefficients* c0;
  const StageCoefficients* cm;
  const StageCoefficients* c1;
  float h;
  const float* x_in;
  const float* v_in;
  float* x_out;
  float* v_out;
};

// The RK4 step of ALGORITHMS.md 6 on the modes [k, k + width) of every group
// from `first` to `last` (each group stays in registers through its four
// stages: modes are independent); adds the groups' |eta|^2 and |eta'|^2 to the sums.
template <typename V>
[[gnu::always_inline]] inline void StepGroups(const StepArgs& a, std::size_t first,
                                              std::size_t last, V& sum_x, V& sum_v) {
  if (first >= last) return;
  const std::size_t stride = a.stride;
  const StageCoefficients& s0 = *a.c0;
  const StageCoefficients& sm = *a.cm;
  const StageCoefficients& s1 = *a.c1;
  const V h = Splat<V>(a.h), hh = Splat<V>(0.5f * a.h), h6 = Splat<V>(a.h / 6.0f);
  const V two = Splat<V>(2.0f);
  for (std::size_t k = first; k < last; k += kWidth<V>) {
    ModeGroup<V> g;
    g.omega2 = Load<V>(a.lanes + kLaneOmega2 * stride + k);
    g.damping = Load<V>(a.lanes + kLaneDamping * stride + k);
    g.sum = Load<V>(a.lanes + kLaneSum * stride + k);
    V x[3], v[3], xs[3], vs[3], sx[3], sv[3], acc[3];
#pragma GCC unroll 3
    for (std::size_t c = 0; c < 3; ++c) {
      g.rest[c] = Load<V>(a.lanes + (kLaneRestX + c) * stride + k);
      x[c] = Load<V>(a.x_in + c * stride + k);
      v[c] = Load<V>(a.v_in + c * stride + k);
    }
    Accelerations(s0, g, x, v, acc);  // k1
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
      sx[c] = v[c];
      sv[c] = acc[c];
      xs[c] = x[c] + hh * v[c];
      vs[c] = v[c] + hh * acc[c];
    }
    Accelerations(sm, g, xs, vs, acc);  // k2
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
      sx[c] = sx[c] + two * vs[c];
      sv[c] = sv[c] + two * acc[c];
      xs[c] = x[c] + hh * vs[c];
      vs[c] = v[c] + hh * acc[c];
    }
    Accelerations(sm, g, xs, vs, acc);  // k3
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
      sx[c] = sx[c] + two * vs[c];
      sv[c] = sv[c] + two * acc[c];
      xs[c] = x[c] + h * vs[c];
      vs[c] = v[c] + h * acc[c];
    }
    Accelerations(s1, g, xs, vs, acc);  // k4
    V xn[3], vn[3];
#pragma GCC unroll 3
    for (std::size_t c = 0; c < 3; ++c) {
      xn[c] = x[c] + h6 * (sx[c] + vs[c]);
      vn[c] = v[c] + h6 * (sv[c] + acc[c]);
      Store(a.x_out + c * stride + k, xn[c]);
      Store(a.v_out + c * stride + k, vn[c]);
    }
    sum_x = sum_x + (xn[0] * xn[0] + xn[1] * xn[1] + xn[2] * xn[2]);
    sum_v = sum_v + (vn[0] * vn[0] + vn[1] * vn[1] + vn[2] * vn[2]);
  }
}

// Modes in groups of 16, then one group of 8 when #free rounded up to 8 is not a
// multiple of 16. A group of 16 is two AVX (four SSE2) registers per value, whose
// dependency chains (each acceleration is a chain of 8 additions, kept in the
// scalar order) interleave instead of waiting on each other.
[[gnu::always_inline]] inline ModalStepSums StepBody(const MassSpringNetwork& net,
                                                     const StageCoefficients& c0,
                                                     const StageCoefficients& cm,
                                                     const StageCoefficients& c1, float h,
                                                     const float* x_in, const float* v_in,
                                                     float* x_out, float* v_out) {
  const std::size_t n8 = static_cast<std::size_t>(net.mode_stride);
  const std::size_t n16 = n8 / 16 * 16;
  const StepArgs args{net.mode_lanes.data(), n8, &c0, &cm, &c1, h, x_in, v_in, x_out, v_out};
  V16 sum_x16 = Splat<V16>(0.0f), sum_v16 = sum_x16;
  V8 sum_x8 = Splat<V8>(0.0f), sum_v8 = sum_x8;
  StepGroups(args, 0, n16, sum_x16, sum_v16);
  StepGroups(args, n16, n8, sum_x8, sum_v8);
  return {SumLanes(sum_x16) + SumLanes(sum_x8), SumLanes(sum_v16) + SumLanes(sum_v8)};
}

// out_c[i] = sum_j m[j * stride + i] in_c[j], j ascending from 0 (the scalar
// code's order), for lanes i of a group.
template <typename V>
[[gnu::always_inline]] inline void MatrixGroups(const float* m, std::size_t n, std::size_t stride,
                                                const float* in, float* out, std::size_t first,
                                                std::size_t last) {
  for (std::size_t i = first; i < last; i += kWidth<V>) {
    V sum[3] = {Splat<V>(0.0f), Splat<V>(0.0f), Splat<V>(0.0f)};
    for (std::size_t j = 0; j < n; ++j) {
      const V column = Load<V>(m + j * stride + i);
#pragma GCC unroll 3
      for (std::size_t c = 0; c < 3; ++c) sum[c] = sum[c] + column * Splat<V>(in[c * stride + j]);
    }
#pragma GCC unroll 3
    for (std::size_t c = 0; c < 3; ++c) Store(out + c * stride + i, sum[c]);
  }
}

[[gnu::always_inline]] inline void MatrixBody(const MassSpringNetwork& net, const float* m,
                                              const float* in, float* out) {
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  const std::size_t n8 = static_cast<std::size_t>(net.mode_stride);
  const std::size_t n16 = n8 / 16 * 16;
  MatrixGroups<V16>(m, n, n8, in, out, 0, n16);
  MatrixGroups<V8>(m, n, n8, in, out, n16, n8);
}

ModalStepSums StepSse(const MassSpringNetwork& net, const StageCoefficients& s0,
                      const StageCoefficients& sm, const StageCoefficients& s1, float h,
                      const float* x, const float* v, float* x_out, float* v_out) {
  return StepBody(net, s0, sm, s1, h, x, v, x_out, v_out);
}

[[gnu::target("avx")]] ModalStepSums StepAvx(const MassSpringNetwork& net,
                                             const StageCoefficients& s0,
                                             const StageCoefficients& sm,
                                             const StageCoefficients& s1, float h, const float* x,
                                             const float* v, float* x_out, float* v_out) {
  return StepBody(net, s0, sm, s1, h, x, v, x_out, v_out);
}

void MatrixSse(const MassSpringNetwork& net, const float* m, const float* in, float* out) {
  MatrixBody(net, m, in, out);
}

[[gnu::target("avx")]] void MatrixAvx(const MassSpringNetwork& net, const float* m,
                                      const float* in, float* out) {
  MatrixBody(net, m, in, out);
}

bool CpuHasAvx() {
  static const bool has = __builtin_cpu_supports("avx");
  return has;
}

}  // namespace

ModalStepFn SelectModalStep(bool allow_avx) {
  return allow_avx && CpuHasAvx() ? &StepAvx : &StepSse;
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

}  // namespace deform::internal
