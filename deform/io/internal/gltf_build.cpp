#include "deform/io/internal/gltf_build.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <vector>

namespace deform::internal {

mocap::JointTransform DecomposeMatrix(const glm::dmat4& m, bool* dropped_shear) {
  glm::dvec3 s(glm::length(glm::dvec3(m[0])), glm::length(glm::dvec3(m[1])), glm::length(glm::dvec3(m[2])));
  if (glm::determinant(glm::dmat3(m)) < 0.0) s.x = -s.x;  // a reflection: fold it into one axis
  glm::dmat3 r(1.0);
  if (s.x != 0.0 && s.y != 0.0 && s.z != 0.0) {
    r = glm::dmat3(glm::dvec3(m[0]) / s.x, glm::dvec3(m[1]) / s.y, glm::dvec3(m[2]) / s.z);
  }
  mocap::JointTransform t;
  t.translation = glm::vec3(glm::dvec3(m[3]));
  t.rotation = glm::normalize(glm::quat(glm::quat_cast(r)));
  t.scale = glm::vec3(s);
  const glm::dmat4 back(t.ToMatrix());
  double err = 0.0;
  double magnitude = 1.0;
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      err = std::max(err, std::abs(back[c][row] - m[c][row]));
      magnitude = std::max(magnitude, std::abs(m[c][row]));
    }
  }
  *dropped_shear = err > 1e-4 * magnitude;
  return t;
}

void AssignChannelLayout(std::span<const std::array<bool, 3>> driven, mocap::Skeleton& skeleton) {
  using mocap::ChannelType;
  static constexpr ChannelType kTranslation[3] = {ChannelType::kXPosition, ChannelType::kYPosition,
                                                  ChannelType::kZPosition};
  static constexpr ChannelType kRotation[4] = {ChannelType::kQuatX, ChannelType::kQuatY, ChannelType::kQuatZ,
                                               ChannelType::kQuatW};
  static constexpr ChannelType kScale[3] = {ChannelType::kXScale, ChannelType::kYScale, ChannelType::kZScale};
  std::uint32_t next = 0;
  skeleton.channels.assign(driven.size(), {});
  for (std::size_t j = 0; j < driven.size(); ++j) {
    mocap::JointChannels& ch = skeleton.channels[j];
    ch.first = next;
    auto add = [&ch](std::span<const ChannelType> types) {
      for (ChannelType type : types) ch.types[ch.count++] = type;
    };
    if (driven[j][0]) add(kTranslation);
    if (driven[j][1]) add(kRotation);
    if (driven[j][2]) add(kScale);
    next += ch.count;
  }
  skeleton.num_channels = static_cast<int>(next);
}

int NormalizeWeightRows(std::span<float> weights, int influences) {
  int unweighted = 0;
  const auto n = static_cast<std::size_t>(influences);
  for (std::size_t row = 0; row + n <= weights.size(); row += n) {
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) sum += weights[row + k];
    if (sum <= 1e-12) {
      weights[row] = 1.0f;  // bind to the first listed joint rather than collapse to the origin
      ++unweighted;
      continue;
    }
    for (std::size_t k = 0; k < n; ++k) weights[row + k] = static_cast<float>(weights[row + k] / sum);
  }
  return unweighted;
}

float RestHeight(const mocap::Skeleton& skeleton) {
  const auto n = static_cast<std::size_t>(skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(n);
  std::vector<glm::mat4> model_from_joint(n);
  mocap::RestPose(skeleton, locals);
  if (!mocap::LocalToModelJob{
          .parents = skeleton.parents, .locals = locals, .model_from_joint = model_from_joint}
           .Run()) {
    return 0.0f;
  }
  float lo = 0.0f;
  float hi = 0.0f;
  for (std::size_t j = 0; j < n; ++j) {
    const float y = model_from_joint[j][3].y;
    lo = j == 0 ? y : std::min(lo, y);
    hi = j == 0 ? y : std::max(hi, y);
  }
  return hi - lo;
}

}  // namespace deform::internal
