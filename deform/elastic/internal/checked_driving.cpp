#include "deform/elastic/internal/checked_driving.h"

#include <bit>
#include <cmath>
#include <limits>
#include <new>

#include <emmintrin.h>

#include "deform/internal/cpu_features.h"

namespace deform::internal {
namespace {

constexpr double kStandardGravityMps2 = 9.81;

// No field of the frame is NaN or Inf: x - x is +0 for a finite x and NaN
// otherwise, and a sum with a NaN term is NaN. Four SSE2 lanes for the 13
// floats instead of 13 scalar tests. (The quaternion is included; a non-finite
// one fails the |q|^2 test below anyway.)
bool AllFinite(const DrivingFrame& d) {
  static_assert(sizeof(DrivingFrame) == 13 * sizeof(float), "DrivingFrame is 13 floats");
  const float* f = &d.rotation.x;
  const __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
  const __m128 e = _mm_set_ss(f[12]);
  const __m128 sum = _mm_add_ps(_mm_add_ps(_mm_sub_ps(a, a), _mm_sub_ps(b, b)),
                                _mm_add_ps(_mm_sub_ps(c, c), _mm_sub_ps(e, e)));
  return _mm_movemask_ps(_mm_cmpunord_ps(sum, sum)) == 0;
}

}  // namespace

CheckedDriving::CheckedDriving(const MassSpringStepJob& job)
    : job_(job), bind_rotation_(job.network->bind_rotation) {
  const MassSpringParams& p = job.network->params;
  const double g = kStandardGravityMps2 * p.units_per_metre;
  const glm::vec3 gravity = glm::vec3(glm::dvec3(glm::normalize(p.down)) * g);
  max_accel_ = p.max_acceleration_mps2 * p.units_per_metre;
  // Below this |a|^2 the length is certainly <= max_accel_ (float rounding of
  // the square is far inside 1%), so most samples skip the square root.
  surely_below_accel2_ = 0.99f * max_accel_ * max_accel_;
  const float lane_bound = 0.999f * std::sqrt(surely_below_accel2_ / 3.0f);
  quick_ = {.min_abs_q = 2e-6f, .max_abs_q = 1e18f, .max_abs_a = lane_bound};
  for (int i = 0; i < 3; ++i) accel_lane_bounds_[i] = lane_bound;
  accel_lane_bounds_[3] = std::numeric_limits<float>::infinity();
  if (!job.kinematics.empty()) {
    sampler_.emplace(job.kinematics, job.num_joints, job.joint, job.frame_time_s);
  }
  forcing_ = {.gain = p.gain, .user_acceleration = job.user_acceleration, .gravity = p.gravity,
              .gravity_model = gravity, .gravity_bind = glm::conjugate(bind_rotation_) * gravity};
}

void CheckedDriving::SampleRaw(double time_s, DrivingFrame& d) {
  // Constructed in place (no temporary to copy: the copy's wide loads of the
  // callee's narrow stores would stall store forwarding).
  if (sampler_) {
    ::new (static_cast<void*>(&d)) DrivingFrame(sampler_->Sample(time_s));
  } else {
    ::new (static_cast<void*>(&d)) DrivingFrame((*job_.driving)(time_s));
  }
}

void CheckedDriving::SampleRawMany(std::span<const double> times, DrivingFrame* frames) {
  if (sampler_) {
    sampler_->SampleMany(times, frames, job_.allow_avx);
    return;
  }
  for (std::size_t i = 0; i < times.size(); ++i) SampleRaw(times[i], frames[i]);
}

// Conservative tests on the frame's 13 floats in four SSE2 registers: a frame
// passes only if every float is finite, some |q_i| >= 2e-6 (so the rounded
// |q|^2 >= 4e-12 (1 - 3 eps) is above 1e-12), every |q_i| <= 1e18 (|q|^2 stays
// finite) and every |a_i| is within accel_lane_bounds_ (3 b^2 with rounding is
// below surely_below_accel2_); Check then provably changes and counts nothing.
// About half the instructions of the per-field tests, run on every stage time.
// (The bounds are quick_'s; QuickTestedCoefficientsOfEight runs the same test
// in AVX lanes.)
bool CheckedDriving::MayNeedChecks(const DrivingFrame& d) const {
  const float* f = &d.rotation.x;
  const __m128 q = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
  const __m128 e = _mm_load_ss(f + 12);
  const __m128 nan_if_not_finite = _mm_add_ps(_mm_add_ps(_mm_sub_ps(q, q), _mm_sub_ps(b, b)),
                                              _mm_add_ps(_mm_sub_ps(c, c), _mm_sub_ps(e, e)));
  const __m128 abs_bits = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 q_abs = _mm_and_ps(q, abs_bits);
  const __m128 flags =
      _mm_or_ps(_mm_or_ps(_mm_cmpunord_ps(nan_if_not_finite, nan_if_not_finite),
                          _mm_cmpgt_ps(q_abs, _mm_set1_ps(quick_.max_abs_q))),
                _mm_cmpgt_ps(_mm_and_ps(b, abs_bits), _mm_load_ps(accel_lane_bounds_)));
  if (_mm_movemask_ps(flags) != 0) return true;
  return _mm_movemask_ps(_mm_cmplt_ps(q_abs, _mm_set1_ps(quick_.min_abs_q))) == 0xF;
}

void CheckedDriving::Check(DrivingFrame& d, SampleChecks& checks) {
  MassSpringCounters& c = job_.state->counters;
  checks = {};
  const glm::vec4 q(d.rotation.x, d.rotation.y, d.rotation.z, d.rotation.w);
  if (!AllFinite(d) || !std::isfinite(glm::dot(q, q)) || glm::dot(q, q) < 1e-12f) {
    ++c.non_finite_inputs;  // a glitch: the frame is taken as at rest in the bind pose
    checks.non_finite = true;
    d = DrivingFrame{bind_rotation_};
  }
  if (glm::dot(d.linear_acceleration, d.linear_acceleration) > surely_below_accel2_) {
    const float a_len = glm::length(d.linear_acceleration);
    if (a_len > max_accel_) {
      ++c.acceleration_clamps;
      checks.clamped = true;
      d.linear_acceleration *= max_accel_ / a_len;
    }
  }
}

void CheckedDriving::Sample(double time_s, DrivingFrame& d, SampleChecks& checks) {
  SampleRaw(time_s, d);
  Check(d, checks);
}

void CheckedDriving::CheckAll(std::span<DrivingFrame> frames, SampleChecks& last_checks) {
  last_checks = {};
  for (std::size_t i = 0; i < frames.size(); ++i) {
    // Most frames need nothing; those that may go through the exact checks.
    if (!MayNeedChecks(frames[i])) continue;
    SampleChecks checks;
    Check(frames[i], checks);
    if (i + 1 == frames.size()) last_checks = checks;
  }
}

void CheckedDriving::CheckAndCoefficients(std::span<DrivingFrame> frames,
                                          std::span<StageCoefficients> out,
                                          SampleChecks& last_checks, bool allow_avx) {
  const std::size_t n = frames.size();
  last_checks = {};
  std::size_t i = 0;
  if (allow_avx && CpuHasAvx()) {
    for (; i + 8 <= n; i += 8) {
      unsigned flags = QuickTestedCoefficientsOfEight(&frames[i], forcing_, quick_, &out[i]);
      if (flags == 0) continue;
      for (; flags != 0; flags &= flags - 1) {  // CheckAll's exact checks, in order
        const std::size_t at = i + static_cast<std::size_t>(std::countr_zero(flags));
        SampleChecks checks;
        Check(frames[at], checks);
        if (at + 1 == n) last_checks = checks;
      }
      StageCoefficientsOfEach(frames.subspan(i, 8), forcing_, out.subspan(i, 8), true);
    }
  }
  if (i == n) return;
  CheckAll(frames.subspan(i), last_checks);  // ends with the last frame
  StageCoefficientsOfEach(frames.subspan(i), forcing_, out.subspan(i), allow_avx);
}

}  // namespace deform::internal
