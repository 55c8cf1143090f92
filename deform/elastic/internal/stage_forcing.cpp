#include "deform/elastic/internal/stage_forcing.h"

#include <algorithm>
#include <cstddef>

#include <immintrin.h>

#include <glm/gtc/quaternion.hpp>

#include "deform/internal/cpu_features.h"

namespace deform::internal {
namespace {

// Four floats, one per frame (SSE2, the x86-64 baseline).
typedef float F4 __attribute__((vector_size(16)));
typedef int I4 __attribute__((vector_size(16)));

inline F4 Splat(float x) { return F4{x, x, x, x}; }

// Lane l of each field is frame l's value.
struct Frames4 {
  F4 qw, qx, qy, qz;  // rotation R
  F4 a[3];            // R^T o''
  F4 w[3];            // angular velocity
  F4 al[3];           // angular acceleration
};

Frames4 Gather(const DrivingFrame* f) {
  Frames4 g;
  for (int l = 0; l < 4; ++l) {
    g.qw[l] = f[l].rotation.w;
    g.qx[l] = f[l].rotation.x;
    g.qy[l] = f[l].rotation.y;
    g.qz[l] = f[l].rotation.z;
    for (int c = 0; c < 3; ++c) {
      g.a[c][l] = f[l].linear_acceleration[c];
      g.w[c][l] = f[l].angular_velocity[c];
      g.al[c][l] = f[l].angular_acceleration[c];
    }
  }
  return g;
}

// StageCoefficientsOf for four frames; `count` (1..4) of them are written.
void Four(const DrivingFrame* frames, int count, const ForcingConstants& k,
          StageCoefficients* out) {
  const Frames4 f = Gather(frames);
  // common = -gam a + u, per component (glm: scalar * vec3, then + vec3).
  const F4 neg_gain = Splat(-k.gain);
  F4 common[3];
  for (int c = 0; c < 3; ++c) common[c] = neg_gain * f.a[c] + Splat(k.user_acceleration[c]);
  if (k.gravity) {
    // glm::normalize(q): len = sqrt((w w + x x) + (y y + z z)); identity if
    // len <= 0, else each component times 1 / len.
    const F4 dot = (f.qw * f.qw + f.qx * f.qx) + (f.qy * f.qy + f.qz * f.qz);
    const F4 len = __builtin_ia32_sqrtps(dot);
    const F4 one_over = Splat(1.0f) / len;
    const I4 degenerate = len <= Splat(0.0f);
    const F4 nw = degenerate ? Splat(1.0f) : f.qw * one_over;
    const F4 nx = degenerate ? Splat(0.0f) : f.qx * one_over;
    const F4 ny = degenerate ? Splat(0.0f) : f.qy * one_over;
    const F4 nz = degenerate ? Splat(0.0f) : f.qz * one_over;
    // glm::conjugate, then quat * vec3: uv = q_xyz x v, uuv = q_xyz x uv,
    // v + ((uv * q_w) + uuv) * 2.
    const F4 qx = -nx, qy = -ny, qz = -nz, qw = nw;
    const F4 vx = Splat(k.gravity_model.x), vy = Splat(k.gravity_model.y),
             vz = Splat(k.gravity_model.z);
    const F4 uvx = qy * vz - vy * qz, uvy = qz * vx - vz * qx, uvz = qx * vy - vx * qy;
    const F4 uuvx = qy * uvz - uvy * qz, uuvy = qz * uvx - uvz * qx, uuvz = qx * uvy - uvx * qy;
    const F4 two = Splat(2.0f);
    const F4 rotated[3] = {vx + ((uvx * qw) + uuvx) * two, vy + ((uvy * qw) + uuvy) * two,
                           vz + ((uvz * qw) + uuvz) * two};
    for (int c = 0; c < 3; ++c) common[c] = common[c] + (rotated[c] - Splat(k.gravity_bind[c]));
  }
  // mx = -gam (skew(al) + w w^T - ww I), mv = (-2 gam) skew(w), entry by entry
  // as the scalar loop (zeros of the skew matrices included: 0 + -0 is +0).
  const F4 zero = Splat(0.0f);
  const F4 ww = (f.w[0] * f.w[0] + f.w[1] * f.w[1]) + f.w[2] * f.w[2];
  const F4 skew_al[3][3] = {{zero, -f.al[2], f.al[1]}, {f.al[2], zero, -f.al[0]},
                            {-f.al[1], f.al[0], zero}};
  const F4 skew_w[3][3] = {{zero, -f.w[2], f.w[1]}, {f.w[2], zero, -f.w[0]},
                           {-f.w[1], f.w[0], zero}};
  const F4 mv_scale = Splat(-2.0f * k.gain);
  F4 mx[3][3], mv[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const F4 w2 = f.w[r] * f.w[c] - (r == c ? ww : zero);
      mx[r][c] = neg_gain * (skew_al[r][c] + w2);
      mv[r][c] = mv_scale * skew_w[r][c];
    }
  }
  for (int l = 0; l < count; ++l) {
    StageCoefficients& o = out[l];
    o = StageCoefficients{};  // the 4th floats 0
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        o.Mx(r, c) = mx[r][c][l];
        if (r != c) o.Mv(r, c) = mv[r][c][l];
      }
      o.common[r] = common[r][l];
    }
  }
}

// Eight frames in AVX lanes: the same per-lane operations as Four (so the same
// bits), with the frames and the results moved by 8 x 8 transposes instead of
// one scalar insert or extract per value (which cost more than the arithmetic).
// The floats of one frame and of one output, in memory order:
static_assert(sizeof(DrivingFrame) == 13 * sizeof(float) &&
                  offsetof(DrivingFrame, linear_acceleration) == 4 * sizeof(float) &&
                  offsetof(DrivingFrame, angular_velocity) == 7 * sizeof(float) &&
                  offsetof(DrivingFrame, angular_acceleration) == 10 * sizeof(float),
              "DrivingFrame: quaternion x y z w, then three vec3");
static_assert(sizeof(StageCoefficients) == 24 * sizeof(float) &&
                  offsetof(StageCoefficients, mx_col) == 4 * sizeof(float) &&
                  offsetof(StageCoefficients, mv_a) == 16 * sizeof(float) &&
                  offsetof(StageCoefficients, mv_b) == 20 * sizeof(float),
              "StageCoefficients: common, mx columns, mv_a, mv_b, four floats each");
static_assert(offsetof(glm::quat, x) == 0 && offsetof(glm::quat, w) == 3 * sizeof(float),
              "glm::quat stored x, y, z, w");

// Rows r[0..7] -> columns: r[i][l] becomes r[l][i].
[[gnu::target("avx"), gnu::always_inline]] inline void Transpose8(__m256 r[8]) {
  const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
  const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
  const __m256 t4 = _mm256_unpacklo_ps(r[4], r[5]), t5 = _mm256_unpackhi_ps(r[4], r[5]);
  const __m256 t6 = _mm256_unpacklo_ps(r[6], r[7]), t7 = _mm256_unpackhi_ps(r[6], r[7]);
  const __m256 s0 = _mm256_shuffle_ps(t0, t2, 0x44), s1 = _mm256_shuffle_ps(t0, t2, 0xEE);
  const __m256 s2 = _mm256_shuffle_ps(t1, t3, 0x44), s3 = _mm256_shuffle_ps(t1, t3, 0xEE);
  const __m256 s4 = _mm256_shuffle_ps(t4, t6, 0x44), s5 = _mm256_shuffle_ps(t4, t6, 0xEE);
  const __m256 s6 = _mm256_shuffle_ps(t5, t7, 0x44), s7 = _mm256_shuffle_ps(t5, t7, 0xEE);
  r[0] = _mm256_permute2f128_ps(s0, s4, 0x20);
  r[1] = _mm256_permute2f128_ps(s1, s5, 0x20);
  r[2] = _mm256_permute2f128_ps(s2, s6, 0x20);
  r[3] = _mm256_permute2f128_ps(s3, s7, 0x20);
  r[4] = _mm256_permute2f128_ps(s0, s4, 0x31);
  r[5] = _mm256_permute2f128_ps(s1, s5, 0x31);
  r[6] = _mm256_permute2f128_ps(s2, s6, 0x31);
  r[7] = _mm256_permute2f128_ps(s3, s7, 0x31);
}

typedef float F8 __attribute__((vector_size(32)));  // an AVX register in EightAvx

[[gnu::target("avx"), gnu::always_inline]] inline F8 Splat8(float x) {
  return F8{x, x, x, x, x, x, x, x};
}

// Eight frames by field: lo[i] and hi[i] hold float i and 8 + i of every frame
// (lane l: frames[l]), i.e. lo: qx qy qz qw ax ay az wx, hi: wy wz alx aly alz.
struct EightFrames {
  __m256 lo[8], hi[8];
};

[[gnu::target("avx"), gnu::always_inline]] inline void LoadEight(const DrivingFrame* frames,
                                                                 EightFrames& f) {
  // Floats 0..7 and 8..12 of each frame (a masked load: nothing past the frame).
  const __m256i first5 = _mm256_setr_epi32(-1, -1, -1, -1, -1, 0, 0, 0);
  for (int l = 0; l < 8; ++l) {
    const float* p = reinterpret_cast<const float*>(frames + l);
    f.lo[l] = _mm256_loadu_ps(p);
    f.hi[l] = _mm256_maskload_ps(p + 8, first5);
  }
  Transpose8(f.lo);
  Transpose8(f.hi);
}

// QuickTestBounds' test on each lane (see stage_forcing.h): bit l set when
// frame l may need the exact checks.
[[gnu::target("avx"), gnu::always_inline]] inline unsigned QuickFlags(const EightFrames& f,
                                                                      const QuickTestBounds& b) {
  // x - x is +0 for a finite x and NaN otherwise; a sum with a NaN term is NaN.
  __m256 nan_if_not_finite = _mm256_sub_ps(f.hi[0], f.hi[0]);
  for (int i = 0; i < 8; ++i) {
    nan_if_not_finite = _mm256_add_ps(nan_if_not_finite, _mm256_sub_ps(f.lo[i], f.lo[i]));
  }
  for (int i = 1; i < 5; ++i) {
    nan_if_not_finite = _mm256_add_ps(nan_if_not_finite, _mm256_sub_ps(f.hi[i], f.hi[i]));
  }
  const __m256 abs_bits = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 q_big = _mm256_set1_ps(b.max_abs_q), q_small = _mm256_set1_ps(b.min_abs_q);
  const __m256 a_bound = _mm256_set1_ps(b.max_abs_a);
  __m256 flags = _mm256_cmp_ps(nan_if_not_finite, nan_if_not_finite, _CMP_UNORD_Q);
  __m256 all_small = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int i = 0; i < 4; ++i) {  // the quaternion
    const __m256 q_abs = _mm256_and_ps(f.lo[i], abs_bits);
    flags = _mm256_or_ps(flags, _mm256_cmp_ps(q_abs, q_big, _CMP_GT_OQ));
    all_small = _mm256_and_ps(all_small, _mm256_cmp_ps(q_abs, q_small, _CMP_LT_OQ));
  }
  for (int i = 4; i < 7; ++i) {  // the linear acceleration
    flags = _mm256_or_ps(flags, _mm256_cmp_ps(_mm256_and_ps(f.lo[i], abs_bits), a_bound, _CMP_GT_OQ));
  }
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(flags, all_small)));
}

[[gnu::target("avx"), gnu::always_inline]] inline void CoefficientsOfEight(
    const EightFrames& f, const ForcingConstants& k, StageCoefficients* out) {
  const __m256 *lo = f.lo, *hi = f.hi;
  const F8 qx0 = lo[0], qy0 = lo[1], qz0 = lo[2], qw0 = lo[3];
  const F8 a[3] = {lo[4], lo[5], lo[6]};
  const F8 w[3] = {lo[7], hi[0], hi[1]};
  const F8 al[3] = {hi[2], hi[3], hi[4]};
  // From here on, Four's operations in Four's order.
  const F8 neg_gain = Splat8(-k.gain);
  F8 common[3];
  for (int c = 0; c < 3; ++c) common[c] = neg_gain * a[c] + Splat8(k.user_acceleration[c]);
  if (k.gravity) {
    const F8 dot = (qw0 * qw0 + qx0 * qx0) + (qy0 * qy0 + qz0 * qz0);
    const F8 len = _mm256_sqrt_ps(dot);
    const F8 one_over = Splat8(1.0f) / len;
    const __m256 degenerate = _mm256_cmp_ps(len, Splat8(0.0f), _CMP_LE_OQ);
    const F8 nw = _mm256_blendv_ps(qw0 * one_over, Splat8(1.0f), degenerate);
    const F8 nx = _mm256_blendv_ps(qx0 * one_over, Splat8(0.0f), degenerate);
    const F8 ny = _mm256_blendv_ps(qy0 * one_over, Splat8(0.0f), degenerate);
    const F8 nz = _mm256_blendv_ps(qz0 * one_over, Splat8(0.0f), degenerate);
    const F8 qx = -nx, qy = -ny, qz = -nz, qw = nw;
    const F8 vx = Splat8(k.gravity_model.x), vy = Splat8(k.gravity_model.y),
             vz = Splat8(k.gravity_model.z);
    const F8 uvx = qy * vz - vy * qz, uvy = qz * vx - vz * qx, uvz = qx * vy - vx * qy;
    const F8 uuvx = qy * uvz - uvy * qz, uuvy = qz * uvx - uvz * qx, uuvz = qx * uvy - uvx * qy;
    const F8 two = Splat8(2.0f);
    const F8 rotated[3] = {vx + ((uvx * qw) + uuvx) * two, vy + ((uvy * qw) + uuvy) * two,
                           vz + ((uvz * qw) + uuvz) * two};
    for (int c = 0; c < 3; ++c) common[c] = common[c] + (rotated[c] - Splat8(k.gravity_bind[c]));
  }
  const F8 zero = Splat8(0.0f);
  const F8 ww = (w[0] * w[0] + w[1] * w[1]) + w[2] * w[2];
  const F8 skew_al[3][3] = {{zero, -al[2], al[1]}, {al[2], zero, -al[0]}, {-al[1], al[0], zero}};
  const F8 skew_w[3][3] = {{zero, -w[2], w[1]}, {w[2], zero, -w[0]}, {-w[1], w[0], zero}};
  const F8 mv_scale = Splat8(-2.0f * k.gain);
  // The 24 floats of StageCoefficients in order: common, the columns of mx,
  // mv[c][a(c)], mv[c][b(c)], each followed by a 0.
  __m256 rows[24];
  for (int r = 0; r < 3; ++r) {
    rows[r] = common[r];
    for (int c = 0; c < 3; ++c) {
      const F8 w2 = w[r] * w[c] - (r == c ? ww : zero);
      rows[4 + 4 * c + r] = neg_gain * (skew_al[r][c] + w2);
    }
  }
  rows[16] = mv_scale * skew_w[0][1];
  rows[17] = mv_scale * skew_w[1][0];
  rows[18] = mv_scale * skew_w[2][0];
  rows[20] = mv_scale * skew_w[0][2];
  rows[21] = mv_scale * skew_w[1][2];
  rows[22] = mv_scale * skew_w[2][1];
  rows[3] = rows[7] = rows[11] = rows[15] = rows[19] = rows[23] = zero;
  Transpose8(rows);
  Transpose8(rows + 8);
  Transpose8(rows + 16);
  for (int l = 0; l < 8; ++l) {
    float* o = reinterpret_cast<float*>(out + l);
    _mm256_storeu_ps(o, rows[l]);
    _mm256_storeu_ps(o + 8, rows[8 + l]);
    _mm256_storeu_ps(o + 16, rows[16 + l]);
  }
}

[[gnu::target("avx")]] void EightAvx(const DrivingFrame* frames, const ForcingConstants& k,
                                     StageCoefficients* out) {
  EightFrames f;
  LoadEight(frames, f);
  CoefficientsOfEight(f, k, out);
}

}  // namespace

StageCoefficients StageCoefficientsOf(const DrivingFrame& d, const ForcingConstants& k) {
  glm::vec3 common = -k.gain * d.linear_acceleration + k.user_acceleration;
  if (k.gravity) common += glm::conjugate(glm::normalize(d.rotation)) * k.gravity_model - k.gravity_bind;
  StageCoefficients m;
  const glm::vec3 w = d.angular_velocity, al = d.angular_acceleration;
  const float ww = glm::dot(w, w);
  const float skew_al[3][3] = {{0, -al.z, al.y}, {al.z, 0, -al.x}, {-al.y, al.x, 0}};
  const float skew_w[3][3] = {{0, -w.z, w.y}, {w.z, 0, -w.x}, {-w.y, w.x, 0}};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const float w2 = w[r] * w[c] - (r == c ? ww : 0.0f);  // [w]x^2 = w w^T - |w|^2 I
      m.Mx(r, c) = -k.gain * (skew_al[r][c] + w2);
      if (r != c) m.Mv(r, c) = -2.0f * k.gain * skew_w[r][c];
    }
    m.common[r] = common[r];
  }
  return m;
}

void StageCoefficientsOfEach(std::span<const DrivingFrame> frames, const ForcingConstants& k,
                             std::span<StageCoefficients> out, bool allow_avx) {
  const std::size_t n = std::min(frames.size(), out.size());
  std::size_t i = 0;
  if (allow_avx && CpuHasAvx()) {
    for (; i + 8 <= n; i += 8) EightAvx(frames.data() + i, k, out.data() + i);
  }
  for (; i < n; i += 4) {
    const int count = static_cast<int>(std::min<std::size_t>(4, n - i));
    if (count == 4) {
      Four(frames.data() + i, 4, k, out.data() + i);
    } else {  // the last few: pad the lanes with the last frame, keep `count`
      DrivingFrame padded[4];
      for (int l = 0; l < 4; ++l) padded[l] = frames[i + static_cast<std::size_t>(std::min(l, count - 1))];
      Four(padded, count, k, out.data() + i);
    }
  }
}

[[gnu::target("avx")]] unsigned QuickTestedCoefficientsOfEight(const DrivingFrame* frames,
                                                               const ForcingConstants& k,
                                                               const QuickTestBounds& bounds,
                                                               StageCoefficients* out) {
  EightFrames f;
  LoadEight(frames, f);
  const unsigned flags = QuickFlags(f, bounds);
  if (flags == 0) CoefficientsOfEight(f, k, out);
  return flags;
}

}  // namespace deform::internal
