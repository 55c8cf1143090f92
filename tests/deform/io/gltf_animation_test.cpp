// glTF features the shared models lack, on small files the tests write
// themselves (JSON + base64 buffer): STEP and CUBICSPLINE sampling, slerp,
// node matrices, computed normals, 8 influences, external buffers and
// symlinks out of the folder, AnimationToMotion's frame layout.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <string>
#include <vector>

#include "deform/io/gltf_import.h"
#include "mocap/pose.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"
#include "support/reference_skinning.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;
using deform::GltfModel;
using testsupport::GltfWriter;
using testsupport::kFloatTol;

// A triangle skinned to a 2-joint chain: node 0 "root" (joint) -> node 1 "tip"
// (joint, rest translation (0,1,0)); node 2 holds the mesh. Vertex 2 follows the tip.
GltfWriter TwoJointTriangle(bool with_normals = true) {
  GltfWriter w;
  const int positions =
      w.Accessor(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, GltfWriter::kFloat, "VEC3", 3);
  const int joints = w.Accessor(std::vector<std::uint16_t>{0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0},
                                GltfWriter::kUnsignedShort, "VEC4", 3);
  const int weights = w.Accessor(std::vector<float>{0.5f, 0.5f, 0, 0, 0.25f, 0.25f, 0, 0, 1, 0, 0, 0},
                                 GltfWriter::kFloat, "VEC4", 3);
  const int indices =
      w.Accessor(std::vector<std::uint16_t>{0, 1, 2, 0}, GltfWriter::kUnsignedShort, "SCALAR", 3);
  const int ibms = w.Accessor(std::vector<float>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,  //
                                                 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                              GltfWriter::kFloat, "MAT4", 2);
  nlohmann::json attributes = {{"POSITION", positions}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}};
  if (with_normals) {
    attributes["NORMAL"] =
        w.Accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, GltfWriter::kFloat, "VEC3", 3);
  }
  w.doc["scenes"] = {{{"nodes", {0, 2}}}};
  w.doc["nodes"] = {{{"name", "root"}, {"children", {1}}},
                    {{"name", "tip"}, {"translation", {0, 1, 0}}},
                    {{"name", "mesh"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0, 1}}, {"inverseBindMatrices", ibms}}};
  w.doc["meshes"] = {{{"primitives", {{{"attributes", attributes}, {"indices", indices}}}}}};
  return w;
}

// Adds an animation with one channel on node `node`.
void AddChannel(GltfWriter& w, int node, const std::string& path, const std::string& interpolation,
                const std::vector<float>& times, const std::vector<float>& values) {
  const int width = path == "rotation" ? 4 : 3;
  const int in = w.Accessor(times, GltfWriter::kFloat, "SCALAR", times.size());
  const int out = w.Accessor(values, GltfWriter::kFloat, width == 4 ? "VEC4" : "VEC3",
                             values.size() / static_cast<std::size_t>(width));
  w.doc["animations"] = {{{"samplers", {{{"input", in}, {"output", out}, {"interpolation", interpolation}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}}}}};
}

GltfModel Load(GltfWriter& w, const std::string& name) {
  const std::string path = w.Write(testsupport::TestOutputPath("gltf/" + name).string());
  auto model = deform::ReadGltf(path);
  EXPECT_TRUE(model.ok()) << model.error().ToString();
  return model.ok() ? std::move(model).value() : GltfModel{};
}

mocap::JointTransform SampleJoint(const GltfModel& model, int joint, double t) {
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(model.skeleton.num_joints()));
  deform::SampleGltfAnimation(model, 0, t, locals);
  return locals[static_cast<std::size_t>(joint)];
}

void ExpectVec3(const glm::vec3& got, const glm::vec3& want, float tol) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], tol) << "component " << i;
}

TEST(GltfAnimation, StepHoldsTheEarlierKey) {
  GltfWriter w = TwoJointTriangle();
  AddChannel(w, 1, "translation", "STEP", {0, 1, 2}, {0, 0, 0, 1, 2, 3, 4, 5, 6});
  const GltfModel model = Load(w, "step.gltf");
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.animations[0].channels[0].interpolation, deform::GltfInterpolation::kStep);
  const int tip = model.skeleton.FindJoint("tip");
  ExpectVec3(SampleJoint(model, tip, 0.5).translation, {0, 0, 0}, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, 1.0).translation, {1, 2, 3}, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, 1.99).translation, {1, 2, 3}, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, 7.0).translation, {4, 5, 6}, kFloatTol);
  // The root is not animated: rest values.
  ExpectVec3(SampleJoint(model, model.skeleton.FindJoint("root"), 1.5).translation, {0, 0, 0}, kFloatTol);
}

// A time a hair below the last key in double that rounds to it as a float used to
// run the key search past the end (AddressSanitizer: heap-buffer-overflow); it must
// give the last key's value, as must every later time. A NaN time gives the first key.
TEST(GltfAnimation, TimeJustBelowTheLastKeyStaysInsideTheKeys) {
  GltfWriter w = TwoJointTriangle();
  const float last = 0.1f;  // not a double: its double value lies off every float-sized step
  AddChannel(w, 1, "translation", "LINEAR", {0.0f, last}, {0, 0, 0, 2, 4, 6});
  const GltfModel model = Load(w, "edge_time.gltf");
  ASSERT_EQ(model.animations.size(), 1u);
  const int tip = model.skeleton.FindJoint("tip");
  const double below = std::nextafter(static_cast<double>(last), 0.0);
  ASSERT_LT(below, static_cast<double>(last));
  ASSERT_EQ(static_cast<float>(below), last);  // the case: equal once rounded to float
  ExpectVec3(SampleJoint(model, tip, below).translation, {2, 4, 6}, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, static_cast<double>(last)).translation, {2, 4, 6}, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, std::nan("")).translation, {0, 0, 0}, kFloatTol);
}

// Hermite basis written out independently of the importer.
glm::vec3 Hermite(const glm::vec3& v0, const glm::vec3& out0, const glm::vec3& in1, const glm::vec3& v1,
                  float dt, float s) {
  const float h00 = 2 * s * s * s - 3 * s * s + 1;
  const float h10 = s * s * s - 2 * s * s + s;
  const float h01 = -2 * s * s * s + 3 * s * s;
  const float h11 = s * s * s - s * s;
  return h00 * v0 + h10 * dt * out0 + h01 * v1 + h11 * dt * in1;
}

TEST(GltfAnimation, CubicSplineFollowsHermiteWithScaledTangents) {
  GltfWriter w = TwoJointTriangle();
  // Per key: in-tangent, value, out-tangent. Keys at t = 1 and t = 3 (dt = 2).
  const glm::vec3 in0(9, 9, 9), v0(1, 0, -1), out0(2, -1, 0.5f);
  const glm::vec3 in1(-1, 3, 0), v1(3, 2, 1), out1(7, 7, 7);
  AddChannel(w, 1, "translation", "CUBICSPLINE", {1, 3},
             {in0.x, in0.y, in0.z, v0.x, v0.y, v0.z, out0.x, out0.y, out0.z,  //
              in1.x, in1.y, in1.z, v1.x, v1.y, v1.z, out1.x, out1.y, out1.z});
  const GltfModel model = Load(w, "cubic.gltf");
  const int tip = model.skeleton.FindJoint("tip");
  ExpectVec3(SampleJoint(model, tip, 1.0).translation, v0, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, 3.0).translation, v1, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, 0.0).translation, v0, kFloatTol);  // before the first key
  // Midpoint by hand: 0.5 v0 + 0.125 dt out0 + 0.5 v1 - 0.125 dt in1.
  const glm::vec3 mid = 0.5f * v0 + 0.25f * out0 + 0.5f * v1 - 0.25f * in1;
  ExpectVec3(SampleJoint(model, tip, 2.0).translation, mid, kFloatTol);
  ExpectVec3(SampleJoint(model, tip, 1.5).translation, Hermite(v0, out0, in1, v1, 2.0f, 0.25f), kFloatTol);
  // Finite-difference slope at the first key is the out-tangent (not scaled by dt).
  const float h = 1e-3f;
  const glm::vec3 slope = (SampleJoint(model, tip, 1.0 + h).translation - v0) / h;
  ExpectVec3(slope, out0, testsupport::kPositionTol * 10);
}

TEST(GltfAnimation, CubicSplineRotationIsNormalized) {
  GltfWriter w = TwoJointTriangle();
  const float c = std::cos(0.5f), s = std::sin(0.5f);  // 1 rad about Z
  AddChannel(w, 1, "rotation", "CUBICSPLINE", {0, 1}, {0, 0, 0,    0, 0, 0, 0, 1, 0, 0, 0.3f, 0,  //
                                                       0, 0, 0.2f, 0, 0, 0, s, c, 0, 0, 0,    0});
  const GltfModel model = Load(w, "cubic_rotation.gltf");
  const glm::quat q = SampleJoint(model, model.skeleton.FindJoint("tip"), 0.5).rotation;
  EXPECT_NEAR(glm::length(q), 1.0f, kFloatTol);
  // Unnormalized Hermite at s = 0.5: 0.5 q0 + 0.125 out0 + 0.5 q1 - 0.125 in1.
  const glm::vec4 raw = 0.5f * glm::vec4(0, 0, 0, 1) + 0.125f * glm::vec4(0, 0, 0.3f, 0) +
                        0.5f * glm::vec4(0, 0, s, c) - 0.125f * glm::vec4(0, 0, 0.2f, 0);
  const glm::vec4 want = glm::normalize(raw);
  EXPECT_NEAR(q.z, want.z, kFloatTol);
  EXPECT_NEAR(q.w, want.w, kFloatTol);
}

TEST(GltfAnimation, LinearRotationSlerpsTheShortWay) {
  GltfWriter w = TwoJointTriangle();
  const float h = std::sqrt(0.5f);
  // Identity to 90 degrees about Z, the second key written as -q (same rotation).
  AddChannel(w, 1, "rotation", "LINEAR", {0, 2}, {0, 0, 0, 1, 0, 0, -h, -h});
  const GltfModel model = Load(w, "slerp.gltf");
  const glm::quat q = SampleJoint(model, model.skeleton.FindJoint("tip"), 1.0).rotation;
  const glm::quat want = glm::angleAxis(glm::radians(45.0f), glm::vec3(0, 0, 1));
  EXPECT_NEAR(std::abs(glm::dot(q, want)), 1.0f, kFloatTol);
  const glm::quat quarter = SampleJoint(model, model.skeleton.FindJoint("tip"), 0.5).rotation;
  EXPECT_NEAR(std::abs(glm::dot(quarter, glm::angleAxis(glm::radians(22.5f), glm::vec3(0, 0, 1)))), 1.0f,
              kFloatTol);
}

TEST(GltfAnimation, MotionMatchesExactSamplingOnGeneratedClip) {
  GltfWriter w = TwoJointTriangle();
  AddChannel(w, 1, "translation", "CUBICSPLINE", {0, 1},
             {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 1, 2, 0, 0, 0, 0});
  const GltfModel model = Load(w, "motion.gltf");
  auto motion = deform::AnimationToMotion(model, 0, 0.25);
  ASSERT_TRUE(motion.ok()) << motion.error().ToString();
  EXPECT_EQ(motion->num_frames, 5);
  EXPECT_EQ(motion->num_channels, 3);  // only the tip's translation is driven
  EXPECT_EQ(model.skeleton.channels[1].types[0], mocap::ChannelType::kXPosition);
  const auto n = static_cast<std::size_t>(model.skeleton.num_joints());
  std::vector<mocap::JointTransform> a(n), b(n);
  std::vector<glm::mat4> ma(n), mb(n);
  for (int f = 0; f < motion->num_frames; ++f) {
    deform::SampleGltfAnimation(model, 0, f * 0.25, a);
    ASSERT_TRUE(
        (mocap::LocalPoseJob{.skeleton = &model.skeleton, .frame_values = motion->frame(f), .locals = b}
             .Run()));
    ASSERT_TRUE(
        (mocap::LocalToModelJob{.parents = model.skeleton.parents, .locals = a, .model_from_joint = ma}
             .Run()));
    ASSERT_TRUE(
        (mocap::LocalToModelJob{.parents = model.skeleton.parents, .locals = b, .model_from_joint = mb}
             .Run()));
    const auto va = testsupport::ReferenceSkin(model.mesh, ma);
    const auto vb = testsupport::ReferenceSkin(model.mesh, mb);
    for (std::size_t v = 0; v < va.size(); ++v)
      EXPECT_NEAR(glm::distance(va[v], vb[v]), 0.0, testsupport::kSkinnedVertexTol);
    // Vertex 2 rides only the tip: bind (0,1,0) -> tip translation.
    const glm::vec3 tip = a[1].translation;
    EXPECT_NEAR(glm::distance(va[2], glm::dvec3(tip)), 0.0, testsupport::kSkinnedVertexTol) << "frame " << f;
  }
  EXPECT_FALSE(deform::AnimationToMotion(model, 1, 0.25).ok());
  EXPECT_FALSE(deform::AnimationToMotion(model, 0, std::nan("")).ok());
}

TEST(GltfImport, NodeMatrixIsDecomposedAndNormalsComputed) {
  GltfWriter w = TwoJointTriangle(/*with_normals=*/false);
  const glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(0, 1, 0)) *
                      glm::rotate(glm::mat4(1.0f), 0.3f, glm::vec3(1, 0, 0)) *
                      glm::scale(glm::mat4(1.0f), glm::vec3(2, 2, 2));
  std::vector<float> flat;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) flat.push_back(m[c][r]);
  w.doc["nodes"][1].erase("translation");
  w.doc["nodes"][1]["matrix"] = flat;
  const GltfModel model = Load(w, "matrix.gltf");
  const int tip = model.skeleton.FindJoint("tip");
  ExpectVec3(model.skeleton.rest_translations[static_cast<std::size_t>(tip)], {0, 1, 0}, kFloatTol);
  ExpectVec3(model.skeleton.rest_scales[static_cast<std::size_t>(tip)], {2, 2, 2}, kFloatTol);
  mocap::JointTransform rest{model.skeleton.rest_translations[1], model.skeleton.rest_rotations[1],
                             model.skeleton.rest_scales[1]};
  const glm::mat4 back = rest.ToMatrix();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(back[c][r], m[c][r], kFloatTol);
  ASSERT_EQ(model.mesh.bind.normals.size(), 3u);
  for (const glm::vec3& n : model.mesh.bind.normals) ExpectVec3(n, {0, 0, 1}, kFloatTol);
  EXPECT_FALSE(model.warnings.empty());
}

TEST(GltfImport, EightInfluencesAreNormalized) {
  GltfWriter w = TwoJointTriangle();
  const int joints1 = w.Accessor(std::vector<std::uint16_t>(12, 1), GltfWriter::kUnsignedShort, "VEC4", 3);
  const int weights1 =
      w.Accessor(std::vector<float>{1, 0, 0, 0, 0.5f, 0, 0, 0, 0, 0, 0, 1}, GltfWriter::kFloat, "VEC4", 3);
  auto& attributes = w.doc["meshes"][0]["primitives"][0]["attributes"];
  attributes["JOINTS_1"] = joints1;
  attributes["WEIGHTS_1"] = weights1;
  const GltfModel model = Load(w, "eight.gltf");
  ASSERT_EQ(model.mesh.weights.influences, 8);
  // Vertex 0: 0.5, 0.5 | 1 -> 0.25, 0.25, 0.5.
  EXPECT_NEAR(model.mesh.weights.weights[0], 0.25f, kFloatTol);
  EXPECT_NEAR(model.mesh.weights.weights[4], 0.5f, kFloatTol);
  EXPECT_EQ(model.mesh.weights.joints[4], 1);
  for (int v = 0; v < 3; ++v) {
    float sum = 0.0f;
    for (int k = 0; k < 8; ++k) sum += model.mesh.weights.weights[static_cast<std::size_t>(v * 8 + k)];
    EXPECT_NEAR(sum, 1.0f, kFloatTol);
  }
}

// Writes the triangle with its buffer in a file next to the model (uri "buffer.bin").
std::string WriteExternal(const fs::path& folder, const std::string& uri) {
  GltfWriter w = TwoJointTriangle();
  const std::string embedded = w.Write((folder / "tmp.gltf").string());
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(embedded));
  const std::string data_uri = doc["buffers"][0]["uri"];
  const std::string b64 = data_uri.substr(data_uri.find(',') + 1);
  // Decode base64 (test-only, no padding tricks beyond '=').
  std::string bytes;
  int bits = 0, value = 0;
  for (char ch : b64) {
    const auto pos = std::string("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/").find(ch);
    if (pos == std::string::npos) break;
    value = value << 6 | static_cast<int>(pos);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes += static_cast<char>(value >> bits & 0xFF);
    }
  }
  std::ofstream(folder / "buffer.bin", std::ios::binary) << bytes;
  doc["buffers"][0]["uri"] = uri;
  const fs::path model = folder / "model.gltf";
  std::ofstream(model) << doc.dump();
  return model.string();
}

TEST(GltfImport, ReadsExternalBufferInsideTheFolder) {
  const fs::path folder = testsupport::TestOutputPath("gltf/external/inside/x").parent_path();
  fs::create_directories(folder);
  auto model = deform::ReadGltf(WriteExternal(folder, "buffer.bin"));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  EXPECT_EQ(model->mesh.bind.num_vertices(), 3);
}

TEST(GltfImport, RejectsSymlinkLeavingTheFolder) {
  const fs::path outside = testsupport::TestOutputPath("gltf/external/outside/x").parent_path();
  const fs::path folder = outside / "model";
  fs::create_directories(folder);
  WriteExternal(outside, "unused");  // puts buffer.bin in `outside`
  std::error_code ec;
  fs::remove(folder / "link.bin", ec);
  fs::create_symlink(outside / "buffer.bin", folder / "link.bin", ec);
  if (ec) GTEST_SKIP() << "cannot create a symlink here: " << ec.message();
  const std::string path = WriteExternal(folder, "link.bin");
  fs::remove(folder / "buffer.bin");
  auto model = deform::ReadGltf(path);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().code, base::ErrorCode::kUnsupported) << model.error().ToString();
  EXPECT_NE(model.error().message.find("outside the model's folder"), std::string::npos)
      << model.error().ToString();
}

}  // namespace
