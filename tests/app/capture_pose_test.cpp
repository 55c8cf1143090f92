// Captures that looked wrong (issue 27): a capture whose rest pose and animated
// poses disagree on the up axis is detected from its poses and rendered
// standing; `--up` still overrides.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "app/character_motion.h"
#include "app/frame_plan.h"
#include "app/pipeline.h"
#include "mocap/bvh_reader.h"
#include "support/data_paths.h"
#include "support/posed_bvh.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;

struct UpCase {
  const char* name;
  bool z_up_offsets;
  float root_x_deg;
  mocap::UpAxis expected;
};

// Rest and poses agree (Y, Z), and the two mismatches: Z-up OFFSETs stood Y-up
// by a root rotation of -90 degrees about X in every frame, and Y-up OFFSETs
// laid Z-up by +90.
constexpr UpCase kCases[] = {
    {"y_agree", false, 0.0f, mocap::UpAxis::kY},
    {"z_agree", true, 0.0f, mocap::UpAxis::kZ},
    {"z_rest_y_poses", true, -90.0f, mocap::UpAxis::kY},
    {"y_rest_z_poses", false, 90.0f, mocap::UpAxis::kZ},
};

fs::path WriteCase(const UpCase& c) {
  const fs::path p = testsupport::TestOutputPath(std::string("capture_pose/") + c.name + ".bvh");
  std::ofstream(p) << testsupport::HumanoidWalkBvh(c.z_up_offsets, c.root_x_deg);
  return p;
}

// Height (Y, after loading Y-up) over depth (Z; the T-pose arms span X) of the
// deformed body at frame 10: about 2.5 standing, below 1 lying on the floor.
float Uprightness(const fs::path& bvh, std::optional<mocap::UpAxis> up = {}) {
  mocap::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true, up);
  EXPECT_TRUE(ch.ok()) << ch.error().ToString();
  if (!ch.ok()) return 0.0f;
  mocap::Result<app::FramePipeline> p = app::FramePipeline::Create(*ch, app::GlobalMethod::kSsd, 1);
  EXPECT_TRUE(p.ok());
  if (!p.ok()) return 0.0f;
  app::DeformedFrame frame;
  EXPECT_TRUE(p->Evaluate(10.0 / 30.0, frame).ok());
  const glm::vec3 size = frame.bounds.size();
  return size.y / size.z;
}

TEST(CapturePose, UpAxisComesFromTheAnimatedPoses) {
  for (const UpCase& c : kCases) {
    SCOPED_TRACE(c.name);
    const mocap::Result<mocap::BvhFile> file =
        mocap::ParseBvh(testsupport::HumanoidWalkBvh(c.z_up_offsets, c.root_x_deg), c.name);
    ASSERT_TRUE(file.ok()) << file.error().ToString();
    EXPECT_EQ(file->skeleton.info.up_axis, c.expected);
    EXPECT_EQ(file->skeleton.info.up_axis_source, mocap::UpAxisSource::kAnimatedPoses);
    // The rest pose alone says the offsets' axis.
    EXPECT_EQ(mocap::DetectBvhUpAxis(file->skeleton),
              c.z_up_offsets ? mocap::UpAxis::kZ : mocap::UpAxis::kY);
  }
}

// Rendered (loaded Y-up as render and export load it) every case stands: the
// body is more than 1.5 times as tall as it is deep. Given the wrong axis
// with --up, the mismatched capture lies down again.
TEST(CapturePose, EveryCaseIsRenderedStanding) {
  for (const UpCase& c : kCases) {
    SCOPED_TRACE(c.name);
    EXPECT_GT(Uprightness(WriteCase(c)), 1.5f);
  }
  const fs::path mismatched = WriteCase(kCases[2]);
  EXPECT_LT(Uprightness(mismatched, mocap::UpAxis::kZ), 1.0f);
  EXPECT_GT(Uprightness(mismatched, mocap::UpAxis::kY), 1.5f);
}

// inspect says which axis it used and what decided it.
TEST(CapturePose, InspectSaysWhichUpAxisAndWhy) {
  const fs::path bvh = WriteCase(kCases[2]);
  const fs::path logs = testsupport::TestOutputPath("capture_pose/logs/x").parent_path();
  testsupport::ProcessResult r = testsupport::RunPatchskin({"inspect", bvh.string()}, logs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("up axis:     Y (animated poses)"), std::string::npos) << r.out;
  r = testsupport::RunPatchskin({"inspect", bvh.string(), "--up", "z", "--json"}, logs);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"up_axis\": \"Z\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"up_axis_from\": \"given\""), std::string::npos) << r.out;
  r = testsupport::RunPatchskin({"inspect", bvh.string(), "--up", "x"}, logs);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.FirstErrLine(), "--up: error: expected y or z, found 'x'");
}

// The follow camera at 1280x720 keeps the body in the picture: the largest
// |x| or |y| in normalised device coordinates over a quarter of the body's
// vertices, at every output frame (infinity when a vertex is behind the eye).
float WorstFollowExtent(const app::Character& ch) {
  mocap::Result<app::FramePipeline> p = app::FramePipeline::Create(ch, app::GlobalMethod::kSsd, 1);
  EXPECT_TRUE(p.ok());
  mocap::Result<app::FramePlan> plan = app::PlanFrames(ch.motion, {.frames = "", .list_frames = false});
  EXPECT_TRUE(plan.ok());
  if (!p.ok() || !plan.ok()) return INFINITY;
  mocap::Result<app::CameraPlan> cameras =
      app::CameraPlan::Create(*p, *plan, "follow", 15.0f, {1280, 720});
  EXPECT_TRUE(cameras.ok());
  if (!cameras.ok()) return INFINITY;
  app::DeformedFrame frame;
  float worst = 0.0f;
  for (std::size_t i = 0; i < plan->count(); ++i) {
    const app::OutputFrame of = plan->At(i);
    EXPECT_TRUE(p->Evaluate(of.time_s, frame).ok());
    const render::Camera camera = cameras->At(of);
    const glm::mat4 clip_from_world = camera.ClipFromView() * camera.ViewFromWorld();
    for (std::size_t v = 0; v < frame.positions.size(); v += 4) {
      const glm::vec4 c = clip_from_world * glm::vec4(frame.positions[v], 1.0f);
      if (!(c.w > 0.0f)) return INFINITY;
      worst = std::max({worst, std::abs(c.x / c.w), std::abs(c.y / c.w)});
    }
  }
  return worst;
}

// Inside the frame with a margin of 5% of its width and height on every side.
constexpr float kMaxFollowExtent = 0.9f;

TEST(CapturePose, FollowCameraKeepsGeneratedBodiesInFrame) {
  const struct {
    const char* name;
    std::string text;
  } cases[] = {
      {"quadruped_run", testsupport::QuadrupedRunBvh()},
      {"quadruped_trot", testsupport::QuadrupedRunBvh(150.0f)},
      {"crawl", testsupport::HumanoidCrawlBvh()},
      {"walk", testsupport::HumanoidWalkBvh(false, 0.0f, 90)},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path bvh = testsupport::TestOutputPath(std::string("capture_pose/") + c.name + ".bvh");
    std::ofstream(bvh) << c.text;
    mocap::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true);
    ASSERT_TRUE(ch.ok()) << ch.error().ToString();
    EXPECT_EQ(ch->skeleton.info.up_axis_source, mocap::UpAxisSource::kAnimatedPoses);
    EXPECT_LE(WorstFollowExtent(*ch), kMaxFollowExtent);
  }
}

TEST(CapturePose, FollowCameraKeepsEveryRealCaptureInFrame) {
  if (!testsupport::HaveSharedData()) GTEST_SKIP() << "no shared data at " << SHARED_DATA_DIR;
  int checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(testsupport::SharedDataPath(""))) {
    const std::string ext = e.path().extension().string();
    if (ext != ".bvh" && ext != ".glb" && ext != ".gltf") continue;
    SCOPED_TRACE(e.path().string());
    mocap::Result<app::Character> ch = app::LoadCommandCharacter(e.path().string(), "", true);
    ASSERT_TRUE(ch.ok()) << ch.error().ToString();
    const float worst = WorstFollowExtent(*ch);
    EXPECT_LE(worst, kMaxFollowExtent);
    std::printf("%-60s %.3f\n", e.path().filename().string().c_str(), worst);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// Bandai Namco's joint_Root stays at the origin while the hips walk away: the
// body has no part (no tube, no weight) on it, so at every sampled frame the
// deformed body is no wider or deeper than a person (it grew a limb to where
// the body was bound, over 4 m long, before).
TEST(CapturePose, BandaiPositioningRootGrowsNoLimb) {
  int checked = 0;
  for (const char* name : {"dataset-1_walk_normal_001.bvh", "dataset-2_run_active_034.bvh"}) {
    const fs::path bvh = testsupport::SharedDataPath(std::string("bvh/bandai_namco/") + name);
    if (!fs::exists(bvh)) continue;
    SCOPED_TRACE(name);
    mocap::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true);
    ASSERT_TRUE(ch.ok()) << ch.error().ToString();
    mocap::Result<app::FramePipeline> p = app::FramePipeline::Create(*ch, app::GlobalMethod::kSsd, 1);
    ASSERT_TRUE(p.ok());
    app::DeformedFrame frame;
    for (int f = 0; f < ch->motion.num_frames; f += 10) {
      ASSERT_TRUE(p->Evaluate(f * ch->motion.frame_time_s, frame).ok());
      const glm::vec3 size = frame.bounds.size();  // centimetres
      EXPECT_LT(std::max(size.x, size.z), 150.0f) << "frame " << f;
      EXPECT_GT(size.y, 120.0f) << "frame " << f;
    }
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no Bandai Namco capture in " << testsupport::SharedDataPath("bvh/bandai_namco");
}

// A capture whose hips hang from two joints animated by position channels
// alone ("World" on the floor at the origin, "Reference" 5 cm above it) walks
// 2.7 m away: neither grows a part of the body, so at every frame the body has
// the bounds of the same walk without them, 5 cm higher (before, a limb ran
// from the origin to the hips).
TEST(CapturePose, PositionOnlyJointsAboveTheHipsGrowNoLimb) {
  std::string walk = testsupport::HumanoidWalkBvh(false, 0.0f, 90);
  const std::size_t root = walk.find("ROOT Hips");
  const std::size_t motion = walk.find("MOTION");
  ASSERT_NE(root, std::string::npos);
  ASSERT_NE(motion, std::string::npos);
  walk.replace(motion, 0, "}\n}\n");
  walk.replace(root, std::string("ROOT Hips").size(),
               "ROOT World\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
               "JOINT Reference\n{\nOFFSET 0 5 0\nCHANNELS 3 Xposition Yposition Zposition\nJOINT Hips");
  // Every frame line gains the two joints' channels first: World at the
  // origin, Reference 5 cm above it.
  std::string out = walk.substr(0, walk.find("Frame Time:"));
  std::istringstream rest(walk.substr(out.size()));
  std::string line;
  std::getline(rest, line);
  out += line + "\n";
  while (std::getline(rest, line)) {
    if (!line.empty()) out += "0 0 0 0 5 0 " + line + "\n";
  }
  const fs::path bvh = testsupport::TestDir("capture_pose") / "world_reference_walk.bvh";
  std::ofstream(bvh) << out;
  mocap::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true);
  ASSERT_TRUE(ch.ok()) << ch.error().ToString();
  for (const char* name : {"World", "Reference"}) {
    const int j = ch->skeleton.FindJoint(name);
    ASSERT_GE(j, 0) << name;
    EXPECT_EQ(std::find(ch->mesh.skin_joints.begin(), ch->mesh.skin_joints.end(), j), ch->mesh.skin_joints.end())
        << name << " carries skin";
  }
  // The same walk without the two joints: the same body, frame by frame.
  const fs::path plain_bvh = testsupport::TestDir("capture_pose") / "plain_walk.bvh";
  std::ofstream(plain_bvh) << testsupport::HumanoidWalkBvh(false, 0.0f, 90);
  mocap::Result<app::Character> plain = app::LoadCommandCharacter(plain_bvh.string(), "", true);
  ASSERT_TRUE(plain.ok()) << plain.error().ToString();
  mocap::Result<app::FramePipeline> p = app::FramePipeline::Create(*ch, app::GlobalMethod::kSsd, 1);
  mocap::Result<app::FramePipeline> q = app::FramePipeline::Create(*plain, app::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(p.ok() && q.ok());
  app::DeformedFrame frame, plain_frame;
  for (int f = 0; f < ch->motion.num_frames; f += 10) {
    ASSERT_TRUE(p->Evaluate(f * ch->motion.frame_time_s, frame).ok());
    ASSERT_TRUE(q->Evaluate(f * ch->motion.frame_time_s, plain_frame).ok());
    for (int a = 0; a < 3; ++a) {  // centimetres; the hips are 2.7 m from World at the end
      EXPECT_NEAR(frame.bounds.min[a], plain_frame.bounds.min[a] + (a == 1 ? 5.0f : 0.0f), 1.0f)
          << "frame " << f << " axis " << a;
      EXPECT_NEAR(frame.bounds.max[a], plain_frame.bounds.max[a] + (a == 1 ? 5.0f : 0.0f), 1.0f)
          << "frame " << f << " axis " << a;
    }
  }
}

}  // namespace
