#include "deform/internal/driving_sampler.h"

#include <algorithm>
#include <cmath>

#include "mocap/sampling.h"

namespace deform::internal {

KinematicsDrivingSampler::KinematicsDrivingSampler(
    std::span<const mocap::JointKinematics> kinematics, int num_joints, int joint,
    double frame_time_s)
    : kinematics_(kinematics),
      num_joints_(static_cast<std::size_t>(num_joints)),
      joint_(static_cast<std::size_t>(joint)),
      num_frames_(static_cast<int>(kinematics.size() / static_cast<std::size_t>(num_joints))),
      frame_time_s_(frame_time_s) {}

// The part of mocap::SlerpShortest that depends only on the two rotations.
void KinematicsDrivingSampler::Prepare(int frame0) {
  const mocap::JointKinematics& k0 = kinematics_[static_cast<std::size_t>(frame0) * num_joints_ + joint_];
  const mocap::JointKinematics& k1 =
      kinematics_[static_cast<std::size_t>(frame0 + 1) * num_joints_ + joint_];
  Interval& in = interval_;
  in.frame0 = frame0;
  const glm::quat q0 = k0.rotation, q1 = k1.rotation;
  in.a = glm::dquat(q0.w, q0.x, q0.y, q0.z);
  in.b = glm::dquat(q1.w, q1.x, q1.y, q1.z);
  double cos_angle = glm::dot(in.a, in.b);
  in.q0 = q0;
  in.q1_near = q1;
  if (cos_angle < 0.0) {  // shorter arc
    in.b = -in.b;
    cos_angle = -cos_angle;
    in.q1_near = -q1;
  }
  in.nearly_equal = cos_angle > 1.0 - 1e-12;
  if (!in.nearly_equal) {
    in.angle = std::acos(std::min(cos_angle, 1.0));
    in.sin_angle = std::sin(in.angle);
  }
}

DrivingFrame KinematicsDrivingSampler::Sample(double time_s) {
  const mocap::FrameBlend blend = mocap::FindFrameBlend(num_frames_, frame_time_s_, time_s);
  const mocap::JointKinematics& k0 =
      kinematics_[static_cast<std::size_t>(blend.frame0) * num_joints_ + joint_];
  if (blend.frame1 == blend.frame0) {
    return {k0.rotation, k0.local_linear_acceleration, k0.local_angular_velocity,
            k0.local_angular_acceleration};
  }
  const mocap::JointKinematics& k1 =
      kinematics_[static_cast<std::size_t>(blend.frame1) * num_joints_ + joint_];
  if (interval_.frame0 != blend.frame0) Prepare(blend.frame0);
  const Interval& in = interval_;
  const float w = blend.weight;
  glm::quat rotation;
  if (w <= 0.0f) {
    rotation = in.q0;
  } else if (w >= 1.0f) {
    rotation = in.q1_near;
  } else if (in.nearly_equal) {
    const double wd = w;
    rotation = glm::quat(glm::normalize(in.a * (1.0 - wd) + in.b * wd));
  } else {
    const double wd = w;
    const glm::dquat r = in.a * (std::sin((1.0 - wd) * in.angle) / in.sin_angle) +
                         in.b * (std::sin(wd * in.angle) / in.sin_angle);
    rotation = glm::quat(glm::normalize(r));
  }
  const auto lerp = [w](const glm::vec3& x, const glm::vec3& y) { return x + w * (y - x); };
  const glm::quat to_joint = glm::conjugate(rotation);
  return {rotation, to_joint * lerp(k0.linear_acceleration, k1.linear_acceleration),
          to_joint * lerp(k0.angular_velocity, k1.angular_velocity),
          to_joint * lerp(k0.angular_acceleration, k1.angular_acceleration)};
}

}  // namespace deform::internal
