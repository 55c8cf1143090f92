// Base colour textures in the renderer (render/raster/texture.h and SceneMesh's
// uvs/textures): the mip pyramid and wrap modes of the sampler, then textured
// renders checked against values computed without the renderer: texel colours
// of a glb written here, the projective (not affine) midpoint of a slanted
// quad, a minified checker averaging to grey, and CesiumMan's mean colour.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "deform/io/gltf_import.h"
#include "render/raster/texture.h"
#include "render/renderer.h"
#include "render/render_fixtures.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"
#include "support/texture_files.h"

namespace {

using deform::TextureWrap;
namespace fs = std::filesystem;


// A checker of n x n texels, texel (x, y) white when x + y is odd.
render::Texture Checker(int n, TextureWrap wrap) {
  std::vector<float> rgb;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) rgb.insert(rgb.end(), 3, static_cast<float>((x + y) % 2));
  return render::Texture(n, n, rgb, wrap, wrap);
}

render::RenderSettings Unlit(int width, int height) {
  render::RenderSettings s;
  s.width = width;
  s.height = height;
  s.threads = 2;
  s.ground = false;
  s.lighting = render::LightingModel::kUnlit;
  return s;
}

TEST(TextureSampler, MipLevelsAreMeansOfTheLevelAbove) {
  const render::Texture t = Checker(64, TextureWrap::kRepeat);
  ASSERT_EQ(t.num_levels(), 7);  // 64, 32, ..., 1
  EXPECT_EQ(t.Texel(0, 0, 0), glm::vec3(0.0f));
  EXPECT_EQ(t.Texel(0, 1, 0), glm::vec3(1.0f));
  for (int level = 1; level < 7; ++level) EXPECT_EQ(t.Texel(level, 0, 0), glm::vec3(0.5f)) << level;
  // A ramp's level 1 is the mean of each 2 x 2 block; odd sizes drop the last column.
  const std::vector<float> ramp = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5};  // 3 x 2
  const render::Texture r(3, 2, ramp, TextureWrap::kClampToEdge, TextureWrap::kClampToEdge);
  ASSERT_EQ(r.num_levels(), 2);
  EXPECT_EQ(r.Texel(1, 0, 0), glm::vec3((0 + 1 + 3 + 4) / 4.0f));
}

TEST(TextureSampler, LevelOfDetailFromTheFootprint) {
  const render::Texture t = Checker(64, TextureWrap::kRepeat);
  EXPECT_FLOAT_EQ(t.Lod({1.0f / 64, 0}, {0, 1.0f / 64}), 0.0f);
  EXPECT_FLOAT_EQ(t.Lod({4.0f / 64, 0}, {0, 1.0f / 64}), 2.0f);  // the longer axis decides
  EXPECT_NEAR(t.Lod({0, 0}, {3.0f / 64, 4.0f / 64}), std::log2(5.0f), 0.004);
  // The log2 approximation: within 0.004 levels over many octaves; magnified = level 0.
  for (float rho = 1.0f; rho < 4096.0f; rho *= 1.037f) {
    EXPECT_NEAR(t.Lod({rho / 64, 0}, {0, 0}), std::log2(rho), 0.004) << rho;
  }
  EXPECT_LE(t.Lod({0.5f / 64, 0}, {0, 0.25f / 64}), 0.0f);
  // Trilinear between levels 0 and 1 at a texel centre: 1 -> 0.5 halfway.
  EXPECT_FLOAT_EQ(t.Sample({1.5f / 64, 0.5f / 64}, 0.5f).x, 0.75f);
}

TEST(TextureSampler, WrapModes) {
  // 2 x 1: texel 0 black (centre u = 0.25), texel 1 white (centre 0.75).
  const std::vector<float> rgb = {0, 0, 0, 1, 1, 1};
  auto at = [&](TextureWrap wrap, float u) {
    return render::Texture(2, 1, rgb, wrap, wrap).SampleLevel({u, 0.5f}, 0).x;
  };
  EXPECT_EQ(at(TextureWrap::kRepeat, -0.75f), 0.0f);         // = 0.25
  EXPECT_EQ(at(TextureWrap::kRepeat, 1.75f), 1.0f);          // = 0.75
  EXPECT_EQ(at(TextureWrap::kMirroredRepeat, -0.75f), 1.0f);  // mirrored: 0.75
  EXPECT_EQ(at(TextureWrap::kMirroredRepeat, 1.25f), 1.0f);   // 2 - 1.25 = 0.75
  EXPECT_EQ(at(TextureWrap::kMirroredRepeat, 1.75f), 0.0f);   // 0.25
  EXPECT_EQ(at(TextureWrap::kClampToEdge, -0.75f), 0.0f);
  EXPECT_EQ(at(TextureWrap::kClampToEdge, 1.25f), 1.0f);
  // Between the centres, repeat blends across the edge and clamp does not.
  EXPECT_FLOAT_EQ(at(TextureWrap::kRepeat, 0.0f), 0.5f);
  EXPECT_EQ(at(TextureWrap::kClampToEdge, 0.0f), 0.0f);
  EXPECT_EQ(at(TextureWrap::kRepeat, 1e9f), at(TextureWrap::kRepeat, 0.0f)) << "huge u stays finite";
}

// A unit-joint skinned quad x, y in [-1, 1] at z = 0 with uv = ((x + 1) / 2,
// (1 - y) / 2) (the image upright), textured with a 2 x 2 PNG (clamped), as a glb.
std::string WriteTexturedQuad(const fs::path& path) {
  testsupport::GltfWriter w;
  using W = testsupport::GltfWriter;
  const std::vector<float> positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const std::vector<float> uvs = {0, 1, 1, 1, 1, 0, 0, 0};
  const std::vector<std::uint16_t> joints(16, 0);
  const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  const std::vector<std::uint16_t> indices = {0, 1, 2, 0, 2, 3};
  const nlohmann::json prim = {
      {"attributes",
       {{"POSITION", w.Accessor(positions, W::kFloat, "VEC3", 4)},
        {"TEXCOORD_0", w.Accessor(uvs, W::kFloat, "VEC2", 4)},
        {"JOINTS_0", w.Accessor(joints, W::kUnsignedShort, "VEC4", 4)},
        {"WEIGHTS_0", w.Accessor(weights, W::kFloat, "VEC4", 4)}}},
      {"indices", w.Accessor(indices, W::kUnsignedShort, "SCALAR", 6)},
      {"material", 0}};
  const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const int ibm_accessor = w.Accessor(ibm, W::kFloat, "MAT4", 1);  // accessors before the image's view
  // Red, green / blue, grey 128 (sRGB codes).
  const auto png = testsupport::EncodeImage(path.parent_path() / "quad.png", 2, 2, 3,
                                            {255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128});
  w.doc["images"] = {{{"bufferView", w.BufferView(png)}, {"mimeType", "image/png"}}};
  w.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33071}}};
  w.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  w.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  w.doc["scenes"] = {{{"nodes", {0, 1}}}};
  w.doc["nodes"] = {{{"name", "root"}}, {{"name", "quad"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0}}, {"inverseBindMatrices", ibm_accessor}}};
  w.doc["meshes"] = {{{"primitives", nlohmann::json::array({prim})}}};
  return w.WriteGlb(path.string());
}

TEST(TexturedRender, PixelsShowTheTexelsOfAnImportedGlb) {
  const fs::path dir = testsupport::TestDir("texture");
  auto model = deform::ReadGltf(WriteTexturedQuad(dir / "quad.glb"));
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::SkinnedMesh& m = model->mesh;
  ASSERT_EQ(m.materials.images.size(), 1u);
  const render::Texture texture(*m.materials.images[0], m.materials.materials[0].wrap_s,
                                m.materials.materials[0].wrap_t);
  render::SceneMesh mesh{.positions = m.bind.positions, .triangles = m.bind.triangles,
                         .uvs = m.bind.uvs, .textures = {&texture, 1}};
  render::Camera cam;
  cam.eye = {0, 0, 3};
  cam.aspect = 1.0f;
  const int n = 200;
  const render::Image image = render::Render(cam, {&mesh, 1}, {}, Unlit(n, n));
  ASSERT_EQ(image.width, n);
  const double expected[2][2][3] = {{{1, 0, 0}, {0, 1, 0}}, {{0, 0, 1}, {testsupport::SrgbCodeToLinear(128), testsupport::SrgbCodeToLinear(128), testsupport::SrgbCodeToLinear(128)}}};
  int checked = 0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      // The quad point under the pixel centre, by ray casting in double.
      const rendertest::Ray ray = rendertest::PixelRay(cam, n, n, x, y);
      const glm::dvec3 p = ray.origin + ray.dir * (-ray.origin.z / ray.dir.z);
      const double u = (p.x + 1) / 2, v = (1 - p.y) / 2;
      // Where both bilinear neighbours are one texel (clamped): its exact colour.
      const bool left = u > 0.01 && u < 0.24, right = u > 0.76 && u < 0.99;
      const bool top = v > 0.01 && v < 0.24, bottom = v > 0.76 && v < 0.99;
      if (!(left || right) || !(top || bottom)) continue;
      const double* want = expected[bottom ? 1 : 0][right ? 1 : 0];
      const glm::vec4 got = image.at(x, y);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], want[c], 1e-6) << x << "," << y << " channel " << c;
      ++checked;
    }
  }
  EXPECT_GT(checked, 4 * 400);
}

TEST(TexturedRender, SlantedQuadIsPerspectiveCorrect) {
  // The floor y = 0, x in [-1, 1], z from 0 (near, v = 0) to -4 (far, v = 1);
  // a 1 x 2 texture black above v = 0.5 and white below: the colour crosses
  // 0.5 at v = 0.5, the world point z = -2, whatever the mip level (each
  // coarser level is the 0.5 mean).
  const std::vector<glm::vec3> positions = {{-1, 0, 0}, {1, 0, 0}, {1, 0, -4}, {-1, 0, -4}};
  const std::vector<glm::uvec3> triangles = {{0, 1, 2}, {0, 2, 3}};
  const std::vector<glm::vec2> uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const render::Texture texture(1, 2, std::vector<float>{0, 0, 0, 1, 1, 1}, TextureWrap::kClampToEdge,
                                TextureWrap::kClampToEdge);
  render::SceneMesh mesh{.positions = positions, .triangles = triangles, .uvs = uvs,
                         .textures = {&texture, 1}};
  render::Camera cam;
  cam.eye = {0, 1.0f, 1.0f};
  cam.target = {0, 0, -2};
  cam.aspect = 1.0f;
  const int n = 400;
  const render::Image image = render::Render(cam, {&mesh, 1}, {}, Unlit(n, n));
  auto row_of = [&](glm::vec3 world) {
    const glm::vec4 clip = cam.ClipFromWorld() * glm::vec4(world, 1.0f);
    return (1.0 - static_cast<double>(clip.y / clip.w)) * 0.5 * n - 0.5;  // pixel-centre rows
  };
  const double projective = row_of({0, 0, -2});
  const double affine = 0.5 * (row_of({0, 0, 0}) + row_of({0, 0, -4}));
  ASSERT_GT(std::abs(projective - affine), 20.0) << "the scene must tell the two apart";
  // The crossing row in the centre column, interpolated between rows (far rows are above).
  double found = -1;
  const int x = n / 2;
  for (int y = 0; y + 1 < n; ++y) {
    const float a = image.at(x, y).x, b = image.at(x, y + 1).x;
    if (a >= 0.5f && b < 0.5f) found = y + (a - 0.5) / (a - b);
  }
  ASSERT_GE(found, 0.0) << "no crossing found";
  EXPECT_NEAR(found, projective, 0.5) << "affine midpoint row " << affine;
}

TEST(TexturedRender, MinifiedCheckerAveragesToGrey) {
  // A 64 x 64 one-texel checker on the upright quad seen from far away (about
  // 8 pixels across): each sample covers >= 4 x 4 texels (2 x 2 samples a
  // pixel too), so the mip levels used (>= 1, all 0.5) give grey; level 0
  // alone would alias into black and white.
  const render::Texture texture = Checker(64, TextureWrap::kRepeat);
  const std::vector<glm::vec3> positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const std::vector<glm::uvec3> triangles = {{0, 1, 2}, {0, 2, 3}};
  const std::vector<glm::vec2> uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  render::SceneMesh mesh{.positions = positions, .triangles = triangles, .uvs = uvs,
                         .textures = {&texture, 1}};
  render::Camera cam;
  cam.eye = {0, 0, 68};
  cam.aspect = 1.0f;
  const int n = 200;
  for (int ss : {1, 2, 3}) {  // 3: 2 x 2 multisampling (one shade per interior pixel)
    render::RenderSettings s = Unlit(n, n);
    s.supersample = std::min(ss, 2);
    if (ss == 3) s.antialias = render::AntiAlias::kMultisample;
    s.background.transparent = true;
    const render::Image image = render::Render(cam, {&mesh, 1}, {}, s);
    int inside = 0;
    for (int y = 1; y + 1 < n; ++y) {
      for (int x = 1; x + 1 < n; ++x) {
        // Interior pixels only (the pixel and its neighbours all covered).
        if (image.at(x, y).w < 1 || image.at(x - 1, y).w < 1 || image.at(x + 1, y).w < 1 ||
            image.at(x, y - 1).w < 1 || image.at(x, y + 1).w < 1)
          continue;
        ++inside;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(image.at(x, y)[c], 0.5f, 1e-5f) << x << "," << y;
      }
    }
    EXPECT_GT(inside, 20) << "ss " << ss;
  }
}

TEST(TexturedRender, UntexturedTrianglesKeepTheirColoursBesideTexturedOnes) {
  // Two triangles, the first textured with a white 1 x 1 texture, the second
  // untextured (index -1): the first shows texture x vertex colour, the second
  // its vertex colour alone.
  const std::vector<glm::vec3> positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const std::vector<glm::uvec3> triangles = {{0, 1, 2}, {0, 2, 3}};
  const std::vector<glm::vec2> uvs(4, glm::vec2(0.5f));
  const std::vector<glm::vec3> colors(4, glm::vec3(0.2f, 0.4f, 0.6f));
  const std::vector<std::int32_t> which = {0, -1};
  const render::Texture texture(1, 1, std::vector<float>{0.5f, 1.0f, 0.25f}, TextureWrap::kRepeat,
                                TextureWrap::kRepeat);
  render::SceneMesh mesh{.positions = positions, .triangles = triangles, .vertex_colors = colors,
                         .uvs = uvs, .textures = {&texture, 1}, .triangle_textures = which};
  render::Camera cam;
  cam.eye = {0, 0, 3};
  cam.aspect = 1.0f;
  const render::Image image = render::Render(cam, {&mesh, 1}, {}, Unlit(100, 100));
  const glm::vec4 textured = image.at(70, 60), plain = image.at(30, 40);  // below / above the diagonal
  EXPECT_NEAR(textured.x, 0.1f, 1e-6f);
  EXPECT_NEAR(textured.y, 0.4f, 1e-6f);
  EXPECT_NEAR(textured.z, 0.15f, 1e-6f);
  EXPECT_NEAR(plain.x, 0.2f, 1e-6f);
  EXPECT_NEAR(plain.z, 0.6f, 1e-6f);
}

TEST(TexturedRender, CesiumManShowsItsTexture) {
  const fs::path path = testsupport::SharedDataPath("gltf/CesiumMan.glb");
  PATCHSKIN_REQUIRE_SHARED_FILE(path);
  auto model = deform::ReadGltf(path.string());
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const deform::SkinnedMesh& m = model->mesh;
  ASSERT_TRUE(m.materials.textured());
  ASSERT_EQ(m.bind.uvs.size(), m.bind.positions.size());
  const deform::Material& material = m.materials.materials[0];
  const deform::TextureImage& image = *m.materials.images[static_cast<std::size_t>(material.texture)];
  const render::Texture texture(image, material.wrap_s, material.wrap_t);
  // The bind mesh seen from its front (glTF +Z), unlit: pixel colour = albedo.
  const deform::Bounds bounds = deform::ComputeBounds(m.bind.positions);
  const render::Camera cam = render::FrameBounds(bounds, 40.0f, 1.0f, {0, 0, -1});
  const int n = 300;
  render::RenderSettings s = Unlit(n, n);
  s.background.transparent = true;
  render::SceneMesh plain{.positions = m.bind.positions, .triangles = m.bind.triangles};
  render::SceneMesh textured = plain;
  textured.uvs = m.bind.uvs;
  textured.textures = {&texture, 1};
  const render::Image with = render::Render(cam, {&textured, 1}, {}, s);
  const render::Image without = render::Render(cam, {&plain, 1}, {}, s);
  render::RenderSettings one_thread = s;
  one_thread.threads = 1;
  EXPECT_EQ(render::Render(cam, {&textured, 1}, {}, one_thread).rgba, with.rgba)
      << "the same bytes whatever the thread count";
  // Mean over covered pixels, and an independent estimate: the texel under
  // the uv of the visible surface point of each pixel (ray cast in double,
  // nearest texel, no filtering) averaged over the same pixels.
  glm::dvec3 mean(0.0), estimate(0.0), control(0.0);
  int covered = 0;
  for (int y = 0; y < n; y += 3) {
    for (int x = 0; x < n; x += 3) {
      if (with.at(x, y).w < 1.0f) continue;
      const rendertest::Ray ray = rendertest::PixelRay(cam, n, n, x, y);
      double best = 1e30;
      glm::dvec2 uv(-1.0);
      for (std::size_t t = 0; t < m.bind.triangles.size(); ++t) {
        const glm::uvec3 tri = m.bind.triangles[t];
        const auto hit = rendertest::HitTriangle(ray, m.bind.positions[tri.x], m.bind.positions[tri.y],
                                                 m.bind.positions[tri.z]);
        if (!hit || hit->u < 0 || hit->v < 0 || hit->u + hit->v > 1 || hit->t <= 0 || hit->t >= best) continue;
        best = hit->t;
        uv = (1 - hit->u - hit->v) * glm::dvec2(m.bind.uvs[tri.x]) + hit->u * glm::dvec2(m.bind.uvs[tri.y]) +
             hit->v * glm::dvec2(m.bind.uvs[tri.z]);
      }
      if (uv.x < 0) continue;  // an edge pixel the ray just misses
      const int tx = std::clamp(static_cast<int>(std::floor((uv.x - std::floor(uv.x)) * image.width)), 0, image.width - 1);
      const int ty = std::clamp(static_cast<int>(std::floor((uv.y - std::floor(uv.y)) * image.height)), 0, image.height - 1);
      const std::size_t at = 3 * (static_cast<std::size_t>(ty) * static_cast<std::size_t>(image.width) +
                                  static_cast<std::size_t>(tx));
      estimate += glm::dvec3(image.rgb[at], image.rgb[at + 1], image.rgb[at + 2]);
      mean += glm::dvec3(glm::vec3(with.at(x, y)));
      control += glm::dvec3(glm::vec3(without.at(x, y)));
      ++covered;
    }
  }
  ASSERT_GT(covered, 300);
  mean /= covered;
  estimate /= covered;
  control /= covered;
  std::printf("CesiumMan mean colour %.3f %.3f %.3f, texel estimate %.3f %.3f %.3f, untextured %.3f %.3f %.3f\n",
              mean.x, mean.y, mean.z, estimate.x, estimate.y, estimate.z, control.x, control.y, control.z);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], estimate[c], 0.03) << "channel " << c;
  EXPECT_NEAR(control.x, 0.75, 1e-4) << "untextured: the grey fallback";
  EXPECT_GT(glm::length(mean - control), 0.1) << "the textured body is not the grey fallback";
}

}  // namespace
