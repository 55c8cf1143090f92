// A glTF character driven by a separate BVH motion: a small skinned glTF
// (Mixamo-style "mixamorig:" joint names, metres, one joint with a turned rest
// frame) is written by the test, driven by a BVH (centimetres, plain and
// differently-cased names), and its deformed vertices are checked against a
// hand computation of the documented convention (mocap/retarget.h); then the
// same through `render MODEL --motion` and a rig file, and the error for a
// motion that lacks a required joint.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/character_motion.h"
#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::GltfWriter;
using testsupport::kPositionTol;

glm::quat Axis(float deg, glm::vec3 axis) { return glm::angleAxis(glm::radians(deg), axis); }

// The character: Hips (1 m up) -> Spine (rest frame turned 90 deg about Y) ->
// Head, and Hips -> LeftLeg (down to the ground). Three vertices near each
// joint, each bound to that joint alone.
const glm::quat kSpineRest = Axis(90, {0, 1, 0});
const char* const kJointNames[4] = {"mixamorig:Hips", "mixamorig:Spine", "mixamorig:Head",
                                    "mixamorig:LeftLeg"};
const int kParents[4] = {-1, 0, 1, 0};
const glm::vec3 kRestTranslations[4] = {{0, 1, 0}, {0, .5f, 0}, {0, .3f, 0}, {.1f, -1, 0}};
const glm::vec3 kCorner[3] = {{.05f, 0, 0}, {0, 0, .05f}, {0, .05f, .02f}};

std::vector<glm::mat4> BindModel() {
  std::vector<glm::mat4> model(4);
  for (int j = 0; j < 4; ++j) {
    glm::mat4 local = glm::translate(glm::mat4(1.0f), kRestTranslations[j]);
    if (j == 1) local = local * glm::mat4_cast(kSpineRest);
    model[static_cast<std::size_t>(j)] = kParents[j] < 0 ? local : model[static_cast<std::size_t>(kParents[j])] * local;
  }
  return model;
}

glm::vec3 BindVertex(int joint, int corner) {
  return glm::vec3(BindModel()[static_cast<std::size_t>(joint)][3]) + kCorner[corner];
}

std::string WriteCharacter(const fs::path& path) {
  GltfWriter w;
  std::vector<float> positions, normals, weights, ibms;
  std::vector<std::uint16_t> joints, indices;
  const std::vector<glm::mat4> bind = BindModel();
  for (int j = 0; j < 4; ++j) {
    for (int c = 0; c < 3; ++c) {
      const glm::vec3 v = BindVertex(j, c);
      positions.insert(positions.end(), {v.x, v.y, v.z});
      normals.insert(normals.end(), {0, 0, 1});
      joints.insert(joints.end(), {static_cast<std::uint16_t>(j), 0, 0, 0});
      weights.insert(weights.end(), {1, 0, 0, 0});
      indices.push_back(static_cast<std::uint16_t>(3 * j + c));
    }
    const glm::mat4 ibm = glm::inverse(bind[static_cast<std::size_t>(j)]);
    ibms.insert(ibms.end(), glm::value_ptr(ibm), glm::value_ptr(ibm) + 16);
  }
  const nlohmann::json attributes = {
      {"POSITION", w.Accessor(positions, GltfWriter::kFloat, "VEC3", 12)},
      {"NORMAL", w.Accessor(normals, GltfWriter::kFloat, "VEC3", 12)},
      {"JOINTS_0", w.Accessor(joints, GltfWriter::kUnsignedShort, "VEC4", 12)},
      {"WEIGHTS_0", w.Accessor(weights, GltfWriter::kFloat, "VEC4", 12)}};
  const int index_accessor = w.Accessor(indices, GltfWriter::kUnsignedShort, "SCALAR", 12);
  const int ibm_accessor = w.Accessor(ibms, GltfWriter::kFloat, "MAT4", 4);
  w.doc["scenes"] = {{{"nodes", {0, 4}}}};
  w.doc["nodes"] = {
      {{"name", kJointNames[0]}, {"translation", {0, 1, 0}}, {"children", {1, 3}}},
      {{"name", kJointNames[1]},
       {"translation", {0, .5, 0}},
       {"rotation", {kSpineRest.x, kSpineRest.y, kSpineRest.z, kSpineRest.w}},
       {"children", {2}}},
      {{"name", kJointNames[2]}, {"translation", {0, .3, 0}}},
      {{"name", kJointNames[3]}, {"translation", {.1, -1, 0}}},
      {{"name", "body"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0, 1, 2, 3}}, {"inverseBindMatrices", ibm_accessor}}};
  w.doc["meshes"] = {
      {{"primitives", {{{"attributes", attributes}, {"indices", index_accessor}}}}}};
  return w.Write(path.string());
}

// The motion, in centimetres: frame 0 is the rest pose standing (hips at
// 100 cm), frame 1 turns the hips, bends the spine, nods and lifts the leg.
std::string WriteMotion(const fs::path& path, const std::string& spine_name = "spine") {
  std::ofstream(path) << "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n"
                         " CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                         " JOINT " << spine_name << "\n {\n  OFFSET 0 50 0\n"
                         "  CHANNELS 3 Zrotation Xrotation Yrotation\n"
                         "  JOINT HEAD\n  {\n   OFFSET 0 30 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
                         "   End Site\n   {\n    OFFSET 0 10 0\n   }\n  }\n }\n"
                         " JOINT LeftLeg\n {\n  OFFSET 10 -100 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
                         "  End Site\n  {\n   OFFSET 0 -5 0\n  }\n }\n}\n"
                         "MOTION\nFrames: 2\nFrame Time: 0.5\n"
                         "0 100 0 0 0 0 0 0 0 0 0 0 0 0 0\n"
                         "20 100 -10 0 0 30 45 0 0 0 20 0 0 -40 0\n";
  return path.string();
}

app::Character LoadDrivenCharacter(const fs::path& d) {
  const std::string model = WriteCharacter(d / "body.gltf");
  const std::string motion = WriteMotion(d / "motion.bvh");
  app::MotionSourceOptions options;
  options.y_up = true;
  auto body = app::LoadMotionSource(model, options);
  auto bvh = app::LoadMotionSource(motion, options);
  EXPECT_TRUE(body.ok() && bvh.ok());
  auto c = app::MakeRetargetedCharacter(std::move(*body), std::move(*bvh));
  EXPECT_TRUE(c.ok()) << c.error().ToString();
  return c.ok() ? std::move(c).value() : app::Character{};
}

TEST(GltfBvhMotion, VerticesFollowTheRetargetedMotion) {
  const fs::path d = TestDir();
  const app::Character ch = LoadDrivenCharacter(d);
  ASSERT_EQ(ch.mesh.bind.num_vertices(), 12);
  EXPECT_EQ(ch.motion.num_frames, 2);
  auto pipeline = deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, 1);
  ASSERT_TRUE(pipeline.ok()) << pipeline.error().ToString();
  deform::DeformedFrame frame;

  // Frame 0 (the BVH's rest pose, standing): the bind mesh.
  ASSERT_TRUE(pipeline->Evaluate(0.0, frame).ok());
  for (int j = 0; j < 4; ++j) {
    for (int c = 0; c < 3; ++c) {
      const glm::vec3 got = frame.positions[static_cast<std::size_t>(3 * j + c)];
      const glm::vec3 want = BindVertex(j, c);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], kPositionTol) << j << " " << c;
    }
  }

  // Frame 1 by hand: each joint turns in world space by its BVH joint's world
  // rotation D; the hips move to 0.01 x the BVH root (hip heights 1 m / 100 cm);
  // bones keep the glTF's lengths; a vertex bound to joint j lands at
  // joint_j + D_j (v - bind_joint_j).
  const glm::quat d_hips = Axis(30, {0, 1, 0});
  const glm::quat d_spine = d_hips * Axis(45, {0, 0, 1});
  const glm::quat d_head = d_spine * Axis(20, {1, 0, 0});
  const glm::quat d_leg = d_hips * Axis(-40, {1, 0, 0});
  const glm::vec3 hips(0.2f, 1.0f, -0.1f);
  const glm::vec3 spine = hips + d_hips * glm::vec3(0, .5f, 0);
  const glm::vec3 head = spine + d_spine * (kSpineRest * glm::vec3(0, .3f, 0));
  const glm::vec3 leg = hips + d_hips * glm::vec3(.1f, -1, 0);
  const glm::vec3 joint_at[4] = {hips, spine, head, leg};
  const glm::quat turn[4] = {d_hips, d_spine, d_head, d_leg};
  const std::vector<glm::mat4> bind = BindModel();
  ASSERT_TRUE(pipeline->Evaluate(0.5, frame).ok());
  for (int j = 0; j < 4; ++j) {
    for (int c = 0; c < 3; ++c) {
      const glm::vec3 want =
          joint_at[j] + turn[j] * (BindVertex(j, c) - glm::vec3(bind[static_cast<std::size_t>(j)][3]));
      const glm::vec3 got = frame.positions[static_cast<std::size_t>(3 * j + c)];
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], kPositionTol) << kJointNames[j] << " corner " << c;
    }
  }
}

TEST(GltfBvhMotion, CommandLineAndRigRenderTheSameFrames) {
  const fs::path d = TestDir();
  const std::string model = WriteCharacter(d / "body.gltf");
  const std::string motion = WriteMotion(d / "motion.bvh");
  const std::vector<std::string> common{"--quiet", "--no-video", "--no-sheet", "--supersample", "1"};
  std::vector<std::string> cli{"render", model, "--motion", motion, "--size", "64x36",
                               "--out", (d / "cli/f_####.png").string()};
  cli.insert(cli.end(), common.begin(), common.end());
  const auto r1 = testsupport::RunPatchskin(cli, d / "logs");
  ASSERT_EQ(r1.exit_code, 0) << r1.err;

  std::ofstream(d / "rig.json") << R"({"character": "body.gltf", "motion": {"file": "motion.bvh"},
    "render": {"size": [64, 36], "output": "rig/f_####.png"}})";
  std::vector<std::string> rig{"render", (d / "rig.json").string()};
  rig.insert(rig.end(), common.begin(), common.end());
  const auto r2 = testsupport::RunPatchskin(rig, d / "logs");
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  // Same pixels (the PNG metadata names the input, so not the same bytes).
  auto pixels = [&d](const std::string& file) {
    const auto image = render::ReadImage((d / file).string());
    EXPECT_TRUE(image.ok()) << file;
    return image.ok() ? image->rgba : std::vector<glm::vec4>{};
  };
  for (const char* f : {"f_0000.png", "f_0001.png"}) {
    ASSERT_TRUE(fs::exists(d / "cli" / f)) << f;
    EXPECT_TRUE(pixels(std::string("cli/") + f) == pixels(std::string("rig/") + f)) << f;
  }
  EXPECT_FALSE(pixels("cli/f_0000.png") == pixels("cli/f_0001.png")) << "the motion moves the body";
}

TEST(GltfBvhMotion, MissingRequiredJointIsNamed) {
  const fs::path d = TestDir();
  const std::string model = WriteCharacter(d / "body.gltf");
  const std::string motion = WriteMotion(d / "chest.bvh", "Chest");  // no spine
  const auto r = testsupport::RunPatchskin(
      {"render", model, "--motion", motion, "--size", "64x36", "--quiet", "--out",
       (d / "out/f_####.png").string()},
      d / "logs");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("chest.bvh"), std::string::npos) << r.err;
  EXPECT_NE(r.FirstErrLine().find("found none for: mixamorig:Spine"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "out"));
}

}  // namespace
