// Camera matrices, framing, follow smoothing and turntable paths.

#include "render/camera.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "support/tolerances.h"

namespace {

using testsupport::kFloatTol;

TEST(CameraTest, ProjectsKnownPointsToAnalyticNdc) {
  render::Camera cam;
  cam.eye = glm::vec3(0.0f, 0.0f, 5.0f);
  cam.target = glm::vec3(0.0f);
  cam.fov_y_deg = 90.0f;  // tan(45) = 1: ndc = view xy / depth (x also / aspect)
  cam.aspect = 2.0f;
  cam.near_plane = 1.0f;
  cam.far_plane = 9.0f;
  const glm::mat4 m = cam.ClipFromWorld();
  const auto ndc = [&](glm::vec3 p) {
    const glm::vec4 c = m * glm::vec4(p, 1.0f);
    return glm::vec4(glm::vec3(c) / c.w, c.w);
  };
  EXPECT_NEAR(ndc({0, 0, 0}).x, 0.0f, kFloatTol);
  EXPECT_NEAR(ndc({0, 0, 0}).w, 5.0f, kFloatTol);  // w = view depth
  const glm::vec4 p = ndc({2.0f, 1.0f, 1.0f});       // depth 4
  EXPECT_NEAR(p.x, 2.0f / 4.0f / 2.0f, kFloatTol);
  EXPECT_NEAR(p.y, 1.0f / 4.0f, kFloatTol);
  EXPECT_NEAR(p.w, 4.0f, kFloatTol);
  EXPECT_NEAR(ndc({0, 0, 4.0f}).z, -1.0f, kFloatTol);  // on the near plane
  EXPECT_NEAR(ndc({0, 0, -4.0f}).z, 1.0f, kFloatTol);  // on the far plane
  // A point to the camera's right (+X when looking down -Z) lands at +x.
  EXPECT_GT(ndc({1.0f, 0.0f, 0.0f}).x, 0.0f);
  EXPECT_NEAR(glm::length(cam.Forward() - glm::vec3(0, 0, -1)), 0.0f, kFloatTol);
}

TEST(CameraTest, FrameBoundsKeepsTheBoxInsideTheView) {
  deform::Bounds box;
  box.Extend({-0.3f, 0.0f, -0.2f});
  box.Extend({0.4f, 1.8f, 0.25f});
  const glm::vec3 dirs[] = {{0, 0, -1}, {1, -0.3f, 0.2f}, {-0.5f, -1.0f, -0.5f}, {0, -1, 0}};
  for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f}) {
    for (const glm::vec3& dir : dirs) {
      const render::Camera cam = render::FrameBounds(box, 35.0f, aspect, dir);
      const glm::mat4 m = cam.ClipFromWorld();
      float widest = 0.0f;
      for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p((corner & 1) ? box.max.x : box.min.x, (corner & 2) ? box.max.y : box.min.y,
                          (corner & 4) ? box.max.z : box.min.z);
        const glm::vec4 c = m * glm::vec4(p, 1.0f);
        ASSERT_GT(c.w, cam.near_plane);
        ASSERT_LT(c.w, cam.far_plane);
        const glm::vec3 ndc = glm::vec3(c) / c.w;
        EXPECT_LE(std::abs(ndc.x), 1.0f) << "aspect " << aspect;
        EXPECT_LE(std::abs(ndc.y), 1.0f) << "aspect " << aspect;
        widest = std::max({widest, std::abs(ndc.x), std::abs(ndc.y)});
      }
      EXPECT_GT(widest, 0.2f);  // framed, not lost in the distance
      EXPECT_NEAR(glm::length(glm::normalize(cam.target - cam.eye) - glm::normalize(dir)), 0.0f, 1e-4f);
    }
  }
}

TEST(CameraTest, TurntableOrbitsAtDistanceAndElevation) {
  const glm::vec3 target(1.0f, 0.5f, -2.0f);
  const int n = 8;
  const std::vector<render::Camera> path = render::TurntablePath(target, 5.0f, 30.0f, n);
  ASSERT_EQ(path.size(), 8u);
  for (int k = 0; k < n; ++k) {
    const render::Camera& cam = path[static_cast<std::size_t>(k)];
    const glm::vec3 d = cam.eye - target;
    EXPECT_NEAR(glm::length(d), 5.0f, testsupport::kPositionTol);
    EXPECT_NEAR(d.y, 5.0f * 0.5f, testsupport::kPositionTol);  // sin 30
    const float azimuth_deg = glm::degrees(std::atan2(d.x, d.z));
    const float expected = 360.0f * static_cast<float>(k) / n;
    EXPECT_NEAR(std::remainder(azimuth_deg - expected, 360.0f), 0.0f, testsupport::kAngleTolDeg);
    EXPECT_EQ(cam.target, target);
  }
  EXPECT_TRUE(render::TurntablePath(target, 5.0f, 30.0f, 0).empty());
}

TEST(CameraTest, FollowCameraIsCriticallyDampedAndChunkIndependent) {
  render::FollowCamera follow;
  follow.window_frames = 90;
  // A step in the target at frame 10.
  std::vector<glm::vec3> centres(200, glm::vec3(0.0f));
  for (std::size_t f = 10; f < centres.size(); ++f) centres[f] = glm::vec3(1.0f, 0.0f, 0.0f);
  float previous = 0.0f;
  for (int f = 0; f < 100; ++f) {
    const float x = follow.SmoothedTarget(centres, f).x;
    EXPECT_GE(x, previous - kFloatTol) << "frame " << f;  // monotone: no overshoot
    EXPECT_LE(x, 1.0f + kFloatTol);
    previous = x;
  }
  EXPECT_NEAR(follow.SmoothedTarget(centres, 99).x, 1.0f, 1e-3f);
  EXPECT_LT(follow.SmoothedTarget(centres, 12).x, 0.5f);  // smoothed, not snapped
  // Frame N depends only on frames [N - window, N]: later frames and frames
  // before the window do not change it, so chunked renders agree.
  std::vector<glm::vec3> changed = centres;
  for (std::size_t f = 150; f < changed.size(); ++f) changed[f] = glm::vec3(-5.0f);
  for (std::size_t f = 0; f < 40; ++f) changed[f] = glm::vec3(7.0f);
  EXPECT_EQ(follow.SmoothedTarget(centres, 140), follow.SmoothedTarget(changed, 140));
  const std::vector<glm::vec3> prefix(centres.begin(), centres.begin() + 141);
  EXPECT_EQ(follow.SmoothedTarget(centres, 140), follow.SmoothedTarget(prefix, 140));
  const render::Camera cam = follow.At(centres, 140);
  EXPECT_EQ(cam.eye - cam.target, follow.offset);
}

}  // namespace
