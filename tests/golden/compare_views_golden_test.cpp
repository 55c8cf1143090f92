// Golden frames of the views that show the patch layer (issue 24): the elbow
// demo (samples/data/elbow.json) at its bent pose, seen by its own camera,
// two whole bodies side by side (ssd | ssd + patches) as `render` draws them,
// plain, with the patch regions tinted, and with the layer's displacement
// coloured (with its colour bar). 320x180, one thread.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/frame_plan.h"
#include "app/frame_render.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "render/renderer.h"
#include "support/example_demos.h"
#include "support/golden.h"

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 180;
constexpr int kFrame = 60;  // the elbow at 150 degrees

enum class View { kPlain, kPatches, kDelta };

render::Image RenderElbow(View view) {
  const auto demo = testsupport::LoadDemo("elbow");
  EXPECT_TRUE(demo->error.empty()) << demo->error;
  if (!demo->error.empty()) return render::Image(kWidth, kHeight);
  const app::Character& ch = demo->character;
  app::FramePlanOptions options;
  options.list_frames = false;
  auto plan = app::PlanFrames(ch.motion, options);
  EXPECT_TRUE(plan.ok());
  app::CameraSpec spec;
  spec.mode = demo->rig.render.camera;
  spec.elevation_deg = demo->rig.render.elevation_deg.value_or(15.0f);
  spec.azimuth_deg = demo->rig.render.azimuth_deg;
  spec.zoom = demo->rig.render.zoom;
  EXPECT_TRUE(app::ResolveLookAt(demo->rig.render.look_at, &demo->rig, ch, spec).ok());
  auto cameras = app::PlanCameras(demo->global->character(), *plan, spec, {kWidth / 2, kHeight});
  EXPECT_TRUE(cameras.ok());
  if (!cameras.ok()) return render::Image(kWidth, kHeight);
  const app::OutputFrame of = plan->At(kFrame);
  deform::DeformedFrame left, right;
  EXPECT_TRUE(demo->global->Evaluate(of.time_s, left).ok());
  EXPECT_TRUE(demo->layered->Evaluate(of.time_s, right).ok());

  render::RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  settings.supersample = 2;
  settings.threads = 1;
  settings.ground_at_scene_min = false;
  settings.ground_y = cameras->ground_y();
  app::FrameDrawOptions draw;
  draw.frame_number = of.number;
  draw.left_label = "ssd";
  draw.right_label = "ssd + patches";
  draw.side_by_side = true;
  std::vector<glm::vec3> tint, heat;
  if (view == View::kPatches) {
    tint = app::PatchTint(demo->patches, ch.mesh.bind.num_vertices(), ch.mesh.bind.colors);
    draw.left_colors = tint;
    draw.right_colors = tint;
  } else if (view == View::kDelta) {
    float largest = 0.0f;
    for (std::size_t v = 0; v < left.positions.size(); ++v) {
      largest = std::max(largest, glm::length(right.positions[v] - left.positions[v]));
    }
    draw.color_bar_scale = app::NiceScale(largest);
    app::DisplacementColors(left.positions, right.positions, draw.color_bar_scale, heat);
    draw.right_colors = heat;
  }
  render::Renderer a, b;
  render::Image image, scratch;
  EXPECT_TRUE(app::DrawCharacterFrame(ch, left, &right, cameras->At(of.camera), settings, draw, a,
                                      b, scratch, image)
                  .ok());
  return image;
}

TEST(CompareViewsGolden, ElbowSideBySide) {
  testsupport::ExpectMatchesGolden(RenderElbow(View::kPlain), "compare_elbow_60", {});
}

TEST(CompareViewsGolden, ElbowPatchOverlay) {
  testsupport::ExpectMatchesGolden(RenderElbow(View::kPatches), "overlay_patches_elbow_60", {});
}

TEST(CompareViewsGolden, ElbowDeltaOverlay) {
  testsupport::ExpectMatchesGolden(RenderElbow(View::kDelta), "overlay_delta_elbow_60", {});
}

}  // namespace
