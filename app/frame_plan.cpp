#include "app/frame_plan.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "base/check.h"
#include "deform/pipeline/body_tracker.h"
#include "render/camera_plan.h"

namespace app {

constexpr int kMaxImageSide = 16384;

base::Error ArgError(const std::string& option, const std::string& message) {
  return base::InvalidArgument({option, 0, 0, {}}, message);
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

namespace {

// The body as the cameras see it, from its joints and a sparse hull of its
// skin (deform/pipeline/body_tracker.h): no body is deformed to frame it.
base::Result<render::BodySampler> TrackedBodySampler(const deform::Character& character,
                                                     const CameraSpec& spec) {
  base::Result<deform::BodyTracker> tracker =
      deform::BodyTracker::Create(character, spec.look_region);
  if (!tracker.ok()) return std::move(tracker).error();
  struct State {
    deform::BodyTracker tracker;
    deform::TrackedBody body;
    int look_joint;
  };
  auto state = std::make_shared<State>(State{std::move(*tracker), {}, spec.look_joint});
  return render::BodySampler([state](double time_s, render::BodySample& out) -> base::Status {
    State& st = *state;
    if (base::Status s = st.tracker.Sample(time_s, st.body); !s.ok()) return s;
    out.bounds = st.body.hull_bounds;
    out.look_bounds = deform::ComputeBounds(st.body.tracked);
    if (st.look_joint >= 0) {
      out.look_point = st.body.joint_positions[static_cast<std::size_t>(st.look_joint)];
    } else if (!st.body.tracked.empty()) {
      glm::dvec3 sum(0.0);
      for (const glm::vec3& p : st.body.tracked) sum += glm::dvec3(p);
      out.look_point = glm::vec3(sum / static_cast<double>(st.body.tracked.size()));
    } else {
      out.look_point = out.bounds.center();
    }
    return base::Status::Ok();
  });
}

}  // namespace

base::Result<render::CameraPlan> PlanCameras(const deform::Character& character,
                                             const FramePlan& plan, const CameraSpec& spec,
                                             glm::ivec2 size) {
  if (spec.azimuth_deg && !(std::abs(*spec.azimuth_deg) <= 3600.0f)) {
    return ArgError("--azimuth", "expected finite degrees in -3600..3600");
  }
  if (!(spec.distance >= 0.0f) || !std::isfinite(spec.distance)) {
    return ArgError("--distance", "expected a finite distance >= 0 (0: framed)");
  }
  if (!(spec.zoom > 0.0f) || !(spec.zoom <= 1000.0f)) {
    return ArgError("--zoom", "expected a factor in (0, 1000]");
  }
  if (spec.look_joint >= character.skeleton.num_joints()) {
    return ArgError("--look-at", "joint index out of range");
  }
  for (const int v : spec.look_region) {
    if (v < 0 || v >= character.mesh.bind.num_vertices()) {
      return ArgError("--look-at", "region vertex out of range");
    }
  }
  const std::string& mode = spec.mode;
  if (mode != "follow" && mode != "fixed" && mode != "turntable") {
    return ArgError("--camera", "expected follow, fixed or turntable, found '" + mode + "'");
  }
  if (plan.count() == 0) return ArgError("--frames", "no frames to frame");
  // At +-90 degrees the view looks straight along the up vector (a degenerate
  // look-at); NaN would reach the rasterizer's float-to-int conversions.
  if (!(std::abs(spec.elevation_deg) <= render::kMaxElevationDeg)) {
    std::ostringstream found;
    found << spec.elevation_deg;
    return ArgError("--elevation", "expected degrees in -89..89, found " + found.str());
  }
  base::Result<render::BodySampler> sampler = TrackedBodySampler(character, spec);
  if (!sampler.ok()) return std::move(sampler).error();
  const render::CameraSettings settings{
      .mode = mode == "fixed"       ? render::CameraMode::kFixed
              : mode == "turntable" ? render::CameraMode::kTurntable
                                    : render::CameraMode::kFollow,
      .elevation_deg = spec.elevation_deg,
      .azimuth_deg = spec.azimuth_deg,
      .distance = spec.distance,
      .zoom = spec.zoom,
      .aim = spec.look_joint >= 0        ? render::CameraAim::kJoint
             : !spec.look_region.empty() ? render::CameraAim::kRegion
                                         : render::CameraAim::kBody,
      .size = size};
  const render::CameraTimes times{.frame_time_s = plan.frame_time_s,
                                  .motion_frames = std::max(1, plan.motion_frames),
                                  .turntable_time_s = plan.At(0).time_s,
                                  .turntable_views = static_cast<int>(plan.count())};
  return render::CameraPlan::Create(std::move(*sampler), settings, times);
}

base::Result<render::CameraPlan> PlanCameras(const deform::Character& character,
                                             const FramePlan& plan, const std::string& mode,
                                             float elevation_deg, glm::ivec2 size) {
  CameraSpec spec;
  spec.mode = mode;
  spec.elevation_deg = elevation_deg;
  return PlanCameras(character, plan, spec, size);
}

}  // namespace app
