// Golden frames of the whole per-frame path: FramePipeline (sampling, forward
// kinematics, global deformation, normals) and render::Renderer through
// app::DrawCharacterFrame, the function `patchskin render` draws with.
// Cases: the built-in demo walk under SWD (first, middle and last frame) and the
// synthetic elbow/knee bend ramp at its last frame (150 degrees), split SSD | SWD, and
// split SSD | SWD with the sample rig's elbow and knee patches (samples/data/
// elbow_knee_swd.json; no displacement yet, control points carried by SWD).

#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "app/demo_data.h"
#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "tools/synthetic.h"
#include "render/camera.h"
#include "support/golden.h"

namespace {

constexpr int kPipelineWidth = 256;
constexpr int kPipelineHeight = 144;

app::Character Demo() {
  app::MotionSourceOptions load;
  load.y_up = true;
  auto src = app::LoadBvhText(app::DemoBvhText(), "demo_walk.bvh", load);
  EXPECT_TRUE(src.ok());
  auto c = app::MakeCharacter(std::move(*src));
  EXPECT_TRUE(c.ok());
  return std::move(*c);
}

app::Character BendRamp() {
  app::MotionSource src;
  src.format = "bvh";
  src.skeleton = synthetic::MakeHumanoidSkeleton();
  auto motion = synthetic::MakeBendRamp(src.skeleton);
  EXPECT_TRUE(motion.ok());
  src.motion = std::move(*motion);
  auto c = app::MakeCharacter(std::move(src));
  EXPECT_TRUE(c.ok());
  return std::move(*c);
}

// The sample rig's elbow and knee patches, built on `c`'s bind mesh.
std::vector<deform::PatchSetup> SampleSwdPatches(const app::Character& c) {
  const std::filesystem::path rig_file =
      std::filesystem::path(GOLDEN_DIR) / ".." / ".." / "samples" / "data" / "elbow_knee_swd.json";
  auto rig = app::LoadRig(rig_file.string());
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  auto patches = app::BuildRigPatches(*rig, c);
  EXPECT_TRUE(patches.ok()) << patches.error().ToString();
  return std::move(*patches);
}

// Renders frame `frame` of `c` (SWD alone, or `left` | SWD when split; `patches`, if any,
// on the SWD side) with a fixed camera framing that frame from the front-left, as the
// command's cameras look.
render::Image Render(const app::Character& c, int frame, bool split,
                     std::vector<deform::PatchSetup> patches = {}) {
  const double t = frame * c.motion.frame_time_s;
  auto swd = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 1);
  EXPECT_TRUE(swd.ok()) << swd.error().ToString();
  const bool layered = !patches.empty();
  if (layered) {
    EXPECT_TRUE(swd->SetPatches(std::move(patches)).ok());
  }
  deform::DeformedFrame right, left;
  EXPECT_TRUE(swd->Evaluate(t, right).ok());
  if (split) {
    auto ssd = deform::FramePipeline::Create(c, deform::GlobalMethod::kSsd, 1);
    EXPECT_TRUE(ssd.ok());
    EXPECT_TRUE(ssd->Evaluate(t, left).ok());
  }
  const float aspect = static_cast<float>(kPipelineWidth) / static_cast<float>(kPipelineHeight);
  const float elevation = 0.26f;
  const glm::vec3 view_dir = -glm::normalize(glm::vec3(0.45f, 0.0f, 1.0f) * std::cos(elevation) +
                                             glm::vec3(0.0f, std::sin(elevation), 0.0f));
  const render::Camera camera = render::FrameBounds(right.bounds, 35.0f, aspect, view_dir);
  render::RenderSettings settings;
  settings.width = kPipelineWidth;
  settings.height = kPipelineHeight;
  settings.supersample = 2;
  settings.threads = 1;
  settings.ground_at_scene_min = false;
  settings.ground_y = right.bounds.min.y;
  render::Renderer renderer, right_renderer;
  render::Image image, scratch;
  const app::FrameDrawOptions options{.frame_number = frame,
                                      .left_label = split ? "ssd" : "",
                                      .right_label = !split    ? ""
                                                     : layered ? "swd + patches"
                                                               : "swd"};
  const base::Status s = split
                             ? app::DrawCharacterFrame(c, left, &right, camera, settings, options,
                                                       renderer, right_renderer, scratch, image)
                             : app::DrawCharacterFrame(c, right, nullptr, camera, settings, options,
                                                       renderer, right_renderer, scratch, image);
  EXPECT_TRUE(s.ok());
  return image;
}

struct PipelineCase {
  std::string name;
  int which;  // 0, 1, 2: demo first/middle/last; 3: bend ramp split; 4: same, with patches
};

void PrintTo(const PipelineCase& c, std::ostream* os) { *os << c.name; }

class PipelineGoldenTest : public ::testing::TestWithParam<PipelineCase> {};

TEST_P(PipelineGoldenTest, MatchesReference) {
  const PipelineCase& pc = GetParam();
  render::Image image;
  if (pc.which < 3) {
    static const app::Character demo = Demo();
    const int last = demo.motion.num_frames - 1;
    const int frame = pc.which == 0 ? 0 : pc.which == 1 ? last / 2 : last;
    image = Render(demo, frame, false);
  } else {
    const app::Character bend = BendRamp();
    image = Render(bend, bend.motion.num_frames - 1, true,
                   pc.which == 4 ? SampleSwdPatches(bend) : std::vector<deform::PatchSetup>{});
  }
  testsupport::ExpectMatchesGolden(image, pc.name, {});
}

INSTANTIATE_TEST_SUITE_P(Frames, PipelineGoldenTest,
                         ::testing::Values(PipelineCase{"demo_swd_first", 0},
                                           PipelineCase{"demo_swd_middle", 1},
                                           PipelineCase{"demo_swd_last", 2},
                                           PipelineCase{"bend_split_ssd_swd", 3},
                                           PipelineCase{"bend_split_ssd_swd_patches", 4}),
                         [](const auto& test_info) { return test_info.param.name; });

}  // namespace
