#include "app/frame_plan.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "mocap/check.h"

namespace app {

constexpr int kMaxImageSide = 16384;

mocap::Error ArgError(const std::string& option, const std::string& message) {
  return mocap::MakeError(mocap::ErrorCode::kInvalidArgument, {option, 0, 0, {}}, message);
}

mocap::Result<glm::ivec2> ParseSize(const std::string& text) {
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

mocap::Result<std::optional<mocap::UpAxis>> ParseUpAxis(const std::string& text) {
  if (text.empty()) return std::optional<mocap::UpAxis>();
  if (text == "y" || text == "Y") return std::optional<mocap::UpAxis>(mocap::UpAxis::kY);
  if (text == "z" || text == "Z") return std::optional<mocap::UpAxis>(mocap::UpAxis::kZ);
  return ArgError("--up", "expected y or z, found '" + text + "'");
}

mocap::Result<FrameRange> ParseFrames(const std::string& text, int num_frames) {
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

mocap::Result<FramePlan> PlanFrames(const mocap::Motion& motion, const FramePlanOptions& o) {
  FramePlan plan;
  plan.frame_time_s = o.fps > 0.0 ? 1.0 / o.fps
                                  : (motion.frame_time_s > 0 ? motion.frame_time_s : 1.0 / 30.0);
  plan.motion_frames =
      motion.num_frames > 0
          ? static_cast<int>(std::floor(motion.duration_s() / plan.frame_time_s + 1e-9)) + 1
          : 1;
  mocap::Result<FrameRange> range = ParseFrames(o.frames, plan.motion_frames);
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

mocap::Result<CameraPlan> CameraPlan::Create(FramePipeline& pipeline, const FramePlan& plan,
                                             const std::string& mode, float elevation_deg,
                                             glm::ivec2 size) {
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
  cp.frame_time_s_ = plan.frame_time_s;
  mocap::Result<FramePipeline> tracker =
      FramePipeline::Create(pipeline.character(), GlobalMethod::kSsd, pipeline.threads());
  if (!tracker.ok()) return std::move(tracker).error();
  cp.tracker_ = std::make_unique<FramePipeline>(std::move(*tracker));
  // Framing: output frames spread evenly over the whole motion, both ends
  // included, the same whatever --frames asks for.
  DeformedFrame& frame = cp.scratch_;
  deform::Bounds all_bounds;
  glm::vec3 largest_extent(0.0f);
  float ground_y = 1e30f;
  const std::int64_t last = std::max(0, plan.motion_frames - 1);
  const std::int64_t samples = std::min<std::int64_t>(kFramingSamples, last + 1);
  for (std::int64_t i = 0; i < samples; ++i) {
    const std::int64_t f = samples > 1 ? last * i / (samples - 1) : 0;
    const mocap::Status s = cp.tracker_->Evaluate(static_cast<double>(f) * plan.frame_time_s, frame);
    if (!s.ok()) return s.error();
    all_bounds.Extend(frame.bounds.min);
    all_bounds.Extend(frame.bounds.max);
    largest_extent = glm::max(largest_extent, frame.bounds.size());
    ground_y = std::min(ground_y, frame.bounds.min.y);
  }
  cp.ground_y_ = ground_y;
  const float aspect = static_cast<float>(size.x) / static_cast<float>(size.y);
  const float elevation = glm::radians(elevation_deg);
  // Seen from the character's front-left, slightly above (characters face +Z).
  const glm::vec3 view_dir = -glm::normalize(glm::vec3(0.45f, 0.0f, 1.0f) * std::cos(elevation) +
                                             glm::vec3(0.0f, std::sin(elevation), 0.0f));
  if (mode == "turntable") {
    const mocap::Status s = cp.tracker_->Evaluate(plan.At(0).time_s, frame);
    if (!s.ok()) return s.error();
    const render::Camera framed = render::FrameBounds(frame.bounds, kFovYDeg, aspect, view_dir);
    cp.turntable_ = render::TurntablePath(frame.bounds.center(),
                                          glm::length(framed.eye - framed.target), elevation_deg,
                                          static_cast<int>(plan.count()));
    for (render::Camera& c : cp.turntable_) {
      c.fov_y_deg = kFovYDeg;
      c.aspect = aspect;
    }
  } else if (mode == "fixed") {
    cp.fixed_ = render::FrameBounds(all_bounds, kFovYDeg, aspect, view_dir);
  } else {
    deform::Bounds typical;
    typical.Extend(-0.5f * largest_extent);
    typical.Extend(0.5f * largest_extent);
    const render::Camera framed = render::FrameBounds(typical, kFovYDeg, aspect, view_dir);
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
    const mocap::Status s = tracker_->Evaluate(g * frame_time_s_, scratch_);
    PATCHSKIN_CHECK(s.ok());
    centres_.push_back(scratch_.bounds.center());
    boxes_.push_back(scratch_.bounds);
  }
  render::Camera camera = follow_.At(centres_, f - centre_base_);
  KeepInFrame(boxes_[static_cast<std::size_t>(f - centre_base_)], camera);
  return camera;
}

}  // namespace app
