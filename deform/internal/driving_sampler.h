#pragma once
// The elastic layer's driving frame from a per-frame kinematics buffer
// (KinematicsJob output, #F x #J) at any time: the values
// mocap::SampleJointKinematics gives, bit for bit (same frames and weight from
// mocap::FindFrameBlend, the same shorter-arc slerp in double, the same lerps,
// the same R^T rotations), computing only the four fields a DrivingFrame holds
// and keeping the slerp's per-interval constants (the two quaternions in double,
// their angle and its sine) while successive times fall between the same two
// frames, as the RK4 stage times of a run do.

#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/mass_spring.h"
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

 private:
  // Constants of the interval [frame0, frame0 + 1].
  struct Interval {
    int frame0 = -1;
    glm::dquat a{1, 0, 0, 0}, b{1, 0, 0, 0};  // q0 and the shorter-arc q1, in double
    glm::quat q0{1, 0, 0, 0}, q1_near{1, 0, 0, 0};
    bool nearly_equal = false;                // lerp branch of the slerp
    double angle = 0.0, sin_angle = 0.0;
  };
  void Prepare(int frame0);

  std::span<const mocap::JointKinematics> kinematics_;
  std::size_t num_joints_ = 0, joint_ = 0;
  int num_frames_ = 0;
  double frame_time_s_ = 0.0;
  Interval interval_;
};

}  // namespace deform::internal
