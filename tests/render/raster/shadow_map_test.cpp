// The key light's shadow map: analytic shadow extents (a box and a sphere
// lit from straight above, a sphere lit at 45 degrees), the ground colour in
// and out of the shadow against a render without it, and determinism.

#include "render/raster/shadow_map.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "support/tolerances.h"
#include "tests/render/render_fixtures.h"

namespace {

// An axis-aligned box [lo, hi] as 12 triangles (winding does not matter to the map).
rendertest::TriMesh MakeBox(glm::vec3 lo, glm::vec3 hi) {
  rendertest::TriMesh m;
  for (int k = 0; k < 8; ++k)
    m.positions.push_back({(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z});
  const unsigned faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

render::ShadowMap BuildMap(const rendertest::TriMesh& mesh, glm::vec3 light_dir) {
  render::ShadowMap map;
  const render::ShadowCaster caster{mesh.positions, mesh.triangles};
  map.Build(light_dir, {&caster, 1}, {});
  return map;
}

TEST(ShadowMap, BoxFromAboveShadowsExactlyItsFootprint) {
  const rendertest::TriMesh box = MakeBox({-0.5f, 1.0f, -0.3f}, {0.5f, 2.0f, 0.3f});
  const render::ShadowMap map = BuildMap(box, {0.0f, 1.0f, 0.0f});
  ASSERT_FALSE(map.empty());
  // The soft edge: the PCF radius plus the bilinear texel on either side.
  const float edge = (render::ShadowMapSettings{}.filter_radius_texels + 1.5f) * map.texel_size();
  EXPECT_LT(edge, 0.02f);
  EXPECT_EQ(map.Visibility({0.0f, 0.0f, 0.0f}), 0.0f);
  EXPECT_EQ(map.Visibility({0.5f - edge, 0.0f, 0.3f - edge}), 0.0f);
  EXPECT_EQ(map.Visibility({0.5f + edge, 0.0f, 0.0f}), 1.0f);
  EXPECT_EQ(map.Visibility({0.0f, 0.0f, -0.3f - edge}), 1.0f);
  EXPECT_EQ(map.Visibility({3.0f, 0.0f, 0.0f}), 1.0f);   // outside the map
  // On the edge itself about half the filter sees the box.
  EXPECT_NEAR(map.Visibility({0.5f, 0.0f, 0.0f}), 0.5f, 0.2f);
  // The box's own top face is not shadowed by itself (the bias), its bottom is.
  EXPECT_EQ(map.Visibility({0.0f, 2.0f, 0.0f}), 1.0f);
  EXPECT_EQ(map.Visibility({0.0f, 1.0f - 0.05f, 0.0f}), 0.0f);
}

TEST(ShadowMap, ObliqueLightMovesTheShadowAlongTheLight) {
  // Light from +x at 45 degrees: a sphere at height 1.5 shadows the ground
  // around x = -1.5, an ellipse with half-axes r * sqrt(2) along x and r along z.
  const rendertest::TriMesh sphere = rendertest::MakeSphere({0.0f, 1.5f, 0.0f}, 0.5f, 32, 64);
  const render::ShadowMap map = BuildMap(sphere, {1.0f, 1.0f, 0.0f});
  const float edge = 0.03f;
  const float half_x = 0.5f * std::sqrt(2.0f);
  EXPECT_EQ(map.Visibility({-1.5f, 0.0f, 0.0f}), 0.0f);
  EXPECT_EQ(map.Visibility({0.0f, 0.0f, 0.0f}), 1.0f);  // right under the sphere: lit
  EXPECT_EQ(map.Visibility({-1.5f + half_x - edge, 0.0f, 0.0f}), 0.0f);
  EXPECT_EQ(map.Visibility({-1.5f + half_x + edge, 0.0f, 0.0f}), 1.0f);
  EXPECT_EQ(map.Visibility({-1.5f - half_x + edge, 0.0f, 0.0f}), 0.0f);
  EXPECT_EQ(map.Visibility({-1.5f - half_x - edge, 0.0f, 0.0f}), 1.0f);
  EXPECT_EQ(map.Visibility({-1.5f, 0.0f, 0.5f - edge}), 0.0f);
  EXPECT_EQ(map.Visibility({-1.5f, 0.0f, 0.5f + edge}), 1.0f);
}

TEST(ShadowMap, NoTrianglesLightsEverything) {
  render::ShadowMap map;
  map.Build({0.0f, 1.0f, 0.0f}, {}, {});
  EXPECT_TRUE(map.empty());
  EXPECT_EQ(map.Visibility({0.0f, 0.0f, 0.0f}), 1.0f);
}

// A sphere of radius 0.5 at height 1.5 over the ground y = 0, seen from above
// and in front, with the key light straight down (in the camera's view space).
struct SphereScene {
  static constexpr int kSize = 384;
  rendertest::TriMesh sphere = rendertest::MakeSphere({0.0f, 1.5f, 0.0f}, 0.5f, 32, 64);
  render::Camera camera{.eye = {0.0f, 7.0f, 4.0f}, .target = {0.0f, 0.0f, 0.0f}, .aspect = 1.0f};

  render::Image Render(bool shadows, int threads) const {
    render::RenderSettings s;
    s.width = s.height = kSize;
    s.threads = threads;
    s.shadows = shadows;
    s.ground_at_scene_min = false;
    s.ground_y = 0.0f;
    s.ground_style.line_width = 0.0f;        // no grid lines: one ground albedo
    s.ground_style.shadow_strength = 0.0f;   // no contact blob
    s.lights.key.direction_view = glm::mat3(camera.ViewFromWorld()) * glm::vec3(0.0f, 1.0f, 0.0f);
    render::SceneMesh mesh{.positions = sphere.positions, .normals = sphere.normals,
                           .triangles = sphere.triangles};
    return render::Render(camera, {&mesh, 1}, {}, s);
  }
};

TEST(ShadowMap, SphereFromAboveDarkensTheGroundDiscOnly) {
  const SphereScene scene;
  const render::Image on = scene.Render(true, 1), off = scene.Render(false, 1);
  ASSERT_EQ(on.rgba.size(), off.rgba.size());
  const glm::dvec3 forward = glm::normalize(glm::dvec3(scene.camera.target - scene.camera.eye));
  // The ground's light without the key light's share, relative to with it.
  const render::ShadingContext ctx = render::MakeShadingContext(
      render::LightRig{.key = {glm::mat3(scene.camera.ViewFromWorld()) * glm::vec3(0, 1, 0),
                               render::LightRig{}.key.color, render::LightRig{}.key.intensity}},
      render::LightingModel::kBlinnPhong, scene.camera.ViewFromWorld());
  const glm::vec3 full = ctx.ambient + ctx.key_radiance * ctx.key_dir.y +
                         ctx.fill_radiance * std::max(ctx.fill_dir.y, 0.0f);
  const glm::vec3 umbra_ratio = (full - ctx.key_radiance * ctx.key_dir.y) / full;
  int darker = 0, inside = 0, ground_pixels = 0;
  for (int y = 0; y < SphereScene::kSize; ++y) {
    for (int x = 0; x < SphereScene::kSize; ++x) {
      const rendertest::Ray ray =
          rendertest::PixelRay(scene.camera, SphereScene::kSize, SphereScene::kSize, x, y);
      if (ray.dir.y >= 0.0) continue;
      const double t = -ray.origin.y / ray.dir.y;
      const glm::dvec3 p = ray.origin + t * ray.dir;
      const std::size_t i = off.index(x, y);
      // Only pixels where the ground is visible (the sphere hides some).
      const double depth = glm::dot(p - ray.origin, forward);
      if (std::abs(off.depth[i] - depth) > 1e-3 * depth) continue;
      ++ground_pixels;
      // One pixel of ground here, in world units (for the analytic edge).
      const double pixel = glm::length(rendertest::PixelRay(scene.camera, SphereScene::kSize,
                                                            SphereScene::kSize, x + 1, y).dir -
                                       ray.dir) * t;
      const double r = std::hypot(p.x, p.z);
      const bool dark = on.rgba[i].g < off.rgba[i].g;
      darker += dark ? 1 : 0;
      if (r < 0.5 - 2.0 * pixel) {
        ++inside;
        EXPECT_TRUE(dark) << "(" << x << ", " << y << ") r = " << r;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(on.rgba[i][c], off.rgba[i][c] * umbra_ratio[c], testsupport::kFloatTol);
      } else if (r > 0.5 + 2.0 * pixel) {
        // Outside the projection: the same bytes as without shadows.
        ASSERT_EQ(std::memcmp(&on.rgba[i], &off.rgba[i], sizeof(glm::vec4)), 0)
            << "(" << x << ", " << y << ") r = " << r;
      }
    }
  }
  EXPECT_GT(ground_pixels, SphereScene::kSize * SphereScene::kSize / 2);
  EXPECT_GT(inside, 500);           // the disc is well sampled
  EXPECT_GE(darker, inside);
  // The ground point under the sphere's centre is visible and in the umbra.
  const glm::vec4 c = scene.camera.ClipFromWorld() * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  const int cx = static_cast<int>((c.x / c.w * 0.5f + 0.5f) * SphereScene::kSize);
  const int cy = static_cast<int>((0.5f - c.y / c.w * 0.5f) * SphereScene::kSize);
  EXPECT_LT(on.rgba[on.index(cx, cy)].g, off.rgba[off.index(cx, cy)].g);
}

TEST(ShadowMap, RenderIsTheSameBytesOnOneOrThreeThreads) {
  const SphereScene scene;
  const render::Image one = scene.Render(true, 1), three = scene.Render(true, 3);
  ASSERT_EQ(one.rgba.size(), three.rgba.size());
  EXPECT_EQ(std::memcmp(one.rgba.data(), three.rgba.data(), one.rgba.size() * sizeof(glm::vec4)), 0);
}

}  // namespace
