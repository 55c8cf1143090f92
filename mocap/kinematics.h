#pragma once
// Joint kinematics over a motion by finite differences of the model matrices:
// per joint and frame, position, orientation, linear velocity and acceleration,
// angular velocity and acceleration, in model space and in the joint's own
// moving frame. The elastic layer (ALGORITHMS.md 6) reads o'', w and al of its
// driving joint from here.
//
// Units: positions in file units (cm for the synthetic humanoid), linear
// velocity in file units/s, linear acceleration in file units/s^2, angular
// velocity in rad/s, angular acceleration in rad/s^2. "Model space" is the
// space of model_from_joint (the world when model_from_root is the identity).
//
// Formulas, h = frame time, p_k and q_k the joint's position and rotation at
// frame k (q from the model matrix with scale removed), rv(q) the rotation
// vector of QuatToRotationVector (shorter arc):
//   interior (0 < f < #F-1), all second order, error O(h^2):
//     v  = (p_f+1 - p_f-1) / 2h             a  = (p_f+1 - 2 p_f + p_f-1) / h^2
//     w  = rv(q_f+1 q_f-1^-1) / 2h          al = (rv(q_f+1 q_f^-1) - rv(q_f q_f-1^-1)) / h^2
//   first frame (one-sided; last frame mirrored):
//     v  = (-3 p_0 + 4 p_1 - p_2) / 2h (second order)
//     w  = (4 rv(q_1 q_0^-1) - rv(q_2 q_0^-1)) / 2h (second order)
//     a, al = the interior formulas of frame 1 (first order at frame 0)
//   2 frames: v, w from the one difference, a = al = 0; 1 frame: all zero.
// Angular velocity comes from relative rotations, never from Euler angle
// differences, so it is independent of the channel order and has no gimbal
// artefacts. Joint-frame values are R^T times the model-space values, with R the
// joint's model rotation at that frame. Each joint's rotation must change by
// less than pi over two frame steps (any real capture does).
// Differentiating captured data twice amplifies noise: SmoothTrajectoriesJob
// below can low-pass the matrices first (not done unless the caller runs it).

#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace mocap {

// The kinematic state of one joint at one time.
struct JointKinematics {
  glm::vec3 position{0.0f};                    // model space, file units
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // model_from_joint rotation (scale removed)
  glm::vec3 linear_velocity{0.0f};             // model space, file units/s
  glm::vec3 linear_acceleration{0.0f};         // model space, file units/s^2
  glm::vec3 angular_velocity{0.0f};            // model space, rad/s
  glm::vec3 angular_acceleration{0.0f};        // model space, rad/s^2
  glm::vec3 local_linear_velocity{0.0f};       // joint frame: R^T linear_velocity
  glm::vec3 local_linear_acceleration{0.0f};   // joint frame: R^T linear_acceleration
  glm::vec3 local_angular_velocity{0.0f};      // joint frame: R^T angular_velocity
  glm::vec3 local_angular_acceleration{0.0f};  // joint frame: R^T angular_acceleration
};

// Model matrices of a range of frames: LocalPoseJob + LocalToModelJob per frame.
struct ModelMatricesJob {
  const Skeleton* skeleton = nullptr;     // required
  const Motion* motion = nullptr;         // required, num_channels == skeleton->num_channels
  int first_frame = 0;                    // first frame evaluated
  glm::mat4 model_from_root{1.0f};        // applied above every root joint
  std::span<JointTransform> locals;       // #J caller-owned workspace
  std::span<glm::mat4> model_from_joint;  // #F' x #J output, frame-major: frame
                                          // first_frame + k at [k * #J, (k+1) * #J)

  // kMissingInput: null skeleton or motion, or a skeleton without joints;
  // kSizeMismatch: locals, channel counts, or an output that is not a whole
  // number of frames; kOutOfRange: frames past the motion's end or
  // motion->values too short.
  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;  // no allocation
};

// Finite-difference kinematics of every joint over a range of frames.
struct KinematicsJob {
  std::span<const glm::mat4> model_from_joint;  // #F x #J, ALL frames of the motion, frame-major
                                                // (neighbours outside the range are read)
  int num_joints = 0;                           // #J >= 1
  double frame_time_s = 0.0;                    // h > 0
  int first_frame = 0;                          // frame of output[0 .. #J)
  std::span<JointKinematics> output;            // #F' x #J, frames first_frame .. first_frame+#F'-1

  // kMissingInput: no joints or no frames; kSizeMismatch: spans that are not
  // whole frames; kOutOfRange: frame_time_s <= 0 or frames outside [0, #F).
  [[nodiscard]] base::JobStatus Validate() const;
  // Validate(), then the formulas above. No allocation. Each output depends only
  // on model_from_joint, so splitting the frame range over threads gives the
  // same bits.
  [[nodiscard]] base::JobStatus Run() const;
};

// Optional zero-phase low-pass of the joint trajectories before KinematicsJob
// (ALGORITHMS.md 6: differentiating captured data twice amplifies noise).
// A symmetric (hence zero-phase) Gaussian FIR kernel over frames with standard
// deviation sigma = sqrt(ln 2) / (2 pi cutoff_hz) seconds, so the gain
// exp(-(2 pi f sigma)^2 / 2) is 1/sqrt(2) at the cutoff (10 Hz: 0.986 at 2 Hz,
// 0.004 at 40 Hz). Truncated at +-3 sigma; at the clip ends the window is cut and
// its weights renormalized. Positions are averaged; rotations are averaged as
// quaternions sign-aligned with the centre frame, then normalized (close to the
// rotation mean for the small spread inside a window); the scale of the centre
// frame is kept. Smoothing leaves the second derivative of a quadratic
// trajectory unchanged (it adds sigma^2 x'' / 2 to positions). With
// sigma < h / 3 the kernel is a single tap and the matrices are copied.
struct SmoothTrajectoriesJob {
  std::span<const glm::mat4> model_from_joint;  // #F x #J, ALL frames, frame-major
  int num_joints = 0;                           // #J >= 1
  double frame_time_s = 0.0;                    // h > 0
  double cutoff_hz = 10.0;                      // > 0
  int first_frame = 0;                          // frame of output[0 .. #J)
  std::span<glm::mat4> output;                  // #F' x #J smoothed matrices; must not alias input

  // Same checks as KinematicsJob, plus kOutOfRange for cutoff_hz <= 0.
  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;  // no allocation; splitting ranges gives the same bits
};

// Kinematics of all frames (#F x #J, frame-major), allocated once, in the model
// space model_from_root puts the root in; the joint paths are low-passed at
// cutoff_hz first (SmoothTrajectoriesJob) when it is > 0, as the elastic layer
// and `patchskin elastic` drive their networks. Errors (kInvalidArgument) for a
// motion that does not match the skeleton or has no frames or a non-positive
// frame time, and for a cutoff the low-pass refuses.
base::Result<std::vector<JointKinematics>> ComputeKinematics(
    const Skeleton& skeleton, const Motion& motion, double cutoff_hz = 0.0,
    const glm::mat4& model_from_root = glm::mat4(1.0f));

// The same kinematics for the listed joints only: a compact #F x #D table,
// frame-major, column d holding joints[d] (any order, no repeats, each in
// [0, #J)). Bit-identical to the matching entries of ComputeKinematics: the
// smoothing and the differences work per joint column. Memory: the model
// matrices are evaluated 256 frames at a time (#J x 64 B each) and only the
// listed columns kept, so the peak is #F x #D x (64 + 124) B plus a constant,
// instead of #F x #J x 252 B. Errors (kInvalidArgument) as ComputeKinematics,
// and for a joint list that is empty, repeats a joint or holds one out of range.
base::Result<std::vector<JointKinematics>> ComputeKinematicsOf(
    const Skeleton& skeleton, const Motion& motion, std::span<const int> joints,
    double cutoff_hz = 0.0, const glm::mat4& model_from_root = glm::mat4(1.0f));

// Kinematics of ONE joint at any time t (seconds), e.g. an RK4 stage time, from
// the two frames around t in a per-frame buffer (as KinematicsJob fills it, for
// all #F frames starting at frame 0):
//   position: cubic Hermite from the neighbouring positions and velocities;
//   rotation: shorter-arc slerp; velocities and accelerations: linear;
//   joint-frame values: R(t)^T times the interpolated model-space values.
// Exact at frame times; t is clamped to [0, (#F-1) h]. kSizeMismatch: buffer not
// a whole number of frames; kOutOfRange: joint outside [0, #J), h <= 0;
// kMissingInput: empty buffer or out == nullptr.
[[nodiscard]] base::JobStatus SampleJointKinematics(std::span<const JointKinematics> kinematics,
                                                    int num_joints, int joint, double frame_time_s,
                                                    double time_s, JointKinematics* out);

}  // namespace mocap
