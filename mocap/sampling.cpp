#include "mocap/sampling.h"

#include <cmath>
#include <string>
#include <vector>

#include "mocap/joint_angles.h"

namespace mocap {

glm::quat SlerpShortest(const glm::quat& q0, const glm::quat& q1, float w) {
  const glm::dquat a(q0.w, q0.x, q0.y, q0.z);
  glm::dquat b(q1.w, q1.x, q1.y, q1.z);
  double cos_angle = glm::dot(a, b);
  glm::quat q1_near = q1;
  if (cos_angle < 0.0) {  // shorter arc
    b = -b;
    cos_angle = -cos_angle;
    q1_near = -q1;
  }
  if (w <= 0.0f) return q0;
  if (w >= 1.0f) return q1_near;
  const double wd = w;
  if (cos_angle > 1.0 - 1e-12) {  // nearly equal: sin(angle) ~ 0, lerp is exact enough
    return glm::quat(glm::normalize(a * (1.0 - wd) + b * wd));
  }
  const double angle = std::acos(std::min(cos_angle, 1.0));
  const double s = std::sin(angle);
  const glm::dquat r = a * (std::sin((1.0 - wd) * angle) / s) + b * (std::sin(wd * angle) / s);
  return glm::quat(glm::normalize(r));
}

FrameBlend FindFrameBlend(int num_frames, double frame_time_s, double time_s) {
  if (num_frames <= 1 || !(frame_time_s > 0.0) || !std::isfinite(time_s) || time_s <= 0.0) {
    return {};
  }
  const double last = num_frames - 1;
  const double f = time_s / frame_time_s;
  if (f >= last) return {num_frames - 1, num_frames - 1, 0.0f};
  // 0 < f < #F - 1 < 2^31: truncation is floor, f - base is exact (base = 0, or
  // f < 2 base), and round (half away from zero) is base or base + 1; no
  // library calls to floor and round (SSE2 has no rounding instruction), which
  // matters to the elastic layer's sampler (every RK4 stage time).
  const double base = static_cast<double>(static_cast<int>(f));
  const double fraction = f - base;
  const double nearest = fraction >= 0.5 ? base + 1.0 : base;
  if (std::abs(f - nearest) <= 1e-9 * std::max(1.0, nearest)) {  // on a frame: exact
    const int k = static_cast<int>(nearest);
    return {k, k, 0.0f};
  }
  const int k = static_cast<int>(base);
  return {k, k + 1, static_cast<float>(fraction)};
}

base::JobStatus SampleLocalsJob::Validate() const {
  if (skeleton == nullptr || motion == nullptr) {
    return {base::JobStatus::kMissingInput, "skeleton and motion are required"};
  }
  if (motion->num_frames < 1) return {base::JobStatus::kMissingInput, "motion has no frames"};
  if (motion->num_channels != skeleton->num_channels) {
    return {base::JobStatus::kSizeMismatch, "motion and skeleton have different channel counts"};
  }
  const std::size_t num_joints = static_cast<std::size_t>(skeleton->num_joints());
  if (locals.size() != num_joints || scratch.size() != num_joints) {
    return {base::JobStatus::kSizeMismatch, "locals and scratch must hold one transform per joint"};
  }
  if (!(motion->frame_time_s > 0.0)) {
    return {base::JobStatus::kOutOfRange, "motion frame_time_s must be positive"};
  }
  if (motion->values.size() < static_cast<std::size_t>(motion->num_frames) *
                                  static_cast<std::size_t>(motion->num_channels)) {
    return {base::JobStatus::kOutOfRange, "motion values hold fewer than num_frames rows"};
  }
  return base::kJobOk;
}

base::JobStatus SampleLocalsJob::Run() const {
  const base::JobStatus status = Validate();
  if (!status) return status;
  const FrameBlend blend = FindFrameBlend(motion->num_frames, motion->frame_time_s, time_s);
  const base::JobStatus first =
      LocalPoseJob{
          .skeleton = skeleton, .frame_values = motion->frame(blend.frame0), .locals = locals}
          .Run();
  if (!first || blend.frame1 == blend.frame0) return first;
  const base::JobStatus second =
      LocalPoseJob{
          .skeleton = skeleton, .frame_values = motion->frame(blend.frame1), .locals = scratch}
          .Run();
  if (!second) return second;
  const float w = blend.weight;
  for (std::size_t j = 0; j < locals.size(); ++j) {
    JointTransform& a = locals[j];
    const JointTransform& b = scratch[j];
    a.translation = a.translation + w * (b.translation - a.translation);
    a.rotation = SlerpShortest(a.rotation, b.rotation, w);
    a.scale = a.scale + w * (b.scale - a.scale);
  }
  return base::kJobOk;
}

namespace {

// Writes the channels of joint j for `local` into `row`, continuing `reference`
// (the previous row, same layout) for Euler angles and quaternion signs.
void WriteJointChannels(const Skeleton& s, std::size_t j, const JointTransform& local,
                        std::span<const float> reference, std::span<float> row) {
  const JointChannels& ch = s.channels[j];
  ChannelType euler_axes[3];
  std::uint32_t euler_index[3];
  int num_euler = 0;
  int quat_index[4] = {-1, -1, -1, -1};  // x, y, z, w channel positions
  for (int c = 0; c < ch.count; ++c) {
    const std::uint32_t index = ch.first + static_cast<std::uint32_t>(c);
    const ChannelType type = ch.types[static_cast<std::size_t>(c)];
    switch (type) {
      case ChannelType::kXPosition:
      case ChannelType::kYPosition:
      case ChannelType::kZPosition: {
        const int axis = static_cast<int>(type);  // kX/Y/ZPosition are 0, 1, 2
        float value = local.translation[axis];
        if (s.position_mode == PositionChannelMode::kAddToOffset)
          value -= s.rest_translations[j][axis];
        row[index] = value;
        break;
      }
      case ChannelType::kXRotation:
      case ChannelType::kYRotation:
      case ChannelType::kZRotation:
        if (num_euler < 3) {
          euler_axes[num_euler] = type;
          euler_index[num_euler] = index;
          ++num_euler;
        }
        break;
      case ChannelType::kQuatX:
        quat_index[0] = static_cast<int>(index);
        break;
      case ChannelType::kQuatY:
        quat_index[1] = static_cast<int>(index);
        break;
      case ChannelType::kQuatZ:
        quat_index[2] = static_cast<int>(index);
        break;
      case ChannelType::kQuatW:
        quat_index[3] = static_cast<int>(index);
        break;
      case ChannelType::kXScale:
        row[index] = local.scale.x;
        break;
      case ChannelType::kYScale:
        row[index] = local.scale.y;
        break;
      case ChannelType::kZScale:
        row[index] = local.scale.z;
        break;
    }
  }
  if (num_euler > 0) {
    // LocalPoseJob builds rotation = rest_rotation * Euler.
    const glm::quat euler = glm::conjugate(s.rest_rotations[j]) * local.rotation;
    float previous[3] = {0.0f, 0.0f, 0.0f};
    float angles[3] = {0.0f, 0.0f, 0.0f};
    for (int i = 0; i < num_euler; ++i) previous[i] = reference[euler_index[i]];
    QuatToEulerNear(euler, euler_axes, num_euler, previous, angles);
    for (int i = 0; i < num_euler; ++i) row[euler_index[i]] = angles[i];
  }
  if (quat_index[0] >= 0 || quat_index[1] >= 0 || quat_index[2] >= 0 || quat_index[3] >= 0) {
    const float q[4] = {local.rotation.x, local.rotation.y, local.rotation.z, local.rotation.w};
    float dot = 0.0f;
    for (int i = 0; i < 4; ++i) {
      if (quat_index[i] >= 0) dot += q[i] * reference[static_cast<std::size_t>(quat_index[i])];
    }
    const float sign = dot < 0.0f ? -1.0f : 1.0f;
    for (int i = 0; i < 4; ++i) {
      if (quat_index[i] >= 0) row[static_cast<std::size_t>(quat_index[i])] = sign * q[i];
    }
  }
}

}  // namespace

base::Result<Motion> Resample(const Skeleton& skeleton, const Motion& motion,
                              double new_frame_time_s) {
  const base::FileLoc loc{skeleton.info.source_file, 0, 0, {}};
  if (!std::isfinite(new_frame_time_s) || new_frame_time_s <= 0.0) {
    return base::InvalidArgument(
        loc, "expected a positive finite frame time, found " + std::to_string(new_frame_time_s));
  }
  if (motion.num_channels != skeleton.num_channels || motion.num_frames < 1 ||
      motion.values.size() != static_cast<std::size_t>(motion.num_frames) *
                                  static_cast<std::size_t>(motion.num_channels) ||
      !(motion.frame_time_s > 0.0)) {
    return base::InvalidArgument(loc, "expected a motion with frames, a positive frame time and " +
                                          std::to_string(skeleton.num_channels) +
                                          " channels per frame, found " +
                                          std::to_string(motion.num_frames) + " frames of " +
                                          std::to_string(motion.num_channels) + " channels");
  }
  const base::Status check = skeleton.Check();
  if (!check) return check.error();
  const double steps = std::floor(motion.duration_s() / new_frame_time_s + 1e-9);
  if (!(steps + 1.0 <= static_cast<double>(kMaxResampledFrames))) {
    return base::MakeError(
        base::ErrorCode::kLimitExceeded, loc,
        "resampling would produce more than " + std::to_string(kMaxResampledFrames) + " frames");
  }
  Motion out;
  out.num_frames = static_cast<int>(steps) + 1;
  out.num_channels = motion.num_channels;
  out.frame_time_s = new_frame_time_s;
  out.values.assign(
      static_cast<std::size_t>(out.num_frames) * static_cast<std::size_t>(out.num_channels), 0.0f);
  const std::size_t num_joints = static_cast<std::size_t>(skeleton.num_joints());
  std::vector<JointTransform> locals(num_joints);
  std::vector<JointTransform> scratch(num_joints);
  for (int f = 0; f < out.num_frames; ++f) {
    const base::JobStatus status = SampleLocalsJob{.skeleton = &skeleton,
                                                   .motion = &motion,
                                                   .time_s = f * new_frame_time_s,
                                                   .scratch = scratch,
                                                   .locals = locals}
                                       .Run();
    if (!status) return base::MakeError(base::ErrorCode::kInternal, loc, status.what);
    const std::span<const float> reference =
        f == 0 ? motion.frame(0) : std::span<const float>(out.frame(f - 1));
    for (std::size_t j = 0; j < num_joints; ++j) {
      WriteJointChannels(skeleton, j, locals[j], reference, out.frame(f));
    }
  }
  return out;
}

}  // namespace mocap
