// Patches on `--global swd` (ALGORITHMS.md 0 and 2.3): the control points are bound to the
// sweeps like skin vertices and carried by SwdJob. At the bind pose the layered body is the
// bind mesh; bent, the patch surface follows the SWD body (no displacement yet, so the
// rebuilt vertices stay near the global result); any thread count gives the same bits; a
// rig file with "global": "swd" and patches renders.

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;

// The sample bend (elbows and knees from straight to 150 degrees) on the mannequin.
app::Character BendCharacter() {
  auto src =
      app::LoadMotionSource(testsupport::SampleDataPath("bend.bvh").string(), {.y_up = true});
  EXPECT_TRUE(src.ok()) << src.error().ToString();
  auto c = app::MakeCharacter(std::move(*src));
  EXPECT_TRUE(c.ok()) << c.error().ToString();
  return std::move(*c);
}

std::vector<deform::PatchSetup> SampleSwdPatches(const app::Character& c) {
  auto rig = app::LoadRig(testsupport::SampleDataPath("elbow_knee_swd.json").string());
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  EXPECT_EQ(rig->global, "swd");
  auto patches = app::BuildRigPatches(*rig, c);
  EXPECT_TRUE(patches.ok()) << patches.error().ToString();
  EXPECT_FALSE(patches->empty());
  return std::move(*patches);
}

// Diagonal of the patch's rest control grid (model units).
float PatchSize(const deform::PatchSetup& p) {
  return glm::length(deform::ComputeBounds(p.rest_control).size());
}

TEST(SwdPatches, LayeredBodyAtTheBindPoseIsTheBindMesh) {
  app::Character c = BendCharacter();
  ASSERT_FALSE(c.bound_at_first_frame);
  c.motion = mocap::Motion{};  // no frames: the rest pose, which is the bind pose
  const std::vector<deform::PatchSetup> patches = SampleSwdPatches(c);
  std::vector<std::vector<int>> regions;
  std::vector<float> sizes;
  for (const deform::PatchSetup& p : patches) regions.push_back(p.region), sizes.push_back(PatchSize(p));
  auto pipeline = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 2);
  ASSERT_TRUE(pipeline.ok()) << pipeline.error().ToString();
  ASSERT_TRUE(pipeline->SetPatches(patches).ok());
  EXPECT_EQ(pipeline->num_patches(), static_cast<int>(patches.size()));
  deform::DeformedFrame f;
  ASSERT_TRUE(pipeline->Evaluate(0.0, f).ok());
  for (std::size_t k = 0; k < regions.size(); ++k) {
    double worst = 0.0;
    for (const int v : regions[k]) {
      const auto vs = static_cast<std::size_t>(v);
      worst = std::max(worst, static_cast<double>(glm::distance(f.positions[vs], c.mesh.bind.positions[vs])));
    }
    EXPECT_LT(worst / sizes[k], testsupport::kRebuildRelTol) << "patch " << k;
  }
}

TEST(SwdPatches, PatchesFollowTheSweepsWhenBentForAnyThreadCount) {
  const app::Character c = BendCharacter();
  const std::vector<deform::PatchSetup> patches = SampleSwdPatches(c);
  auto global = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 1);
  auto one = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 1);
  auto two = deform::FramePipeline::Create(c, deform::GlobalMethod::kSwd, 2);
  ASSERT_TRUE(global.ok() && one.ok() && two.ok());
  ASSERT_TRUE(one->SetPatches(patches).ok());
  ASSERT_TRUE(two->SetPatches(patches).ok());
  deform::DeformedFrame g, a, b;
  for (double t : {0.5 * c.motion.duration_s(), c.motion.duration_s()}) {
    ASSERT_TRUE(global->Evaluate(t, g).ok());
    ASSERT_TRUE(one->Evaluate(t, a).ok());
    ASSERT_TRUE(two->Evaluate(t, b).ok());
    EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(),
                             a.positions.size() * sizeof(glm::vec3)))
        << "thread count changed the layered result at t = " << t;
    for (std::size_t k = 0; k < patches.size(); ++k) {
      // With no displacement the carried surface is the SWD body's: the rebuilt region
      // stays within a small share of the patch of the global result (a control point
      // bound to the wrong sweep moves by a limb's length).
      double worst = 0.0;
      for (const int v : patches[k].region) {
        const auto vs = static_cast<std::size_t>(v);
        worst = std::max(worst, static_cast<double>(glm::distance(a.positions[vs], g.positions[vs])));
      }
      const double share = worst / PatchSize(patches[k]);
      std::printf("t = %.2f s patch %zu: largest layered - global %.4f of the patch size\n", t, k, share);
      EXPECT_LT(share, testsupport::kSwdPatchFollowRelTol) << "patch " << k << " at t = " << t;
    }
  }
}

TEST(SwdPatches, RenderCommandRendersTheSwdSampleRig) {
  const fs::path dir = testsupport::TestOutputPath("swd_patches/render/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  const testsupport::ProcessResult r = testsupport::RunPatchskin(
      {"render", testsupport::SampleDataPath("elbow_knee_swd.json").string(), "--frames", "45:45",
       "--no-video", "--no-sheet", "--quiet", "--out", (dir / "f_####.png").string()},
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto img = render::ReadImage((dir / "f_0045.png").string());
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img->width, 1280);  // the rig's render.size
  EXPECT_EQ(img->height, 720);
}

}  // namespace
