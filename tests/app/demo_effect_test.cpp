// How much of the picture the patch layer changes in each shipped demo rig
// (issue 24), at the rig's own settings: its size, its camera (aimed at the
// effect), the two bodies side by side as `render` draws them. Measured at the
// frame where the layer moves the skin most (the largest elastic displacement
// for the elastic demos): the share of the image's pixels, inside the patch's
// screen region, where the two bodies differ by more than 8 levels of 255
// (8-bit sRGB, as the PNG frames store them). A pixel pair of the two halves
// counts twice over the whole frame, so the share is that of one half.
//
// Required: >= 2 % for the example-shape demos, >= 0.5 % for the elastic ones.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/frame_plan.h"
#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "render/output/image_io.h"
#include "render/renderer.h"
#include "support/example_demos.h"

namespace {

struct DemoCase {
  const char* demo;
  double required;  // share of the image, 0..1
};

int Level(float linear) {
  return static_cast<int>(std::lround(255.0f * render::LinearToSrgb(std::clamp(linear, 0.0f, 1.0f))));
}

struct EffectMeasure {
  int frame = 0;
  double moved = 0.0;   // largest |layered - global| over the vertices at that frame, model units
  double share = 0.0;   // of the image
  int region_pixels = 0;
};

EffectMeasure Measure(const std::string& demo) {
  EffectMeasure m;
  auto rig = app::LoadRig(testsupport::SampleDataPath(demo + ".json").string());
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  if (!rig.ok()) return m;
  auto source = app::LoadMotionSource(rig->motion, {.y_up = true});
  EXPECT_TRUE(source.ok());
  if (!source.ok()) return m;
  auto ch = app::MakeCharacter(std::move(*source), {}, app::RigBodyKind(*rig));
  EXPECT_TRUE(ch.ok());
  if (!ch.ok()) return m;
  const auto method = app::ParseGlobalMethod(rig->global);
  auto global = deform::FramePipeline::Create(*ch, *method, 1);
  auto layered = deform::FramePipeline::Create(*ch, *method, 1);
  EXPECT_TRUE(global.ok() && layered.ok());
  if (!global.ok() || !layered.ok()) return m;
  const base::Status layers = app::ApplyRigLayers(*rig, *ch, *layered);
  EXPECT_TRUE(layers.ok()) << layers.error().ToString();
  if (!layers.ok()) return m;

  app::FramePlanOptions options;
  options.fps = rig->fps;
  options.list_frames = false;
  auto plan = app::PlanFrames(ch->motion, options);
  EXPECT_TRUE(plan.ok());
  if (!plan.ok()) return m;
  // The frame where the layer moves the skin most.
  deform::DeformedFrame g, l;
  for (std::size_t i = 0; i < plan->count(); ++i) {
    const double t = plan->At(i).time_s;
    EXPECT_TRUE(global->Evaluate(t, g).ok() && layered->Evaluate(t, l).ok());
    for (std::size_t v = 0; v < g.positions.size(); ++v) {
      const double d = glm::length(g.positions[v] - l.positions[v]);
      if (d > m.moved) m.moved = d, m.frame = static_cast<int>(i);
    }
  }
  const app::OutputFrame of = plan->At(static_cast<std::size_t>(m.frame));
  EXPECT_TRUE(global->Evaluate(of.time_s, g).ok() && layered->Evaluate(of.time_s, l).ok());

  // The rig's camera, as `render` sets it up (side by side: half the width).
  app::CameraSpec spec;
  spec.mode = rig->render.camera;
  spec.elevation_deg = rig->render.elevation_deg.value_or(15.0f);
  spec.azimuth_deg = rig->render.azimuth_deg;
  spec.distance = rig->render.distance;
  spec.zoom = rig->render.zoom;
  const base::Status look = app::ResolveLookAt(rig->render.look_at, &*rig, *ch, spec);
  EXPECT_TRUE(look.ok()) << look.error().ToString();
  const glm::ivec2 size = rig->render.size;
  auto cameras = app::PlanCameras(global->character(), *plan, spec, {size.x / 2, size.y});
  EXPECT_TRUE(cameras.ok());
  if (!cameras.ok()) return m;
  const render::Camera camera = cameras->At(of.camera);
  render::RenderSettings settings;
  settings.width = size.x / 2;
  settings.height = size.y;
  settings.supersample = 2;
  settings.threads = 0;
  settings.ground_at_scene_min = false;
  settings.ground_y = cameras->ground_y();

  // The patch regions' pixels in either body: where turning their vertices red
  // changes the picture.
  std::vector<bool> in_region(static_cast<std::size_t>(ch->mesh.bind.num_vertices()), false);
  auto patches = app::BuildRigPatches(*rig, *ch);
  EXPECT_TRUE(patches.ok());
  if (!patches.ok()) return m;
  for (const deform::PatchSetup& p : *patches) {
    for (const int v : p.region) in_region[static_cast<std::size_t>(v)] = true;
  }
  std::vector<glm::vec3> plain(in_region.size(), glm::vec3(0.8f)), red = plain;
  for (std::size_t v = 0; v < red.size(); ++v) {
    if (in_region[v]) red[v] = glm::vec3(1.0f, 0.0f, 0.0f);
  }
  std::vector<bool> mask(static_cast<std::size_t>(settings.width) * settings.height, false);
  for (const deform::DeformedFrame* f : {&g, &l}) {
    render::SceneMesh a{.positions = f->positions, .normals = f->normals,
                        .triangles = ch->mesh.bind.triangles, .vertex_colors = plain};
    render::SceneMesh b = a;
    b.vertex_colors = red;
    const render::Image pa = render::Render(camera, {&a, 1}, {}, settings);
    const render::Image pb = render::Render(camera, {&b, 1}, {}, settings);
    for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = mask[i] || pa.rgba[i] != pb.rgba[i];
  }

  // The frame as `render` draws it, both halves compared.
  render::Renderer left_renderer, right_renderer;
  render::Image frame, scratch;
  settings.width = size.x;
  app::FrameDrawOptions draw;
  draw.frame_number = of.number;
  draw.side_by_side = true;
  const base::Status drawn = app::DrawCharacterFrame(*ch, g, &l, camera, settings, draw,
                                                     left_renderer, right_renderer, scratch, frame);
  EXPECT_TRUE(drawn.ok());
  const int half = size.x / 2;
  int differing = 0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 2; x < half; ++x) {  // not the divider
      if (!mask[static_cast<std::size_t>(y) * half + x]) continue;
      ++m.region_pixels;
      const glm::vec4 a = frame.at(x, y), b = frame.at(x + half, y);
      int worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(Level(a[c]) - Level(b[c])));
      differing += worst > 8 ? 1 : 0;
    }
  }
  m.share = static_cast<double>(differing) / (static_cast<double>(half) * size.y);
  return m;
}

class DemoEffectTest : public ::testing::TestWithParam<DemoCase> {};

TEST_P(DemoEffectTest, TheLayerChangesEnoughOfThePicture) {
  const DemoCase& c = GetParam();
  const EffectMeasure m = Measure(c.demo);
  std::printf("%s: frame %d (layer moves the skin up to %.2f), %d pixels in the patch region, "
              "%.2f %% of the image differ by more than 8/255 (required %.1f %%)\n",
              c.demo, m.frame, m.moved, m.region_pixels, 100.0 * m.share, 100.0 * c.required);
  EXPECT_GE(m.share, c.required);
}

INSTANTIATE_TEST_SUITE_P(
    Demos, DemoEffectTest,
    ::testing::Values(DemoCase{"elbow", 0.02}, DemoCase{"biceps", 0.02}, DemoCase{"knee", 0.02},
                      DemoCase{"shoulder", 0.02}, DemoCase{"hip", 0.02},
                      DemoCase{"belly_jump", 0.005}, DemoCase{"jowl", 0.005}),
    [](const auto& param_info) { return std::string(param_info.param.demo); });

}  // namespace
