#pragma once
// The elastic layer's driving source for one MassSpringStepJob run: the job's
// kinematics (internal/driving_sampler.h) or its callback, with the input limits
// of ALGORITHMS.md 6 applied to every sample: a frame with a NaN/Inf field or a
// zero rotation becomes the bind frame at rest, |a| above the clamp is scaled
// back to it. Each such sample adds to the state's counters. Also the run's
// ForcingConstants (internal/stage_forcing.h). Shared by the modal and the
// point-space solvers.

#include <optional>
#include <span>

#include <glm/glm.hpp>

#include "deform/elastic/internal/driving_sampler.h"
#include "deform/elastic/internal/stage_forcing.h"
#include "deform/elastic/mass_spring.h"

namespace deform::internal {

// What the checks did to one sample.
struct SampleChecks {
  bool non_finite = false;  // replaced by the bind frame (counted in non_finite_inputs)
  bool clamped = false;     // |a| scaled to the clamp (counted in acceleration_clamps)
};

class CheckedDriving {
 public:
  // `job` must have passed Validate(); it must outlive this object.
  explicit CheckedDriving(const MassSpringStepJob& job);

  // The checked driving frame at `time_s`, written to `frame`; the checks are
  // counted in job.state->counters and returned in `checks`.
  void Sample(double time_s, DrivingFrame& frame, SampleChecks& checks);
  DrivingFrame Sample(double time_s) {
    DrivingFrame frame;
    SampleChecks unused;
    Sample(time_s, frame, unused);
    return frame;
  }

  // The batch form, for many stage times sampled before any is used: the raw
  // frames first (SampleRaw), then CheckAll over them: the same frames and
  // counts as Sample on each, with a quick test per frame first (wide loads:
  // cheap once the frames' stores are done) and the exact checks only on
  // frames that may need them. `last_checks`: what the checks did to the last
  // frame.
  void SampleRaw(double time_s, DrivingFrame& frame);
  // SampleRaw on each of `times` in order, into frames[0, times.size()): the
  // sampler's batch form (KinematicsDrivingSampler::SampleMany, same bits).
  void SampleRawMany(std::span<const double> times, DrivingFrame* frames);
  void CheckAll(std::span<DrivingFrame> frames, SampleChecks& last_checks);

  // CheckAll on `frames`, then their stage coefficients into `out` (as long as
  // frames): the frames, counts, last_checks and coefficient bits of CheckAll
  // followed by StageCoefficientsOfEach(frames, forcing(), out, allow_avx). With
  // allow_avx on a CPU with AVX, eight frames at a time take the quick test in
  // the coefficients' own pass (QuickTestedCoefficientsOfEight); a block with a
  // frame that fails it gets the exact checks on those frames and then its
  // coefficients.
  void CheckAndCoefficients(std::span<DrivingFrame> frames, std::span<StageCoefficients> out,
                            SampleChecks& last_checks, bool allow_avx);

  // gain, push and gravity of the run.
  const ForcingConstants& forcing() const { return forcing_; }

 private:
  void Check(DrivingFrame& frame, SampleChecks& checks);
  // False only if Check would leave the frame alone (no count).
  bool MayNeedChecks(const DrivingFrame& frame) const;

  const MassSpringStepJob& job_;
  glm::quat bind_rotation_{1, 0, 0, 0};
  float max_accel_ = 0.0f;            // the |a| clamp, model units/s^2
  float surely_below_accel2_ = 0.0f;  // |a|^2 below this needs no square root
  // MayNeedChecks' bounds (see there); quick_.max_abs_a keeps |a|^2 below
  // surely_below_accel2_.
  QuickTestBounds quick_;
  // The same |a_i| bound for a frame's floats 4..7 (a_x, a_y, a_z, w_x) as one
  // SSE2 register: w_x is not tested (+inf).
  alignas(16) float accel_lane_bounds_[4] = {};
  std::optional<KinematicsDrivingSampler> sampler_;
  ForcingConstants forcing_;
};

}  // namespace deform::internal
