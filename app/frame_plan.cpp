#include "app/frame_plan.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "base/check.h"

namespace app {

constexpr int kMaxImageSide = 16384;

base::Error ArgError(const std::string& option, const std::string& message) {
  return base::MakeError(base::ErrorCode::kInvalidArgument, {option, 0, 0, {}}, message);
}

std::optional<base::Error> CheckThreads(int threads) {
  if (threads < 0 || threads > 256) return ArgError("--threads", "expected 0..256");
  return std::nullopt;
}

std::optional<base::Error> CheckFps(double fps) {
  if (!(fps >= 0.0) || fps > 10000.0) return ArgError("--fps", "expected 0 < fps <= 10000");
  return std::nullopt;
}

base::Result<glm::ivec2> ParseSize(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra)) {
    return ArgError("--size", "expected WIDTHxHEIGHT such as 1280x720, found '" + text + "'");
  }
  if (w < 16 || h < 16 || w > kMaxImageSide || h > kMaxImageSide) {
    return ArgError("--size", "width and height must be within 16.." + std::to_string(kMaxImageSide) +
                                  ", found " + text);
  }
  return glm::ivec2(w, h);
}

base::Result<std::optional<mocap::UpAxis>> ParseUpAxis(const std::string& text) {
  if (text.empty()) return std::optional<mocap::UpAxis>();
  if (text == "y" || text == "Y") return std::optional<mocap::UpAxis>(mocap::UpAxis::kY);
  if (text == "z" || text == "Z") return std::optional<mocap::UpAxis>(mocap::UpAxis::kZ);
  return ArgError("--up", "expected y or z, found '" + text + "'");
}

base::Result<FrameRange> ParseFrames(const std::string& text, int num_frames) {
  FrameRange r{0, num_frames - 1, 1};
  if (text.empty()) return r;
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string part; std::getline(ss, part, ':');) parts.push_back(part);
  if (parts.empty() || parts.size() > 3) {
    return ArgError("--frames", "expected A:B or A:B:STEP, found '" + text + "'");
  }
  auto parse_int = [&](const std::string& s, int fallback) -> std::optional<int> {
    if (s.empty()) return fallback;
    std::size_t used = 0;
    try {
      const long v = std::stol(s, &used);
      if (used != s.size() || v < INT32_MIN || v > INT32_MAX) return std::nullopt;
      return static_cast<int>(v);
    } catch (...) {
      return std::nullopt;
    }
  };
  const auto a = parse_int(parts[0], 0);
  const auto b = parse_int(parts.size() > 1 ? parts[1] : parts[0], num_frames - 1);
  const auto c = parse_int(parts.size() > 2 ? parts[2] : "", 1);
  if (!a || !b || !c) return ArgError("--frames", "expected whole numbers in '" + text + "'");
  r = {*a, *b, *c};
  if (r.step < 1) return ArgError("--frames", "STEP must be at least 1, found " + std::to_string(r.step));
  if (r.first < 0 || r.last < r.first || r.last >= num_frames) {
    return ArgError("--frames", "range " + text + " is outside the motion's frames 0.." +
                                    std::to_string(num_frames - 1) + " (A <= B, both inclusive)");
  }
  return r;
}

base::Result<FramePlan> PlanFrames(const mocap::Motion& motion, const FramePlanOptions& o) {
  FramePlan plan;
  plan.frame_time_s = o.fps > 0.0 ? 1.0 / o.fps
                                  : (motion.frame_time_s > 0 ? motion.frame_time_s : 1.0 / 30.0);
  plan.motion_frames =
      motion.num_frames > 0
          ? static_cast<int>(std::floor(motion.duration_s() / plan.frame_time_s + 1e-9)) + 1
          : 1;
  base::Result<FrameRange> range = ParseFrames(o.frames, plan.motion_frames);
  if (!range.ok()) return range.error();
  plan.range = *range;
  plan.turntable = o.turntable;
  plan.turntable_frames = o.turntable ? o.turntable_frames : 0;
  if (o.start_number < 0 || o.start_number > kMaxStartNumber) {
    return ArgError("--start-number", "expected 0.." + std::to_string(kMaxStartNumber) +
                                          ", found " + std::to_string(o.start_number));
  }
  plan.start_number = o.start_number;
  if (o.list_frames) {
    const std::size_t n = plan.count();
    plan.frames.reserve(n);
    for (std::size_t i = 0; i < n; ++i) plan.frames.push_back(plan.At(i));
  }
  return plan;
}

std::size_t FramePlan::count() const {
  if (turntable) return static_cast<std::size_t>(std::max(turntable_frames, 0));
  if (range.last < range.first || range.step < 1) return 0;
  return static_cast<std::size_t>((std::int64_t{range.last} - range.first) / range.step) + 1;
}

OutputFrame FramePlan::At(std::size_t i) const {
  if (turntable) {
    const int k = static_cast<int>(i);
    return {start_number + k, range.first * frame_time_s, k};
  }
  const int f = static_cast<int>(range.first + static_cast<std::int64_t>(i) * range.step);
  return {start_number + f, f * frame_time_s, f};
}

base::Result<CameraPlan> CameraPlan::Create(deform::FramePipeline& pipeline, const FramePlan& plan,
                                            const std::string& mode, float elevation_deg,
                                            glm::ivec2 size) {
  CameraSpec spec;
  spec.mode = mode;
  spec.elevation_deg = elevation_deg;
  return Create(pipeline, plan, spec, size);
}

glm::vec3 CameraPlan::LookPoint(const deform::DeformedFrame& f) const {
  if (look_joint_ >= 0) return f.joint_positions[static_cast<std::size_t>(look_joint_)];
  if (look_region_.empty()) return f.bounds.center();
  glm::dvec3 sum(0.0);
  for (const int v : look_region_) sum += glm::dvec3(f.positions[static_cast<std::size_t>(v)]);
  return glm::vec3(sum / static_cast<double>(look_region_.size()));
}

namespace {

// The direction the camera looks along: from the eye at `azimuth_deg` about +Y
// (0 = the body's front, +Z) and `elevation_deg` above the horizontal.
glm::vec3 ViewDirection(const CameraSpec& spec) {
  const float elevation = glm::radians(spec.elevation_deg);
  if (!spec.azimuth_deg) {
    // Seen from the character's front-left, slightly above (characters face +Z).
    return -glm::normalize(glm::vec3(0.45f, 0.0f, 1.0f) * std::cos(elevation) +
                           glm::vec3(0.0f, std::sin(elevation), 0.0f));
  }
  const float azimuth = glm::radians(*spec.azimuth_deg);
  return -glm::vec3(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                    std::cos(azimuth) * std::cos(elevation));
}

// Moves the eye of a framed camera to `spec`'s distance and zoom (the target
// stays), near and far following it. Without either it is left as framed.
void ApplyDistance(const CameraSpec& spec, float body_extent, render::Camera& c) {
  if (spec.distance <= 0.0f && spec.zoom == 1.0f) return;
  const glm::vec3 offset = c.eye - c.target;
  const float framed = glm::length(offset);
  const float distance = (spec.distance > 0.0f ? spec.distance : framed) / spec.zoom;
  c.eye = c.target + offset * (distance / framed);
  c.near_plane = std::max(distance * 0.02f, 1e-3f);
  c.far_plane = distance + 4.0f * body_extent;
}

}  // namespace

base::Result<CameraPlan> CameraPlan::Create(deform::FramePipeline& pipeline, const FramePlan& plan,
                                            const CameraSpec& spec, glm::ivec2 size) {
  const std::string& mode = spec.mode;
  const float elevation_deg = spec.elevation_deg;
  if (spec.azimuth_deg && !(std::abs(*spec.azimuth_deg) <= 3600.0f)) {
    return ArgError("--azimuth", "expected finite degrees in -3600..3600");
  }
  if (!(spec.distance >= 0.0f) || !std::isfinite(spec.distance)) {
    return ArgError("--distance", "expected a finite distance >= 0 (0: framed)");
  }
  if (!(spec.zoom > 0.0f) || !(spec.zoom <= 1000.0f)) {
    return ArgError("--zoom", "expected a factor in (0, 1000]");
  }
  const deform::Character& character = pipeline.character();
  if (spec.look_joint >= character.skeleton.num_joints()) {
    return ArgError("--look-at", "joint index out of range");
  }
  for (const int v : spec.look_region) {
    if (v < 0 || v >= character.mesh.bind.num_vertices()) {
      return ArgError("--look-at", "region vertex out of range");
    }
  }
  if (mode != "follow" && mode != "fixed" && mode != "turntable") {
    return ArgError("--camera", "expected follow, fixed or turntable, found '" + mode + "'");
  }
  if (plan.count() == 0) return ArgError("--frames", "no frames to frame");
  // At +-90 degrees the view looks straight along the up vector (a degenerate
  // look-at); NaN would reach the rasterizer's float-to-int conversions.
  if (!(std::abs(elevation_deg) <= kMaxElevationDeg)) {
    std::ostringstream found;
    found << elevation_deg;
    return ArgError("--elevation", "expected degrees in -89..89, found " + found.str());
  }
  CameraPlan cp;
  cp.mode_ = mode;
  cp.look_joint_ = spec.look_joint;
  cp.look_region_ = spec.look_region;
  const bool look = spec.look_joint >= 0 || !spec.look_region.empty();
  cp.frame_time_s_ = plan.frame_time_s;
  base::Result<deform::FramePipeline> tracker = deform::FramePipeline::Create(
      pipeline.character(), deform::GlobalMethod::kSsd, pipeline.threads());
  if (!tracker.ok()) return std::move(tracker).error();
  cp.tracker_ = std::make_unique<deform::FramePipeline>(std::move(*tracker));
  // Framing: output frames spread evenly over the whole motion, both ends
  // included, the same whatever --frames asks for.
  deform::DeformedFrame& frame = cp.scratch_;
  deform::Bounds all_bounds;
  glm::vec3 largest_extent(0.0f);
  float ground_y = 1e30f;
  // Look-at: the followed point of every sample and the region's largest extent.
  std::vector<glm::vec3> look_points;
  glm::vec3 region_extent(0.0f);
  const std::int64_t last = std::max(0, plan.motion_frames - 1);
  const std::int64_t samples = std::min<std::int64_t>(kFramingSamples, last + 1);
  for (std::int64_t i = 0; i < samples; ++i) {
    const std::int64_t f = samples > 1 ? last * i / (samples - 1) : 0;
    const base::Status s = cp.tracker_->Evaluate(static_cast<double>(f) * plan.frame_time_s, frame);
    if (!s.ok()) return s.error();
    all_bounds.Extend(frame.bounds.min);
    all_bounds.Extend(frame.bounds.max);
    largest_extent = glm::max(largest_extent, frame.bounds.size());
    ground_y = std::min(ground_y, frame.bounds.min.y);
    if (look) {
      look_points.push_back(cp.LookPoint(frame));
      deform::Bounds region;
      for (const int v : spec.look_region) region.Extend(frame.positions[static_cast<std::size_t>(v)]);
      if (!region.empty()) region_extent = glm::max(region_extent, region.size());
    }
  }
  // The box framed around the followed point: the whole body, or the look-at
  // neighbourhood (a joint: a third of the body's largest extent; a region:
  // its own extent and as much again around it).
  const float body_extent = std::max({largest_extent.x, largest_extent.y, largest_extent.z});
  const glm::vec3 half_box = !look ? 0.5f * largest_extent
                             : spec.look_region.empty() ? glm::vec3(body_extent / 6.0f)
                                                        : region_extent;
  cp.ground_y_ = ground_y;
  const float aspect = static_cast<float>(size.x) / static_cast<float>(size.y);
  const glm::vec3 view_dir = ViewDirection(spec);
  if (mode == "turntable") {
    const base::Status s = cp.tracker_->Evaluate(plan.At(0).time_s, frame);
    if (!s.ok()) return s.error();
    deform::Bounds box = frame.bounds;
    if (look) {
      box = deform::Bounds();
      box.Extend(cp.LookPoint(frame) - half_box);
      box.Extend(cp.LookPoint(frame) + half_box);
    }
    render::Camera framed = render::FrameBounds(box, kFovYDeg, aspect, view_dir);
    ApplyDistance(spec, body_extent, framed);
    cp.turntable_ = render::TurntablePath(box.center(), glm::length(framed.eye - framed.target),
                                          elevation_deg, static_cast<int>(plan.count()));
    for (render::Camera& c : cp.turntable_) {
      c.fov_y_deg = kFovYDeg;
      c.aspect = aspect;
      if (look || spec.distance > 0.0f || spec.zoom != 1.0f) {
        c.near_plane = framed.near_plane;
        c.far_plane = framed.far_plane;
      }
    }
  } else if (mode == "fixed") {
    deform::Bounds box = all_bounds;
    if (look) {
      box = deform::Bounds();
      for (const glm::vec3& p : look_points) {
        box.Extend(p - half_box);
        box.Extend(p + half_box);
      }
    }
    cp.fixed_ = render::FrameBounds(box, kFovYDeg, aspect, view_dir);
    if (look) {
      const float d = glm::length(cp.fixed_.eye - cp.fixed_.target);
      cp.fixed_.near_plane = std::max(d * 0.02f, 1e-3f);
      cp.fixed_.far_plane = d + 4.0f * body_extent;
    }
    ApplyDistance(spec, body_extent, cp.fixed_);
  } else {
    deform::Bounds typical;
    typical.Extend(-half_box);
    typical.Extend(half_box);
    render::Camera framed = render::FrameBounds(typical, kFovYDeg, aspect, view_dir);
    if (look) {
      // Close to a part of the body: the rest of it may lie between the eye and
      // the part's box, so near may not stop at the box.
      framed.near_plane = std::max(glm::length(framed.eye - framed.target) * 0.02f, 1e-3f);
      framed.far_plane = glm::length(framed.eye - framed.target) + 4.0f * body_extent;
    }
    ApplyDistance(spec, body_extent, framed);
    render::FollowCamera& follow = cp.follow_;
    follow.offset = framed.eye - framed.target;
    follow.fov_y_deg = kFovYDeg;
    follow.aspect = aspect;
    follow.near_plane = framed.near_plane;
    follow.far_plane = framed.far_plane * 4.0f;
    follow.frame_time_s = static_cast<float>(plan.frame_time_s);
    cp.centres_.reserve(static_cast<std::size_t>(follow.window_frames) + 1);
  }
  return cp;
}

namespace {

// Largest |x| or |y| in normalised device coordinates of the corners of `box`.
float ProjectedExtent(const deform::Bounds& box, const render::Camera& camera) {
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

}  // namespace

void CameraPlan::KeepInFrame(const deform::Bounds& box, render::Camera& camera) const {
  if (box.empty() || ProjectedExtent(box, camera) <= kFollowFrameLimit) return;
  // Slide target and eye together toward the box's centre: the least pull s
  // in [0, 1] that brings the box inside the limit (bisection; s = 1 centres it).
  const glm::vec3 offset = camera.eye - camera.target;
  const glm::vec3 lagging = camera.target;
  const glm::vec3 centre = box.center();
  const auto at = [&](float s) {
    render::Camera c = camera;
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

render::Camera CameraPlan::At(const OutputFrame& frame) const {
  if (mode_ == "turntable") return turntable_[static_cast<std::size_t>(frame.camera)];
  if (mode_ == "fixed") return fixed_;
  // The window of centres frame - window .. frame: keep what is already
  // evaluated, drop what fell out, evaluate the rest in ascending order.
  const int f = frame.camera;
  const int first = std::max(0, f - std::max(follow_.window_frames, 0));
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
  for (int g = centre_base_ + static_cast<int>(centres_.size()); g <= f; ++g) {
    // Evaluate() only fails on sizes, which Create() already checked with
    // the same pipeline.
    const base::Status s = tracker_->Evaluate(g * frame_time_s_, scratch_);
    PATCHSKIN_CHECK(s.ok());
    centres_.push_back(LookPoint(scratch_));
    boxes_.push_back(scratch_.bounds);
  }
  render::Camera camera = follow_.At(centres_, f - centre_base_);
  // A camera aimed at a joint or a region frames that close up on purpose.
  const bool whole_body = look_joint_ < 0 && look_region_.empty();
  if (whole_body) KeepInFrame(boxes_[static_cast<std::size_t>(f - centre_base_)], camera);
  return camera;
}

}  // namespace app
