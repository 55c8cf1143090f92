// `patchskin export` of a textured glTF character (CesiumMan, ../shared/data)
// read back: the OBJ frames' vt lines give the imported uvs, materials.mtl
// names the texture written next to them, whose bytes and decoded texels are
// the file's; the .glb gives back the uvs and the texture's texels.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "deform/io/gltf_import.h"
#include "deform/io/internal/gltf_material.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;

TEST(ExportTexture, CesiumManObjAndGlbKeepUvsAndTexture) {
  const fs::path input = testsupport::SharedDataPath("gltf/CesiumMan.glb");
  PATCHSKIN_REQUIRE_SHARED_FILE(input);
  auto model = deform::ReadGltf(input.string());
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::Mesh& bind = model->mesh.bind;
  const deform::TextureImage& image = *model->mesh.materials.images.at(0);
  const fs::path dir = testsupport::TestDir("export_texture");

  const auto obj = testsupport::RunPatchskin(
      {"export", input.string(), "--frames", "0:1", "--out", (dir / "obj" / "mesh_####.obj").string(), "--quiet"},
      dir / "logs" / "obj");
  ASSERT_EQ(obj.exit_code, 0) << obj.err;
  const std::string mtl = testsupport::SlurpFile(dir / "obj" / "materials.mtl");
  EXPECT_NE(mtl.find("map_Kd texture_0.jpg"), std::string::npos) << mtl;
  const std::string jpg = testsupport::SlurpFile(dir / "obj" / "texture_0.jpg");
  ASSERT_EQ(jpg.size(), image.encoded.size());
  EXPECT_TRUE(std::equal(jpg.begin(), jpg.end(), image.encoded.begin(),
                         [](char a, unsigned char b) { return static_cast<unsigned char>(a) == b; }));
  auto decoded = deform::internal::DecodeTextureImage(image.encoded, "image/jpeg", "texture_0.jpg", "");
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->rgb, image.rgb) << "the same texels as the import's";
  std::istringstream lines(testsupport::SlurpFile(dir / "obj" / "mesh_0001.obj"));
  std::string line;
  std::size_t v = 0;
  bool textured_faces = false;
  while (std::getline(lines, line)) {
    if (line.rfind("vt ", 0) == 0) {
      ASSERT_LT(v, bind.uvs.size());
      std::istringstream in(line.substr(3));
      float u = 0, w = 0;
      in >> u >> w;
      EXPECT_EQ(u, bind.uvs[v].x) << v;
      EXPECT_NEAR(1.0f - w, bind.uvs[v].y, 6e-8f) << v;
      ++v;
    }
    if (line == "usemtl material_0") textured_faces = true;
  }
  EXPECT_EQ(v, bind.uvs.size());
  EXPECT_TRUE(textured_faces);

  const fs::path glb = dir / "c.glb";
  const auto g = testsupport::RunPatchskin({"export", input.string(), "--frames", "0:2", "--out", glb.string(), "--quiet"},
                                           dir / "logs" / "glb");
  ASSERT_EQ(g.exit_code, 0) << g.err;
  deform::GltfReadOptions read;
  read.require_skin = false;
  auto back = deform::ReadGltf(glb.string(), read);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->mesh.bind.uvs, bind.uvs);
  ASSERT_TRUE(back->mesh.materials.textured());
  EXPECT_EQ(back->mesh.materials.images.at(0)->rgb, image.rgb);
}

}  // namespace
