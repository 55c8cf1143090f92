#pragma once
// The elastic layer's driving frame from a per-frame kinematics buffer
// (KinematicsJob output, #F x #J) at any time: the values
// mocap::SampleJointKinematics gives, bit for bit (same frames and weight from
// mocap::FindFrameBlend, the same shorter-arc slerp in double, the same lerps,
// the same R^T rotations), computing only the four fields a DrivingFrame holds.
//
// Successive times mostly fall between the same two frames (the RK4 stage
// times of a run: four or more per frame interval), so what depends only on the
// interval is kept while they do: the slerp's constants (the two quaternions in
// double, their angle and its sine) and the three vectors at the first frame
// and their differences to the second (x and y - x of the lerp x + w (y - x)).
// The slerp's sines are remembered by argument: a weight w and the 1 - w of
// another stage time in the same interval give the same argument.
//
// The per-time work runs in SIMD lanes: the double quaternion two components a
// lane (SSE2), the three vectors one a lane, and in SampleMany on a CPU with
// AVX two times at once. Each lane does the scalar code's operations in its
// order and precision (the build has -ffp-contract=off), so the bits are the
// scalar code's.

#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <span>

#include "deform/elastic/mass_spring.h"
#include "mocap/kinematics.h"
#include "mocap/sampling.h"

namespace deform::internal {

class KinematicsDrivingSampler {
 public:
  // `kinematics` (#F x #J, frame-major, not empty) must outlive the sampler;
  // num_joints >= 1, 0 <= joint < num_joints, frame_time_s > 0 (as
  // MassSpringStepJob::Validate checks).
  KinematicsDrivingSampler(std::span<const mocap::JointKinematics> kinematics, int num_joints,
                           int joint, double frame_time_s);

  // The driving frame at `time_s` (clamped to the buffer like SampleJointKinematics).
  DrivingFrame Sample(double time_s);

  // out[i] = Sample(times[i]) for each i in order, bit for bit, with the frame
  // search done two times at a time and, with allow_avx on a CPU that has AVX,
  // two times of one frame interval rotated together. `out` holds
  // times.size() frames (its previous contents are not read); any times, in
  // any order (best when successive times share frame intervals, as RK4 stage
  // times do).
  void SampleMany(std::span<const double> times, DrivingFrame* out, bool allow_avx = true);

 private:
  // Where one time falls (mocap::FrameBlend's values): on frame `frame0`
  // exactly, or between frame0 and frame0 + 1 with weight `weight` of the second.
  struct Blend {
    int frame0 = 0;
    bool on_frame = true;
    float weight = 0.0f;
  };

  // Constants of the interval [frame0, frame0 + 1]. Prepare writes every
  // field before any is read (frame0 is -1 until then); the rest has no
  // initializer, as a sampler is built for each run, i.e. each output frame.
  struct Interval {
    int frame0 = -1;
    // q0 and the shorter-arc q1, in double, in glm's x, y, z, w memory order;
    // 32-byte aligned so WritePairAvx's 256-bit loads never split a line.
    alignas(32) double a[4];
    alignas(32) double b[4];
    // Linear acceleration, angular velocity and angular acceleration by
    // component: x0[c][v] is component c of vector v at frame0, dx[c][v] the
    // difference frame0 + 1 minus frame0; lane 3 is 0.
    alignas(16) float x0[3][4];
    alignas(16) float dx[3][4];
    glm::quat q0, q1_near;
    bool nearly_equal;        // lerp branch of the slerp
    double angle, sin_angle;  // set when !nearly_equal
  };

  void Prepare(int frame0);
  double SinAt(double x);                  // std::sin(x), remembered
  Blend ScalarBlend(double time_s) const;  // mocap::FindFrameBlend's answer
  // The interval starting at frame0, prepared. Two are kept, by the parity of
  // frame0, so that two neighbouring intervals can be sampled together.
  Interval& Slot(int frame0) {
    Interval& in = intervals_[frame0 & 1];
    if (in.frame0 != frame0) Prepare(frame0);
    return in;
  }
  // The weights of q0 and q1' in the slerp at 0 < w < 1: the nearly-equal
  // lerp's inline, the sines' (SineWeights, with calls to sin) out of line.
  void SlerpWeights(const Interval& in, float w, double& ca, double& cb) {
    if (in.nearly_equal) {
      const double wd = w;
      ca = 1.0 - wd;
      cb = wd;
    } else {
      SineWeights(in, w, ca, cb);
    }
  }
  void SineWeights(const Interval& in, float w, double& ca, double& cb);
  void Write(const Blend& blend, DrivingFrame* out);
  // Two times strictly between frames (0 < weight < 1), into out0 and out1:
  // Write on each, in one pass of AVX lanes (needs a CPU with AVX).
  void WritePairAvx(const Blend& b0, DrivingFrame* out0, const Blend& b1, DrivingFrame* out1);

  std::span<const mocap::JointKinematics> kinematics_;
  std::size_t num_joints_ = 0, joint_ = 0;
  int num_frames_ = 0;
  double frame_time_s_ = 0.0;
  Interval intervals_[2];
  // sin(x) for arguments x the slerp took (keyed by the bits of x,
  // direct-mapped by a few of them; a pure function, so kept across
  // intervals). An empty slot holds the bits of -1, which no argument has:
  // they are w angle and (1 - w) angle with 0 < w < 1 and angle in [0, pi] or NaN.
  static constexpr std::size_t kSines = 16;
  std::uint64_t sine_arg_[kSines];
  double sine_[kSines];
};

}  // namespace deform::internal
