#include "deform/internal/checked_driving.h"

#include <cmath>

namespace deform::internal {
namespace {

constexpr double kStandardGravityMps2 = 9.81;

bool Finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
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
  if (!job.kinematics.empty()) {
    sampler_.emplace(job.kinematics, job.num_joints, job.joint, job.frame_time_s);
  }
  forcing_ = {.gain = p.gain, .user_acceleration = job.user_acceleration, .gravity = p.gravity,
              .gravity_model = gravity, .gravity_bind = glm::conjugate(bind_rotation_) * gravity};
}

void CheckedDriving::Sample(double time_s, DrivingFrame& d, SampleChecks& checks) {
  // Kinematics: SampleJointKinematics' values (internal/driving_sampler.h).
  d = sampler_ ? sampler_->Sample(time_s) : (*job_.driving)(time_s);
  MassSpringCounters& c = job_.state->counters;
  checks = {};
  const glm::vec4 q(d.rotation.x, d.rotation.y, d.rotation.z, d.rotation.w);
  if (!Finite(d.linear_acceleration) || !Finite(d.angular_velocity) ||
      !Finite(d.angular_acceleration) || !std::isfinite(glm::dot(q, q)) ||
      glm::dot(q, q) < 1e-12f) {
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

}  // namespace deform::internal
