// `--layer auto` and `patchskin rig auto` (app/auto_rig.h, app/rig_writer.h):
//   - placement on a humanoid found by topology: the joints the regions name are
//     the elbow, shoulder, knee, hip, spine and head joints of the capture (its
//     joint names are read here only to check what the topology found), and the
//     hinge sides point the way the capture bends them;
//   - a quadruped (tests/data/bvh/quadruped.bvh: horizontal spine, four legs, a
//     tail) gets only an elastic belly on its underside, and a note;
//   - the written rig reads back through LoadRig to the same rig, and renders
//     the same frames as `render CAPTURE --layer auto`, pixel for pixel.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/auto_rig.h"
#include "app/rig_file.h"
#include "app/rig_writer.h"
#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;

const app::RigPatch* Find(const app::Rig& rig, const std::string& name) {
  for (const app::RigPatch& p : rig.patches) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

app::AutoRig AutoRigOfTheWalk() {
  auto made = app::MakeAutoRig(testsupport::SampleDataPath("demo_walk.bvh").string(), "generated",
                               "", true);
  EXPECT_TRUE(made.ok()) << made.error().ToString();
  return made.ok() ? std::move(*made) : app::AutoRig{};
}

TEST(AutoRig, PlacesTheDemosPatchesOnTheWalksJoints) {
  const app::AutoRig a = AutoRigOfTheWalk();
  ASSERT_EQ(a.rig.patches.size(), 12u);
  const std::pair<const char*, const char*> expected[] = {
      {"left_elbow_back", "LeftForeArm"}, {"left_biceps", "LeftForeArm"},
      {"left_shoulder_top", "LeftArm"},   {"left_knee_front", "LeftLeg"},
      {"left_hip_back", "LeftUpLeg"},     {"right_elbow_back", "RightForeArm"},
      {"right_knee_front", "RightLeg"},   {"right_hip_back", "RightUpLeg"},
      {"jowl", "Head"}};
  for (const auto& [name, joint] : expected) {
    const app::RigPatch* p = Find(a.rig, name);
    ASSERT_NE(p, nullptr) << name;
    EXPECT_EQ(p->region.joint, joint) << name;
  }
  // The walk faces +Z and is Y-up: a knee's front and the belly face +Z, the
  // back of the hip -Z, the top of the shoulder +Y; the elbows bend forwards
  // in this walk, so their backs face -Z.
  EXPECT_GT(Find(a.rig, "left_knee_front")->region.side.z, 0.9f);
  EXPECT_LT(Find(a.rig, "left_hip_back")->region.side.z, -0.9f);
  EXPECT_GT(Find(a.rig, "left_shoulder_top")->region.side.y, 0.9f);
  EXPECT_LT(Find(a.rig, "left_elbow_back")->region.side.z, -0.9f);
  EXPECT_GT(Find(a.rig, "belly")->region.side.z, 0.9f);
  ASSERT_TRUE(Find(a.rig, "belly")->elastic.has_value());
  ASSERT_TRUE(Find(a.rig, "jowl")->elastic.has_value());
  // A computed volume example at the walk's deepest knee bend (61 degrees at
  // frame 24 for the left knee, frame 39 for the right: the gait's half cycle).
  const app::RigPatch* knee = Find(a.rig, "left_knee_front");
  ASSERT_EQ(knee->examples.size(), 1u);
  EXPECT_EQ(knee->examples[0].auto_kind, "volume");
  EXPECT_EQ(knee->examples[0].pose.frame, 24);
  EXPECT_EQ(Find(a.rig, "right_knee_front")->examples.at(0).pose.frame, 39);
  // Sizes follow the bones: the biceps patch reaches further than the elbow's.
  EXPECT_GT(Find(a.rig, "left_biceps")->region.radius, Find(a.rig, "left_elbow_back")->region.radius);
}

TEST(AutoRig, QuadrupedGetsAnElasticBellyUnderItsSpineAndANote) {
  auto made = app::MakeAutoRig(testsupport::TestDataPath("bvh/quadruped.bvh").string(), "generated",
                               "", true);
  ASSERT_TRUE(made.ok()) << made.error().ToString();
  ASSERT_EQ(made->rig.patches.size(), 1u);
  const app::RigPatch& belly = made->rig.patches[0];
  EXPECT_EQ(belly.name, "belly");
  EXPECT_TRUE(belly.elastic.has_value());
  EXPECT_LT(belly.region.side.y, -0.95f) << "the belly is the underside of a horizontal spine";
  bool noted = false;
  for (const std::string& n : made->notes) noted = noted || n.find("not a humanoid") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(AutoRig, WrittenRigReadsBackToTheSameRig) {
  const app::AutoRig a = AutoRigOfTheWalk();
  const fs::path dir = testsupport::TestDir("auto_rig");
  auto text = app::WriteRigJson(a.rig, dir.string());
  ASSERT_TRUE(text.ok()) << text.error().ToString();
  const fs::path file = dir / "walk.json";
  { std::ofstream(file) << *text; }
  auto back = app::LoadRig(file.string());
  ASSERT_TRUE(back.ok()) << back.error().ToString() << "\n" << *text;
  EXPECT_EQ(back->character, a.rig.character);
  EXPECT_TRUE(fs::equivalent(back->motion, a.rig.motion));
  EXPECT_EQ(back->global, a.rig.global);
  EXPECT_EQ(back->render.size, a.rig.render.size);
  EXPECT_EQ(back->render.camera, a.rig.render.camera);
  EXPECT_EQ(back->render.split, a.rig.render.split);
  ASSERT_EQ(back->patches.size(), a.rig.patches.size());
  for (std::size_t i = 0; i < a.rig.patches.size(); ++i) {
    const app::RigPatch &p = a.rig.patches[i], &q = back->patches[i];
    SCOPED_TRACE(p.name);
    EXPECT_EQ(q.name, p.name);
    EXPECT_EQ(q.region.kind, p.region.kind);
    EXPECT_EQ(q.region.joint, p.region.joint);
    EXPECT_EQ(q.region.radius, p.region.radius);
    EXPECT_EQ(q.region.side, p.region.side);
    EXPECT_EQ(q.region.half_angle_deg, p.region.half_angle_deg);
    EXPECT_EQ(q.region.min_bone_weight, p.region.min_bone_weight);
    EXPECT_EQ(q.cylinder, p.cylinder);
    EXPECT_EQ(q.grid, p.grid);
    EXPECT_EQ(q.sampling, p.sampling);
    EXPECT_EQ(q.border_width, p.border_width);
    ASSERT_EQ(q.examples.size(), p.examples.size());
    for (std::size_t k = 0; k < p.examples.size(); ++k) {
      EXPECT_EQ(q.examples[k].pose.frame, p.examples[k].pose.frame);
      EXPECT_EQ(q.examples[k].auto_kind, p.examples[k].auto_kind);
    }
    ASSERT_EQ(q.elastic.has_value(), p.elastic.has_value());
    if (p.elastic) {
      EXPECT_EQ(q.elastic->params.frequency_hz, p.elastic->params.frequency_hz);
      EXPECT_EQ(q.elastic->params.damping_ratio, p.elastic->params.damping_ratio);
      EXPECT_EQ(q.elastic->params.gain, p.elastic->params.gain);
      EXPECT_EQ(q.elastic->params.max_displacement, p.elastic->params.max_displacement);
    }
  }
  // Writing what was read gives the same text: nothing is lost either way.
  auto again = app::WriteRigJson(*back, dir.string());
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, *text);
}

// Renders frames 0, 20, 40 of the jump into `folder` with `args` first.
void RenderAutoRig(std::vector<std::string> args, const fs::path& folder) {
  for (const char* a : {"--frames", "0:40:20", "--size", "320x180", "--supersample", "1", "--quiet",
                        "--no-video", "--no-sheet", "--out"}) {
    args.push_back(a);
  }
  args.push_back((folder / "f_####.png").string());
  const testsupport::ProcessResult r = testsupport::RunPatchskin(args, folder.parent_path() / "logs");
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// Frames 0, 20 and 40 (as RenderAutoRig writes them) are the same bytes in folders
// `a` and `b`, and each differs from the one in `other` (else the comparison
// would show nothing).
void ExpectSameFramesUnlikeThird(const fs::path& a, const fs::path& b, const fs::path& other,
                                 const char* why_same) {
  for (const char* f : {"f_0000.png", "f_0020.png", "f_0040.png"}) {
    auto x = render::ReadImage((a / f).string());
    auto y = render::ReadImage((b / f).string());
    auto z = render::ReadImage((other / f).string());
    ASSERT_TRUE(x.ok() && y.ok() && z.ok()) << f;
    EXPECT_TRUE(x->rgba == y->rgba) << f << ": " << why_same;
    EXPECT_TRUE(x->rgba != z->rgba) << f << ": the same as " << other.filename().string();
  }
}

TEST(AutoRig, RigFileRendersTheFramesOfLayerAuto) {
  const fs::path dir = testsupport::TestDir("auto_rig");
  const std::string capture = testsupport::SampleDataPath("jump.bvh").string();
  const fs::path rig = dir / "jump.json";
  const testsupport::ProcessResult written =
      testsupport::RunPatchskin({"rig", "auto", capture, "--out", rig.string()}, dir / "logs");
  ASSERT_EQ(written.exit_code, 0) << written.err;
  EXPECT_NE(written.err.find("patches"), std::string::npos);
  RenderAutoRig({"render", capture, "--layer", "auto"}, dir / "layer");
  RenderAutoRig({"render", rig.string()}, dir / "rig");
  RenderAutoRig({"render", capture}, dir / "global");
  // The layer view is the comparison: twice the body, so not the global image.
  ExpectSameFramesUnlikeThird(dir / "layer", dir / "rig", dir / "global", "rig.json and --layer auto differ");
}

// An up axis given to `rig auto` is written into the rig (motion.up), so the
// rig renders the capture as `--layer auto --up z` does, not as detected.
TEST(AutoRig, RigRecordsTheUpAxisItWasMadeWith) {
  const fs::path dir = testsupport::TestDir("auto_rig");
  const std::string capture = testsupport::SampleDataPath("jump.bvh").string();
  const fs::path rig = dir / "jump_z.json";
  const testsupport::ProcessResult written = testsupport::RunPatchskin(
      {"rig", "auto", capture, "--up", "z", "--out", rig.string()}, dir / "logs");
  ASSERT_EQ(written.exit_code, 0) << written.err;
  EXPECT_NE(testsupport::SlurpFile(rig).find(R"("up": "z")"), std::string::npos) << testsupport::SlurpFile(rig);
  RenderAutoRig({"render", capture, "--layer", "auto", "--up", "z"}, dir / "layer_z");
  RenderAutoRig({"render", rig.string()}, dir / "rig_z");
  RenderAutoRig({"render", capture, "--layer", "auto"}, dir / "layer_detected");
  ExpectSameFramesUnlikeThird(dir / "layer_z", dir / "rig_z", dir / "layer_detected", "the rig lost --up z");
}

TEST(AutoRig, BadLayerAndRigInputAreRefused) {
  const fs::path dir = testsupport::TestDir("auto_rig");
  const std::string capture = testsupport::SampleDataPath("jump.bvh").string();
  auto r = testsupport::RunPatchskin({"render", capture, "--layer", "magic"}, dir / "logs");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--layer"), std::string::npos) << r.err;
  r = testsupport::RunPatchskin(
      {"render", testsupport::SampleDataPath("elbow.json").string(), "--layer", "auto"}, dir / "logs");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("rig file"), std::string::npos) << r.err;
  r = testsupport::RunPatchskin({"rig", "auto", (dir / "missing.bvh").string()}, dir / "logs");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing.bvh"), std::string::npos) << r.err;
}

}  // namespace
