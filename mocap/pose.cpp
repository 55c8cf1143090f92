#include "mocap/pose.h"

#include <glm/gtc/matrix_transform.hpp>

namespace mocap {

glm::mat4 JointTransform::ToMatrix() const {
  glm::mat4 m = glm::mat4_cast(rotation);
  m[0] *= scale.x;
  m[1] *= scale.y;
  m[2] *= scale.z;
  m[3] = glm::vec4(translation, 1.0f);
  return m;
}

glm::quat EulerToQuat(const ChannelType* axes, const float* angles_deg, int count) {
  glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
  for (int i = 0; i < count; ++i) {
    glm::vec3 axis(0.0f);
    switch (axes[i]) {
      case ChannelType::kXRotation: axis.x = 1.0f; break;
      case ChannelType::kYRotation: axis.y = 1.0f; break;
      case ChannelType::kZRotation: axis.z = 1.0f; break;
      default: continue;
    }
    q = q * glm::angleAxis(glm::radians(angles_deg[i]), axis);  // intrinsic: later axes apply first
  }
  return q;
}

void RestPose(const Skeleton& skeleton, std::span<JointTransform> locals) {
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const auto js = static_cast<std::size_t>(j);
    locals[js] = {skeleton.rest_translations[js], skeleton.rest_rotations[js],
                  skeleton.rest_scales[js]};
  }
}

base::JobStatus LocalPoseJob::Validate() const {
  if (skeleton == nullptr) return {base::JobStatus::kMissingInput, "skeleton is null"};
  if (frame_values.size() != static_cast<std::size_t>(skeleton->num_channels)) {
    return {base::JobStatus::kSizeMismatch, "frame_values must hold num_channels values"};
  }
  if (locals.size() != static_cast<std::size_t>(skeleton->num_joints())) {
    return {base::JobStatus::kSizeMismatch, "locals must hold one transform per joint"};
  }
  return base::kJobOk;
}

base::JobStatus LocalPoseJob::Run() const {
  const base::JobStatus status = Validate();
  if (!status) return status;
  const Skeleton& s = *skeleton;
  for (std::size_t j = 0; j < static_cast<std::size_t>(s.num_joints()); ++j) {
    JointTransform& out = locals[j];
    out = {s.rest_translations[j], s.rest_rotations[j], s.rest_scales[j]};
    const JointChannels& ch = s.channels[j];
    if (ch.count == 0) continue;
    const float* v = frame_values.data() + ch.first;
    glm::vec3 position(0.0f);
    bool has_position = false;
    ChannelType euler_axes[3];
    float euler_deg[3];
    int num_euler = 0;
    glm::quat quat(1.0f, 0.0f, 0.0f, 0.0f);
    bool has_quat = false;
    for (int c = 0; c < ch.count; ++c) {
      const float x = v[c];
      switch (ch.types[static_cast<std::size_t>(c)]) {
        case ChannelType::kXPosition: position.x = x; has_position = true; break;
        case ChannelType::kYPosition: position.y = x; has_position = true; break;
        case ChannelType::kZPosition: position.z = x; has_position = true; break;
        case ChannelType::kXRotation:
        case ChannelType::kYRotation:
        case ChannelType::kZRotation:
          if (num_euler < 3) {
            euler_axes[num_euler] = ch.types[static_cast<std::size_t>(c)];
            euler_deg[num_euler] = x;
            ++num_euler;
          }
          break;
        case ChannelType::kQuatX: quat.x = x; has_quat = true; break;
        case ChannelType::kQuatY: quat.y = x; has_quat = true; break;
        case ChannelType::kQuatZ: quat.z = x; has_quat = true; break;
        case ChannelType::kQuatW: quat.w = x; has_quat = true; break;
        case ChannelType::kXScale: out.scale.x = x; break;
        case ChannelType::kYScale: out.scale.y = x; break;
        case ChannelType::kZScale: out.scale.z = x; break;
      }
    }
    if (has_position) {
      // A joint with only some position channels keeps the offset's other components.
      glm::vec3 base = s.position_mode == PositionChannelMode::kAddToOffset
                           ? s.rest_translations[j]
                           : glm::vec3(0.0f);
      glm::vec3 t = base;
      for (int c = 0; c < ch.count; ++c) {
        const ChannelType type = ch.types[static_cast<std::size_t>(c)];
        const int axis = type == ChannelType::kXPosition   ? 0
                         : type == ChannelType::kYPosition ? 1
                         : type == ChannelType::kZPosition ? 2
                                                           : -1;
        if (axis < 0) continue;
        t[axis] = base[axis] + position[axis];
      }
      if (s.position_mode == PositionChannelMode::kReplaceOffset) {
        for (int axis = 0; axis < 3; ++axis) {
          bool driven = false;
          for (int c = 0; c < ch.count; ++c) {
            const ChannelType type = ch.types[static_cast<std::size_t>(c)];
            driven |= static_cast<int>(type) == axis;  // kX/Y/ZPosition are 0, 1, 2
          }
          if (!driven) t[axis] = s.rest_translations[j][axis];
        }
      }
      out.translation = t;
    }
    if (num_euler > 0) out.rotation = s.rest_rotations[j] * EulerToQuat(euler_axes, euler_deg, num_euler);
    if (has_quat) out.rotation = glm::normalize(quat);
  }
  return base::kJobOk;
}

base::JobStatus LocalToModelJob::Validate() const {
  if (locals.size() != parents.size()) {
    return {base::JobStatus::kSizeMismatch, "locals must hold one transform per joint"};
  }
  if (model_from_joint.size() != parents.size()) {
    return {base::JobStatus::kSizeMismatch, "model_from_joint must hold one matrix per joint"};
  }
  return base::kJobOk;
}

base::JobStatus LocalToModelJob::Run() const {
  const base::JobStatus status = Validate();
  if (!status) return status;
  for (std::size_t j = 0; j < parents.size(); ++j) {
    const int p = parents[j];
    const glm::mat4& parent = p == kNoParent ? model_from_root : model_from_joint[static_cast<std::size_t>(p)];
    model_from_joint[j] = parent * locals[j].ToMatrix();
  }
  return base::kJobOk;
}

}  // namespace mocap
