#pragma once
// Test-only per-frame kinematics of one joint for the driving sampler's tests:
// 40 frames at 30 fps turning 0.9 rad per frame about a fixed axis for the first
// 30 (the slerp's sines), every other quaternion negated (the shorter-arc flip),
// then standing at 27 rad (the nearly-equal lerp), with accelerations and
// angular velocities that differ per frame and per component.

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mocap/kinematics.h"

namespace test_clips {

inline std::vector<mocap::JointKinematics> FastTurnsClip() {
  std::vector<mocap::JointKinematics> kin(40);
  for (std::size_t f = 0; f < kin.size(); ++f) {
    const float angle = f < 30 ? 0.9f * static_cast<float>(f) : 27.0f;
    kin[f].rotation = glm::angleAxis(angle, glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f)));
    if (f % 2 == 1) kin[f].rotation = -kin[f].rotation;
    kin[f].angular_velocity = glm::vec3(0.0f, 27.0f, static_cast<float>(f));
    kin[f].linear_acceleration = glm::vec3(static_cast<float>(f), -3.0f, 1e3f);
    kin[f].angular_acceleration = glm::vec3(-2.0f, static_cast<float>(f * f), 5.0f);
  }
  return kin;
}

}  // namespace test_clips
