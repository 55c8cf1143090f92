#include "render/camera_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "base/check.h"

namespace render {
namespace {

// The direction the camera looks along: from the eye at `azimuth_deg` about +Y
// (0 = the body's front, +Z) and `elevation_deg` above the horizontal.
glm::vec3 ViewDirection(const CameraSettings& s) {
  const float elevation = glm::radians(s.elevation_deg);
  if (!s.azimuth_deg) {
    // Seen from the character's front-left, slightly above (characters face +Z).
    return -glm::normalize(glm::vec3(0.45f, 0.0f, 1.0f) * std::cos(elevation) +
                           glm::vec3(0.0f, std::sin(elevation), 0.0f));
  }
  const float azimuth = glm::radians(*s.azimuth_deg);
  return -glm::vec3(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                    std::cos(azimuth) * std::cos(elevation));
}

// Moves the eye of a framed camera to the settings' distance and zoom (the
// target stays), near and far following it. Without either it is left as framed.
void ApplyDistance(const CameraSettings& s, float body_extent, Camera& c) {
  if (s.distance <= 0.0f && s.zoom == 1.0f) return;
  const glm::vec3 offset = c.eye - c.target;
  const float framed = glm::length(offset);
  const float distance = (s.distance > 0.0f ? s.distance : framed) / s.zoom;
  c.eye = c.target + offset * (distance / framed);
  c.near_plane = std::max(distance * 0.02f, 1e-3f);
  c.far_plane = distance + 4.0f * body_extent;
}

// Close to a part of the body the rest of it may lie between the eye and the
// part's box, so near may not stop at the box.
void NearAndFarForAPart(float body_extent, Camera& c) {
  const float d = glm::length(c.eye - c.target);
  c.near_plane = std::max(d * 0.02f, 1e-3f);
  c.far_plane = d + 4.0f * body_extent;
}

// Largest |x| or |y| in normalised device coordinates of the corners of `box`.
float ProjectedExtent(const deform::Bounds& box, const Camera& camera) {
  const glm::mat4 clip_from_world = camera.ClipFromView() * camera.ViewFromWorld();
  float worst = 0.0f;
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 p((k & 1) ? box.max.x : box.min.x, (k & 2) ? box.max.y : box.min.y,
                      (k & 4) ? box.max.z : box.min.z);
    const glm::vec4 c = clip_from_world * glm::vec4(p, 1.0f);
    if (!(c.w > 0.0f)) return std::numeric_limits<float>::infinity();
    worst = std::max({worst, std::abs(c.x / c.w), std::abs(c.y / c.w)});
  }
  return worst;
}

base::Error SettingError(const std::string& message) {
  return base::InvalidArgument("camera: " + message);
}

std::optional<base::Error> CheckSettings(const CameraSettings& s, const CameraTimes& t) {
  if (s.azimuth_deg && !(std::abs(*s.azimuth_deg) <= 3600.0f)) {
    return SettingError("expected an azimuth in -3600..3600 degrees");
  }
  if (!(s.distance >= 0.0f) || !std::isfinite(s.distance)) {
    return SettingError("expected a finite distance >= 0");
  }
  if (!(s.zoom > 0.0f) || !(s.zoom <= 1000.0f)) return SettingError("expected a zoom in (0, 1000]");
  if (!(std::abs(s.elevation_deg) <= kMaxElevationDeg)) {
    return SettingError("expected an elevation in -89..89 degrees");
  }
  if (s.size.x < 1 || s.size.y < 1) return SettingError("expected an image of at least 1x1");
  if (!(t.frame_time_s > 0.0) || t.motion_frames < 1 || t.turntable_views < 1) {
    return SettingError("expected a frame time > 0 and at least one frame and view");
  }
  return std::nullopt;
}

}  // namespace

base::Result<CameraPlan> CameraPlan::Create(BodySampler sampler, const CameraSettings& settings,
                                            const CameraTimes& times) {
  if (std::optional<base::Error> e = CheckSettings(settings, times)) return *e;
  CameraPlan cp;
  cp.mode_ = settings.mode;
  cp.whole_body_ = settings.aim == CameraAim::kBody;
  cp.sampler_ = std::move(sampler);
  cp.frame_time_s_ = times.frame_time_s;
  // Framing: frames spread evenly over the whole motion, both ends included,
  // the same whatever frames are asked for later.
  BodySample sample;
  deform::Bounds all_bounds;
  glm::vec3 largest_extent(0.0f), region_extent(0.0f);
  float ground_y = std::numeric_limits<float>::max();
  const std::int64_t last = times.motion_frames - 1;
  const std::int64_t samples = std::min<std::int64_t>(kFramingSamples, last + 1);
  std::vector<glm::vec3> look_points;
  for (std::int64_t i = 0; i < samples; ++i) {
    const std::int64_t f = samples > 1 ? last * i / (samples - 1) : 0;
    if (base::Status s = cp.sampler_(static_cast<double>(f) * times.frame_time_s, sample); !s.ok())
      return s.error();
    all_bounds.Extend(sample.bounds.min);
    all_bounds.Extend(sample.bounds.max);
    largest_extent = glm::max(largest_extent, sample.bounds.size());
    ground_y = std::min(ground_y, sample.bounds.min.y);
    look_points.push_back(sample.look_point);
    if (!sample.look_bounds.empty()) {
      region_extent = glm::max(region_extent, sample.look_bounds.size());
    }
  }
  // The box framed around the followed point: the whole body, or the aimed-at
  // neighbourhood (a joint: a third of the body's largest extent; a region:
  // its own extent and as much again around it).
  const float body_extent = std::max({largest_extent.x, largest_extent.y, largest_extent.z});
  const glm::vec3 half_box = settings.aim == CameraAim::kBody    ? 0.5f * largest_extent
                             : settings.aim == CameraAim::kJoint ? glm::vec3(body_extent / 6.0f)
                                                                 : region_extent;
  const auto box_around = [&](std::span<const glm::vec3> points) {
    deform::Bounds box;
    for (const glm::vec3& p : points) {
      box.Extend(p - half_box);
      box.Extend(p + half_box);
    }
    return box;
  };
  cp.ground_y_ = ground_y;
  const float aspect = static_cast<float>(settings.size.x) / static_cast<float>(settings.size.y);
  const glm::vec3 view_dir = ViewDirection(settings);
  const bool part = !cp.whole_body_;
  if (settings.mode == CameraMode::kTurntable) {
    if (base::Status s = cp.sampler_(times.turntable_time_s, sample); !s.ok()) return s.error();
    const deform::Bounds box =
        part ? box_around(std::span<const glm::vec3>(&sample.look_point, 1)) : sample.bounds;
    Camera framed = FrameBounds(box, kFovYDeg, aspect, view_dir);
    ApplyDistance(settings, body_extent, framed);
    cp.turntable_ = TurntablePath(box.center(), glm::length(framed.eye - framed.target),
                                  settings.elevation_deg, times.turntable_views);
    for (Camera& c : cp.turntable_) {
      c.fov_y_deg = kFovYDeg;
      c.aspect = aspect;
      if (part || settings.distance > 0.0f || settings.zoom != 1.0f) {
        c.near_plane = framed.near_plane;
        c.far_plane = framed.far_plane;
      }
    }
  } else if (settings.mode == CameraMode::kFixed) {
    cp.fixed_ =
        FrameBounds(part ? box_around(look_points) : all_bounds, kFovYDeg, aspect, view_dir);
    if (part) NearAndFarForAPart(body_extent, cp.fixed_);
    ApplyDistance(settings, body_extent, cp.fixed_);
  } else {
    deform::Bounds typical;
    typical.Extend(-half_box);
    typical.Extend(half_box);
    Camera framed = FrameBounds(typical, kFovYDeg, aspect, view_dir);
    if (part) NearAndFarForAPart(body_extent, framed);
    ApplyDistance(settings, body_extent, framed);
    FollowCamera& follow = cp.follow_;
    follow.offset = framed.eye - framed.target;
    follow.fov_y_deg = kFovYDeg;
    follow.aspect = aspect;
    follow.near_plane = framed.near_plane;
    follow.far_plane = framed.far_plane * 4.0f;
    follow.frame_time_s = static_cast<float>(times.frame_time_s);
    cp.centres_.reserve(static_cast<std::size_t>(follow.window_frames) + 1);
  }
  return cp;
}

void CameraPlan::KeepInFrame(const deform::Bounds& box, Camera& camera) const {
  if (box.empty() || ProjectedExtent(box, camera) <= kFollowFrameLimit) return;
  // Slide target and eye together toward the box's centre: the least pull s
  // in [0, 1] that brings the box inside the limit (bisection; s = 1 centres it).
  const glm::vec3 offset = camera.eye - camera.target;
  const glm::vec3 lagging = camera.target;
  const glm::vec3 centre = box.center();
  const auto at = [&](float s) {
    Camera c = camera;
    c.target = lagging + s * (centre - lagging);
    c.eye = c.target + offset;
    return c;
  };
  float lo = 0.0f, hi = 1.0f;
  for (int i = 0; i < 20; ++i) {
    const float mid = 0.5f * (lo + hi);
    (ProjectedExtent(box, at(mid)) <= kFollowFrameLimit ? hi : lo) = mid;
  }
  camera = at(hi);
}

Camera CameraPlan::At(int frame) const {
  if (mode_ == CameraMode::kTurntable) return turntable_[static_cast<std::size_t>(frame)];
  if (mode_ == CameraMode::kFixed) return fixed_;
  // The window of look points frame - window .. frame: keep what is already
  // sampled, drop what fell out, sample the rest in ascending order.
  const int first = std::max(0, frame - std::max(follow_.window_frames, 0));
  const int cached_end = centre_base_ + static_cast<int>(centres_.size());
  if (first < centre_base_ || first > cached_end) {
    centres_.clear();
    boxes_.clear();
    centre_base_ = first;
  } else if (first > centre_base_) {
    centres_.erase(centres_.begin(), centres_.begin() + (first - centre_base_));
    boxes_.erase(boxes_.begin(), boxes_.begin() + (first - centre_base_));
    centre_base_ = first;
  }
  BodySample sample;
  for (int g = centre_base_ + static_cast<int>(centres_.size()); g <= frame; ++g) {
    // The sampler succeeded on the same body in Create; it fails only on sizes.
    const base::Status s = sampler_(g * frame_time_s_, sample);
    PATCHSKIN_CHECK(s.ok());
    centres_.push_back(sample.look_point);
    boxes_.push_back(sample.bounds);
  }
  Camera camera = follow_.At(centres_, frame - centre_base_);
  // A camera aimed at a joint or a region frames that close up on purpose.
  if (whole_body_) KeepInFrame(boxes_[static_cast<std::size_t>(frame - centre_base_)], camera);
  return camera;
}

}  // namespace render
