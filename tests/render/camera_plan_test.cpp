// render::CameraPlan on bodies given only by their bounds (no mesh): a box that
// walks, then sprints, along +X.

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "render/camera_plan.h"

namespace {

constexpr double kFrameTime = 1.0 / 30.0;
constexpr int kFrames = 240;

// A 0.5 x 1.8 x 0.3 box standing on y = 0.1, at x = 1 m/s for 4 s, then 6 m/s.
render::BodySample BoxAt(double t) {
  const float x = t < 4.0 ? static_cast<float>(t) : 4.0f + 6.0f * static_cast<float>(t - 4.0);
  render::BodySample s;
  s.bounds.Extend(glm::vec3(x - 0.25f, 0.1f, -0.15f));
  s.bounds.Extend(glm::vec3(x + 0.25f, 1.9f, 0.15f));
  s.look_point = s.bounds.center();
  return s;
}

render::BodySampler Walker(int* calls = nullptr) {
  return [calls](double t, render::BodySample& out) {
    if (calls) ++*calls;
    out = BoxAt(t);
    return base::Status::Ok();
  };
}

const render::CameraTimes kTimes{.frame_time_s = kFrameTime,
                                 .motion_frames = kFrames,
                                 .turntable_time_s = 0.0,
                                 .turntable_views = 12};

// Largest |x|, |y| in NDC of the box's corners (infinite behind the eye).
float Projected(const deform::Bounds& box, const render::Camera& c) {
  const glm::mat4 m = c.ClipFromView() * c.ViewFromWorld();
  float worst = 0.0f;
  for (int k = 0; k < 8; ++k) {
    const glm::vec4 p =
        m * glm::vec4((k & 1) ? box.max.x : box.min.x, (k & 2) ? box.max.y : box.min.y,
                      (k & 4) ? box.max.z : box.min.z, 1.0f);
    if (!(p.w > 0.0f)) return INFINITY;
    worst = std::max({worst, std::abs(p.x / p.w), std::abs(p.y / p.w)});
  }
  return worst;
}

bool Same(const render::Camera& a, const render::Camera& b) {
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

TEST(CameraPlan, FixedFramesEveryFrameAndGroundIsTheLowestPoint) {
  const auto plan = render::CameraPlan::Create(
      Walker(), {.mode = render::CameraMode::kFixed, .size = {640, 360}}, kTimes);
  ASSERT_TRUE(plan.ok()) << plan.error().ToString();
  EXPECT_FLOAT_EQ(plan->ground_y(), 0.1f);
  for (int f = 0; f < kFrames; f += 7) {
    EXPECT_LE(Projected(BoxAt(f * kFrameTime).bounds, plan->At(f)), 1.0f) << "frame " << f;
  }
}

TEST(CameraPlan, FollowKeepsASprintingBodyInFrame) {
  const auto plan = render::CameraPlan::Create(Walker(), {.size = {640, 360}}, kTimes);
  ASSERT_TRUE(plan.ok());
  float worst = 0.0f;
  for (int f = 0; f < kFrames; ++f) {
    worst = std::max(worst, Projected(BoxAt(f * kFrameTime).bounds, plan->At(f)));
  }
  // The smoothed target lags the sprint; KeepInFrame pulls it back to the limit.
  EXPECT_LE(worst, render::CameraPlan::kFollowFrameLimit + 1e-4f);
  EXPECT_GT(worst, 0.5f);  // the body fills a good part of the frame
}

TEST(CameraPlan, AFollowCameraDoesNotDependOnTheFramesAskedBefore) {
  int calls = 0;
  const auto whole = render::CameraPlan::Create(Walker(), {.size = {640, 360}}, kTimes);
  const auto chunk = render::CameraPlan::Create(Walker(&calls), {.size = {640, 360}}, kTimes);
  ASSERT_TRUE(whole.ok() && chunk.ok());
  std::vector<render::Camera> ascending;
  for (int f = 0; f < kFrames; ++f) ascending.push_back(whole->At(f));
  calls = 0;
  for (const int f : {200, 150, 151, 7, 239}) {
    EXPECT_TRUE(Same(chunk->At(f), ascending[static_cast<std::size_t>(f)])) << "frame " << f;
  }
  // Each frame samples at most its window, never the whole motion.
  EXPECT_LT(calls, 5 * (render::FollowCamera().window_frames + 1) + 1);
}

TEST(CameraPlan, TurntableOrbitsOneMomentAtOneDistance) {
  const auto plan = render::CameraPlan::Create(
      Walker(), {.mode = render::CameraMode::kTurntable, .size = {400, 400}}, kTimes);
  ASSERT_TRUE(plan.ok());
  const glm::vec3 centre = BoxAt(0.0).bounds.center();
  const float d0 = glm::distance(plan->At(0).eye, centre);
  for (int v = 0; v < kTimes.turntable_views; ++v) {
    const render::Camera c = plan->At(v);
    EXPECT_NEAR(glm::distance(c.eye, centre), d0, 1e-4f * d0) << "view " << v;
    EXPECT_LE(Projected(BoxAt(0.0).bounds, c), 1.0f) << "view " << v;
  }
  EXPECT_GT(glm::distance(plan->At(0).eye, plan->At(3).eye), 0.5f * d0);
}

TEST(CameraPlan, BadSettingsAndSamplerErrorsAreReported) {
  const auto refused = [](render::CameraSettings s, render::CameraTimes t = kTimes) {
    const auto plan = render::CameraPlan::Create(Walker(), s, t);
    return !plan.ok() && plan.error().code == base::ErrorCode::kInvalidArgument;
  };
  EXPECT_TRUE(refused({.elevation_deg = 90.0f}));
  EXPECT_TRUE(refused({.elevation_deg = NAN}));
  EXPECT_TRUE(refused({.azimuth_deg = INFINITY}));
  EXPECT_TRUE(refused({.distance = -1.0f}));
  EXPECT_TRUE(refused({.zoom = 0.0f}));
  EXPECT_TRUE(refused({.size = {0, 10}}));
  EXPECT_TRUE(refused({}, {.frame_time_s = 0.0, .motion_frames = 10}));
  EXPECT_TRUE(refused({}, {.frame_time_s = kFrameTime, .motion_frames = 0}));
  const auto failing = [](double, render::BodySample&) -> base::Status {
    return base::MakeError(base::ErrorCode::kIo, {"body.bin", 3, 0, {}}, "unreadable");
  };
  const auto plan = render::CameraPlan::Create(failing, {}, kTimes);
  ASSERT_FALSE(plan.ok());
  EXPECT_EQ(plan.error().code, base::ErrorCode::kIo);
}

}  // namespace
