// Morph targets in the glTF import: hand-made files with known deltas, the
// morph weights evaluated at key times and between them (LINEAR, STEP,
// CUBICSPLINE, worked out by hand), sparse and buffer-less target accessors,
// morphing before skinning, and files that must be refused.

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "deform/io/gltf_import.h"
#include "deform/io/gltf_mesh_sampler.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"
#include "support/tolerances.h"

namespace {

using deform::GltfModel;
using testsupport::GltfWriter;
using testsupport::kFloatTol;

// Base triangle (0,0,0) (1,0,0) (0,1,0), normals +Z.
const std::vector<float> kBase = {0, 0, 0, 1, 0, 0, 0, 1, 0};
// Target 0 moves every vertex by its own vector; target 1 (sparse) moves only vertex 2.
const glm::vec3 kD0[3] = {{0, 0, 1}, {0, 0, 2}, {1, 0, 3}};
const glm::vec3 kD1Vertex2{0, 5, 0};
const glm::vec3 kN0{1, 0, 0};  // target 0's normal delta, every vertex

struct MorphFile {
  GltfWriter w;
  int mesh_node = 1;
};

// No skin: node 0 (translation (1,2,3)) -> node 1 holding the mesh. Mesh
// weights [0.25, 0]. Target 0 dense POSITION + NORMAL; target 1 POSITION as a
// sparse accessor without a buffer view (one element: vertex 2).
MorphFile TriangleWithTargets() {
  MorphFile f;
  GltfWriter& w = f.w;
  const int positions = w.Accessor(kBase, GltfWriter::kFloat, "VEC3", 3);
  const int normals = w.Accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, GltfWriter::kFloat, "VEC3", 3);
  std::vector<float> d0;
  for (const glm::vec3& d : kD0) d0.insert(d0.end(), {d.x, d.y, d.z});
  const int t0_pos = w.Accessor(d0, GltfWriter::kFloat, "VEC3", 3);
  const int t0_nrm = w.Accessor(std::vector<float>{1, 0, 0, 1, 0, 0, 1, 0, 0}, GltfWriter::kFloat, "VEC3", 3);
  const int sparse_idx = w.Accessor(std::vector<std::uint16_t>{2, 0}, GltfWriter::kUnsignedShort, "SCALAR", 1);
  const int sparse_val = w.Accessor(std::vector<float>{kD1Vertex2.x, kD1Vertex2.y, kD1Vertex2.z},
                                    GltfWriter::kFloat, "VEC3", 1);
  const int t1_pos = static_cast<int>(w.doc["accessors"].size());
  w.doc["accessors"].push_back(
      {{"componentType", GltfWriter::kFloat},
       {"type", "VEC3"},
       {"count", 3},
       {"sparse",
        {{"count", 1},
         {"indices", {{"bufferView", sparse_idx}, {"componentType", GltfWriter::kUnsignedShort}}},
         {"values", {{"bufferView", sparse_val}}}}}});
  w.doc["scenes"] = {{{"nodes", {0}}}};
  w.doc["nodes"] = {{{"name", "root"}, {"translation", {1, 2, 3}}, {"children", {1}}},
                    {{"name", "body"}, {"mesh", 0}}};
  nlohmann::json primitive;
  primitive["attributes"] = {{"POSITION", positions}, {"NORMAL", normals}};
  primitive["targets"] = nlohmann::json::array(
      {nlohmann::json{{"POSITION", t0_pos}, {"NORMAL", t0_nrm}}, nlohmann::json{{"POSITION", t1_pos}}});
  nlohmann::json mesh;
  mesh["primitives"] = nlohmann::json::array({primitive});
  mesh["weights"] = {0.25, 0.0};
  w.doc["meshes"] = nlohmann::json::array({mesh});
  return f;
}

// Adds an animation driving the mesh node's weights; returns its index.
int AddWeights(GltfWriter& w, int node, const std::string& interpolation, const std::vector<float>& times,
               const std::vector<float>& values) {
  // Accessor() returns the buffer view; the accessor is the last one added.
  w.Accessor(times, GltfWriter::kFloat, "SCALAR", times.size());
  const int in = static_cast<int>(w.doc["accessors"].size()) - 1;
  w.Accessor(values, GltfWriter::kFloat, "SCALAR", values.size());
  const int out = static_cast<int>(w.doc["accessors"].size()) - 1;
  w.doc["animations"].push_back(
      {{"samplers", {{{"input", in}, {"output", out}, {"interpolation", interpolation}}}},
       {"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", "weights"}}}}}}});
  return static_cast<int>(w.doc["animations"].size()) - 1;
}

base::Result<GltfModel> Read(GltfWriter& w, const std::string& name, bool require_skin = false) {
  const std::string path = w.Write(testsupport::TestOutputPath("gltf_morph/" + name).string());
  deform::GltfReadOptions options;
  options.require_skin = require_skin;
  return deform::ReadGltf(path, options);
}

// The analytic morphed-and-translated vertex v for weights (w0, w1).
glm::vec3 Expected(int v, float w0, float w1) {
  const glm::vec3 base(kBase[3 * v], kBase[3 * v + 1], kBase[3 * v + 2]);
  const glm::vec3 d1 = v == 2 ? kD1Vertex2 : glm::vec3(0.0f);
  return base + w0 * kD0[v] + w1 * d1 + glm::vec3(1, 2, 3);
}

void ExpectVertices(deform::GltfMeshSampler& sampler, int animation, double t, float w0, float w1) {
  std::vector<glm::vec3> p(3), n(3);
  ASSERT_TRUE(sampler.Sample(animation, t, p, n).ok());
  EXPECT_NEAR(sampler.weights()[0], w0, kFloatTol) << "t = " << t;
  EXPECT_NEAR(sampler.weights()[1], w1, kFloatTol) << "t = " << t;
  for (int v = 0; v < 3; ++v) {
    const glm::vec3 e = Expected(v, w0, w1);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[static_cast<std::size_t>(v)][c], e[c], kFloatTol) << "t " << t << " v " << v;
    const glm::vec3 en = glm::normalize(glm::vec3(0, 0, 1) + w0 * kN0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(n[static_cast<std::size_t>(v)][c], en[c], kFloatTol);
  }
}

TEST(GltfMorphImport, ReadsDenseSparseAndDefaultWeights) {
  MorphFile f = TriangleWithTargets();
  auto model = Read(f.w, "targets.gltf");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::GltfMorphTargets& m = model->morph;
  ASSERT_EQ(m.num_targets, 2);
  ASSERT_EQ(m.position_deltas.size(), 6u);
  for (int v = 0; v < 3; ++v) {
    EXPECT_EQ(m.position_deltas[static_cast<std::size_t>(v)], kD0[v]);
    EXPECT_EQ(m.position_deltas[static_cast<std::size_t>(3 + v)], v == 2 ? kD1Vertex2 : glm::vec3(0.0f));
    EXPECT_EQ(m.normal_deltas[static_cast<std::size_t>(v)], kN0);
    EXPECT_EQ(m.normal_deltas[static_cast<std::size_t>(3 + v)], glm::vec3(0.0f));  // no NORMAL: zeros
  }
  EXPECT_EQ(m.default_weights, (std::vector<float>{0.25f, 0.0f}));
  // Rigid attachment: one joint per node, the mesh node's vertices on its own.
  EXPECT_EQ(model->skeleton.num_joints(), 2);
  ASSERT_EQ(model->mesh.skin_joints.size(), 1u);
  EXPECT_EQ(model->skeleton.names[static_cast<std::size_t>(model->mesh.skin_joints[0])], "body");
  // No animation: the defaults, translated by the parent node.
  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok()) << sampler.error().ToString();
  ExpectVertices(*sampler, -1, 0.0, 0.25f, 0.0f);
}

TEST(GltfMorphImport, LinearWeightsAtKeysAndBetween) {
  MorphFile f = TriangleWithTargets();
  // Keys at 0, 1, 3 s: [0,0] -> [1,0] -> [0,2].
  AddWeights(f.w, f.mesh_node, "LINEAR", {0, 1, 3}, {0, 0, 1, 0, 0, 2});
  auto model = Read(f.w, "linear.gltf");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  ASSERT_EQ(model->animations.size(), 1u);
  EXPECT_DOUBLE_EQ(model->animations[0].duration_s, 3.0);
  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok());
  ExpectVertices(*sampler, 0, -1.0, 0.0f, 0.0f);  // before the first key: the first value
  ExpectVertices(*sampler, 0, 0.0, 0.0f, 0.0f);
  ExpectVertices(*sampler, 0, 0.5, 0.5f, 0.0f);
  ExpectVertices(*sampler, 0, 1.0, 1.0f, 0.0f);
  ExpectVertices(*sampler, 0, 2.5, 0.25f, 1.5f);  // 3/4 of the way from [1,0] to [0,2]
  ExpectVertices(*sampler, 0, 3.0, 0.0f, 2.0f);
  ExpectVertices(*sampler, 0, 9.0, 0.0f, 2.0f);   // after the last key: the last value
}

TEST(GltfMorphImport, StepHoldsEachKey) {
  MorphFile f = TriangleWithTargets();
  AddWeights(f.w, f.mesh_node, "STEP", {0, 1, 3}, {0, 0, 1, 0, 0, 2});
  auto model = Read(f.w, "step.gltf");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok());
  ExpectVertices(*sampler, 0, 0.999, 0.0f, 0.0f);
  ExpectVertices(*sampler, 0, 1.0, 1.0f, 0.0f);
  ExpectVertices(*sampler, 0, 2.9, 1.0f, 0.0f);
  ExpectVertices(*sampler, 0, 3.0, 0.0f, 2.0f);
}

TEST(GltfMorphImport, CubicSplineIsTheHermiteForm) {
  MorphFile f = TriangleWithTargets();
  // Two keys 2 s apart; per key: in-tangents [2], values [2], out-tangents [2].
  // Key 0: value [0, 1], out-tangent [1, 0]; key 1: in-tangent [0, -1], value [1, 0].
  AddWeights(f.w, f.mesh_node, "CUBICSPLINE", {0, 2}, {9, 9, 0, 1, 1, 0, /**/ 0, -1, 1, 0, 9, 9});
  auto model = Read(f.w, "cubic.gltf");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok());
  // s = 0.5, dt = 2: h00 = h01 = 0.5, h10 = 0.125, h11 = -0.125.
  // w0 = 0.5*0 + 0.125*2*1 + 0.5*1 - 0.125*2*0 = 0.75
  // w1 = 0.5*1 + 0.125*2*0 + 0.5*0 - 0.125*2*(-1) = 0.75
  ExpectVertices(*sampler, 0, 1.0, 0.75f, 0.75f);
  ExpectVertices(*sampler, 0, 0.0, 0.0f, 1.0f);  // the key values, not the tangents
  ExpectVertices(*sampler, 0, 2.0, 1.0f, 0.0f);
}

// Morphing happens in bind space, before skinning: a joint translated by
// (0, 0, 10) at t = 1 carries the morphed vertices.
TEST(GltfMorphImport, MorphsBeforeSkinning) {
  GltfWriter w;
  const int positions = w.Accessor(kBase, GltfWriter::kFloat, "VEC3", 3);
  const int joints = w.Accessor(std::vector<std::uint16_t>(12, 0), GltfWriter::kUnsignedShort, "VEC4", 3);
  const int weights =
      w.Accessor(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, GltfWriter::kFloat, "VEC4", 3);
  std::vector<float> d0;
  for (const glm::vec3& d : kD0) d0.insert(d0.end(), {d.x, d.y, d.z});
  const int target = w.Accessor(d0, GltfWriter::kFloat, "VEC3", 3);
  const int times = w.Accessor(std::vector<float>{0, 1}, GltfWriter::kFloat, "SCALAR", 2);
  const int moves = w.Accessor(std::vector<float>{0, 0, 0, 0, 0, 10}, GltfWriter::kFloat, "VEC3", 2);
  const int morph = w.Accessor(std::vector<float>{0, 1}, GltfWriter::kFloat, "SCALAR", 2);
  w.doc["scenes"] = {{{"nodes", {0, 1}}}};
  w.doc["nodes"] = {{{"name", "joint"}}, {{"name", "mesh"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0}}}};
  nlohmann::json primitive;
  primitive["attributes"] = {{"POSITION", positions}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}};
  primitive["targets"] = nlohmann::json::array({{{"POSITION", target}}});
  w.doc["meshes"] = nlohmann::json::array({{{"primitives", nlohmann::json::array({primitive})}}});
  w.doc["animations"] = {
      {{"samplers", {{{"input", times}, {"output", moves}}, {{"input", times}, {"output", morph}}}},
       {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}},
                     {{"sampler", 1}, {"target", {{"node", 1}, {"path", "weights"}}}}}}}};
  auto model = Read(w, "skinned.gltf", /*require_skin=*/true);
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  ASSERT_EQ(model->morph.num_targets, 1);
  EXPECT_TRUE(model->morph.normal_deltas.empty());
  auto sampler = deform::GltfMeshSampler::Create(*model);
  ASSERT_TRUE(sampler.ok());
  std::vector<glm::vec3> p(3), n(3);
  for (const double t : {0.0, 0.5, 1.0}) {
    ASSERT_TRUE(sampler->Sample(0, t, p, n).ok());
    const auto tf = static_cast<float>(t);
    for (int v = 0; v < 3; ++v) {
      const glm::vec3 e =
          glm::vec3(kBase[3 * v], kBase[3 * v + 1], kBase[3 * v + 2]) + tf * kD0[v] + glm::vec3(0, 0, 10 * tf);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[static_cast<std::size_t>(v)][c], e[c], kFloatTol);
    }
  }
}

// Each broken file gives the expected code and names the glTF field.
struct BadCase {
  const char* name;
  void (*edit)(GltfWriter&);
  base::ErrorCode code;
  const char* field;
};

class GltfMorphBadFile : public ::testing::TestWithParam<BadCase> {};

TEST_P(GltfMorphBadFile, IsRefusedNamingTheField) {
  MorphFile f = TriangleWithTargets();
  GetParam().edit(f.w);
  auto model = Read(f.w, std::string("bad_") + GetParam().name + ".gltf");
  ASSERT_FALSE(model.ok()) << GetParam().name;
  EXPECT_EQ(model.error().code, GetParam().code) << model.error().ToString();
  EXPECT_NE(model.error().loc.field_path.find(GetParam().field), std::string::npos)
      << model.error().ToString();
}

INSTANTIATE_TEST_SUITE_P(
    Cases, GltfMorphBadFile,
    ::testing::Values(
        BadCase{"target_count", [](GltfWriter& w) { w.doc["accessors"][2]["count"] = 2; },
                base::ErrorCode::kCountMismatch, "accessors[2].count"},
        BadCase{"target_type", [](GltfWriter& w) { w.doc["accessors"][2]["type"] = "VEC4"; },
                base::ErrorCode::kUnsupported, "accessors[2].type"},
        BadCase{"target_nan",
                [](GltfWriter& w) {
                  const float nan = std::numeric_limits<float>::quiet_NaN();
                  w.doc["accessors"][2]["bufferView"] =
                      w.Accessor(std::vector<float>{0, 0, 0, nan, 0, 0, 0, 0, 0}, GltfWriter::kFloat, "VEC3", 3);
                },
                base::ErrorCode::kNonFinite, "accessors["},
        BadCase{"mesh_weights", [](GltfWriter& w) { w.doc["meshes"][0]["weights"] = {1.0}; },
                base::ErrorCode::kCountMismatch, "meshes[0].weights"},
        BadCase{"sparse_index_past_count",
                [](GltfWriter& w) {
                  w.doc["accessors"][6]["sparse"]["indices"]["bufferView"] =
                      w.Accessor(std::vector<std::uint16_t>{3, 0}, GltfWriter::kUnsignedShort, "SCALAR", 1);
                },
                base::ErrorCode::kCountMismatch, "accessors[6]"},
        BadCase{"sparse_not_increasing",
                [](GltfWriter& w) {
                  w.doc["accessors"][6]["sparse"]["count"] = 2;
                  w.doc["accessors"][6]["sparse"]["indices"]["bufferView"] =
                      w.Accessor(std::vector<std::uint16_t>{2, 1}, GltfWriter::kUnsignedShort, "SCALAR", 2);
                  w.doc["accessors"][6]["sparse"]["values"]["bufferView"] =
                      w.Accessor(std::vector<float>(6, 0.0f), GltfWriter::kFloat, "VEC3", 2);
                },
                base::ErrorCode::kBadNumber, "accessors[6].sparse.indices"},
        BadCase{"sparse_values_short",
                [](GltfWriter& w) {
                  w.doc["accessors"][6]["sparse"]["count"] = 2;
                  w.doc["accessors"][6]["sparse"]["indices"]["bufferView"] =
                      w.Accessor(std::vector<std::uint16_t>{0, 2}, GltfWriter::kUnsignedShort, "SCALAR", 2);
                },
                base::ErrorCode::kCountMismatch, "accessors[6].sparse.values"},
        BadCase{"weights_output_count",
                [](GltfWriter& w) {
                  AddWeights(w, 1, "LINEAR", {0, 1}, {0, 0, 1});
                },
                base::ErrorCode::kCountMismatch, ".count"},
        BadCase{"weights_output_nan",
                [](GltfWriter& w) {
                  AddWeights(w, 1, "LINEAR", {0, 1}, {0, 0, std::numeric_limits<float>::infinity(), 0});
                },
                base::ErrorCode::kNonFinite, "accessors["},
        BadCase{"weights_times_decrease",
                [](GltfWriter& w) {
                  AddWeights(w, 1, "STEP", {1, 0}, {0, 0, 1, 0});
                },
                base::ErrorCode::kBadNumber, "accessors["},
        BadCase{"weights_interpolation",
                [](GltfWriter& w) {
                  AddWeights(w, 1, "SMOOTH", {0, 1}, {0, 0, 1, 0});
                },
                base::ErrorCode::kUnsupported, "animations[0].samplers[0].interpolation"},
        BadCase{"primitives_disagree",
                [](GltfWriter& w) {
                  nlohmann::json second = w.doc["meshes"][0]["primitives"][0];
                  second["targets"].erase(1);
                  w.doc["meshes"][0]["primitives"].push_back(second);
                },
                base::ErrorCode::kCountMismatch, "meshes[0].primitives"}),
    [](const ::testing::TestParamInfo<BadCase>& p) { return std::string(p.param.name); });

TEST(GltfMorphImport, MorphDeltasAreBoundedBeforeAllocating) {
  MorphFile f = TriangleWithTargets();
  const std::string path = f.w.Write(testsupport::TestOutputPath("gltf_morph/limit.gltf").string());
  deform::GltfReadOptions options;
  options.require_skin = false;
  options.max_morph_values = 5;  // 2 targets x 3 vertices = 6
  auto model = deform::ReadGltf(path, options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().code, base::ErrorCode::kLimitExceeded) << model.error().ToString();
  options.max_morph_values = 6;
  EXPECT_TRUE(deform::ReadGltf(path, options).ok());
}

TEST(GltfMorphImport, UnskinnedFilesNeedTheOption) {
  MorphFile f = TriangleWithTargets();
  auto model = Read(f.w, "unskinned.gltf", /*require_skin=*/true);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().code, base::ErrorCode::kNotFound);
  EXPECT_EQ(model.error().loc.field_path, "skins");
}

}  // namespace
