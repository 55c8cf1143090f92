// Colours of an imported glTF mesh (deform/io/gltf_import.h): COLOR_0 (float RGB or
// normalized-byte RGBA) times the material's baseColorFactor; a primitive with
// neither gets the default grey only when another primitive of the mesh has
// colours; a file with none leaves the mesh without colours (the renderer's grey).

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "deform/io/gltf_import.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"

namespace {

using testsupport::GltfWriter;

// One joint; each primitive a triangle of its own three vertices bound to it.
// `colors[p]`: "" (no COLOR_0), "rgb" (float VEC3) or "rgba8" (normalized bytes).
std::string Write(const std::string& name, const std::vector<std::string>& colors,
                  const std::vector<int>& materials, const nlohmann::json& material_list) {
  GltfWriter w;
  nlohmann::json primitives = nlohmann::json::array();
  for (std::size_t p = 0; p < colors.size(); ++p) {
    const float x = static_cast<float>(p);
    const std::vector<float> positions = {x, 0, 0, x + 1, 0, 0, x, 1, 0};
    const std::vector<float> normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    const std::vector<std::uint16_t> joints(12, 0);
    const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    nlohmann::json attributes = {{"POSITION", w.Accessor(positions, GltfWriter::kFloat, "VEC3", 3)},
                                 {"NORMAL", w.Accessor(normals, GltfWriter::kFloat, "VEC3", 3)},
                                 {"JOINTS_0", w.Accessor(joints, GltfWriter::kUnsignedShort, "VEC4", 3)},
                                 {"WEIGHTS_0", w.Accessor(weights, GltfWriter::kFloat, "VEC4", 3)}};
    if (colors[p] == "rgb") {
      const std::vector<float> c = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f};
      attributes["COLOR_0"] = w.Accessor(c, GltfWriter::kFloat, "VEC3", 3);
    } else if (colors[p] == "rgba8") {
      const std::vector<std::uint8_t> c = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 51, 0};
      const int a = w.Accessor(c, GltfWriter::kUnsignedByte, "VEC4", 3);
      w.doc["accessors"][static_cast<std::size_t>(a)]["normalized"] = true;
      attributes["COLOR_0"] = a;
    }
    nlohmann::json prim = {{"attributes", attributes}};
    if (materials[p] >= 0) prim["material"] = materials[p];
    primitives.push_back(prim);
  }
  const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const int ibm_accessor = w.Accessor(ibm, GltfWriter::kFloat, "MAT4", 1);
  w.doc["scenes"] = {{{"nodes", {0, 1}}}};
  w.doc["nodes"] = {{{"name", "root"}}, {{"name", "body"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0}}, {"inverseBindMatrices", ibm_accessor}}};
  w.doc["meshes"] = {{{"primitives", primitives}}};
  if (!material_list.empty()) w.doc["materials"] = material_list;
  return w.Write(testsupport::TestOutputPath("gltf_colors/" + name).string());
}

void ExpectColor(glm::vec3 got, glm::vec3 want, const std::string& what) {
  EXPECT_NEAR(got.r, want.r, 1e-3f) << what;
  EXPECT_NEAR(got.g, want.g, 1e-3f) << what;
  EXPECT_NEAR(got.b, want.b, 1e-3f) << what;
}

TEST(GltfColors, VertexColoursTimesTheBaseColourFactor) {
  const nlohmann::json materials = {
      {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1.0, 1.0, 1.0}}}}},
      {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.4, 0.6, 1.0}}}}}};
  const std::string path = Write("mixed.gltf", {"rgb", "rgba8", "", ""}, {0, -1, 1, -1}, materials);
  auto model = deform::ReadGltf(path);
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const std::vector<glm::vec3>& c = model->mesh.bind.colors;
  ASSERT_EQ(c.size(), 12u);
  ExpectColor(c[0], {0.5f, 0, 0}, "float COLOR_0 x factor");
  ExpectColor(c[1], {0, 1, 0}, "float COLOR_0 x factor");
  ExpectColor(c[2], {0, 0, 0.5f}, "float COLOR_0 x factor");
  ExpectColor(c[3], {1, 0, 0}, "normalized bytes, no material");
  ExpectColor(c[4], {0, 1, 0}, "normalized bytes");
  ExpectColor(c[5], {0, 0, 0.2f}, "normalized bytes (51/255)");
  for (int v = 6; v < 9; ++v) ExpectColor(c[static_cast<std::size_t>(v)], {0.2f, 0.4f, 0.6f}, "factor alone");
  for (int v = 9; v < 12; ++v) ExpectColor(c[static_cast<std::size_t>(v)], deform::kDefaultAlbedo, "none: grey");
}

TEST(GltfColors, AFileWithoutColoursLeavesTheMeshWithout) {
  const nlohmann::json white = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}}}}}};
  auto model = deform::ReadGltf(Write("plain.gltf", {"", ""}, {-1, 0}, white));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  EXPECT_TRUE(model->mesh.bind.colors.empty());
}

TEST(GltfColors, CesiumManHasNoColoursOfItsOwn) {
  const std::string path = testsupport::SharedDataPath("gltf/CesiumMan.glb").string();
  PATCHSKIN_REQUIRE_SHARED_FILE(path);
  auto model = deform::ReadGltf(path);
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  EXPECT_TRUE(model->mesh.bind.colors.empty());  // a texture only (not rendered yet)
}

}  // namespace
