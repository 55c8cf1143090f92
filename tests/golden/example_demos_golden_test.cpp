// Golden frames of the example-shape demos shipped in samples/data (issue 6):
// each demo rig on the generated body at an example pose and at a pose between
// examples, split: the global method alone (left) | global + patch with its
// example shapes (right), close up on the patch. The figures these frames show
// are measured in tests/app/example_demos_test.cpp.

#include <cmath>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "render/camera.h"
#include "render/renderer.h"
#include "support/example_demos.h"
#include "support/golden.h"

namespace {

constexpr int kDemoWidth = 256;
constexpr int kDemoHeight = 144;

struct DemoCase {
  std::string name;     // golden reference name
  std::string demo;     // samples/data/<demo>.json
  int frame;            // frame of the demo's motion
  glm::vec3 view_dir;   // camera looking direction (world)
  float margin;         // padding around the patch region, model units
};

void PrintTo(const DemoCase& c, std::ostream* os) { *os << c.name; }

render::Image RenderDemo(const DemoCase& c) {
  const auto demo = testsupport::LoadDemo(c.demo);
  EXPECT_TRUE(demo->error.empty()) << demo->error;
  if (!demo->error.empty()) return render::Image(kDemoWidth, kDemoHeight);
  const double t = c.frame * demo->character.motion.frame_time_s;
  deform::DeformedFrame left, right;
  EXPECT_TRUE(demo->global->Evaluate(t, left).ok());
  EXPECT_TRUE(demo->layered->Evaluate(t, right).ok());
  deform::Bounds box;
  for (int v : demo->patches[0].region) {
    const glm::vec3 p = right.positions[static_cast<std::size_t>(v)];
    box.Extend(p - glm::vec3(c.margin));
    box.Extend(p + glm::vec3(c.margin));
  }
  const float aspect = static_cast<float>(kDemoWidth / 2) / static_cast<float>(kDemoHeight);
  const render::Camera camera =
      render::FrameBounds(box, 35.0f, aspect, glm::normalize(c.view_dir), 1.0f);
  render::RenderSettings settings;
  settings.width = kDemoWidth / 2;
  settings.height = kDemoHeight;
  settings.supersample = 2;
  settings.threads = 1;
  settings.ground = false;
  // Side by side, the same camera: global only | global + examples.
  render::Image out(kDemoWidth, kDemoHeight);
  for (int side = 0; side < 2; ++side) {
    const deform::DeformedFrame& f = side == 0 ? left : right;
    const render::SceneMesh mesh{.positions = f.positions, .normals = f.normals,
                                 .triangles = demo->character.mesh.bind.triangles};
    const render::Image half = render::Render(camera, {&mesh, 1}, {}, settings);
    for (int y = 0; y < kDemoHeight; ++y) {
      for (int x = 0; x < kDemoWidth / 2; ++x)
        out.at(side * (kDemoWidth / 2) + x, y) = half.at(x, y);
    }
  }
  for (int y = 0; y < kDemoHeight; ++y) out.at(kDemoWidth / 2, y) = glm::vec4(1.0f);  // divider
  return out;
}

class ExampleDemoGoldenTest : public ::testing::TestWithParam<DemoCase> {};

TEST_P(ExampleDemoGoldenTest, MatchesReference) {
  testsupport::ExpectMatchesGolden(RenderDemo(GetParam()), GetParam().name, {});
}

// Views: the elbow and the knee from the outside of the bend, the biceps from
// above (its front is the silhouette), the shoulder from the front, the hip
// from behind and the side. Frames: an example pose and one between examples
// (elbow, knee: 150 and 112.5 degrees; biceps: 90 and 105; shoulder: arm up
// and halfway back down; hip: stretched back and halfway there).
INSTANTIATE_TEST_SUITE_P(
    Demos, ExampleDemoGoldenTest,
    ::testing::Values(
        DemoCase{"examples_elbow_150", "elbow", 60, {-0.6f, -0.3f, 1.0f}, 3.0f},
        DemoCase{"examples_elbow_112", "elbow", 45, {-0.6f, -0.3f, 1.0f}, 3.0f},
        DemoCase{"examples_biceps_90", "biceps", 36, {0.1f, -1.0f, -0.25f}, 3.0f},
        DemoCase{"examples_biceps_105", "biceps", 42, {0.1f, -1.0f, -0.25f}, 3.0f},
        DemoCase{"examples_knee_150", "knee", 60, {-1.0f, -0.2f, 0.0f}, 3.0f},
        DemoCase{"examples_knee_112", "knee", 45, {-1.0f, -0.2f, 0.0f}, 3.0f},
        DemoCase{"examples_shoulder_up", "shoulder", 45, {-0.3f, -0.2f, -1.0f}, 4.0f},
        DemoCase{"examples_shoulder_between", "shoulder", 52, {-0.3f, -0.2f, -1.0f}, 4.0f},
        DemoCase{"examples_hip_back", "hip", 15, {-1.0f, -0.1f, 0.4f}, 4.0f},
        DemoCase{"examples_hip_between", "hip", 8, {-1.0f, -0.1f, 0.4f}, 4.0f}),
    [](const auto& param_info) { return param_info.param.name; });

}  // namespace
