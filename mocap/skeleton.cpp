#include "mocap/skeleton.h"

#include <cmath>

#include "mocap/motion.h"

namespace mocap {

const char* ChannelTypeName(ChannelType type) {
  switch (type) {
    case ChannelType::kXPosition: return "Xposition";
    case ChannelType::kYPosition: return "Yposition";
    case ChannelType::kZPosition: return "Zposition";
    case ChannelType::kXRotation: return "Xrotation";
    case ChannelType::kYRotation: return "Yrotation";
    case ChannelType::kZRotation: return "Zrotation";
    case ChannelType::kQuatX: return "Xquaternion";
    case ChannelType::kQuatY: return "Yquaternion";
    case ChannelType::kQuatZ: return "Zquaternion";
    case ChannelType::kQuatW: return "Wquaternion";
    case ChannelType::kXScale: return "Xscale";
    case ChannelType::kYScale: return "Yscale";
    case ChannelType::kZScale: return "Zscale";
  }
  return "unknown";
}

int Skeleton::FindJoint(std::string_view name) const {
  for (int j = 0; j < num_joints(); ++j) {
    if (names[static_cast<std::size_t>(j)] == name) return j;
  }
  return -1;
}

base::Status Skeleton::Check() const {
  const std::size_t n = parents.size();
  base::FileLoc loc{info.source_file, 0, 0, {}};
  if (n > static_cast<std::size_t>(kMaxJoints)) {
    return base::MakeError(base::ErrorCode::kLimitExceeded, loc,
                           "skeleton has " + std::to_string(n) +
                               " joints, more than the limit of " + std::to_string(kMaxJoints));
  }
  if (names.size() != n || rest_translations.size() != n || rest_rotations.size() != n ||
      rest_scales.size() != n || channels.size() != n ||
      (!channel_use.empty() && channel_use.size() != n)) {
    return base::MakeError(base::ErrorCode::kInternal, loc, "skeleton arrays have different sizes");
  }
  int expected_first = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const int p = parents[j];
    if (p != kNoParent && (p < 0 || p >= static_cast<int>(j))) {
      return base::MakeError(base::ErrorCode::kInternal, loc,
                             "joint '" + names[j] + "' does not come after its parent");
    }
    const JointChannels& c = channels[j];
    if (c.count > kMaxChannelsPerJoint) {
      return base::MakeError(base::ErrorCode::kInternal, loc,
                             "joint '" + names[j] + "' has too many channels");
    }
    if (c.count > 0) {
      if (static_cast<int>(c.first) != expected_first) {
        return base::MakeError(base::ErrorCode::kInternal, loc,
                               "channels of joint '" + names[j] + "' are not contiguous");
      }
      expected_first += c.count;
    }
  }
  if (expected_first != num_channels) {
    return base::MakeError(base::ErrorCode::kInternal, loc,
                           "channel count does not match the joints'");
  }
  for (const EndSite& e : end_sites) {
    if (e.parent < 0 || e.parent >= static_cast<int>(n)) {
      return base::MakeError(base::ErrorCode::kInternal, loc, "end site with an invalid parent");
    }
  }
  return base::Status::Ok();
}

double NominalFps(double frame_time_s) {
  if (!(frame_time_s > 0.0)) return 0.0;
  const double fps = 1.0 / frame_time_s;
  const double rounded = std::round(fps);
  if (rounded >= 1.0 && std::abs(fps - rounded) <= 1e-3 * rounded) return rounded;
  return fps;
}

}  // namespace mocap
