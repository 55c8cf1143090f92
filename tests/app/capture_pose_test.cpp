// Captures that looked wrong (issue 27): a capture whose rest pose and animated
// poses disagree on the up axis is detected from its poses and rendered
// standing; `--up` still overrides.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "app/character_motion.h"
#include "app/frame_plan.h"
#include "app/character.h"
#include "deform/pipeline/body_tracker.h"
#include "deform/pipeline/frame_pipeline.h"
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
  base::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true, up);
  EXPECT_TRUE(ch.ok()) << ch.error().ToString();
  if (!ch.ok()) return 0.0f;
  base::Result<deform::FramePipeline> p =
      deform::FramePipeline::Create(*ch, deform::GlobalMethod::kSsd, 1);
  EXPECT_TRUE(p.ok());
  if (!p.ok()) return 0.0f;
  deform::DeformedFrame frame;
  EXPECT_TRUE(p->Evaluate(10.0 / 30.0, frame).ok());
  const glm::vec3 size = frame.bounds.size();
  return size.y / size.z;
}

TEST(CapturePose, UpAxisComesFromTheAnimatedPoses) {
  for (const UpCase& c : kCases) {
    SCOPED_TRACE(c.name);
    const base::Result<mocap::BvhFile> file =
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

// What the follow camera at 1280x720 sees of a capture, over every output frame:
// the largest |x| or |y| in normalised device coordinates over a quarter of
// the body's vertices (infinity when a vertex is behind the eye), and how far
// the bounds the cameras track (deform::BodyTracker) fall short of the SSD
// body's, as a fraction of its largest extent.
struct FollowCheck {
  float extent = INFINITY;
  float hull_gap = INFINITY;
};

FollowCheck CheckFollowCamera(const app::Character& ch) {
  base::Result<deform::FramePipeline> p =
      deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, 1);
  EXPECT_TRUE(p.ok());
  base::Result<app::FramePlan> plan =
      app::PlanFrames(ch.motion, {.frames = "", .list_frames = false});
  EXPECT_TRUE(plan.ok());
  base::Result<deform::BodyTracker> tracker = deform::BodyTracker::Create(ch, {});
  EXPECT_TRUE(tracker.ok());
  if (!p.ok() || !plan.ok() || !tracker.ok()) return {};
  base::Result<render::CameraPlan> cameras =
      app::PlanCameras(ch, *plan, "follow", 15.0f, {1280, 720});
  EXPECT_TRUE(cameras.ok());
  if (!cameras.ok()) return {};
  deform::DeformedFrame frame;
  deform::TrackedBody tracked;
  FollowCheck worst{0.0f, 0.0f};
  for (std::size_t i = 0; i < plan->count(); ++i) {
    const app::OutputFrame of = plan->At(i);
    EXPECT_TRUE(p->Evaluate(of.time_s, frame).ok());
    EXPECT_TRUE(tracker->Sample(of.time_s, tracked).ok());
    const glm::vec3 size = frame.bounds.size();
    const float body = std::max({size.x, size.y, size.z});
    for (int a = 0; a < 3; ++a) {
      worst.hull_gap =
          std::max({worst.hull_gap, (tracked.hull_bounds.min[a] - frame.bounds.min[a]) / body,
                    (frame.bounds.max[a] - tracked.hull_bounds.max[a]) / body});
    }
    const render::Camera camera = cameras->At(of.camera);
    const glm::mat4 clip_from_world = camera.ClipFromView() * camera.ViewFromWorld();
    for (std::size_t v = 0; v < frame.positions.size(); v += 4) {
      const glm::vec4 c = clip_from_world * glm::vec4(frame.positions[v], 1.0f);
      if (!(c.w > 0.0f)) return {};
      worst.extent = std::max({worst.extent, std::abs(c.x / c.w), std::abs(c.y / c.w)});
    }
  }
  return worst;
}

// Inside the frame with a margin of 5% of its width and height on every side.
constexpr float kMaxFollowExtent = 0.9f;
// The tracked bounds are the body's to within 1.5% of its size on every side.
constexpr float kMaxHullGap = 0.015f;

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
    base::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true);
    ASSERT_TRUE(ch.ok()) << ch.error().ToString();
    EXPECT_EQ(ch->skeleton.info.up_axis_source, mocap::UpAxisSource::kAnimatedPoses);
    const FollowCheck check = CheckFollowCamera(*ch);
    EXPECT_LE(check.extent, kMaxFollowExtent);
    EXPECT_LE(check.hull_gap, kMaxHullGap);
  }
}

TEST(CapturePose, FollowCameraKeepsEveryRealCaptureInFrame) {
  if (!testsupport::HaveSharedData()) GTEST_SKIP() << "no shared data at " << SHARED_DATA_DIR;
  int checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(testsupport::SharedDataPath(""))) {
    const std::string ext = e.path().extension().string();
    if (ext != ".bvh" && ext != ".glb" && ext != ".gltf") continue;
    SCOPED_TRACE(e.path().string());
    base::Result<app::Character> ch = app::LoadCommandCharacter(e.path().string(), "", true);
    ASSERT_TRUE(ch.ok()) << ch.error().ToString();
    const FollowCheck check = CheckFollowCamera(*ch);
    EXPECT_LE(check.extent, kMaxFollowExtent);
    EXPECT_LE(check.hull_gap, kMaxHullGap);
    std::printf("%-60s extent %.3f, hull gap %.4f\n", e.path().filename().string().c_str(),
                check.extent, check.hull_gap);
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
    base::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true);
    ASSERT_TRUE(ch.ok()) << ch.error().ToString();
    base::Result<deform::FramePipeline> p =
        deform::FramePipeline::Create(*ch, deform::GlobalMethod::kSsd, 1);
    ASSERT_TRUE(p.ok());
    deform::DeformedFrame frame;
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

// The humanoid walk (90 frames, 2.7 m) with its hips hung from other joints:
// `above` opens `opened` joints before the hips (which become a JOINT),
// `beside` adds joints after the hips' block inside the innermost of them,
// and `line(f, walk)` writes frame f's values from the plain walk's.
std::string HipsHungFrom(const std::string& above, int opened, const std::string& beside,
                         const std::function<std::string(int, const std::string&)>& line) {
  std::string walk = testsupport::HumanoidWalkBvh(false, 0.0f, 90);
  const std::size_t motion = walk.find("MOTION");
  std::string closers;
  for (int i = 0; i < opened; ++i) closers += "}\n";
  walk.replace(motion, 0, beside + closers);
  walk.replace(walk.find("ROOT Hips"), std::string("ROOT Hips").size(), above + "JOINT Hips");
  std::string out = walk.substr(0, walk.find("Frame Time:"));
  std::istringstream rest(walk.substr(out.size()));
  std::string text;
  std::getline(rest, text);
  out += text + "\n";
  for (int f = 0; std::getline(rest, text);) {
    if (!text.empty()) out += line(f++, text) + "\n";
  }
  return out;
}

// Loads `bvh_text` and checks that the joints named in `not_body` carry no
// skin and that at every tenth frame the body has the bounds of the plain
// walk, raised by `lift` cm (before, each such capture grew a limb from the
// origin to the hips, 2.7 m long by the end).
void ExpectBodyOfThePlainWalk(const std::string& bvh_text, const char* file,
                              std::initializer_list<const char*> not_body, float lift) {
  const fs::path bvh = testsupport::TestDir("capture_pose") / file;
  std::ofstream(bvh) << bvh_text;
  base::Result<app::Character> ch = app::LoadCommandCharacter(bvh.string(), "", true);
  ASSERT_TRUE(ch.ok()) << ch.error().ToString();
  for (const char* name : not_body) {
    const int j = ch->skeleton.FindJoint(name);
    ASSERT_GE(j, 0) << name;
    EXPECT_EQ(std::find(ch->mesh.skin_joints.begin(), ch->mesh.skin_joints.end(), j), ch->mesh.skin_joints.end())
        << name << " carries skin";
  }
  const fs::path plain_bvh = testsupport::TestDir("capture_pose") / "plain_walk.bvh";
  std::ofstream(plain_bvh) << testsupport::HumanoidWalkBvh(false, 0.0f, 90);
  base::Result<app::Character> plain = app::LoadCommandCharacter(plain_bvh.string(), "", true);
  ASSERT_TRUE(plain.ok()) << plain.error().ToString();
  base::Result<deform::FramePipeline> p =
      deform::FramePipeline::Create(*ch, deform::GlobalMethod::kSsd, 1);
  base::Result<deform::FramePipeline> q =
      deform::FramePipeline::Create(*plain, deform::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(p.ok() && q.ok());
  deform::DeformedFrame frame, plain_frame;
  for (int f = 0; f < ch->motion.num_frames; f += 10) {
    ASSERT_TRUE(p->Evaluate(f * ch->motion.frame_time_s, frame).ok());
    ASSERT_TRUE(q->Evaluate(f * ch->motion.frame_time_s, plain_frame).ok());
    for (int a = 0; a < 3; ++a) {  // centimetres
      EXPECT_NEAR(frame.bounds.min[a], plain_frame.bounds.min[a] + (a == 1 ? lift : 0.0f), 1.0f)
          << "frame " << f << " axis " << a;
      EXPECT_NEAR(frame.bounds.max[a], plain_frame.bounds.max[a] + (a == 1 ? lift : 0.0f), 1.0f)
          << "frame " << f << " axis " << a;
    }
  }
}

// "World" on the floor at the origin and "Reference" 5 cm above it, animated
// by position channels alone.
TEST(CapturePose, PositionOnlyJointsAboveTheHipsGrowNoLimb) {
  const std::string bvh = HipsHungFrom(
      "ROOT World\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
      "JOINT Reference\n{\nOFFSET 0 5 0\nCHANNELS 3 Xposition Yposition Zposition\n",
      2, "", [](int, const std::string& walk) { return "0 0 0 0 5 0 " + walk; });
  ExpectBodyOfThePlainWalk(bvh, "world_reference_walk.bvh", {"World", "Reference"}, 5.0f);
}

// The same two joints with rotation channels that are declared but zero in
// every frame: they orient nothing and bend nothing.
TEST(CapturePose, StillRotationChannelsAboveTheHipsGrowNoLimb) {
  const char* six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
  const std::string bvh = HipsHungFrom(
      std::string("ROOT World\n{\nOFFSET 0 0 0\n") + six + "JOINT Reference\n{\nOFFSET 0 5 0\n" + six, 2, "",
      [](int, const std::string& walk) { return "0 0 0 0 0 0 0 5 0 0 0 0 " + walk; });
  ExpectBodyOfThePlainWalk(bvh, "still_world_reference_walk.bvh", {"World", "Reference"}, 5.0f);
}

// A root on the floor with three children: the hips walking away by their
// position channels, a prop standing beside the root and an IK target
// following the left foot. Only the hips' subtree is body.
TEST(CapturePose, FloorRootWithPropAndIkTargetGrowsNoLimb) {
  const char* six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
  const std::string bvh = HipsHungFrom(
      std::string("ROOT Root\n{\nOFFSET 0 0 0\n") + six, 1,
      std::string("JOINT Prop\n{\nOFFSET 60 0 0\n") + six + "End Site\n{\nOFFSET 0 120 0\n}\n}\n" +
          "JOINT IkFootL\n{\nOFFSET 10 5 0\n" + six + "End Site\n{\nOFFSET 0 0 15\n}\n}\n",
      [](int f, const std::string& walk) {
        return "0 0 0 0 0 0 " + walk + " 60 0 0 0 0 0 10 5 " + std::to_string(3 * f) + " 0 0 0";
      });
  ExpectBodyOfThePlainWalk(bvh, "floor_root_prop_walk.bvh", {"Root", "Prop", "IkFootL"}, 0.0f);
}

// A camera joint parked 5 m in front of the hips, never moved: it ends
// nowhere near the body, so it grows no 5 m limb.
TEST(CapturePose, FarParkedJointGrowsNoLimb) {
  std::string walk = testsupport::HumanoidWalkBvh(false, 0.0f, 90);
  const std::size_t hips_end = walk.rfind("}\n", walk.find("MOTION"));
  ASSERT_NE(hips_end, std::string::npos);
  walk.insert(hips_end, "JOINT Camera\n{\nOFFSET 0 60 500\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
                        "End Site\n{\nOFFSET 0 0 -20\n}\n}\n");
  std::string out = walk.substr(0, walk.find("Frame Time:"));
  std::istringstream rest(walk.substr(out.size()));
  std::string line;
  std::getline(rest, line);
  out += line + "\n";
  while (std::getline(rest, line)) {
    if (!line.empty()) out += line + " 0 0 0\n";
  }
  ExpectBodyOfThePlainWalk(out, "far_camera_walk.bvh", {"Camera"}, 0.0f);
}

// A root on the floor that carries the walk's translation, with the hips a
// fixed 95 cm above it (rotation channels only) and a prop beside it: the
// root is an anchor under the body, not a bone from the floor to the hips.
TEST(CapturePose, FloorAnchorUnderTheHipsGrowsNoLimb) {
  std::string bvh = HipsHungFrom(
      "ROOT Root\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n", 1,
      "JOINT Prop\n{\nOFFSET 40 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\nOFFSET 0 100 0\n}\n}\n",
      [](int, const std::string& walk) {
        std::istringstream in(walk);
        float x = 0, y = 0, z = 0;
        in >> x >> y >> z;  // the hips' position moves to the root, 95 cm lower
        std::string rest;
        std::getline(in, rest);
        std::ostringstream out;
        out << x << " " << y - 95.0f << " " << z << rest << " 0 0 0";
        return out.str();
      });
  const std::string six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation";
  const std::size_t hips = bvh.find(six, bvh.find("JOINT Hips"));
  ASSERT_NE(hips, std::string::npos);
  bvh.replace(hips, six.size(), "CHANNELS 3 Zrotation Xrotation Yrotation");
  ExpectBodyOfThePlainWalk(bvh, "floor_anchor_walk.bvh", {"Root", "Prop"}, 0.0f);
}

}  // namespace
