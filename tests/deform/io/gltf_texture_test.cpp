// Texture coordinates, materials and base colour textures of an imported glTF
// mesh (deform/io/gltf_import.h): TEXCOORD_0 as floats or normalized integers,
// the texture's image from a buffer view, a data: URI or a file, decoded and
// converted from sRGB to linear, the sampler's wrap modes, a material per
// triangle, and clear errors (or a warning where a texture may be absent).

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "deform/io/gltf_export.h"
#include "deform/io/gltf_import.h"
#include "deform/io/internal/gltf_material.h"
#include "deform/io/obj_writer.h"
#include "deform/mesh.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"
#include "support/texture_files.h"

namespace {

using testsupport::GltfWriter;
namespace fs = std::filesystem;


// The 2 x 2 RGB image every test uses: red, green / blue, mid grey (128).
const std::vector<std::uint8_t> kCodes = {255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128};

fs::path Folder() { return testsupport::TestOutputPath("gltf_texture/x").parent_path(); }

std::vector<unsigned char> Png() { return testsupport::EncodeImage(Folder() / "tex.png", 2, 2, 3, kCodes); }

struct Quad {
  std::string uvs = "float";  // "", float, u8, u16, nan, short (one fewer than the vertices)
  std::string image = "view";  // view, data, file, missing, garbage, truncated
  int texture = 0;             // baseColorTexture.index; -1: none
  int tex_coord = 0;
  std::vector<int> wrap = {};   // wrapS, wrapT of a sampler, or none
  bool second_primitive = false;      // plus an untextured quad ...
  std::vector<double> second_factor;  // ... with this baseColorFactor (empty: no material)
  std::vector<double> factor;         // the textured material's baseColorFactor, or none
};

// A skinned quad (two triangles, four vertices bound to one joint) with the
// texture of `q`; returns the written file.
// The textured quad plus an untextured one with its own base colour factor.
Quad TwoMaterials() {
  Quad q;
  q.second_primitive = true;
  q.second_factor = {0.5, 0.25, 1.0, 1.0};
  return q;
}

std::string Write(const std::string& name, const Quad& q) {
  GltfWriter w;
  nlohmann::json primitives = nlohmann::json::array();
  const int prims = q.second_primitive ? 2 : 1;
  for (int p = 0; p < prims; ++p) {
    const float x = static_cast<float>(2 * p);
    const std::vector<float> positions = {x, 0, 0, x + 1, 0, 0, x + 1, 1, 0, x, 1, 0};
    const std::vector<std::uint16_t> joints(16, 0);
    const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const std::vector<std::uint16_t> indices = {0, 1, 2, 0, 2, 3};
    nlohmann::json attributes = {{"POSITION", w.Accessor(positions, GltfWriter::kFloat, "VEC3", 4)},
                                 {"JOINTS_0", w.Accessor(joints, GltfWriter::kUnsignedShort, "VEC4", 4)},
                                 {"WEIGHTS_0", w.Accessor(weights, GltfWriter::kFloat, "VEC4", 4)}};
    if (p == 0 && !q.uvs.empty()) {
      int a = -1;
      if (q.uvs == "float" || q.uvs == "nan") {
        std::vector<float> uv = {0, 0, 1, 0, 1, 1, 0, 1};
        if (q.uvs == "nan") uv[3] = std::numeric_limits<float>::quiet_NaN();
        a = w.Accessor(uv, GltfWriter::kFloat, "VEC2", 4);
      } else if (q.uvs == "short") {
        a = w.Accessor(std::vector<float>{0, 0, 1, 0, 1, 1}, GltfWriter::kFloat, "VEC2", 3);
      } else if (q.uvs == "u8") {
        a = w.Accessor(std::vector<std::uint8_t>{0, 0, 255, 0, 255, 128, 0, 51}, GltfWriter::kUnsignedByte,
                       "VEC2", 4);
        w.doc["accessors"][static_cast<std::size_t>(a)]["normalized"] = true;
      } else if (q.uvs == "u16") {
        a = w.Accessor(std::vector<std::uint16_t>{0, 0, 65535, 0, 65535, 32768, 0, 13107},
                       GltfWriter::kUnsignedShort, "VEC2", 4);
        w.doc["accessors"][static_cast<std::size_t>(a)]["normalized"] = true;
      }
      attributes["TEXCOORD_0"] = a;
    }
    nlohmann::json prim = {{"attributes", attributes},
                           {"indices", w.Accessor(indices, GltfWriter::kUnsignedShort, "SCALAR", 6)}};
    if (p == 0) prim["material"] = 0;
    if (p == 1 && !q.second_factor.empty()) prim["material"] = 1;
    primitives.push_back(prim);
  }
  const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const int ibm_accessor = w.Accessor(ibm, GltfWriter::kFloat, "MAT4", 1);  // before the image's view
  nlohmann::json textured = {{"name", "skin"}, {"pbrMetallicRoughness", nlohmann::json::object()}};
  if (!q.factor.empty()) textured["pbrMetallicRoughness"]["baseColorFactor"] = q.factor;
  if (q.texture >= 0) {
    textured["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", q.texture}, {"texCoord", q.tex_coord}};
  }
  w.doc["materials"] = nlohmann::json::array({textured});
  if (!q.second_factor.empty()) {
    w.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorFactor", q.second_factor}}}});
  }
  nlohmann::json texture = {{"source", 0}};
  if (!q.wrap.empty()) {
    w.doc["samplers"] = {{{"wrapS", q.wrap[0]}, {"wrapT", q.wrap[1]}}};
    texture["sampler"] = 0;
  }
  w.doc["textures"] = nlohmann::json::array({texture});
  std::vector<unsigned char> bytes = Png();
  if (q.image == "garbage") bytes = {'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'a', 'g', 'e'};
  if (q.image == "truncated") bytes.resize(40);
  if (q.image == "data") {
    w.doc["images"] = {{{"uri", "data:image/png;base64," + testsupport::Base64(bytes)}}};
  } else if (q.image == "file" || q.image == "missing") {
    w.doc["images"] = {{{"uri", q.image == "file" ? "tex.png" : "absent.png"}}};
  } else {
    w.doc["images"] = {{{"bufferView", w.BufferView(bytes)}, {"mimeType", "image/png"}}};
  }
  w.doc["scenes"] = {{{"nodes", {0, 1}}}};
  w.doc["nodes"] = {{{"name", "root"}}, {{"name", "body"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0}}, {"inverseBindMatrices", ibm_accessor}}};
  w.doc["meshes"] = {{{"primitives", primitives}}};
  const std::string path = (Folder() / name).string();
  return name.ends_with(".glb") ? w.WriteGlb(path) : w.Write(path);
}

void ExpectTexel(const deform::TextureImage& image, int x, int y, double r, double g, double b) {
  const std::size_t at = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                              static_cast<std::size_t>(x));
  EXPECT_NEAR(image.rgb[at], r, 1e-6) << "texel " << x << "," << y;
  EXPECT_NEAR(image.rgb[at + 1], g, 1e-6) << "texel " << x << "," << y;
  EXPECT_NEAR(image.rgb[at + 2], b, 1e-6) << "texel " << x << "," << y;
}

TEST(GltfTexture, GlbWithUvsMaterialAndEmbeddedPng) {
  Quad q;
  q.wrap = {33648, 33071};  // MIRRORED_REPEAT, CLAMP_TO_EDGE
  const std::string path = Write("quad.glb", q);
  auto model = deform::ReadGltf(path);
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::Mesh& bind = model->mesh.bind;
  ASSERT_EQ(bind.uvs.size(), 4u);
  EXPECT_EQ(bind.uvs[0], glm::vec2(0, 0));
  EXPECT_EQ(bind.uvs[1], glm::vec2(1, 0));
  EXPECT_EQ(bind.uvs[2], glm::vec2(1, 1));
  EXPECT_EQ(bind.uvs[3], glm::vec2(0, 1));
  EXPECT_TRUE(bind.colors.empty()) << "a white factor without COLOR_0 adds no colours";
  const deform::MeshMaterials& m = model->mesh.materials;
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "skin");
  EXPECT_EQ(m.materials[0].texture, 0);
  EXPECT_EQ(m.materials[0].wrap_s, deform::TextureWrap::kMirroredRepeat);
  EXPECT_EQ(m.materials[0].wrap_t, deform::TextureWrap::kClampToEdge);
  EXPECT_EQ(m.triangle_material, (std::vector<std::int32_t>{0, 0}));
  ASSERT_EQ(m.images.size(), 1u);
  const deform::TextureImage& image = *m.images[0];
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 2);
  // Row 0 of the file is v = 0; sRGB codes become linear light.
  ExpectTexel(image, 0, 0, 1, 0, 0);
  ExpectTexel(image, 1, 0, 0, 1, 0);
  ExpectTexel(image, 0, 1, 0, 0, 1);
  ExpectTexel(image, 1, 1, testsupport::SrgbCodeToLinear(128), testsupport::SrgbCodeToLinear(128), testsupport::SrgbCodeToLinear(128));
  EXPECT_NEAR(testsupport::SrgbCodeToLinear(128), 0.2158605, 1e-6);  // not 128 / 255 = 0.502
  EXPECT_EQ(image.encoded, Png());
  EXPECT_EQ(image.mime_type, "image/png");
}

TEST(GltfTexture, NormalizedIntegerUvs) {
  for (const std::string kind : {"u8", "u16"}) {
    Quad q;
    q.uvs = kind;
    auto model = deform::ReadGltf(Write("uv_" + kind + ".gltf", q));
    ASSERT_TRUE(model.ok()) << model.error().ToString();
    const std::vector<glm::vec2>& uv = model->mesh.bind.uvs;
    ASSERT_EQ(uv.size(), 4u);
    const float half = kind == "u8" ? 128.0f / 255.0f : 32768.0f / 65535.0f;
    EXPECT_EQ(uv[1], glm::vec2(1, 0)) << kind;
    EXPECT_FLOAT_EQ(uv[2].y, half) << kind;
    EXPECT_FLOAT_EQ(uv[3].y, 0.2f) << kind;  // 51 / 255 = 13107 / 65535
  }
}

TEST(GltfTexture, ImageFromDataUriAndFromFile) {
  for (const std::string kind : {"data", "file"}) {
    Quad q;
    q.image = kind;
    auto model = deform::ReadGltf(Write("img_" + kind + ".gltf", q));
    ASSERT_TRUE(model.ok()) << model.error().ToString();
    ASSERT_EQ(model->mesh.materials.images.size(), 1u) << kind;
    ExpectTexel(*model->mesh.materials.images[0], 1, 1, testsupport::SrgbCodeToLinear(128), testsupport::SrgbCodeToLinear(128), testsupport::SrgbCodeToLinear(128));
  }
}

TEST(GltfTexture, MissingImageFileWarnsAndLeavesTheTextureOut) {
  Quad q;
  q.image = "missing";
  auto model = deform::ReadGltf(Write("missing.gltf", q));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  EXPECT_FALSE(model->mesh.materials.textured());
  bool warned = false;
  for (const base::Warning& w : model->warnings)
    warned = warned || w.ToString().find("absent.png' could not be read") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(GltfTexture, OtherTexCoordSetOrNoUvsWarnsAndLeavesTheTextureOut) {
  Quad q;
  q.tex_coord = 1;
  auto model = deform::ReadGltf(Write("texcoord1.gltf", q));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  EXPECT_FALSE(model->mesh.materials.textured());
  q = Quad{};
  q.uvs = "";
  model = deform::ReadGltf(Write("no_uvs.gltf", q));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  EXPECT_FALSE(model->mesh.materials.textured());
  EXPECT_FALSE(model->warnings.empty());
}

TEST(GltfTexture, BadInputIsAnErrorNamingTheFileAndField) {
  struct Case {
    std::string name;
    Quad quad;
    std::string field;
    std::string says;
  };
  Quad bad_index, garbage, truncated, short_uvs, nan_uvs;
  bad_index.texture = 5;
  garbage.image = "garbage";
  truncated.image = "truncated";
  short_uvs.uvs = "short";
  nan_uvs.uvs = "nan";
  const std::vector<Case> cases = {
      {"bad_index.glb", bad_index, "materials[0].pbrMetallicRoughness.baseColorTexture.index", "out of range"},
      {"garbage.glb", garbage, "images[0]", "neither PNG nor JPEG"},
      {"truncated.glb", truncated, "images[0]", "cannot decode"},
      {"short_uvs.glb", short_uvs, ".count", "TEXCOORD_0"},
      {"nan_uvs.glb", nan_uvs, "accessors[", ""},
  };
  for (const Case& c : cases) {
    auto model = deform::ReadGltf(Write(c.name, c.quad));
    ASSERT_FALSE(model.ok()) << c.name;
    const std::string text = model.error().ToString();
    EXPECT_NE(text.find(c.name), std::string::npos) << text;
    EXPECT_NE(text.find(c.field), std::string::npos) << text;
    EXPECT_NE(text.find(c.says), std::string::npos) << text;
  }
}

TEST(GltfTexture, MaterialPerTriangleAndWhiteUnderTheTextureWhenOthersHaveColours) {
  const Quad q = TwoMaterials();
  auto model = deform::ReadGltf(Write("two.glb", q));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::MeshMaterials& m = model->mesh.materials;
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[1].texture, -1);
  EXPECT_EQ(m.materials[1].base_color_factor, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_EQ(m.triangle_material, (std::vector<std::int32_t>{0, 0, 1, 1}));
  const deform::Mesh& bind = model->mesh.bind;
  ASSERT_EQ(bind.colors.size(), 8u);
  EXPECT_EQ(bind.colors[0], glm::vec3(1.0f)) << "textured part: texture x white, not the grey";
  EXPECT_EQ(bind.colors[4], glm::vec3(0.5f, 0.25f, 1.0f));
  ASSERT_EQ(bind.uvs.size(), 8u);  // the untextured part gets (0, 0)
  EXPECT_EQ(bind.uvs[5], glm::vec2(0.0f));
}

TEST(GltfTexture, JpegAndGreyAlphaImagesDecode) {
  const std::vector<std::uint8_t> rgb(4 * 4 * 3, 0);
  std::vector<std::uint8_t> codes;
  for (int i = 0; i < 16; ++i) codes.insert(codes.end(), {200, 100, 50});
  const auto jpeg = testsupport::EncodeImage(Folder() / "flat.jpg", 4, 4, 3, codes);
  ASSERT_FALSE(jpeg.empty());
  auto image = deform::internal::DecodeTextureImage(jpeg, "image/jpeg", "x.glb", "images[0]");
  ASSERT_TRUE(image.ok()) << image.error().ToString();
  EXPECT_EQ(image->mime_type, "image/jpeg");
  // A flat JPEG at quality 100 decodes within a few codes.
  EXPECT_NEAR(image->rgb[0], testsupport::SrgbCodeToLinear(200), testsupport::SrgbCodeToLinear(203) - testsupport::SrgbCodeToLinear(200));
  EXPECT_NEAR(image->rgb[1], testsupport::SrgbCodeToLinear(100), testsupport::SrgbCodeToLinear(103) - testsupport::SrgbCodeToLinear(100));
  EXPECT_NEAR(image->rgb[2], testsupport::SrgbCodeToLinear(50), testsupport::SrgbCodeToLinear(53) - testsupport::SrgbCodeToLinear(50));
  const auto grey = testsupport::EncodeImage(Folder() / "grey.png", 1, 2, 2, {64, 255, 192, 0});
  auto g = deform::internal::DecodeTextureImage(grey, "image/png", "x.glb", "images[0]");
  ASSERT_TRUE(g.ok()) << g.error().ToString();
  ASSERT_EQ(g->rgb.size(), 6u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(g->rgb[static_cast<std::size_t>(c)], testsupport::SrgbCodeToLinear(64), 1e-6);
    EXPECT_NEAR(g->rgb[static_cast<std::size_t>(3 + c)], testsupport::SrgbCodeToLinear(192), 1e-6) << "alpha 0 keeps its colour";
  }
}

TEST(GltfTexture, ImagesWiderThanTheLimitAreRefused) {
  const auto wide = testsupport::EncodeImage(Folder() / "wide.png", 8193, 1, 3,
                                             std::vector<std::uint8_t>(8193 * 3, 7));
  ASSERT_FALSE(wide.empty());
  auto image = deform::internal::DecodeTextureImage(wide, "image/png", "w.glb", "images[0]");
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.error().code, base::ErrorCode::kLimitExceeded);
  EXPECT_NE(image.error().ToString().find("8193 x 1 x 3"), std::string::npos) << image.error().ToString();
}

// Exports `mesh` (its bind pose as two frames) to a .glb and reads it back
// (no skin in an export: each mesh node is rigid).
base::Result<deform::GltfModel> ExportAndReimport(const deform::SkinnedMesh& mesh,
                                                  const std::string& name,
                                                  deform::GltfExportLayout layout) {
  deform::GltfExportOptions options;
  options.layout = layout;
  options.scratch_dir = Folder().string();
  const deform::Mesh& bind = mesh.bind;
  std::vector<glm::vec3> normals(bind.positions.size(), glm::vec3(0, 0, 1));
  auto w = deform::GltfSequenceWriter::Create(bind.triangles, bind.colors, bind.num_vertices(), 2, options,
                                              {.uvs = bind.uvs, .materials = &mesh.materials});
  if (!w.ok()) return std::move(w).error();
  for (int f = 0; f < 2; ++f) {
    if (auto s = w->AddFrame(bind.positions, normals); !s) return s.error();
  }
  const std::string path = (Folder() / name).string();
  if (auto s = w->Finish(path); !s) return s.error();
  deform::GltfReadOptions read;
  read.require_skin = false;
  return deform::ReadGltf(path, read);
}

TEST(GltfTextureExport, GlbRoundTripKeepsUvsMaterialAndTexturePixels) {
  Quad q;
  q.wrap = {33648, 33071};
  q.factor = {0.5, 0.25, 1.0, 1.0};  // folded into the imported colours
  auto original = deform::ReadGltf(Write("export_src.glb", q));
  ASSERT_TRUE(original.ok()) << original.error().ToString();
  for (const auto layout : {deform::GltfExportLayout::kMorphTargets, deform::GltfExportLayout::kBakedMeshes}) {
    auto back = ExportAndReimport(original->mesh, "export_back.glb", layout);
    ASSERT_TRUE(back.ok()) << back.error().ToString();
    const deform::Mesh& a = original->mesh.bind;
    const deform::Mesh& b = back->mesh.bind;
    // Baked: one mesh per frame, which the importer merges; frame 0 comes first.
    const int copies = layout == deform::GltfExportLayout::kBakedMeshes ? 2 : 1;
    ASSERT_EQ(b.num_vertices(), copies * a.num_vertices());
    const auto first = [&](const auto& v, std::size_t n) { return std::vector(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n)); };
    EXPECT_EQ(first(b.uvs, a.uvs.size()), a.uvs);
    EXPECT_EQ(first(b.colors, a.colors.size()), a.colors) << "colour / factor written, times factor read";
    EXPECT_EQ(first(b.triangles, a.triangles.size()), a.triangles);
    const deform::MeshMaterials& ma = original->mesh.materials;
    const deform::MeshMaterials& mb = back->mesh.materials;
    ASSERT_EQ(mb.materials.size(), 1u);  // shared by the frames' primitives
    EXPECT_EQ(mb.materials[0].base_color_factor, glm::vec3(0.5f, 0.25f, 1.0f));
    EXPECT_EQ(mb.materials[0].wrap_s, deform::TextureWrap::kMirroredRepeat);
    EXPECT_EQ(mb.materials[0].wrap_t, deform::TextureWrap::kClampToEdge);
    ASSERT_EQ(mb.images.size(), 1u);
    EXPECT_EQ(mb.images[0]->encoded, ma.images[0]->encoded) << "the image is embedded unchanged";
    EXPECT_EQ(mb.images[0]->rgb, ma.images[0]->rgb);
  }
}

TEST(GltfTextureExport, GlbOnePrimitivePerMaterial) {
  const Quad q = TwoMaterials();
  auto original = deform::ReadGltf(Write("export_two.glb", q));
  ASSERT_TRUE(original.ok()) << original.error().ToString();
  auto back = ExportAndReimport(original->mesh, "export_two_back.glb", deform::GltfExportLayout::kMorphTargets);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  const deform::MeshMaterials& m = back->mesh.materials;
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].texture, 0);
  EXPECT_EQ(m.materials[1].texture, -1);
  EXPECT_EQ(m.materials[1].base_color_factor, glm::vec3(0.5f, 0.25f, 1.0f));
  // The primitives share the vertex attributes, and the importer reads them
  // once: the same vertices and triangles as the original (it had one copy of
  // the vertices per primitive before).
  ASSERT_EQ(back->mesh.bind.num_vertices(), original->mesh.bind.num_vertices());
  EXPECT_EQ(back->mesh.bind.triangles, original->mesh.bind.triangles);
  EXPECT_EQ(back->mesh.bind.uvs, original->mesh.bind.uvs);
  EXPECT_EQ(m.triangle_material, (std::vector<std::int32_t>{0, 0, 1, 1}));
  // Every corner keeps its albedo: white under the texture, the factor on the other part.
  EXPECT_EQ(back->mesh.bind.colors, original->mesh.bind.colors);
}

// A closed octahedron, its upper half in one material and its lower half in
// another; the four equator vertices belong to both.
deform::SkinnedMesh TwoMaterialOctahedron(const glm::vec3& upper, const glm::vec3& lower) {
  deform::SkinnedMesh mesh;
  mesh.bind.positions = {{1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}, {0, 1, 0}, {0, -1, 0}};
  for (std::uint32_t i = 0; i < 4; ++i) {
    const std::uint32_t next = (i + 1) % 4;
    mesh.bind.triangles.push_back({next, i, 4});
  }
  for (std::uint32_t i = 0; i < 4; ++i) {
    const std::uint32_t next = (i + 1) % 4;
    mesh.bind.triangles.push_back({i, next, 5});
  }
  mesh.materials.materials = {{.base_color_factor = upper, .name = "upper"}, {.base_color_factor = lower, .name = "lower"}};
  mesh.materials.triangle_material = {0, 0, 0, 0, 1, 1, 1, 1};
  return mesh;
}

TEST(GltfTextureExport, SharedVerticesStayOneClosedSurface) {
  const deform::SkinnedMesh octahedron = TwoMaterialOctahedron(glm::vec3(0.8f, 0.2f, 0.2f), glm::vec3(0.8f, 0.2f, 0.2f));
  ASSERT_TRUE(deform::IsClosedOutward(octahedron.bind.positions, octahedron.bind.triangles));
  auto back = ExportAndReimport(octahedron, "octahedron_back.glb", deform::GltfExportLayout::kMorphTargets);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  const deform::Mesh& b = back->mesh.bind;
  EXPECT_EQ(b.positions, octahedron.bind.positions);
  EXPECT_EQ(b.triangles, octahedron.bind.triangles);
  EXPECT_TRUE(deform::IsClosedOutward(b.positions, b.triangles)) << "the materials' seam stays closed";
  EXPECT_EQ(back->mesh.materials.triangle_material, octahedron.materials.triangle_material);
  ASSERT_EQ(b.colors.size(), 6u);
  for (const glm::vec3& c : b.colors) EXPECT_EQ(c, glm::vec3(0.8f, 0.2f, 0.2f));
}

// Two different factors: an equator vertex has two albedos, so it is copied
// once (for the lower half) and every corner keeps its own material's colour.
TEST(GltfTextureExport, SharedVertexWithTwoAlbedosIsCopiedOnce) {
  const glm::vec3 red(0.8f, 0.2f, 0.2f), blue(0.2f, 0.2f, 0.8f);
  const deform::SkinnedMesh octahedron = TwoMaterialOctahedron(red, blue);
  auto back = ExportAndReimport(octahedron, "octahedron_two_back.glb", deform::GltfExportLayout::kMorphTargets);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  const deform::Mesh& b = back->mesh.bind;
  EXPECT_EQ(b.num_vertices(), 6 + 4) << "the four equator vertices, once more";
  ASSERT_EQ(b.triangles.size(), 8u);
  for (std::size_t t = 0; t < 8; ++t) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(b.positions[b.triangles[t][c]], octahedron.bind.positions[octahedron.bind.triangles[t][c]]);
      EXPECT_EQ(b.colors[b.triangles[t][c]], t < 4 ? red : blue) << "triangle " << t;
    }
  }
}

TEST(GltfTextureExport, ObjKeepsUvsAndMaterials) {
  const Quad q = TwoMaterials();
  auto model = deform::ReadGltf(Write("obj_src.glb", q));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::Mesh& bind = model->mesh.bind;
  const std::vector<std::string> names = {"skin", "plain"};
  std::string text;
  ASSERT_TRUE(deform::AppendObj({.positions = bind.positions, .triangles = bind.triangles, .uvs = bind.uvs,
                                 .material_library = "m.mtl", .material_names = names,
                                 .triangle_material = model->mesh.materials.triangle_material},
                                text)
                  .ok());
  std::istringstream lines(text);
  std::string line;
  std::vector<glm::vec2> uvs;
  std::vector<std::string> faces, usemtl;
  bool mtllib = false;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    if (tag == "vt") {
      glm::vec2 uv;
      in >> uv.x >> uv.y;
      uvs.emplace_back(uv.x, 1.0f - uv.y);  // OBJ's v runs up the image
    }
    if (tag == "f") faces.push_back(line);
    if (tag == "usemtl") usemtl.push_back(line);
    mtllib = mtllib || line == "mtllib m.mtl";
  }
  EXPECT_TRUE(mtllib);
  ASSERT_EQ(uvs.size(), bind.uvs.size());
  for (std::size_t v = 0; v < uvs.size(); ++v) {
    EXPECT_NEAR(uvs[v].x, bind.uvs[v].x, 0.0f) << v;
    EXPECT_NEAR(uvs[v].y, bind.uvs[v].y, 1e-7f) << v;  // 1 - (1 - v): one rounding
  }
  ASSERT_EQ(faces.size(), 4u);
  EXPECT_EQ(faces[0], "f 1/1 2/2 3/3");
  EXPECT_EQ(usemtl, (std::vector<std::string>{"usemtl skin", "usemtl plain"}));
  const fs::path mtl = Folder() / "m.mtl";
  const std::vector<glm::vec3> kd = {glm::vec3(1.0f), glm::vec3(0.5f, 0.25f, 1.0f)};
  const std::vector<std::string> files = {"skin.png", ""};
  ASSERT_TRUE(deform::WriteObjMaterials(mtl.string(), names, kd, files).ok());
  std::ifstream in(mtl);
  const std::string content{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_NE(content.find("newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n"), std::string::npos) << content;
  EXPECT_NE(content.find("newmtl plain\nKd 0.5 0.25 1\n"), std::string::npos) << content;
}

}  // namespace
