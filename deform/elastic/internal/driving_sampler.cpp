#include "deform/elastic/internal/driving_sampler.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>

#include "deform/internal/cpu_features.h"

namespace deform::internal {
namespace {

static_assert(sizeof(DrivingFrame) == 13 * sizeof(float), "DrivingFrame is 13 packed floats");
static_assert(offsetof(mocap::JointKinematics, local_angular_velocity) ==
                      offsetof(mocap::JointKinematics, local_linear_acceleration) + 12 &&
                  offsetof(mocap::JointKinematics, local_angular_acceleration) ==
                      offsetof(mocap::JointKinematics, local_angular_velocity) + 12 &&
                  sizeof(mocap::JointKinematics) ==
                      offsetof(mocap::JointKinematics, local_angular_acceleration) + 12,
              "the local vectors are the last 9 floats of JointKinematics");

static_assert(offsetof(mocap::JointKinematics, angular_velocity) ==
                      offsetof(mocap::JointKinematics, linear_acceleration) + 12 &&
                  offsetof(mocap::JointKinematics, angular_acceleration) ==
                      offsetof(mocap::JointKinematics, angular_velocity) + 12,
              "linear acceleration, angular velocity and acceleration are 9 packed floats");

// Three packed vec3 (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 0 0 0) by component:
// out[c] = (c of vector 0, 1, 2, 0).
void StoreByComponent(__m128 v01, __m128 v12, __m128 v2, float (*out)[4]) {
  const __m128 y2 = _mm_shuffle_ps(v12, v2, _MM_SHUFFLE(1, 1, 3, 3));       // y2 y2 0 0
  const __m128 x2 = _mm_shuffle_ps(v12, v2, _MM_SHUFFLE(1, 1, 2, 2));       // x2 x2 0 0
  const __m128 y0y1 = _mm_shuffle_ps(v01, v12, _MM_SHUFFLE(0, 0, 1, 1));    // y0 y0 y1 y1
  const __m128 z0z1 = _mm_shuffle_ps(v01, v12, _MM_SHUFFLE(1, 1, 2, 2));    // z0 z0 z1 z1
  _mm_store_ps(out[0], _mm_shuffle_ps(v01, x2, _MM_SHUFFLE(2, 0, 3, 0)));   // x0 x1 x2 0
  _mm_store_ps(out[1], _mm_shuffle_ps(y0y1, y2, _MM_SHUFFLE(2, 0, 2, 0)));  // y0 y1 y2 0
  _mm_store_ps(out[2], _mm_shuffle_ps(z0z1, v2, _MM_SHUFFLE(1, 0, 2, 0)));  // z0 z1 z2 0
}

// A frame's own fields, as SampleJointKinematics returns them on a frame.
void CopyFrame(const mocap::JointKinematics& k, DrivingFrame* out) {
  const float* local = &k.local_linear_acceleration.x;
  float* o = &out->rotation.x;
  _mm_storeu_ps(o, _mm_loadu_ps(&k.rotation.x));
  _mm_storeu_ps(o + 4, _mm_loadu_ps(local));
  _mm_storeu_ps(o + 8, _mm_loadu_ps(local + 4));
  o[12] = local[8];
}

// glm::dot of two double quaternions held as (x, y) and (z, w):
// (w w' + x x') + (y y' + z z').
double Dot(__m128d a_xy, __m128d a_zw, __m128d b_xy, __m128d b_zw) {
  const __m128d p_xy = _mm_mul_pd(a_xy, b_xy), p_zw = _mm_mul_pd(a_zw, b_zw);
  const __m128d pairs = _mm_add_pd(p_xy, _mm_shuffle_pd(p_zw, p_zw, 1));  // xx+ww, yy+zz
  return _mm_cvtsd_f64(_mm_add_sd(pairs, _mm_unpackhi_pd(pairs, pairs)));
}

// glm::quat(glm::normalize(a * ca + b * cb)) for double quaternions a, b in
// x, y, z, w order: the products, sums, dot ((w w + x x) + (y y + z z)), square
// root and reciprocal of glm's code, two components a lane.
__m128 NormalizedBlend(const double* a, const double* b, double ca, double cb) {
  const __m128d sa = _mm_set1_pd(ca), sb = _mm_set1_pd(cb);
  const __m128d r_xy = _mm_add_pd(_mm_mul_pd(_mm_load_pd(a), sa), _mm_mul_pd(_mm_load_pd(b), sb));
  const __m128d r_zw =
      _mm_add_pd(_mm_mul_pd(_mm_load_pd(a + 2), sa), _mm_mul_pd(_mm_load_pd(b + 2), sb));
  const double len = std::sqrt(Dot(r_xy, r_zw, r_xy, r_zw));
  if (len <= 0.0) return _mm_setr_ps(0.0f, 0.0f, 0.0f, 1.0f);  // glm's identity
  const __m128d inv = _mm_set1_pd(1.0 / len);
  return _mm_movelh_ps(_mm_cvtpd_ps(_mm_mul_pd(r_xy, inv)), _mm_cvtpd_ps(_mm_mul_pd(r_zw, inv)));
}

// conjugate(q) * v for the three vectors whose components are the lanes of
// vx, vy, vz (glm: uv = cross(u, v), uuv = cross(u, uv), v + ((uv w) + uuv) 2
// with u = -(q.x, q.y, q.z)); written to `out` as three packed vec3.
void StoreRotated(__m128 q, __m128 vx, __m128 vy, __m128 vz, float* out) {
  const __m128 u = _mm_xor_ps(q, _mm_set1_ps(-0.0f));
  const __m128 ux = _mm_shuffle_ps(u, u, 0x00), uy = _mm_shuffle_ps(u, u, 0x55),
               uz = _mm_shuffle_ps(u, u, 0xAA), w = _mm_shuffle_ps(q, q, 0xFF);
  const auto cross = [&](__m128 x, __m128 y, __m128 z, __m128& cx, __m128& cy, __m128& cz) {
    cx = _mm_sub_ps(_mm_mul_ps(uy, z), _mm_mul_ps(y, uz));
    cy = _mm_sub_ps(_mm_mul_ps(uz, x), _mm_mul_ps(z, ux));
    cz = _mm_sub_ps(_mm_mul_ps(ux, y), _mm_mul_ps(x, uy));
  };
  __m128 uvx, uvy, uvz, uuvx, uuvy, uuvz;
  cross(vx, vy, vz, uvx, uvy, uvz);
  cross(uvx, uvy, uvz, uuvx, uuvy, uuvz);
  const __m128 two = _mm_set1_ps(2.0f);
  const __m128 rx = _mm_add_ps(vx, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(uvx, w), uuvx), two));
  const __m128 ry = _mm_add_ps(vy, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(uvy, w), uuvy), two));
  const __m128 rz = _mm_add_ps(vz, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(uvz, w), uuvz), two));
  // Lanes (vector 0, 1, 2) by component to x0 y0 z0 x1 | y1 z1 x2 y2 | z2.
  const __m128 x0y0x1y1 = _mm_unpacklo_ps(rx, ry);
  const __m128 z0x0z1x1 = _mm_unpacklo_ps(rz, rx);
  const __m128 y0z0y1z1 = _mm_unpacklo_ps(ry, rz);
  const __m128 x2y2x3y3 = _mm_unpackhi_ps(rx, ry);
  _mm_storeu_ps(out, _mm_shuffle_ps(x0y0x1y1, z0x0z1x1, _MM_SHUFFLE(3, 0, 1, 0)));
  _mm_storeu_ps(out + 4, _mm_shuffle_ps(y0z0y1z1, x2y2x3y3, _MM_SHUFFLE(1, 0, 3, 2)));
  _mm_store_ss(out + 8, _mm_movehl_ps(rz, rz));
}

}  // namespace

// NormalizedBlend and StoreRotated for the two samples in 256-bit lanes (the
// four components of a quaternion a lane each, the two samples' vectors in the
// two 128-bit halves), with the same operations per lane. Both intervals are
// kept at once unless they have the same parity; then, and for a blend of
// length 0 (glm's identity case), Write on each.
[[gnu::target("avx")]] void KinematicsDrivingSampler::WritePairAvx(const Blend& b0,
                                                                   DrivingFrame* out0,
                                                                   const Blend& b1,
                                                                   DrivingFrame* out1) {
  if (b0.frame0 != b1.frame0 && ((b0.frame0 ^ b1.frame0) & 1) == 0) {
    Write(b0, out0);
    Write(b1, out1);
    return;
  }
  const Interval& in0 = Slot(b0.frame0);
  const Interval& in1 = Slot(b1.frame0);
  const float w0 = b0.weight, w1 = b1.weight;
  double ca0, cb0, ca1, cb1;
  SlerpWeights(in0, w0, ca0, cb0);
  SlerpWeights(in1, w1, ca1, cb1);
  const __m256d r0 = _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(in0.a), _mm256_set1_pd(ca0)),
                                   _mm256_mul_pd(_mm256_loadu_pd(in0.b), _mm256_set1_pd(cb0)));
  const __m256d r1 = _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(in1.a), _mm256_set1_pd(ca1)),
                                   _mm256_mul_pd(_mm256_loadu_pd(in1.b), _mm256_set1_pd(cb1)));
  // Squares x y z w plus w z y x: xx+ww, yy+zz in lanes 0 and 1; hadd then
  // gives each dot (ww + xx) + (yy + zz).
  const __m256d sq0 = _mm256_mul_pd(r0, r0), sq1 = _mm256_mul_pd(r1, r1);
  const __m256d p0 = _mm256_add_pd(sq0, _mm256_permute_pd(_mm256_permute2f128_pd(sq0, sq0, 1), 5));
  const __m256d p1 = _mm256_add_pd(sq1, _mm256_permute_pd(_mm256_permute2f128_pd(sq1, sq1, 1), 5));
  const __m128d len = _mm_sqrt_pd(_mm256_castpd256_pd128(_mm256_hadd_pd(p0, p1)));
  if (_mm_movemask_pd(_mm_cmple_pd(len, _mm_setzero_pd())) != 0) {
    Write(b0, out0);
    Write(b1, out1);
    return;
  }
  const __m128d inv = _mm_div_pd(_mm_set1_pd(1.0), len);
  const __m256d inv01 = _mm256_insertf128_pd(_mm256_castpd128_pd256(inv), inv, 1);
  const __m128 q0 = _mm256_cvtpd_ps(_mm256_mul_pd(r0, _mm256_permute_pd(inv01, 0)));
  const __m128 q1 = _mm256_cvtpd_ps(_mm256_mul_pd(r1, _mm256_permute_pd(inv01, 15)));
  float* o0 = &out0->rotation.x;
  float* o1 = &out1->rotation.x;
  _mm_storeu_ps(o0, q0);
  _mm_storeu_ps(o1, q1);

  const __m256 q = _mm256_insertf128_ps(_mm256_castps128_ps256(q0), q1, 1);
  const __m256 u = _mm256_xor_ps(q, _mm256_set1_ps(-0.0f));
  const __m256 ux = _mm256_permute_ps(u, 0x00), uy = _mm256_permute_ps(u, 0x55),
               uz = _mm256_permute_ps(u, 0xAA), w = _mm256_permute_ps(q, 0xFF);
  const __m256 wv = _mm256_insertf128_ps(_mm256_set1_ps(w0), _mm_set1_ps(w1), 1);
  __m256 v[3];
  for (int c = 0; c < 3; ++c) {
    const __m256 x0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(in0.x0[c])),
                                           _mm_load_ps(in1.x0[c]), 1);
    const __m256 dx = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(in0.dx[c])),
                                           _mm_load_ps(in1.dx[c]), 1);
    v[c] = _mm256_add_ps(x0, _mm256_mul_ps(wv, dx));
  }
  const __m256 vx = v[0], vy = v[1], vz = v[2];
  const __m256 uvx = _mm256_sub_ps(_mm256_mul_ps(uy, vz), _mm256_mul_ps(vy, uz));
  const __m256 uvy = _mm256_sub_ps(_mm256_mul_ps(uz, vx), _mm256_mul_ps(vz, ux));
  const __m256 uvz = _mm256_sub_ps(_mm256_mul_ps(ux, vy), _mm256_mul_ps(vx, uy));
  const __m256 uuvx = _mm256_sub_ps(_mm256_mul_ps(uy, uvz), _mm256_mul_ps(uvy, uz));
  const __m256 uuvy = _mm256_sub_ps(_mm256_mul_ps(uz, uvx), _mm256_mul_ps(uvz, ux));
  const __m256 uuvz = _mm256_sub_ps(_mm256_mul_ps(ux, uvy), _mm256_mul_ps(uvx, uy));
  const __m256 two = _mm256_set1_ps(2.0f);
  const __m256 rx =
      _mm256_add_ps(vx, _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(uvx, w), uuvx), two));
  const __m256 ry =
      _mm256_add_ps(vy, _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(uvy, w), uuvy), two));
  const __m256 rz =
      _mm256_add_ps(vz, _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(uvz, w), uuvz), two));
  // StoreRotated's shuffles, in each 128-bit half.
  const __m256 x0y0x1y1 = _mm256_unpacklo_ps(rx, ry);
  const __m256 z0x0z1x1 = _mm256_unpacklo_ps(rz, rx);
  const __m256 y0z0y1z1 = _mm256_unpacklo_ps(ry, rz);
  const __m256 x2y2x3y3 = _mm256_unpackhi_ps(rx, ry);
  const __m256 first = _mm256_shuffle_ps(x0y0x1y1, z0x0z1x1, _MM_SHUFFLE(3, 0, 1, 0));
  const __m256 second = _mm256_shuffle_ps(y0z0y1z1, x2y2x3y3, _MM_SHUFFLE(1, 0, 3, 2));
  const __m256 third = _mm256_unpackhi_ps(rz, rz);
  _mm_storeu_ps(o0 + 4, _mm256_castps256_ps128(first));
  _mm_storeu_ps(o1 + 4, _mm256_extractf128_ps(first, 1));
  _mm_storeu_ps(o0 + 8, _mm256_castps256_ps128(second));
  _mm_storeu_ps(o1 + 8, _mm256_extractf128_ps(second, 1));
  _mm_store_ss(o0 + 12, _mm256_castps256_ps128(third));
  _mm_store_ss(o1 + 12, _mm256_extractf128_ps(third, 1));
}

KinematicsDrivingSampler::KinematicsDrivingSampler(
    std::span<const mocap::JointKinematics> kinematics, int num_joints, int joint,
    double frame_time_s)
    : kinematics_(kinematics),
      num_joints_(static_cast<std::size_t>(num_joints)),
      joint_(static_cast<std::size_t>(joint)),
      num_frames_(static_cast<int>(kinematics.size() / static_cast<std::size_t>(num_joints))),
      frame_time_s_(frame_time_s) {
  std::fill(std::begin(sine_arg_), std::end(sine_arg_), std::bit_cast<std::uint64_t>(-1.0));
}

// The part of mocap::SlerpShortest that depends only on the two rotations, and
// the lerps' x and y - x.
void KinematicsDrivingSampler::Prepare(int frame0) {
  const mocap::JointKinematics& k0 =
      kinematics_[static_cast<std::size_t>(frame0) * num_joints_ + joint_];
  const mocap::JointKinematics& k1 =
      kinematics_[static_cast<std::size_t>(frame0 + 1) * num_joints_ + joint_];
  Interval& in = intervals_[frame0 & 1];
  in.frame0 = frame0;
  // SlerpShortest's double quaternions, x y z w, two components a register.
  const __m128 q0 = _mm_loadu_ps(&k0.rotation.x), q1 = _mm_loadu_ps(&k1.rotation.x);
  const __m128d a_xy = _mm_cvtps_pd(q0), a_zw = _mm_cvtps_pd(_mm_movehl_ps(q0, q0));
  __m128d b_xy = _mm_cvtps_pd(q1), b_zw = _mm_cvtps_pd(_mm_movehl_ps(q1, q1));
  double cos_angle = Dot(a_xy, a_zw, b_xy, b_zw);
  __m128 q1_near = q1;
  if (cos_angle < 0.0) {  // shorter arc
    const __m128d flip = _mm_set1_pd(-0.0);
    b_xy = _mm_xor_pd(b_xy, flip);
    b_zw = _mm_xor_pd(b_zw, flip);
    cos_angle = -cos_angle;
    q1_near = _mm_xor_ps(q1, _mm_set1_ps(-0.0f));
  }
  _mm_storeu_ps(&in.q0.x, q0);
  _mm_storeu_ps(&in.q1_near.x, q1_near);
  _mm_store_pd(in.a, a_xy);
  _mm_store_pd(in.a + 2, a_zw);
  _mm_store_pd(in.b, b_xy);
  _mm_store_pd(in.b + 2, b_zw);
  in.nearly_equal = cos_angle > 1.0 - 1e-12;
  if (!in.nearly_equal) {
    in.angle = std::acos(std::min(cos_angle, 1.0));
    in.sin_angle = std::sin(in.angle);
  }
  const float* v0 = &k0.linear_acceleration.x;
  const float* v1 = &k1.linear_acceleration.x;
  const __m128 x_01 = _mm_loadu_ps(v0), x_12 = _mm_loadu_ps(v0 + 4), x_2 = _mm_load_ss(v0 + 8);
  StoreByComponent(x_01, x_12, x_2, in.x0);
  StoreByComponent(_mm_sub_ps(_mm_loadu_ps(v1), x_01), _mm_sub_ps(_mm_loadu_ps(v1 + 4), x_12),
                   _mm_sub_ps(_mm_load_ss(v1 + 8), x_2), in.dx);
}

double KinematicsDrivingSampler::SinAt(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  const std::size_t slot = ((bits >> 44) ^ (bits >> 52)) & (kSines - 1);
  if (sine_arg_[slot] == bits) return sine_[slot];
  const double s = std::sin(x);
  sine_arg_[slot] = bits;
  sine_[slot] = s;
  return s;
}

void KinematicsDrivingSampler::SineWeights(const Interval& in, float w, double& ca, double& cb) {
  const double wd = w;
  ca = SinAt((1.0 - wd) * in.angle) / in.sin_angle;
  cb = SinAt(wd * in.angle) / in.sin_angle;
}

KinematicsDrivingSampler::Blend KinematicsDrivingSampler::ScalarBlend(double time_s) const {
  const mocap::FrameBlend b = mocap::FindFrameBlend(num_frames_, frame_time_s_, time_s);
  return {.frame0 = b.frame0, .on_frame = b.frame1 == b.frame0, .weight = b.weight};
}

// SampleJointKinematics's rotation, then R^T lerp(x, y) of the three vectors.
void KinematicsDrivingSampler::Write(const Blend& blend, DrivingFrame* out) {
  if (blend.on_frame) {
    CopyFrame(kinematics_[static_cast<std::size_t>(blend.frame0) * num_joints_ + joint_], out);
    return;
  }
  const Interval& in = Slot(blend.frame0);
  const float w = blend.weight;
  __m128 q;
  if (w <= 0.0f) {
    q = _mm_loadu_ps(&in.q0.x);
  } else if (w >= 1.0f) {
    q = _mm_loadu_ps(&in.q1_near.x);
  } else {
    double ca, cb;
    SlerpWeights(in, w, ca, cb);
    q = NormalizedBlend(in.a, in.b, ca, cb);
  }
  float* o = &out->rotation.x;
  _mm_storeu_ps(o, q);
  const __m128 wv = _mm_set1_ps(w);
  const auto lerp = [&](int c) {
    return _mm_add_ps(_mm_load_ps(in.x0[c]), _mm_mul_ps(wv, _mm_load_ps(in.dx[c])));
  };
  StoreRotated(q, lerp(0), lerp(1), lerp(2), o + 4);
}

DrivingFrame KinematicsDrivingSampler::Sample(double time_s) {
  DrivingFrame frame;
  Write(ScalarBlend(time_s), &frame);
  return frame;
}

// FindFrameBlend two lanes at a time where a time falls inside the clip; the
// clamped cases (t <= 0, t not finite, past the last frame) go to FindFrameBlend
// itself. With AVX, times strictly between frames go in pairs (WritePairAvx):
// each waits for the next such time, wherever it is in `times`.
void KinematicsDrivingSampler::SampleMany(std::span<const double> times, DrivingFrame* out,
                                          bool allow_avx) {
  const bool avx = allow_avx && CpuHasAvx();
  Blend waiting;
  DrivingFrame* waiting_out = nullptr;
  const auto put = [&](const Blend& blend, DrivingFrame* o) {
    if (!avx || blend.on_frame || !(blend.weight > 0.0f && blend.weight < 1.0f)) {
      Write(blend, o);
    } else if (waiting_out == nullptr) {
      waiting = blend;
      waiting_out = o;
    } else {
      WritePairAvx(waiting, waiting_out, blend, o);
      waiting_out = nullptr;
    }
  };
  std::size_t i = 0;
  if (num_frames_ > 1) {
    const __m128d frame_time = _mm_set1_pd(frame_time_s_);
    const __m128d last = _mm_set1_pd(static_cast<double>(num_frames_ - 1));
    const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0), half = _mm_set1_pd(0.5);
    const __m128d inf = _mm_set1_pd(HUGE_VAL), tolerance = _mm_set1_pd(1e-9);
    const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffff));
    for (; i + 2 <= times.size(); i += 2) {
      const __m128d t = _mm_loadu_pd(&times[i]);
      const __m128d f = _mm_div_pd(t, frame_time);
      const __m128d inside = _mm_and_pd(_mm_and_pd(_mm_cmpgt_pd(t, zero), _mm_cmplt_pd(t, inf)),
                                        _mm_cmplt_pd(f, last));
      if (_mm_movemask_pd(inside) != 3) {
        put(ScalarBlend(times[i]), out + i);
        put(ScalarBlend(times[i + 1]), out + i + 1);
        continue;
      }
      // As FindFrameBlend: base = floor(f) by truncation, nearest = base or
      // base + 1, on a frame within 1e-9 max(1, nearest) frames.
      const __m128i base_int = _mm_cvttpd_epi32(f);
      const __m128d base = _mm_cvtepi32_pd(base_int);
      const __m128d fraction = _mm_sub_pd(f, base);
      const __m128d up = _mm_cmpge_pd(fraction, half);
      const __m128d nearest = _mm_add_pd(base, _mm_and_pd(up, one));
      const __m128d distance = _mm_and_pd(_mm_sub_pd(f, nearest), abs_mask);
      const __m128d on = _mm_cmple_pd(distance, _mm_mul_pd(tolerance, _mm_max_pd(nearest, one)));
      const int on_bits = _mm_movemask_pd(on), up_bits = _mm_movemask_pd(up);
      const __m128 weight = _mm_cvtpd_ps(fraction);
      put({.frame0 = _mm_cvtsi128_si32(base_int) + (on_bits & up_bits & 1),
           .on_frame = (on_bits & 1) != 0,
           .weight = _mm_cvtss_f32(weight)},
          out + i);
      put({.frame0 = _mm_cvtsi128_si32(_mm_shuffle_epi32(base_int, 1)) + ((on_bits & up_bits) >> 1),
           .on_frame = (on_bits & 2) != 0,
           .weight = _mm_cvtss_f32(_mm_shuffle_ps(weight, weight, 1))},
          out + i + 1);
    }
  }
  for (; i < times.size(); ++i) put(ScalarBlend(times[i]), out + i);
  if (waiting_out != nullptr) Write(waiting, waiting_out);
}

}  // namespace deform::internal
