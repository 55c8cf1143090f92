#pragma once
// Sampling a motion at any time between its frames, and resampling a motion to
// another frame rate.
//
// Between frames f and f+1 (w = t / frame_time_s - f in [0, 1)):
//   rotation    = slerp(q_f, q_f+1, w) on the shorter arc (5.4: q_f+1 is negated
//                 first when dot(q_f, q_f+1) < 0)
//   translation = lerp, scale = lerp.
// Times outside [0, duration] are clamped to the first or last frame. A time
// within 1e-9 frames of a frame time returns that frame's pose exactly (the
// same bits as LocalPoseJob on that frame).

#include <span>

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace mocap {

// Shorter-arc spherical interpolation of unit quaternions, computed in double:
// q0 (q0^-1 q1')^w with q1' = +-q1 such that dot(q0, q1') >= 0. Exact at w = 0
// and w = 1 (returns q0 and q1' themselves). Falls back to normalized lerp when
// the two are closer than ~1e-6 rad.
glm::quat SlerpShortest(const glm::quat& q0, const glm::quat& q1, float w);

// Where time t falls in a motion: the two frames around it and the weight of
// the second. frame1 == frame0 and weight 0 at and beyond the ends, and at
// frame times (within 1e-9 frames).
struct FrameBlend {
  int frame0 = 0;
  int frame1 = 0;
  float weight = 0.0f;  // of frame1, in [0, 1)
};
// Requires num_frames >= 1 and frame_time_s > 0; a non-finite time clamps to frame 0.
FrameBlend FindFrameBlend(int num_frames, double frame_time_s, double time_s);

// Local transforms of every joint at time t (seconds from the first frame).
struct SampleLocalsJob {
  const Skeleton* skeleton = nullptr;  // required
  const Motion* motion = nullptr;      // required; num_channels == skeleton->num_channels,
                                       // num_frames >= 1, frame_time_s > 0
  double time_s = 0.0;                 // clamped to [0, motion->duration_s()]
  std::span<JointTransform> scratch;   // #J caller-owned workspace (the second frame)
  std::span<JointTransform> locals;    // #J output, parent-from-joint

  // kMissingInput: skeleton or motion null, or motion without frames;
  // kSizeMismatch: channel counts or span sizes; kOutOfRange: frame_time_s <= 0
  // or motion->values too short. Reads no channel values.
  [[nodiscard]] base::JobStatus Validate() const;
  // Validate(), then two LocalPoseJob evaluations and the blend. No allocation.
  [[nodiscard]] base::JobStatus Run() const;
};

// Largest number of frames Resample produces (about 2.3 hours at 120 fps).
inline constexpr int kMaxResampledFrames = 1 << 20;

// A new motion with the same channel layout sampled every new_frame_time_s
// seconds, from t = 0 to the last whole step not past the original duration
// (num_frames = floor(duration / new_frame_time_s + 1e-9) + 1).
// Channel values are re-derived from the sampled local transforms:
// - position channels: translation (minus the rest offset in kAddToOffset mode);
// - Euler channels: QuatToEulerNear of rest_rotation^-1 * rotation in the joint's
//   own channel order, continuous with the previous new frame (the first new
//   frame is continued from the original frame 0), so no 360-degree jumps;
// - quaternion channels: the rotation with the sign that keeps dot >= 0 with the
//   previous new frame (the first from the original frame 0);
// - scale channels: the lerped scale.
// Errors (kInvalidArgument): new_frame_time_s not finite or <= 0, a motion that
// does not match the skeleton or has no frames; kLimitExceeded: more than
// kMaxResampledFrames frames.
base::Result<Motion> Resample(const Skeleton& skeleton, const Motion& motion,
                              double new_frame_time_s);

}  // namespace mocap
