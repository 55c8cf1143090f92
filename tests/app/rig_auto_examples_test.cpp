// Computed corrective examples through the rig file (issue 26): "auto":
// "volume" and "rest" on the generated body bent 150 degrees at the elbow by
// samples/data/bend.bvh, measured here from the pipeline's frames.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include <gtest/gtest.h>

#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_examples.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "deform/global/skinning_job.h"
#include "deform/patch/fold_measure.h"
#include "deform/shapes/corrective_example.h"
#include "mocap/pose.h"

namespace {

namespace fs = std::filesystem;

constexpr int kBentFrame = 60;  // both elbows at 150 degrees

std::string Rig(const std::string& examples) {
  return R"({"character": "generated", "motion": {"file": "bend.bvh"}, "patches": [
    {"name": "left_elbow",
     "region": {"joint": "LeftForeArm", "radius": 14, "side": [0, 0, 1], "half_angle_deg": 120},
     "sampling": [12, 12], "grid": [8, 8], "border_width": 0.1)" +
         examples + "}]}";
}

struct AutoFixture {
  app::Character character;
  std::vector<deform::PatchSetup> patches;
};

std::optional<AutoFixture> LoadAutoFixture() {
  const std::string bvh = testsupport::SampleDataPath("bend.bvh").string();
  auto source = app::LoadMotionSource(bvh, {.y_up = true});
  if (!source.ok()) return std::nullopt;
  auto character = app::MakeCharacter(std::move(*source), {}, app::BodyKind::kGenerated);
  if (!character.ok()) return std::nullopt;
  AutoFixture f{std::move(*character), {}};
  auto rig = app::ParseRig(Rig(""), "r.json");
  if (!rig.ok()) return std::nullopt;
  auto patches = app::BuildRigPatches(*rig, f.character);
  if (!patches.ok()) return std::nullopt;
  f.patches = std::move(*patches);
  return f;
}

// Positions at the bent frame: the patch layer alone, or with the example.
std::vector<glm::vec3> Bent(const AutoFixture& f, const std::string& examples,
                            std::vector<std::string>* notes = nullptr) {
  auto pipeline = deform::FramePipeline::Create(f.character, deform::GlobalMethod::kSsd, 1);
  EXPECT_TRUE(pipeline.ok());
  EXPECT_TRUE(pipeline->SetPatches(f.patches).ok());
  if (!examples.empty()) {
    auto rig = app::ParseRig(Rig(examples), "r.json");
    EXPECT_TRUE(rig.ok()) << rig.error().ToString();
    auto spaces = app::BuildRigPoseSpaces(*rig, f.character, f.patches, deform::GlobalMethod::kSsd);
    EXPECT_TRUE(spaces.ok()) << spaces.error().ToString();
    if (notes) *notes = spaces->notes;
    EXPECT_TRUE(pipeline->SetPoseSpaces(std::move(spaces->patches)).ok());
  }
  deform::DeformedFrame frame;
  EXPECT_TRUE(pipeline->Evaluate(kBentFrame * f.character.motion.frame_time_s, frame).ok());
  return frame.positions;
}

// The SSD palette at the bent frame.
std::vector<glm::mat4> BentPalette(const app::Character& ch) {
  const auto nj = static_cast<std::size_t>(ch.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj), palette(ch.mesh.skin_joints.size());
  EXPECT_TRUE((mocap::LocalPoseJob{&ch.skeleton, ch.motion.frame(kBentFrame), locals}.Run()));
  EXPECT_TRUE((mocap::LocalToModelJob{.parents = ch.skeleton.parents, .locals = locals,
                                      .model_from_root = ch.world_from_model,
                                      .model_from_joint = model}
                   .Run()));
  EXPECT_TRUE(deform::BuildSkinningPalette(model, ch.mesh, palette));
  return palette;
}

std::vector<glm::dvec3> Double(std::span<const glm::vec3> p) { return {p.begin(), p.end()}; }

TEST(RigAutoExamples, VolumeRestoresTheBentElbowRegion) {
  const auto f = LoadAutoFixture();
  ASSERT_TRUE(f.has_value());
  const app::Character& ch = f->character;
  const deform::PatchSetup& patch = f->patches[0];
  const int drv = deform::DrivingSkinJoint(patch, static_cast<int>(ch.mesh.skin_joints.size()));
  ASSERT_GE(drv, 0);
  const std::vector<glm::mat4> palette = BentPalette(ch);
  const glm::dvec3 centre_bind{glm::inverse(glm::dmat4(ch.mesh.joint_from_bind[static_cast<std::size_t>(drv)]))[3]};
  const glm::dvec3 centre{glm::dmat4(palette[static_cast<std::size_t>(drv)]) * glm::dvec4(centre_bind, 1.0)};
  const std::vector<int> tris = deform::RegionTriangles(ch.mesh.bind.triangles, patch.region,
                                                        ch.mesh.bind.num_vertices());
  const double v_bind = deform::RegionVolume(Double(ch.mesh.bind.positions), ch.mesh.bind.triangles,
                                             tris, centre_bind);
  std::vector<std::string> notes;
  const std::vector<glm::vec3> plain = Bent(*f, "");
  const std::vector<glm::vec3> fixed =
      Bent(*f, R"(, "examples": [{"pose": {"frame": 60}, "auto": "volume"}])", &notes);
  const double v_plain = deform::RegionVolume(Double(plain), ch.mesh.bind.triangles, tris, centre);
  const double v_fixed = deform::RegionVolume(Double(fixed), ch.mesh.bind.triangles, tris, centre);
  const double lost_plain = (v_bind - v_plain) / v_bind, lost_fixed = (v_bind - v_fixed) / v_bind;
  std::printf("elbow region at 150 deg: bind volume %.1f, lost without %.2f %%, with auto volume %.2f %%\n",
              v_bind, 100.0 * lost_plain, 100.0 * lost_fixed);
  for (const std::string& n : notes) std::printf("%s\n", n.c_str());
  EXPECT_GT(std::abs(lost_plain), 0.02) << "the bend should lose volume for this test to mean anything";
  EXPECT_LT(std::abs(lost_fixed), 0.25 * std::abs(lost_plain));
  const double fold_plain = deform::MaxFoldAngleDeg(plain, ch.mesh.bind.triangles, tris);
  const double fold_fixed = deform::MaxFoldAngleDeg(fixed, ch.mesh.bind.triangles, tris);
  std::printf("fold measure: without %.1f deg, with %.1f deg\n", fold_plain, fold_fixed);
}

TEST(RigAutoExamples, RestPullsTowardTheRigidRestShape) {
  const auto f = LoadAutoFixture();
  ASSERT_TRUE(f.has_value());
  const app::Character& ch = f->character;
  const deform::PatchSetup& patch = f->patches[0];
  const std::vector<glm::mat4> palette = BentPalette(ch);
  const std::vector<glm::vec3> plain = Bent(*f, "");
  const std::vector<glm::vec3> fixed = Bent(*f, R"(, "examples": [{"pose": {"frame": 60}, "auto": "rest"}])");
  auto rms = [&](const std::vector<glm::vec3>& x) {
    double sum = 0.0;
    for (int v : patch.bound.binding.vertex) {
      const glm::dmat4 carry{palette[static_cast<std::size_t>(deform::DominantSkinJoint(ch.mesh.weights, v))]};
      const glm::dvec3 target(carry * glm::dvec4(glm::dvec3(ch.mesh.bind.positions[static_cast<std::size_t>(v)]), 1.0));
      const glm::dvec3 e = glm::dvec3(x[static_cast<std::size_t>(v)]) - target;
      sum += glm::dot(e, e);
    }
    return std::sqrt(sum / static_cast<double>(patch.bound.binding.vertex.size()));
  };
  std::printf("rms distance to the rigid rest shape: without %.3f, with auto rest %.3f\n", rms(plain),
              rms(fixed));
  EXPECT_LT(rms(fixed), 0.8 * rms(plain));
  const std::vector<int> tris = deform::RegionTriangles(ch.mesh.bind.triangles, patch.region,
                                                        ch.mesh.bind.num_vertices());
  std::printf("fold measure: without %.1f deg, with auto rest %.1f deg\n",
              deform::MaxFoldAngleDeg(plain, ch.mesh.bind.triangles, tris),
              deform::MaxFoldAngleDeg(fixed, ch.mesh.bind.triangles, tris));
}

}  // namespace
