// Overlays: depth-tested lines and points, skeleton and control-net helpers, text.

#include "render/raster/overlay.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "tests/render/render_fixtures.h"

namespace {

// A unit sphere at the origin seen from +Z, unlit grey on a transparent background.
struct SphereScene {
  rendertest::TriMesh sphere = rendertest::MakeSphere(glm::vec3(0.0f), 1.0f, 24, 48);
  render::Camera cam;
  render::RenderSettings settings;
  SphereScene() {
    cam.eye = glm::vec3(0.0f, 0.0f, 4.0f);
    cam.aspect = 1.0f;
    settings.width = 80;
    settings.height = 80;
    settings.ground = false;
    settings.lighting = render::LightingModel::kUnlit;
    settings.background.transparent = true;
  }
  render::Image Render(const render::Overlays& overlays) const {
    const render::SceneMesh mesh{.positions = sphere.positions, .normals = sphere.normals,
                                 .triangles = sphere.triangles, .base_color = glm::vec3(0.5f)};
    return render::Render(cam, {&mesh, 1}, overlays, settings);
  }
};

TEST(OverlayTest, DepthTestedLineHidesBehindTheSurface) {
  SphereScene scene;
  // A horizontal line at y = 0 through the sphere's centre plane z = -0.5
  // (behind the front surface) and one in front of it at z = 1.5.
  render::Overlays overlays;
  overlays.lines.push_back({.endpoints = {{-3.0f, 0.0f, -0.5f}, {3.0f, 0.0f, -0.5f}},
                            .color = {1.0f, 0.0f, 0.0f, 1.0f}, .width_px = 3.0f, .depth_test = true});
  overlays.lines.push_back({.endpoints = {{-3.0f, 0.5f, 1.5f}, {3.0f, 0.5f, 1.5f}},
                            .color = {0.0f, 1.0f, 0.0f, 1.0f}, .width_px = 3.0f, .depth_test = true});
  const render::Image image = scene.Render(overlays);
  const glm::mat4 m = scene.cam.ClipFromWorld();
  const auto row_of = [&](glm::vec3 p) {
    const glm::vec4 c = m * glm::vec4(p, 1.0f);
    return static_cast<int>((1.0f - c.y / c.w) * 0.5f * 80.0f);
  };
  const int hidden_row = row_of({0.0f, 0.0f, -0.5f}), front_row = row_of({0.0f, 0.5f, 1.5f});
  // Centre of the image: the red line is behind the sphere, the green one in front.
  EXPECT_EQ(image.at(40, hidden_row), glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  EXPECT_GT(image.at(40, front_row).g, 0.9f);
  // Far left, off the sphere: the red line shows.
  EXPECT_GT(image.at(3, hidden_row).r, 0.9f);
  // Without the depth test it is drawn over the sphere.
  overlays.lines[0].depth_test = false;
  EXPECT_GT(scene.Render(overlays).at(40, hidden_row).r, 0.9f);
}

TEST(OverlayTest, PointsAndHelpersBuildTheExpectedPrimitives) {
  SphereScene scene;
  render::Overlays overlays;
  overlays.points.push_back({.points = {{0.0f, 0.0f, 1.2f}, {0.0f, 0.0f, -1.2f}},
                             .color = {0.0f, 0.0f, 1.0f, 1.0f}, .radius_px = 2.0f});
  const render::Image image = scene.Render(overlays);
  EXPECT_GT(image.at(40, 40).b, 0.9f);  // the front point; the back one is hidden
  EXPECT_LT(image.at(40, 40).r, 0.1f);

  // Skeleton: joints 0 <- 1 <- 2 and a second root 3: two bones.
  const std::vector<glm::vec3> joints = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {1, 0, 0}};
  const std::vector<std::int16_t> parents = {-1, 0, 1, -1};
  render::LineOverlay bones;
  render::AppendSkeletonLines(joints, parents, bones);
  ASSERT_EQ(bones.endpoints.size(), 4u);
  EXPECT_EQ(bones.endpoints[2], joints[1]);
  EXPECT_EQ(bones.endpoints[3], joints[2]);
  // A 3 x 4 control net has 3*3 + 2*4 = 17 edges.
  std::vector<glm::vec3> net;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) net.emplace_back(static_cast<float>(c), static_cast<float>(r), 0.0f);
  render::LineOverlay net_lines;
  render::AppendControlNetLines(net, 3, 4, net_lines);
  EXPECT_EQ(net_lines.endpoints.size(), 34u);
  render::LineOverlay bad;
  render::AppendControlNetLines(net, 4, 4, bad);  // too few points: nothing
  EXPECT_TRUE(bad.endpoints.empty());
}

TEST(OverlayTest, TextChangesOnlyTheTextArea) {
  render::Image image(120, 40, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  render::DrawText({.text = "frame 42", .origin_px = {5, 30}}, image);
  int lit_top = 0, lit_text = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 120; ++x)
      if (image.at(x, y).r > 0.5f) (y < 8 ? lit_top : lit_text)++;
  EXPECT_GT(lit_text, 30);
  EXPECT_EQ(lit_top, 0);
}

}  // namespace
