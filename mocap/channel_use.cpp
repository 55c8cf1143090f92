#include "mocap/channel_use.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/glm.hpp>

namespace mocap {
namespace {

bool IsQuaternion(ChannelType t) {
  return t == ChannelType::kQuatX || t == ChannelType::kQuatY || t == ChannelType::kQuatZ ||
         t == ChannelType::kQuatW;
}

bool IsRotation(ChannelType t) {
  return IsQuaternion(t) || t == ChannelType::kXRotation || t == ChannelType::kYRotation ||
         t == ChannelType::kZRotation;
}

int PositionAxis(ChannelType t) {
  switch (t) {
    case ChannelType::kXPosition:
      return 0;
    case ChannelType::kYPosition:
      return 1;
    case ChannelType::kZPosition:
      return 2;
    default:
      return -1;
  }
}

// Largest side of the rest pose's joint bounds: a length scale that needs no
// up axis (the up axis is detected with these flags).
float RestExtent(const Skeleton& skeleton) {
  std::vector<glm::vec3> pos(skeleton.rest_translations.size());
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (std::size_t j = 0; j < pos.size(); ++j) {
    const int p = skeleton.parents[j];
    pos[j] = skeleton.rest_translations[j] + (p == kNoParent ? glm::vec3(0.0f) : pos[static_cast<std::size_t>(p)]);
    lo = glm::min(lo, pos[j]);
    hi = glm::max(hi, pos[j]);
  }
  return pos.empty() ? 0.0f : std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

}  // namespace

std::vector<std::uint8_t> ChannelUse(const Skeleton& skeleton, const Motion& motion) {
  const int nj = skeleton.num_joints();
  if (motion.num_channels != skeleton.num_channels ||
      motion.values.size() != static_cast<std::size_t>(motion.num_frames) * static_cast<std::size_t>(motion.num_channels)) {
    return {};
  }
  // Per channel, the range of its values over the motion (non-finite values
  // were refused by the readers; a NaN here would only compare false).
  std::vector<float> lo(static_cast<std::size_t>(motion.num_channels), std::numeric_limits<float>::max());
  std::vector<float> hi(static_cast<std::size_t>(motion.num_channels), std::numeric_limits<float>::lowest());
  for (int f = 0; f < motion.num_frames; ++f) {
    const std::span<const float> row = motion.frame(f);
    for (std::size_t c = 0; c < row.size(); ++c) {
      lo[c] = std::min(lo[c], row[c]);
      hi[c] = std::max(hi[c], row[c]);
    }
  }
  // A turn of 1e-3 degrees (a quaternion component moves by about 1e-5 for it)
  // is printing noise, not a rotation.
  const float still_degrees = 1e-3f;
  const float still_quat = 1e-5f;
  const float min_stretch = 0.01f * RestExtent(skeleton);
  std::vector<std::uint8_t> use(static_cast<std::size_t>(nj), 0);
  for (int j = 0; j < nj && motion.num_frames > 0; ++j) {
    const JointChannels& ch = skeleton.channels[static_cast<std::size_t>(j)];
    glm::vec3 travel(0.0f);
    std::uint8_t flags = 0;
    for (std::size_t k = 0; k < ch.count; ++k) {
      const std::size_t c = ch.first + k;
      const float range = hi[c] - lo[c];
      if (IsRotation(ch.types[k]) && range > (IsQuaternion(ch.types[k]) ? still_quat : still_degrees)) {
        flags |= kJointRotates;
      }
      if (const int a = PositionAxis(ch.types[k]); a >= 0) travel[a] = range;
    }
    const float offset = glm::length(skeleton.rest_translations[static_cast<std::size_t>(j)]);
    if (glm::length(travel) > std::max(0.25f * offset, min_stretch)) flags |= kJointStretches;
    use[static_cast<std::size_t>(j)] = flags;
  }
  return use;
}

}  // namespace mocap
