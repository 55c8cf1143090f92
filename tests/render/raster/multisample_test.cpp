// Multisampling (AntiAlias::kMultisample): coverage and depth per sample,
// one shade per pixel inside a triangle. Checked against supersampling: equal
// where the colour is constant over a triangle, as close (99th percentile) to a 4x4 supersampled reference as 2x2
// supersampling on thin and slanted edges, and the same bytes for any thread
// count. Its mean error is NOT asserted to be as low: one shade at a pixel's
// centre is a little further from the 4x4 mean than four shades' mean on
// curved Blinn-Phong interiors (printed; bench/RESULTS.md).

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "tests/render/render_fixtures.h"

namespace {

// Smooth-shaded spheres (curved shading inside, silhouettes at every angle),
// thin slivers a fraction of a pixel wide at several slants, and the ground.
struct MsaaEdgeScene {
  int w = 160, h = 120;
  render::Camera cam;
  std::vector<rendertest::TriMesh> meshes;

  MsaaEdgeScene() {
    cam.eye = glm::vec3(0.3f, 1.2f, 4.0f);
    cam.target = glm::vec3(0.0f, 0.6f, 0.0f);
    cam.aspect = static_cast<float>(w) / static_cast<float>(h);
    meshes.push_back(rendertest::MakeSphere({-0.8f, 0.7f, 0.0f}, 0.6f, 12, 18));
    meshes.push_back(rendertest::MakeSphere({0.7f, 0.5f, -0.6f}, 0.5f, 10, 14));
    rendertest::TriMesh slivers;
    // Fans of long triangles about 0.3 to 1 pixel wide, from near-horizontal to
    // near-vertical, two-sided (normals towards the camera).
    for (int k = 0; k < 9; ++k) {
      const float angle = 0.05f + 0.19f * static_cast<float>(k);  // radians
      const glm::vec3 base(-1.6f + 0.35f * static_cast<float>(k), 0.05f, 1.0f);
      const glm::vec3 dir(std::cos(angle), std::sin(angle), 0.0f);
      const glm::vec3 side = glm::vec3(-dir.y, dir.x, 0.0f) * (0.004f + 0.002f * static_cast<float>(k % 3));
      const auto v = static_cast<unsigned>(slivers.positions.size());
      slivers.positions.insert(slivers.positions.end(),
                               {base - side, base + 1.3f * dir, base + side});
      const glm::vec3 n = glm::normalize(glm::vec3(0.2f * dir.x, 0.3f, 1.0f));
      slivers.normals.insert(slivers.normals.end(), {n, n, n});
      slivers.triangles.push_back({v, v + 1, v + 2});
    }
    meshes.push_back(std::move(slivers));
  }

  render::Image Render(int ss, render::AntiAlias aa, render::LightingModel lighting,
                       int threads = 1, const render::GroundStyle& ground = {}) const {
    std::vector<render::SceneMesh> scene;
    const glm::vec3 colors[3] = {{0.8f, 0.3f, 0.2f}, {0.2f, 0.5f, 0.9f}, {0.95f, 0.95f, 0.9f}};
    for (std::size_t m = 0; m < meshes.size(); ++m) {
      scene.push_back({.positions = meshes[m].positions, .normals = meshes[m].normals,
                       .triangles = meshes[m].triangles, .base_color = colors[m]});
    }
    render::RenderSettings s;
    s.width = w;
    s.height = h;
    s.supersample = ss;
    s.antialias = aa;
    s.threads = threads;
    s.lighting = lighting;
    s.ground_style = ground;
    return render::Render(cam, scene, {}, s);
  }
};

struct Errors {
  double mean = 0.0, p99 = 0.0;
};

// Per-channel absolute differences of the rgb of two same-sized images.
Errors Compare(const render::Image& a, const render::Image& ref) {
  std::vector<double> d;
  for (std::size_t i = 0; i < ref.rgba.size(); ++i)
    for (int c = 0; c < 3; ++c)
      d.push_back(std::abs(static_cast<double>(a.rgba[i][c]) - static_cast<double>(ref.rgba[i][c])));
  Errors e;
  for (const double x : d) e.mean += x;
  e.mean /= static_cast<double>(d.size());
  const auto k = static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(d.size()));
  std::nth_element(d.begin(), d.begin() + k, d.end());
  e.p99 = d[static_cast<std::size_t>(k)];
  return e;
}

bool SameBytes(const render::Image& a, const render::Image& b) {
  return a.rgba.size() == b.rgba.size() &&
         std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(glm::vec4)) == 0 &&
         a.depth == b.depth;
}

TEST(Multisample, EqualsSupersamplingWhereEachTriangleHasOneColour) {
  // Unlit, one albedo per mesh and a plain ground (its lines the colour
  // between them, no contact shadow): a sample's colour depends only on which
  // triangle covers it, so shading once per pixel changes nothing.
  const MsaaEdgeScene scene;
  render::GroundStyle plain;
  plain.line_color = plain.color;
  plain.shadow_strength = 0.0f;
  for (const int ss : {2, 4}) {
    const render::Image msaa =
        scene.Render(ss, render::AntiAlias::kMultisample, render::LightingModel::kUnlit, 1, plain);
    const render::Image ssaa =
        scene.Render(ss, render::AntiAlias::kSupersample, render::LightingModel::kUnlit, 1, plain);
    EXPECT_TRUE(SameBytes(msaa, ssaa)) << "supersample " << ss;
  }
}

TEST(Multisample, AsCloseToFourByFourAsSupersampling) {
  const MsaaEdgeScene scene;
  for (const render::LightingModel lighting :
       {render::LightingModel::kBlinnPhong, render::LightingModel::kLambert}) {
    const render::Image ref = scene.Render(4, render::AntiAlias::kSupersample, lighting);
    const render::Image ss2 = scene.Render(2, render::AntiAlias::kSupersample, lighting);
    const render::Image ms2 = scene.Render(2, render::AntiAlias::kMultisample, lighting);
    const render::Image one = scene.Render(1, render::AntiAlias::kSupersample, lighting);
    // The scene has edges worth measuring: no anti-aliasing is far worse.
    const Errors none = Compare(one, ref), ssaa = Compare(ss2, ref), msaa = Compare(ms2, ref);
    EXPECT_GT(none.mean, 2.0 * ssaa.mean);
    EXPECT_GT(none.p99, 2.0 * ssaa.p99);
    EXPECT_LE(msaa.mean, ssaa.mean) << "lighting " << static_cast<int>(lighting);
    EXPECT_LE(msaa.p99, ssaa.p99) << "lighting " << static_cast<int>(lighting);
    std::printf("lighting %d: error vs 4x4  none mean %.5f p99 %.5f | ssaa2 mean %.5f p99 %.5f | "
                "msaa2 mean %.5f p99 %.5f\n",
                static_cast<int>(lighting), none.mean, none.p99, ssaa.mean, ssaa.p99, msaa.mean,
                msaa.p99);
    // Interior pixels differ (one shade instead of four), edge pixels do not:
    // some pixels differ, but fewer than those the 1-sample render changes.
    int differing = 0, aliased = 0;
    for (int y = 0; y < scene.h; ++y) {
      for (int x = 0; x < scene.w; ++x) {
        differing += ms2.at(x, y) == ss2.at(x, y) ? 0 : 1;
        aliased += one.at(x, y) == ss2.at(x, y) ? 0 : 1;
      }
    }
    EXPECT_GT(differing, 0);
    EXPECT_LT(differing, aliased);
  }
}

TEST(Multisample, SameBytesForAnyThreadCount) {
  const MsaaEdgeScene scene;
  for (const int ss : {2, 4}) {
    const render::Image one = scene.Render(ss, render::AntiAlias::kMultisample,
                                           render::LightingModel::kBlinnPhong, 1);
    const render::Image three = scene.Render(ss, render::AntiAlias::kMultisample,
                                             render::LightingModel::kBlinnPhong, 3);
    EXPECT_TRUE(SameBytes(one, three)) << "supersample " << ss;
  }
}

}  // namespace

// The ground alone, seen low towards the horizon: grid lines from several
// pixels wide near the eye to a fraction of a pixel far off, and the body's
// cast shadow. Multisampling shades a ground pixel once with its lines
// box-filtered over the pixel and the shadow averaged over its samples; it is
// as close to 4x4 supersampling as 2x2 supersampling's four point samples.
TEST(Multisample, GroundLinesAsCloseToFourByFourAsSupersampling) {
  MsaaEdgeScene scene;
  scene.cam.eye = glm::vec3(0.4f, 0.5f, 5.0f);
  scene.cam.target = glm::vec3(-0.3f, 0.2f, 0.0f);
  scene.meshes.resize(1);  // one sphere, for the cast shadow
  render::GroundStyle grid;
  grid.grid_spacing = 0.3f;
  grid.line_width = 0.06f;
  const render::Image ref =
      scene.Render(4, render::AntiAlias::kSupersample, render::LightingModel::kLambert, 1, grid);
  const render::Image ss2 =
      scene.Render(2, render::AntiAlias::kSupersample, render::LightingModel::kLambert, 1, grid);
  const render::Image ms2 =
      scene.Render(2, render::AntiAlias::kMultisample, render::LightingModel::kLambert, 1, grid);
  const render::Image one =
      scene.Render(1, render::AntiAlias::kSupersample, render::LightingModel::kLambert, 1, grid);
  const Errors none = Compare(one, ref), ssaa = Compare(ss2, ref), msaa = Compare(ms2, ref);
  std::printf(
      "ground: error vs 4x4  none mean %.5f p99 %.5f | ssaa2 mean %.5f p99 %.5f | "
      "msaa2 mean %.5f p99 %.5f\n",
      none.mean, none.p99, ssaa.mean, ssaa.p99, msaa.mean, msaa.p99);
  EXPECT_GT(none.mean, 2.0 * ssaa.mean) << "the lines alias without anti-aliasing";
  EXPECT_LE(msaa.mean, ssaa.mean);
  EXPECT_LE(msaa.p99, ssaa.p99);
}
