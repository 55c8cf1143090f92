// ReadGltf on the real models of ../shared/data/gltf (counts of SOURCES.md,
// weights, bind matrices, key values, Motion vs exact sampling) and on the bad
// files of tests/data/gltf/bad.

#include "deform/io/gltf_import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "mocap/pose.h"
#include "support/data_paths.h"
#include "support/reference_skinning.h"
#include "support/tolerances.h"

namespace {

using deform::GltfModel;
using deform::ReadGltf;
using testsupport::kFloatTol;

struct RealModel {
  const char* file;
  int vertices;
  int triangles;
  int skin_joints;
  double duration_s;  // SOURCES.md gives 3 decimals
  // Frame of the rest-pose bind: "identity", "mesh" (model_from_bind) or a joint name.
  const char* bind_frame;
};

// The table of ../shared/data/SOURCES.md, "glTF 2.0 files (skinned)".
constexpr RealModel kRealModels[] = {
    {"gltf/RiggedSimple.glb", 160, 188, 2, 2.083, "Z_UP"},
    {"gltf/CesiumMan.glb", 3273, 4672, 19, 2.0, "mesh"},
    {"gltf/SimpleSkin.gltf", 10, 8, 2, 5.5, "identity"},
};
constexpr double kSourcesDurationTol = 5e-4;  // SOURCES.md rounds to milliseconds

class RealGltf : public testing::TestWithParam<RealModel> {
 protected:
  GltfModel Load() {
    const auto path = testsupport::SharedDataPath(GetParam().file);
    auto model = ReadGltf(path.string());
    EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().ToString());
    return model.ok() ? std::move(model).value() : GltfModel{};
  }
};

TEST_P(RealGltf, CountsMatchSources) {
  PATCHSKIN_REQUIRE_SHARED_FILE(testsupport::SharedDataPath(GetParam().file));
  const GltfModel model = Load();
  EXPECT_EQ(model.mesh.bind.num_vertices(), GetParam().vertices);
  EXPECT_EQ(model.mesh.bind.num_triangles(), GetParam().triangles);
  EXPECT_EQ(static_cast<int>(model.mesh.bind.normals.size()), GetParam().vertices);
  EXPECT_EQ(static_cast<int>(model.mesh.skin_joints.size()), GetParam().skin_joints);
  EXPECT_EQ(static_cast<int>(model.mesh.joint_from_bind.size()), GetParam().skin_joints);
  EXPECT_EQ(model.mesh.weights.influences, 4);
  EXPECT_EQ(model.mesh.weights.num_vertices(), GetParam().vertices);
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_NEAR(model.animations[0].duration_s, GetParam().duration_s, kSourcesDurationTol);
  EXPECT_TRUE(model.skeleton.Check().ok());
  EXPECT_GE(model.skeleton.num_joints(), GetParam().skin_joints);
}

TEST_P(RealGltf, WeightsSumToOneAndIndexTheSkin) {
  PATCHSKIN_REQUIRE_SHARED_FILE(testsupport::SharedDataPath(GetParam().file));
  const GltfModel model = Load();
  const auto& w = model.mesh.weights;
  for (int v = 0; v < w.num_vertices(); ++v) {
    double sum = 0.0;
    for (int k = 0; k < w.influences; ++k) {
      const auto slot = static_cast<std::size_t>(v * w.influences + k);
      sum += w.weights[slot];
      EXPECT_GE(w.weights[slot], 0.0f);
      EXPECT_LT(w.joints[slot], model.mesh.skin_joints.size());
    }
    ASSERT_NEAR(sum, 1.0, kFloatTol) << "vertex " << v;
  }
}

// In the rest pose, model_from_joint (through every non-joint ancestor such as
// Z_UP and Armature) times joint_from_bind must be the same matrix B for every
// skin joint (the rest pose places the bind mesh rigidly), and B is known per
// file: the identity (SimpleSkin), the mesh node's own rest transform
// model_from_bind (CesiumMan), or, in this early COLLADA2GLTF export of
// RiggedSimple, the Z_UP node alone (its bind matrices leave out "Armature").
// inverse(B) * model_from_joint * joint_from_bind is then the identity.
TEST_P(RealGltf, InverseBindTimesRestPoseIsIdentity) {
  PATCHSKIN_REQUIRE_SHARED_FILE(testsupport::SharedDataPath(GetParam().file));
  const GltfModel model = Load();
  const auto n = static_cast<std::size_t>(model.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(n);
  std::vector<glm::mat4> model_from_joint(n);
  mocap::RestPose(model.skeleton, locals);
  ASSERT_TRUE((mocap::LocalToModelJob{
      .parents = model.skeleton.parents, .locals = locals, .model_from_joint = model_from_joint}
                   .Run()));
  glm::mat4 bind_frame(1.0f);
  const std::string frame = GetParam().bind_frame;
  if (frame == "mesh") {
    bind_frame = model.model_from_bind;
  } else if (frame != "identity") {
    const int j = model.skeleton.FindJoint(frame);
    ASSERT_GE(j, 0) << frame;
    bind_frame = model_from_joint[static_cast<std::size_t>(j)];
  }
  for (std::size_t s = 0; s < model.mesh.skin_joints.size(); ++s) {
    const glm::mat4 product = glm::inverse(bind_frame) *
                              model_from_joint[static_cast<std::size_t>(model.mesh.skin_joints[s])] *
                              model.mesh.joint_from_bind[s];
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(product[c][r], c == r ? 1.0f : 0.0f, testsupport::kBindIdentityTol)
            << "skin joint " << s << " [" << c << "][" << r << "]";
  }
}

// Sampling exactly at a key time gives the key's value (LINEAR in these files).
TEST_P(RealGltf, SampledAtKeyTimesEqualsKeyValues) {
  PATCHSKIN_REQUIRE_SHARED_FILE(testsupport::SharedDataPath(GetParam().file));
  const GltfModel model = Load();
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(model.skeleton.num_joints()));
  int checked = 0;
  for (const deform::GltfChannel& ch : model.animations[0].channels) {
    ASSERT_EQ(ch.interpolation, deform::GltfInterpolation::kLinear);
    for (int k = 0; k < ch.num_keys(); ++k) {
      deform::SampleGltfAnimation(model, 0, ch.times_s[static_cast<std::size_t>(k)], locals);
      const float* key = ch.values.data() + static_cast<std::size_t>(k * ch.width());
      const mocap::JointTransform& l = locals[static_cast<std::size_t>(ch.joint)];
      if (ch.path == deform::GltfPath::kRotation) {
        const glm::quat q(key[3], key[0], key[1], key[2]);
        EXPECT_NEAR(std::abs(glm::dot(q, l.rotation)), 1.0f, kFloatTol) << "key " << k;
      } else {
        const glm::vec3 expected(key[0], key[1], key[2]);
        const glm::vec3 got = ch.path == deform::GltfPath::kTranslation ? l.translation : l.scale;
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], expected[i], kFloatTol) << "key " << k;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

// The Motion path (AnimationToMotion + LocalPoseJob) and the exact path
// (SampleGltfAnimation) skin the vertices to the same places at every frame.
TEST_P(RealGltf, MotionAndExactSamplingSkinAlike) {
  PATCHSKIN_REQUIRE_SHARED_FILE(testsupport::SharedDataPath(GetParam().file));
  const GltfModel model = Load();
  auto motion = deform::AnimationToMotion(model, 0);
  ASSERT_TRUE(motion.ok()) << motion.error().ToString();
  EXPECT_GE(motion->duration_s(), model.animations[0].duration_s - kSourcesDurationTol);
  const auto n = static_cast<std::size_t>(model.skeleton.num_joints());
  std::vector<mocap::JointTransform> exact(n), from_motion(n);
  std::vector<glm::mat4> exact_m(n), motion_m(n);
  double max_moved = 0.0;
  for (int f = 0; f < motion->num_frames; f += 7) {
    deform::SampleGltfAnimation(model, 0, std::min(f * motion->frame_time_s, model.animations[0].duration_s),
                                exact);
    ASSERT_TRUE((mocap::LocalPoseJob{
        .skeleton = &model.skeleton, .frame_values = motion->frame(f), .locals = from_motion}
                     .Run()));
    ASSERT_TRUE((mocap::LocalToModelJob{
        .parents = model.skeleton.parents, .locals = exact, .model_from_joint = exact_m}
                     .Run()));
    ASSERT_TRUE((mocap::LocalToModelJob{
        .parents = model.skeleton.parents, .locals = from_motion, .model_from_joint = motion_m}
                     .Run()));
    const auto a = testsupport::ReferenceSkin(model.mesh, exact_m);
    const auto b = testsupport::ReferenceSkin(model.mesh, motion_m);
    for (std::size_t v = 0; v < a.size(); ++v) {
      ASSERT_NEAR(glm::distance(a[v], b[v]), 0.0, testsupport::kSkinnedVertexTol)
          << "frame " << f << " vertex " << v;
      max_moved = std::max(max_moved, glm::distance(a[v], glm::dvec3(model.mesh.bind.positions[v])));
    }
  }
  EXPECT_GT(max_moved, 0.0) << "the animation should move some vertex";
}

INSTANTIATE_TEST_SUITE_P(SharedData, RealGltf, testing::ValuesIn(kRealModels),
                         [](const testing::TestParamInfo<RealModel>& p) {
                           std::string name = std::filesystem::path(p.param.file).stem().string();
                           return name;
                         });

// Not only the table above: any model added to the shared folder must load.
TEST(ReadGltf, EveryFileOfTheSharedFolderLoads) {
  const auto folder = testsupport::SharedDataPath("gltf");
  PATCHSKIN_REQUIRE_SHARED_FILE(folder);
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    auto model = ReadGltf(entry.path().string());
    EXPECT_TRUE(model.ok()) << model.error().ToString();
    ++loaded;
  }
  EXPECT_GE(loaded, 3);
}

TEST(ReadGltf, CesiumManJointsSitBelowZUpAndArmature) {
  const auto path = testsupport::SharedDataPath("gltf/CesiumMan.glb");
  PATCHSKIN_REQUIRE_SHARED_FILE(path);
  auto model = ReadGltf(path.string());
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const mocap::Skeleton& sk = model->skeleton;
  ASSERT_EQ(sk.num_joints(), 21);  // 19 skin joints + Z_UP + Armature; the mesh node is not a joint
  EXPECT_EQ(sk.names[0], "Z_UP");
  EXPECT_EQ(sk.names[1], "Armature");
  EXPECT_EQ(sk.parents[1], 0);
  EXPECT_EQ(sk.FindJoint("Cesium_Man"), -1);
  EXPECT_EQ(model->animations[0].channels.size(), 57u);  // 19 joints x T, R, S
  EXPECT_NEAR(deform::DetectFrameTime(model->animations[0]), 1.0 / 24.0, testsupport::kDoubleTol);
}

struct BadFile {
  const char* file;
  base::ErrorCode code;
  const char* field;
};

constexpr BadFile kBadFiles[] = {
    {"uri_dotdot.gltf", base::ErrorCode::kUnsupported, "buffers[0].uri"},
    {"uri_absolute.gltf", base::ErrorCode::kUnsupported, "buffers[0].uri"},
    {"accessor_out_of_range.gltf", base::ErrorCode::kCountMismatch, "accessors[0].count"},
    {"nan_position.gltf", base::ErrorCode::kNonFinite, "accessors[0]"},
    {"joint_past_skin.gltf", base::ErrorCode::kCountMismatch, "accessors[1]"},
    {"node_cycle.gltf", base::ErrorCode::kSyntax, "nodes"},
    {"truncated.glb", base::ErrorCode::kCountMismatch, "glb header.length"},
    {"broken_json.gltf", base::ErrorCode::kSyntax, ""},
};

class BadGltf : public testing::TestWithParam<BadFile> {};

TEST_P(BadGltf, GivesExpectedError) {
  const std::string path = testsupport::TestDataPath(std::string("gltf/bad/") + GetParam().file).string();
  auto model = ReadGltf(path);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(base::ErrorCodeName(model.error().code), base::ErrorCodeName(GetParam().code))
      << model.error().ToString();
  EXPECT_EQ(model.error().loc.file, path);
  EXPECT_EQ(model.error().loc.field_path, GetParam().field) << model.error().ToString();
  if (std::string(GetParam().field).empty()) {  // a whole-file error comes from tinygltf
    EXPECT_EQ(model.error().message.rfind("tinygltf: ", 0), 0u) << model.error().ToString();
  }
}

INSTANTIATE_TEST_SUITE_P(BadFiles, BadGltf, testing::ValuesIn(kBadFiles),
                         [](const testing::TestParamInfo<BadFile>& p) {
                           std::string name = std::filesystem::path(p.param.file).stem().string();
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(ReadGltf, MissingFileIsAnIoError) {
  auto model = ReadGltf(testsupport::TestDataPath("gltf/bad/does_not_exist.gltf").string());
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().code, base::ErrorCode::kIo);
}

}  // namespace
