// The overlays and frame options that make the patch layer visible (issue 24):
// --overlay wire stays readable on a dense body seen small, --overlay delta
// colours the layered body and draws its colour bar, --background transparent
// writes alpha 0 off the body and ground, --label none|frame|timecode.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "render/camera.h"
#include "render/output/image_io.h"
#include "render/renderer.h"
#include "support/data_paths.h"
#include "support/example_demos.h"
#include "support/run_process.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;

testsupport::ProcessResult RenderWith(const fs::path& d, std::vector<std::string> args) {
  args.insert(args.begin(), "render");
  for (const char* a : {"--quiet", "--no-video", "--no-sheet"}) args.push_back(a);
  return testsupport::RunPatchskin(args, d / "logs");
}

float Luminance(const glm::vec4& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// The whole mannequin at 640x360 (about 200 px tall, its triangles a few
// pixels across): with the wire its surface keeps most of its brightness
// (it used to turn black), and the wire still shows on part of it.
TEST(RenderOverlays, WireStaysReadableOnTheWholeBodyAt640x360) {
  auto source = app::LoadMotionSource(testsupport::SampleDataPath("bend.bvh").string(), {.y_up = true});
  ASSERT_TRUE(source.ok());
  auto ch = app::MakeCharacter(std::move(*source));
  ASSERT_TRUE(ch.ok());
  auto pipeline = deform::FramePipeline::Create(*ch, deform::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(pipeline.ok());
  deform::DeformedFrame f;
  ASSERT_TRUE(pipeline->Evaluate(1.0, f).ok());
  const render::Camera camera =
      render::FrameBounds(f.bounds, 35.0f, 640.0f / 360.0f, glm::vec3(-0.4f, -0.2f, -1.0f), 1.6f);
  render::RenderSettings settings;
  settings.width = 640;
  settings.height = 360;
  settings.supersample = 2;
  settings.threads = 1;
  settings.ground = false;
  const render::SceneMesh body{.positions = f.positions, .normals = f.normals,
                               .triangles = ch->mesh.bind.triangles};
  render::Overlays wire;
  wire.wireframe = true;
  const render::Image plain = render::Render(camera, {&body, 1}, {}, settings);
  const render::Image wired = render::Render(camera, {&body, 1}, wire, settings);
  double sum_plain = 0.0, sum_wired = 0.0;
  int body_pixels = 0, darker = 0;
  for (std::size_t i = 0; i < plain.rgba.size(); ++i) {
    if (!std::isfinite(plain.depth[i])) continue;  // off the body
    ++body_pixels;
    sum_plain += Luminance(plain.rgba[i]);
    sum_wired += Luminance(wired.rgba[i]);
    darker += Luminance(plain.rgba[i]) - Luminance(wired.rgba[i]) > 8.0f / 255.0f ? 1 : 0;
  }
  ASSERT_GT(body_pixels, 5000);
  std::printf("wire at 640x360: body keeps %.1f %% of its brightness, wire visible on %.1f %% of it\n",
              100.0 * sum_wired / sum_plain, 100.0 * darker / body_pixels);
  EXPECT_GT(sum_wired / sum_plain, 0.85);
  EXPECT_GT(static_cast<double>(darker) / body_pixels, 0.02);
}

TEST(RenderOverlays, TransparentBackgroundKeepsTheBodyAndGroundOpaque) {
  const fs::path d = TestDir();
  const std::string bend = testsupport::SampleDataPath("bend.bvh").string();
  auto r = RenderWith(d, {bend, "--frames", "30", "--size", "160x90", "--background", "transparent",
                          "--camera", "fixed", "--out", (d / "t_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto image = render::ReadImage((d / "t_0030.png").string());
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->at(2, 2).a, 0.0f);     // the sky
  EXPECT_EQ(image->at(80, 85).a, 1.0f);   // the ground in front of the body
  EXPECT_EQ(image->at(80, 45).a, 1.0f);   // the body
  // JPEG has no alpha: refused before anything is written.
  r = RenderWith(d, {bend, "--frames", "30", "--background", "transparent", "--out",
                     (d / "j/t_####.jpg").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--background"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "j"));
}

// The label sits in the bottom left quarter (x < 240, y > 140 of 320x180).
TEST(RenderOverlays, LabelNoneFrameAndTimecodeChangeOnlyTheBottomLeft) {
  const fs::path d = TestDir();
  const std::string bend = testsupport::SampleDataPath("bend.bvh").string();
  for (const char* label : {"none", "frame", "timecode"}) {
    const auto r = RenderWith(d, {bend, "--frames", "45", "--size", "320x180", "--camera", "fixed",
                                  "--label", label, "--out", (d / label / "f_####.png").string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const auto none = render::ReadImage((d / "none/f_0045.png").string());
  const auto frame = render::ReadImage((d / "frame/f_0045.png").string());
  const auto timecode = render::ReadImage((d / "timecode/f_0045.png").string());
  ASSERT_TRUE(none.ok() && frame.ok() && timecode.ok());
  for (const render::Image* labelled : {&*frame, &*timecode}) {
    int inside = 0, outside = 0;
    for (int y = 0; y < 180; ++y) {
      for (int x = 0; x < 320; ++x) {
        if (none->at(x, y) == labelled->at(x, y)) continue;
        (x < 240 && y > 140 ? inside : outside) += 1;
      }
    }
    EXPECT_GT(inside, 20);
    EXPECT_EQ(outside, 0);
  }
  EXPECT_NE(frame->rgba, timecode->rgba);
  const auto bad =
      RenderWith(d, {bend, "--label", "seconds", "--out", (d / "bad/f_####.png").string()});
  EXPECT_EQ(bad.exit_code, 2);
}

// The elbow demo at its bent pose: the layered body (right half) is drawn in
// the heat ramp, the global one keeps its albedo, and the colour bar's top is
// the ramp's hottest colour.
TEST(RenderOverlays, DeltaColoursTheLayeredBodyAndDrawsItsScale) {
  const fs::path d = TestDir();
  const std::string rig = testsupport::SampleDataPath("elbow.json").string();
  auto r = RenderWith(d, {rig, "--frames", "60", "--size", "640x360", "--overlay", "delta",
                          "--supersample", "1", "--out", (d / "f_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto image = render::ReadImage((d / "f_0060.png").string());
  ASSERT_TRUE(image.ok());
  int bluish_left = 0, bluish_right = 0;
  for (int y = 40; y < 360; ++y) {
    for (int x = 0; x < 640; ++x) {
      const glm::vec4 c = image->at(x, y);
      const bool bluish = c.b > 2.0f * c.r && c.b > 0.1f;  // the ramp's cold end, lit
      (x < 320 ? bluish_left : bluish_right) += bluish ? 1 : 0;
    }
  }
  EXPECT_EQ(bluish_left, 0);
  EXPECT_GT(bluish_right, 1000);
  // The bar: 14 px wide, 12 px from the right edge, from y = 44 down.
  const glm::vec4 top = image->at(640 - 12 - 7, 45);
  const glm::vec3 hot = app::HeatRamp(1.0f);
  EXPECT_NEAR(top.r, hot.r, 0.04f);
  EXPECT_NEAR(top.g, hot.g, 0.04f);
  EXPECT_NEAR(top.b, hot.b, 0.04f);
  // Without patches there is no layer to colour.
  r = RenderWith(d, {testsupport::SampleDataPath("bend.bvh").string(), "--overlay", "delta",
                     "--out", (d / "bad/f_####.png").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--overlay"), std::string::npos) << r.err;
}

TEST(RenderOverlays, NiceScaleRoundsUpToOneTwoOrFive) {
  EXPECT_EQ(app::NiceScale(0.0f), 1.0f);
  EXPECT_FLOAT_EQ(app::NiceScale(0.3f), 0.5f);
  EXPECT_FLOAT_EQ(app::NiceScale(1.0f), 1.0f);
  EXPECT_FLOAT_EQ(app::NiceScale(1.2f), 2.0f);
  EXPECT_FLOAT_EQ(app::NiceScale(7.0f), 10.0f);
  EXPECT_FLOAT_EQ(app::NiceScale(42.0f), 50.0f);
}

}  // namespace
