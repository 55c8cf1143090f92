// Evaluation of imported glTF animations (no tinygltf here: the channels are
// our own GltfChannel keys). Interpolation follows the glTF 2.0 specification,
// appendix "Interpolation"; math in double, stored as float.

#include <algorithm>
#include <cmath>
#include <limits>

#include "deform/io/gltf_import.h"
#include "base/check.h"

namespace deform {
namespace {

// Shortest-path spherical interpolation of unit quaternions (x, y, z, w).
glm::dvec4 Slerp(glm::dvec4 a, glm::dvec4 b, double s) {
  double d = glm::dot(a, b);
  if (d < 0.0) {  // q and -q are the same rotation: take the short arc
    b = -b;
    d = -d;
  }
  if (d > 0.9995) return glm::normalize(a + s * (b - a));  // nearly parallel: lerp is exact enough
  const double theta = std::acos(d);
  const double sin_theta = std::sin(theta);
  return (std::sin((1.0 - s) * theta) / sin_theta) * a + (std::sin(s * theta) / sin_theta) * b;
}

// Value of `channel` at time t, as up to 4 doubles.
glm::dvec4 Evaluate(const GltfChannel& channel, double t) {
  const int width = channel.width();
  const std::size_t w = static_cast<std::size_t>(width);
  const bool cubic = channel.interpolation == GltfInterpolation::kCubicSpline;
  const std::size_t key_stride = cubic ? 3 * w : w;
  const std::size_t value_offset = cubic ? w : 0;  // skip the in-tangent
  auto read = [&](std::size_t key, std::size_t offset) {
    glm::dvec4 v(0.0);
    const float* p = channel.values.data() + key * key_stride + offset;
    for (std::size_t i = 0; i < w; ++i) v[static_cast<int>(i)] = p[i];
    return v;
  };
  const std::vector<float>& times = channel.times_s;
  const std::size_t n = times.size();
  // Key times are floats, and a time is placed among them as a float: a time computed
  // in double as "key k" must land on key k even where the double lies a hair below
  // the float key. Every test below uses that same float, so k1 stays inside the keys
  // (comparing the ends in double once let a time just below the last key run the
  // search past the end: found by AddressSanitizer). !(tf > front) takes NaN to key 0.
  const float tf = static_cast<float>(t);
  if (n == 1 || !(tf > times.front())) return read(0, value_offset);
  if (tf >= times.back()) return read(n - 1, value_offset);
  // First key strictly after tf: segment [k, k+1] with times[k] <= tf < times[k+1].
  const std::size_t k1 =
      static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), tf) - times.begin());
  const std::size_t k = k1 - 1;
  const double t0 = times[k];
  const double dt = static_cast<double>(times[k1]) - t0;
  if (channel.interpolation == GltfInterpolation::kStep || dt <= 0.0) return read(k, value_offset);
  const double s = std::clamp((t - t0) / dt, 0.0, 1.0);
  const bool rotation = channel.path == GltfPath::kRotation;
  if (!cubic) {
    const glm::dvec4 a = read(k, 0);
    const glm::dvec4 b = read(k1, 0);
    return rotation ? Slerp(a, b, s) : a + s * (b - a);
  }
  const double s2 = s * s;
  const double s3 = s2 * s;
  const glm::dvec4 v0 = read(k, w);      // value at k
  const glm::dvec4 b0 = read(k, 2 * w);  // out-tangent at k
  const glm::dvec4 a1 = read(k1, 0);     // in-tangent at k+1
  const glm::dvec4 v1 = read(k1, w);     // value at k+1
  glm::dvec4 p = (2 * s3 - 3 * s2 + 1) * v0 + (s3 - 2 * s2 + s) * dt * b0 + (-2 * s3 + 3 * s2) * v1 +
                 (s3 - s2) * dt * a1;
  if (rotation) {
    const double len = glm::length(p);
    p = len > 0.0 ? p / len : glm::dvec4(0.0, 0.0, 0.0, 1.0);
  }
  return p;
}

}  // namespace

void SampleGltfAnimation(const GltfModel& model, int animation, double t_s,
                         std::span<mocap::JointTransform> locals) {
  PATCHSKIN_CHECK(animation >= 0 && animation < static_cast<int>(model.animations.size()));
  PATCHSKIN_CHECK(locals.size() == static_cast<std::size_t>(model.skeleton.num_joints()));
  mocap::RestPose(model.skeleton, locals);
  for (const GltfChannel& channel : model.animations[static_cast<std::size_t>(animation)].channels) {
    const glm::dvec4 v = Evaluate(channel, t_s);
    mocap::JointTransform& out = locals[static_cast<std::size_t>(channel.joint)];
    switch (channel.path) {
      case GltfPath::kTranslation:
        out.translation = glm::vec3(glm::dvec3(v));
        break;
      case GltfPath::kScale:
        out.scale = glm::vec3(glm::dvec3(v));
        break;
      case GltfPath::kRotation:
        out.rotation = glm::normalize(glm::quat(static_cast<float>(v.w), static_cast<float>(v.x),
                                                static_cast<float>(v.y), static_cast<float>(v.z)));
        break;
    }
  }
}

double DetectFrameTime(const GltfAnimation& animation) {
  constexpr int kMaxFps = 240;
  for (int fps = 1; fps <= kMaxFps; ++fps) {
    bool on_grid = true;
    for (const GltfChannel& channel : animation.channels) {
      for (float t : channel.times_s) {
        const double frames = static_cast<double>(t) * fps;
        // Key times are floats: allow float round-off of the time, not a fraction of a frame.
        if (std::abs(frames - std::round(frames)) > 1e-3) {
          on_grid = false;
          break;
        }
      }
      if (!on_grid) break;
    }
    if (on_grid && !animation.channels.empty()) {
      // fps = 1 fits any integer-second keys; prefer a common video rate that also fits.
      for (int common : {24, 25, 30, 60}) {
        if (common % fps == 0) return 1.0 / common;
      }
      return 1.0 / fps;
    }
  }
  return 1.0 / 30.0;
}

base::Result<mocap::Motion> AnimationToMotion(const GltfModel& model, int animation,
                                              double frame_time_s) {
  using base::ErrorCode;
  const base::FileLoc loc{model.skeleton.info.source_file, 0, 0, {}};
  if (animation < 0 || animation >= static_cast<int>(model.animations.size())) {
    return base::InvalidArgument(loc, "animation " + std::to_string(animation) +
                                          " requested, the model has " +
                                          std::to_string(model.animations.size()));
  }
  const GltfAnimation& anim = model.animations[static_cast<std::size_t>(animation)];
  if (!std::isfinite(frame_time_s)) {
    return base::InvalidArgument(loc, "frame time must be finite");
  }
  if (frame_time_s <= 0.0) frame_time_s = DetectFrameTime(anim);
  const double intervals = anim.duration_s / frame_time_s;
  constexpr double kMaxFrames = 1e7;
  if (intervals > kMaxFrames) {
    return base::MakeError(ErrorCode::kLimitExceeded, loc,
                           "sampling " + std::to_string(anim.duration_s) + " s every " +
                               std::to_string(frame_time_s) + " s needs more than 10^7 frames");
  }
  const int num_frames = static_cast<int>(std::ceil(intervals * (1.0 - 1e-6))) + 1;

  const mocap::Skeleton& sk = model.skeleton;
  mocap::Motion motion;
  motion.num_frames = num_frames;
  motion.num_channels = sk.num_channels;
  motion.frame_time_s = frame_time_s;
  motion.values.resize(static_cast<std::size_t>(num_frames) * static_cast<std::size_t>(sk.num_channels));
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(sk.num_joints()));
  for (int f = 0; f < num_frames; ++f) {
    const double t = std::min(f * frame_time_s, anim.duration_s);
    SampleGltfAnimation(model, animation, t, locals);
    std::span<float> row = motion.frame(f);
    for (std::size_t j = 0; j < locals.size(); ++j) {
      const mocap::JointChannels& ch = sk.channels[j];
      const mocap::JointTransform& l = locals[j];
      for (std::size_t c = 0; c < ch.count; ++c) {
        float value = 0.0f;
        switch (ch.types[c]) {
          case mocap::ChannelType::kXPosition:
            value = l.translation.x;
            break;
          case mocap::ChannelType::kYPosition:
            value = l.translation.y;
            break;
          case mocap::ChannelType::kZPosition:
            value = l.translation.z;
            break;
          case mocap::ChannelType::kQuatX:
            value = l.rotation.x;
            break;
          case mocap::ChannelType::kQuatY:
            value = l.rotation.y;
            break;
          case mocap::ChannelType::kQuatZ:
            value = l.rotation.z;
            break;
          case mocap::ChannelType::kQuatW:
            value = l.rotation.w;
            break;
          case mocap::ChannelType::kXScale:
            value = l.scale.x;
            break;
          case mocap::ChannelType::kYScale:
            value = l.scale.y;
            break;
          case mocap::ChannelType::kZScale:
            value = l.scale.z;
            break;
          default:
            break;  // Euler channels never appear in an imported glTF skeleton
        }
        row[ch.first + c] = value;
      }
    }
  }
  return motion;
}

}  // namespace deform
