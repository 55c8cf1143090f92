#include "deform/elastic/internal/modal_run.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include <emmintrin.h>

#include "deform/elastic/internal/checked_driving.h"
#include "deform/elastic/internal/mass_spring_modal.h"
#include "deform/elastic/internal/stage_forcing.h"

namespace deform::internal {
namespace {

// Modal steps whose stage coefficients are computed together (one 30 fps frame
// at h = 1/240 s).
constexpr std::size_t kBatchSteps = 8;


static_assert(sizeof(StageCoefficients) == sizeof(MassSpringState::LastStage::coefficients),
              "MassSpringState::LastStage holds a StageCoefficients");

// A batch's frames and coefficients without the default member initializers'
// zero fill (2.3 KB a run).
struct BatchStorage {
  union Frames {
    Frames() {}
    DrivingFrame at[2 * kBatchSteps];
  } frames;
  union Coefficients {
    Coefficients() {}
    StageCoefficients at[2 * kBatchSteps + 1];
  } coeffs;
};

// Whether `last` is the checked sample this run would take at `time_s`.
bool SameStage(const MassSpringState::LastStage& last, const MassSpringStepJob& job,
               double time_s) {
  const bool callback = job.kinematics.empty();
  return last.valid && last.time_s == time_s && last.network == job.network &&
         last.source == (callback ? static_cast<const void*>(job.driving)
                                  : static_cast<const void*>(job.kinematics.data())) &&
         last.source_size == job.kinematics.size() &&
         (callback || (last.num_joints == job.num_joints && last.joint == job.joint &&
                       last.frame_time_s == job.frame_time_s));
}

void Remember(MassSpringState::LastStage& last, const MassSpringStepJob& job, double time_s,
              const DrivingFrame& frame, const SampleChecks& checks,
              const StageCoefficients& coefficients) {
  const bool callback = job.kinematics.empty();
  last.valid = true;
  last.time_s = time_s;
  last.network = job.network;
  last.source = callback ? static_cast<const void*>(job.driving)
                         : static_cast<const void*>(job.kinematics.data());
  last.source_size = job.kinematics.size();
  last.num_joints = job.num_joints;
  last.joint = job.joint;
  last.frame_time_s = job.frame_time_s;
  last.frame = frame;
  last.non_finite = checks.non_finite;
  last.clamped = checks.clamped;
  last.user_acceleration = job.user_acceleration;
  std::memcpy(last.coefficients, &coefficients, sizeof(StageCoefficients));
}

class ModalRunner {
 public:
  explicit ModalRunner(const MassSpringStepJob& job)
      : job_(job),
        net_(*job.network),
        st_(*job.state),
        n_(static_cast<std::size_t>(job.network->num_free)),
        stride_(static_cast<std::size_t>(job.network->mode_stride)) {}

  void Run(double until_s) {
    const bool stepping = st_.step_time_s < until_s;
    if (!stepping && job_.displacements.empty()) return;
    // The state's fields, in place (MassSpringState::modal): the newest pair
    // and the one before; a run that ends on the other pair flips modal_newest.
    const int newest = st_.modal_newest;
    ModalBuffers b{st_.ModalField(2 * newest), st_.ModalField(2 * newest + 1),
                   st_.ModalField(2 - 2 * newest), st_.ModalField(3 - 2 * newest)};
    if (stepping) {
      Steps(until_s, b);
      if (b.x != st_.ModalField(2 * newest)) st_.modal_newest = 1 - newest;
    }
    if (!job_.displacements.empty()) Output(b.x, b.prev_x);
  }

 private:
  // The coefficients at the run's first stage time (the state's step time):
  // the previous run's last when it is the same stage, else sampled.
  StageCoefficients FirstStage(CheckedDriving& driving) {
    MassSpringState::LastStage& last = st_.last_stage;
    const double t = st_.step_time_s;
    StageCoefficients c;
    if (SameStage(last, job_, t)) {
      // Counted again, as sampling the same stage again would count it.
      st_.counters.non_finite_inputs += last.non_finite ? 1 : 0;
      st_.counters.acceleration_clamps += last.clamped ? 1 : 0;
      if (last.user_acceleration == job_.user_acceleration) {
        std::memcpy(&c, last.coefficients, sizeof(StageCoefficients));
      } else {  // another push this run: the same frame, new coefficients
        c = StageCoefficientsOf(last.frame, driving.forcing());
      }
      return c;
    }
    SampleChecks checks;
    DrivingFrame frame;
    driving.Sample(t, frame, checks);
    c = StageCoefficientsOf(frame, driving.forcing());
    Remember(last, job_, t, frame, checks, c);
    return c;
  }

  // Whole RK4 steps of every mode until the step time reaches `until_s`; b.x,
  // b.v hold the newest step on entry and on return, b.prev_x, b.prev_v the one
  // before.
  // Steps go in batches of up to kBatchSteps: the frames at the batch's stage
  // times first (t + h/2, t + h, t + 3h/2, ...: the times and the order of the
  // step-by-step loop), their coefficients together (internal/stage_forcing.h:
  // the same bits as one at a time), then the steps. coeffs[2 i], [2 i + 1],
  // [2 i + 2]: step i's start, middle and end.
  void Steps(double until_s, ModalBuffers& b) {
    CheckedDriving driving(job_);
    // An exact kernel that stops early has seen the limit's cheap exits fail.
    const auto [steps, bound_tested] = ChooseModalSteps(job_.allow_avx, job_.allow_fma);
    const double h = net_.time_step_s;
    BatchStorage batch;  // left uninitialized: every entry is written before it is read
    DrivingFrame* const frames = batch.frames.at;
    StageCoefficients* const coeffs = batch.coeffs.at;
    coeffs[0] = FirstStage(driving);
    SampleChecks last_checks;
    std::size_t count = 0;
    while (st_.step_time_s < until_s) {
      double starts[kBatchSteps];
      count = 0;
      for (double t = st_.step_time_s; count < kBatchSteps && t < until_s; t = t + h) {
        starts[count++] = t;
      }
      double times[2 * kBatchSteps];
      for (std::size_t i = 0; i < count; ++i) {
        times[2 * i] = starts[i] + 0.5 * h;
        times[2 * i + 1] = starts[i] + h;
      }
      driving.SampleRawMany({times, 2 * count}, frames);
      driving.CheckAndCoefficients({frames, 2 * count}, {coeffs + 1, 2 * count}, last_checks,
                                   job_.allow_avx);
      // The steps run on until one needs the limits (internal/mass_spring_modal.h);
      // Limits changes nothing after the others.
      ModalStepSums sums;
      for (std::size_t i = 0; i < count;) {
        const int done = steps(net_, coeffs + 2 * i, static_cast<int>(count - i),
                               static_cast<float>(h), b, sums);
        const bool stopped = i + static_cast<std::size_t>(done) < count;
        i += static_cast<std::size_t>(done);
        st_.step_time_s = starts[i - 1] + h;
        st_.counters.steps += done;
        Limits(sums, b, stopped && bound_tested);
      }
      if (sums.sum_x < kRestSumOfSquares && sums.sum_v < kRestSumOfSquares) Zero(b);  // rest
      coeffs[0] = coeffs[2 * count];
    }
    Remember(st_.last_stage, job_, st_.step_time_s, frames[2 * count - 1], last_checks, coeffs[0]);
  }

  // The displacement limit and the non-finite reset (ALGORITHMS.md 6) on the
  // modes (3 x stride each) of the newest step (ModalDisplacementLimit).
  // `exits_failed`: ModalDisplacementLimit's.
  void Limits(const ModalStepSums& sums, const ModalBuffers& b, bool exits_failed) {
    if (!std::isfinite(sums.sum_x) || !std::isfinite(sums.sum_v)) {
      ++st_.counters.non_finite_resets;
      Zero(b);
      return;
    }
    st_.counters.displacement_clamps +=
        ModalDisplacementLimit(net_, sums.sum_x, b.x, b.v, job_.allow_avx, exits_failed);
  }

  // All four fields 0 (padding lanes included).
  void Zero(const ModalBuffers& b) const {
    for (float* a : {b.x, b.v, b.prev_x, b.prev_v}) std::fill(a, a + 3 * stride_, 0.0f);
  }

  // e(time_s) = U (prev + alpha (x - prev)): linear interpolation between the
  // last two steps (exact when no step was taken since a reset: both are the
  // same zero state), in point space (eta's padding lanes past #free rounded up
  // to 4 are not written: ModalToPoints reads only the first #free).
  void Output(const float* x, const float* prev_x) const {
    const double h = net_.time_step_s;
    const float alpha =
        static_cast<float>(std::clamp((job_.time_s - (st_.step_time_s - h)) / h, 0.0, 1.0));
    alignas(32) float eta[3 * kMaxModeStride];
    alignas(32) float e[3 * kMaxModeStride];
    const __m128 a4 = _mm_set1_ps(alpha);
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t k = c * stride_; k < c * stride_ + n_; k += 4) {
        const __m128 p = _mm_load_ps(prev_x + k);
        _mm_store_ps(eta + k, _mm_add_ps(p, _mm_mul_ps(a4, _mm_sub_ps(_mm_load_ps(x + k), p))));
      }
    }
    ModalToPoints(net_, eta, e, job_.allow_avx);
    std::span<glm::vec3> out = job_.displacements;
    std::memset(static_cast<void*>(out.data()), 0, out.size_bytes());  // boundary points
    for (std::size_t a = 0; a < n_; ++a) {
      out[static_cast<std::size_t>(net_.point_of_free[a])] =
          glm::vec3(e[a], e[stride_ + a], e[2 * stride_ + a]);
    }
  }

  const MassSpringStepJob& job_;
  const MassSpringNetwork& net_;
  MassSpringState& st_;
  const std::size_t n_, stride_;
};


// ModalDisplacementLimit past its cheap exits; out of line, so that the exits
// do not pay for this part's prologue (saved registers, an aligned 11 KB frame).
[[gnu::noinline]] int LimitPoints(const MassSpringNetwork& net, float* x, float* v, bool allow_avx) {
  const float e_max = net.params.max_displacement;
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  alignas(32) float e[3 * kMaxModeStride];
  ModalToPoints(net, x, e, allow_avx);
  // Candidates: |e_a|^2 above e_max^2 less a margin far wider than the
  // rounding of either side; ClampDisplacement makes the exact decision. Every
  // point's e and velocity are those before any clamp (a clamp at a changes no
  // other point, U being orthonormal), and the clamps reach the modes together.
  const __m128 candidate2 = _mm_set1_ps(0.9999f * e_max * e_max);
  std::size_t points[kMaxModeStride];  // candidates, then the points clamped
  int candidates = 0;
  for (std::size_t a = 0; a < n; a += 4) {  // padding lanes hold 0: never candidates
    const __m128 ex = _mm_load_ps(e + a), ey = _mm_load_ps(e + stride + a),
                 ez = _mm_load_ps(e + 2 * stride + a);
    const __m128 len2 =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ex), _mm_mul_ps(ey, ey)), _mm_mul_ps(ez, ez));
    unsigned mask = static_cast<unsigned>(_mm_movemask_ps(_mm_cmpgt_ps(len2, candidate2)));
    for (; mask != 0; mask &= mask - 1) {
      points[candidates++] = a + static_cast<std::size_t>(std::countr_zero(mask));
    }
  }
  if (candidates == 0) return 0;
  float vel[3 * kMaxModeStride], dx[3 * kMaxModeStride], dv[3 * kMaxModeStride];
  PointVelocities(net, points, candidates, v, vel, allow_avx);
  int clamps = 0;
  for (int j = 0; j < candidates; ++j) {
    const std::size_t p = points[j];
    const glm::vec3 e0(e[p], e[stride + p], e[2 * stride + p]);
    const glm::vec3 v0(vel[3 * j], vel[3 * j + 1], vel[3 * j + 2]);
    glm::vec3 e1 = e0, v1 = v0;
    if (!ClampDisplacement(e1, v1, e_max)) continue;
    for (int c = 0; c < 3; ++c) {
      dx[3 * clamps + c] = e1[c] - e0[c];
      dv[3 * clamps + c] = v1[c] - v0[c];
    }
    points[clamps++] = p;
  }
  if (clamps > 0) AddPointChanges(net, points, clamps, dx, dv, x, v, allow_avx);
  return clamps;
}

}  // namespace

int ModalDisplacementLimit(const MassSpringNetwork& net, float sum_x, float* x, float* v,
                           bool allow_avx, bool exits_failed) {
  // U is orthonormal, so |e_a|^2 <= sum_k |eta_k|^2; also |e_a| <= sum_k u_k |eta_k|
  // with u_k = max_a |U[a, k]|. Below e_max by either bound nothing can exceed.
  const float e_max = net.params.max_displacement;
  if (!exits_failed && (sum_x <= e_max * e_max || ModeBound(net, x, allow_avx) <= e_max)) return 0;
  return LimitPoints(net, x, v, allow_avx);
}

void RunModal(const MassSpringStepJob& job, double until_s) { ModalRunner(job).Run(until_s); }

}  // namespace deform::internal
