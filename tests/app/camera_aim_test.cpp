// Cameras aimed at the effect (issue 24): --azimuth, --elevation, --distance,
// --zoom and --look-at (app::CameraSpec). Checked against independent
// computations: the eye's direction from the angles, the distance, and a
// look-at target that is the follow camera's smoothing of the joint's (or the
// region centroid's) positions, evaluated here by a separate pipeline.

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/frame_plan.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "render/camera.h"
#include "support/example_demos.h"

namespace {

// The walk (90 frames: past the follow camera's 60-frame window).
app::Character WalkCharacter() {
  auto source = app::LoadMotionSource(testsupport::SampleDataPath("demo_walk.bvh").string(), {.y_up = true});
  EXPECT_TRUE(source.ok());
  auto character = app::MakeCharacter(std::move(*source));
  EXPECT_TRUE(character.ok());
  return std::move(*character);
}

struct Scene {
  app::Character character = WalkCharacter();
  app::FramePlan plan;
  std::optional<deform::FramePipeline> pipeline;
  Scene() {
    app::FramePlanOptions options;
    options.list_frames = false;
    auto p = app::PlanFrames(character.motion, options);
    EXPECT_TRUE(p.ok());
    plan = *p;
    auto pipe = deform::FramePipeline::Create(character, deform::GlobalMethod::kSsd, 1);
    EXPECT_TRUE(pipe.ok());
    pipeline.emplace(std::move(*pipe));
  }
};

TEST(CameraAim, AzimuthElevationAndDistancePlaceTheEye) {
  Scene s;
  const int joint = s.character.skeleton.FindJoint("LeftForeArm");
  ASSERT_GE(joint, 0);
  for (const float azimuth : {0.0f, 90.0f, 200.0f}) {
    app::CameraSpec spec;
    spec.mode = "fixed";
    spec.azimuth_deg = azimuth;
    spec.elevation_deg = 20.0f;
    spec.distance = 80.0f;
    spec.look_joint = joint;
    auto cameras = app::PlanCameras(s.pipeline->character(), s.plan, spec, {640, 360});
    ASSERT_TRUE(cameras.ok()) << cameras.error().ToString();
    const render::Camera c = cameras->At(s.plan.At(0).camera);
    const glm::vec3 offset = c.eye - c.target;
    EXPECT_NEAR(glm::length(offset), 80.0f, 1e-3f);
    const float a = glm::radians(azimuth), e = glm::radians(20.0f);
    const glm::vec3 expected(std::sin(a) * std::cos(e), std::sin(e), std::cos(a) * std::cos(e));
    EXPECT_GT(glm::dot(glm::normalize(offset), expected), 0.99999f) << azimuth;
    // Zoom 2 halves the distance, the direction stays.
    spec.zoom = 2.0f;
    auto zoomed = app::PlanCameras(s.pipeline->character(), s.plan, spec, {640, 360});
    ASSERT_TRUE(zoomed.ok());
    const render::Camera z = zoomed->At(s.plan.At(0).camera);
    EXPECT_NEAR(glm::length(z.eye - z.target), 40.0f, 1e-3f);
    EXPECT_NEAR(glm::distance(z.target, c.target), 0.0f, 1e-4f);
  }
}

// The follow camera's target is the smoothed look-at point, whether a joint
// or a patch region's centroid: the same filter as render::FollowCamera over
// the positions a separate pipeline gives.
TEST(CameraAim, LookAtFollowsTheJointAndTheRegionWithTheFollowSmoothing) {
  Scene s;
  const int joint = s.character.skeleton.FindJoint("LeftForeArm");
  std::vector<int> region;
  for (int v = 0; v < s.character.mesh.bind.num_vertices(); v += 97) region.push_back(v);
  auto twin = deform::FramePipeline::Create(s.character, deform::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(twin.ok());
  const int frames = static_cast<int>(s.plan.count());
  ASSERT_GT(frames, 62);
  std::vector<glm::vec3> joint_points, region_points;
  deform::DeformedFrame f;
  for (int i = 0; i < frames; ++i) {
    ASSERT_TRUE(twin->Evaluate(s.plan.At(static_cast<std::size_t>(i)).time_s, f).ok());
    joint_points.push_back(f.joint_positions[static_cast<std::size_t>(joint)]);
    glm::dvec3 sum(0.0);
    for (const int v : region) sum += glm::dvec3(f.positions[static_cast<std::size_t>(v)]);
    region_points.push_back(glm::vec3(sum / static_cast<double>(region.size())));
  }
  for (int kind = 0; kind < 2; ++kind) {
    app::CameraSpec spec;
    spec.azimuth_deg = 90.0f;
    if (kind == 0) spec.look_joint = joint;
    else spec.look_region = region;
    auto cameras = app::PlanCameras(s.pipeline->character(), s.plan, spec, {640, 360});
    ASSERT_TRUE(cameras.ok());
    render::FollowCamera follow;
    follow.frame_time_s = static_cast<float>(s.plan.frame_time_s);
    const std::vector<glm::vec3>& points = kind == 0 ? joint_points : region_points;
    for (const int i : {0, 30, 61, frames - 1}) {  // 61 and later: the window restarts
      const render::Camera c = cameras->At(s.plan.At(static_cast<std::size_t>(i)).camera);
      const glm::vec3 expected = follow.SmoothedTarget(points, i);
      EXPECT_LT(glm::distance(c.target, expected), 1e-3f) << "kind " << kind << " frame " << i;
    }
  }
}

TEST(CameraAim, RefusesValuesOutOfRange) {
  Scene s;
  const auto refused = [&](app::CameraSpec spec, const std::string& option) {
    auto c = app::PlanCameras(s.pipeline->character(), s.plan, spec, {640, 360});
    ASSERT_FALSE(c.ok()) << option;
    EXPECT_NE(c.error().ToString().find(option), std::string::npos) << c.error().ToString();
  };
  app::CameraSpec spec;
  spec.zoom = 0.0f;
  refused(spec, "--zoom");
  spec = {};
  spec.distance = -1.0f;
  refused(spec, "--distance");
  spec = {};
  spec.azimuth_deg = std::nanf("");
  refused(spec, "--azimuth");
  spec = {};
  spec.look_region = {s.character.mesh.bind.num_vertices()};
  refused(spec, "--look-at");
}

}  // namespace
