#pragma once
// Pose evaluation: one frame of channel values -> local joint transforms ->
// model-space joint matrices. Jobs in the ozz-animation shape: a plain struct
// of spans, Validate() checks sizes only, Run() computes and never allocates.
//
// Local transform of a BVH joint: translation, then the rotation channels in
// the order the file lists them, R = R(first) * R(second) * R(third) on column
// vectors (so a ZXY joint is Rz * Rx * Ry). Angles are degrees in the file.
// Position channels replace the rest offset (PositionChannelMode::kReplaceOffset,
// the default) or add to it (kAddToOffset). Quaternion and scale channels
// (glTF import) replace the rest rotation and rest scale.
// Model matrix: model_from_joint[j] = model_from_joint[parent] * local[j].

#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"
#include "mocap/skeleton.h"

namespace mocap {

// A local (parent-from-joint) transform: p_parent = T * R * S * p_joint.
struct JointTransform {
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};

  glm::mat4 ToMatrix() const;
};

// Rotation of Euler angles (degrees) applied in the listed axis order:
// R = R(axes[0], angles[0]) * R(axes[1], angles[1]) * ... for `count` axes (0..3).
// axes are ChannelType::kXRotation / kYRotation / kZRotation.
glm::quat EulerToQuat(const ChannelType* axes, const float* angles_deg, int count);

// The rest pose: rest translations, rotations and scales of every joint.
void RestPose(const Skeleton& skeleton, std::span<JointTransform> locals);

// Local transforms of every joint from one frame of channel values.
struct LocalPoseJob {
  const Skeleton* skeleton = nullptr;         // required
  std::span<const float> frame_values;        // #C values of one frame (Motion::frame)
  std::span<JointTransform> locals;           // #J output

  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;
};

// Model-space matrices from local transforms, one forward pass over the
// parent-before-child order.
struct LocalToModelJob {
  std::span<const std::int16_t> parents;      // #J, Skeleton::parents
  std::span<const JointTransform> locals;     // #J
  glm::mat4 model_from_root{1.0f};            // applied above every root joint
  std::span<glm::mat4> model_from_joint;      // #J output

  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;
};

}  // namespace mocap
