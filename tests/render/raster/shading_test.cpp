// Shading: Lambert against the analytic sphere, Blinn-Phong terms, ground,
// contact shadow, background, per-region tint, flat shading.

#include "render/raster/shading.h"

#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "render/renderer.h"
#include "render/raster/shading4.h"
#include "support/tolerances.h"
#include "tests/render/render_fixtures.h"

namespace {

TEST(ShadingTest, LambertSphereMatchesAnalyticNDotL) {
  const int w = 160, h = 120;
  const glm::vec3 centre(0.1f, 0.2f, -0.3f);
  const rendertest::TriMesh sphere = rendertest::MakeSphere(centre, 1.0f, 64, 128);
  render::Camera cam;
  cam.eye = glm::vec3(0.4f, 0.9f, 3.5f);
  cam.target = centre;
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  render::RenderSettings s;
  s.width = w;
  s.height = h;
  s.lighting = render::LightingModel::kLambert;
  s.lights.ambient = glm::vec3(0.0f);
  s.lights.key = {.direction_view = {-0.5f, 0.7f, 0.5f}, .color = glm::vec3(1.0f), .intensity = 1.0f};
  s.ground = false;
  const render::SceneMesh mesh{.positions = sphere.positions, .normals = sphere.normals,
                               .triangles = sphere.triangles, .base_color = glm::vec3(1.0f)};
  const render::Image image = render::Render(cam, {&mesh, 1}, {}, s);
  // The key light in world space, from the camera basis (independent of the renderer).
  const glm::vec3 f = glm::normalize(cam.target - cam.eye);
  const glm::vec3 r = glm::normalize(glm::cross(f, cam.up));
  const glm::vec3 u = glm::cross(r, f);
  const glm::vec3 lv = glm::normalize(s.lights.key.direction_view);
  const glm::dvec3 light = glm::normalize(glm::dvec3(lv.x * r + lv.y * u - lv.z * f));
  int checked = 0, lit = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const rendertest::Ray ray = rendertest::PixelRay(cam, w, h, x, y);
      if (!rendertest::HitSphere(ray, centre, 1.05)) {
        EXPECT_NE(image.at(x, y), glm::vec4(1.0f));  // background
        continue;
      }
      // Skip the silhouette band, where the facets and the sphere part ways.
      if (!rendertest::HitSphere(ray, centre, 0.95)) continue;
      const double t = *rendertest::HitSphere(ray, centre, 1.0);
      const glm::dvec3 n = glm::normalize(ray.origin + t * ray.dir - glm::dvec3(centre));
      const float expected = static_cast<float>(std::max(glm::dot(n, light), 0.0));
      ASSERT_NEAR(image.at(x, y).r, expected, testsupport::kTessellatedShadingTol) << x << "," << y;
      ++checked;
      lit += expected > 0.2f ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 3000);
  EXPECT_GT(lit, 1000);
}

TEST(ShadingTest, BlinnPhongTermsFollowTheFormula) {
  render::LightRig rig;
  rig.key = {.direction_view = {0.0f, 0.0f, 1.0f}, .color = glm::vec3(1.0f), .intensity = 0.8f};
  rig.fill.intensity = 0.0f;
  rig.rim.intensity = 0.0f;
  rig.ambient = glm::vec3(0.1f);
  rig.specular = 0.5f;
  rig.shininess = 16.0f;
  render::Camera cam;  // at (0,0,5) looking down -Z: view +Z is world +Z
  const render::ShadingContext ctx =
      render::MakeShadingContext(rig, render::LightingModel::kBlinnPhong, cam.ViewFromWorld());
  EXPECT_NEAR(glm::length(ctx.key_dir - glm::vec3(0, 0, 1)), 0.0f, testsupport::kFloatTol);
  const glm::vec3 albedo(0.5f, 0.4f, 0.3f);
  // Facing light and viewer: N.L = N.H = 1.
  const glm::vec3 c0 = render::ShadeSurface(ctx, albedo, {0, 0, 1}, {0, 0, 0});
  const glm::vec3 e0 = albedo * (0.1f + 0.8f) + glm::vec3(0.8f * 0.5f);
  EXPECT_NEAR(glm::length(c0 - e0), 0.0f, testsupport::kFloatTol);
  // Tilted 60 degrees: N.L = 0.5, H = L (viewer on the light axis far away is not
  // exact: the eye is at z = 5 and the point at the origin, so V = L exactly).
  const glm::vec3 n(std::sin(glm::radians(60.0f)), 0.0f, 0.5f);
  const glm::vec3 c1 = render::ShadeSurface(ctx, albedo, n, {0, 0, 0});
  const glm::vec3 e1 = albedo * (0.1f + 0.8f * 0.5f) + glm::vec3(0.8f * 0.5f * std::pow(0.5f, 16.0f));
  EXPECT_NEAR(glm::length(c1 - e1), 0.0f, testsupport::kFloatTol);
  // Facing away: ambient only.
  const glm::vec3 c2 = render::ShadeSurface(ctx, albedo, {0, 0, -1}, {0, 0, 0});
  EXPECT_NEAR(glm::length(c2 - albedo * 0.1f), 0.0f, testsupport::kFloatTol);
}

TEST(ShadingTest, GroundShowsGridContactShadowAndBackgroundGradient) {
  const int w = 160, h = 120;
  const rendertest::TriMesh sphere = rendertest::MakeSphere(glm::vec3(0.0f, 1.0f, 0.0f), 1.0f, 16, 24);
  render::Camera cam;
  cam.eye = glm::vec3(0.0f, 1.5f, 6.0f);  // the horizon is in view
  cam.target = glm::vec3(0.0f, 0.8f, 0.0f);
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  render::RenderSettings s;
  s.width = w;
  s.height = h;
  s.lighting = render::LightingModel::kUnlit;  // ground albedo x shadow only
  s.ground_style.line_width = 0.0f;            // no grid lines
  const render::SceneMesh mesh{.positions = sphere.positions, .normals = sphere.normals,
                               .triangles = sphere.triangles};
  const render::Image image = render::Render(cam, {&mesh, 1}, {}, s);
  // Ground points in front of the contact (z = 0.6, still visible under the
  // sphere) and far to the side, found by projecting them.
  const glm::mat4 m = cam.ClipFromWorld();
  const auto pixel = [&](glm::vec3 p) {
    const glm::vec4 c = m * glm::vec4(p, 1.0f);
    return glm::ivec2(static_cast<int>((c.x / c.w + 1.0f) * 0.5f * w), static_cast<int>((1.0f - c.y / c.w) * 0.5f * h));
  };
  const glm::ivec2 near_px = pixel({0.0f, 0.0f, 0.6f}), far_px = pixel({1.8f, 0.0f, 1.05f});
  ASSERT_TRUE(far_px.x >= 0 && far_px.x < w && far_px.y >= 0 && far_px.y < h);
  ASSERT_TRUE(near_px.x >= 0 && near_px.x < w && near_px.y >= 0 && near_px.y < h);
  const float near_v = image.at(near_px.x, near_px.y).r, far_v = image.at(far_px.x, far_px.y).r;
  EXPECT_NEAR(far_v, s.ground_style.color.r, testsupport::kPixelFootprintTol);
  EXPECT_LT(near_v, far_v * 0.8f);  // darker next to the contact
  const render::ContactShadow shadow = render::ShadowUnder(deform::ComputeBounds(sphere.positions), 0.0f, 0.6f);
  const glm::vec3 ground_point(0.0f, 0.0f, 0.6f);
  EXPECT_NEAR(near_v, s.ground_style.color.r * render::ContactShadowFactor({&shadow, 1}, ground_point), testsupport::kPixelFootprintTol);
  // Background: top row above the horizon takes the gradient's first row.
  const glm::vec3 top = render::BackgroundColor(s.background, 0.5f / static_cast<float>(h * s.supersample));
  EXPECT_EQ(glm::vec3(image.at(0, 0)), top);
  // Grid lines: a point on a line gets the line colour.
  render::GroundStyle style;
  const glm::vec3 eye(2.0f, 1.0f, 0.0f);
  EXPECT_EQ(render::GroundAlbedo(style, 1.0f, {2.0f, 0.0f, 0.37f}, eye), style.line_color);
  EXPECT_EQ(render::GroundAlbedo(style, 1.0f, {2.5f, 0.0f, 0.37f}, eye), style.color);
  // Far away (beyond twice fade_start spacings) the lines have faded out.
  EXPECT_EQ(render::GroundAlbedo(style, 1.0f, {2.0f, 0.0f, 30.37f}, eye), style.color);
}

TEST(ShadingTest, TriangleColorsTintRegionsAndFlatShadingIsConstantPerFace) {
  const int w = 64, h = 64;
  render::Camera cam;
  cam.eye = glm::vec3(0.0f, 0.0f, 3.0f);
  cam.aspect = 1.0f;
  // A folded quad: two triangles with different normals.
  const std::vector<glm::vec3> p = {{-1, -1, 0}, {1, -1, 0.5f}, {1, 1, 0}, {-1, 1, 0}};
  const std::vector<glm::uvec3> t = {{0u, 1u, 2u}, {0u, 2u, 3u}};
  const std::vector<glm::vec3> tint = {{1.0f, 0.2f, 0.2f}, {0.2f, 0.2f, 1.0f}};
  const render::SceneMesh mesh{.positions = p, .triangles = t, .triangle_colors = tint};
  render::RenderSettings s;
  s.width = w;
  s.height = h;
  s.ground = false;
  s.lighting = render::LightingModel::kLambert;
  s.shading = render::ShadingMode::kFlat;
  const render::Image image = render::Render(cam, {&mesh, 1}, {}, s);
  // Below-right of the diagonal is triangle 0 (red tint), above-left triangle 1.
  const glm::vec4 a = image.at(44, 40), b = image.at(46, 50);
  const glm::vec4 c = image.at(20, 24), d = image.at(16, 10);
  EXPECT_EQ(a, b);  // flat: one colour per face
  EXPECT_EQ(c, d);
  EXPECT_GT(a.r, a.b);
  EXPECT_GT(c.b, c.r);
}

}  // namespace

namespace {

TEST(ShadingTest, EmptyTilesMatchBackgroundOfShadedTiles) {
  // A small triangle in the top-left tile: the rest of each row lies in tiles
  // with no triangles (a fast fill); both paths must give the same bytes.
  const int w = 100, h = 70;
  render::Camera cam;
  cam.eye = glm::vec3(0.0f);
  cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.fov_y_deg = 90.0f;
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  const std::vector<glm::vec3> p = {{-1.3f, 0.9f, -1.0f}, {-1.2f, 0.7f, -1.0f}, {-1.35f, 0.75f, -1.0f}};
  const std::vector<glm::uvec3> t = {{0u, 2u, 1u}};
  const render::SceneMesh mesh{.positions = p, .triangles = t};
  for (int ss : {1, 2, 4}) {
    render::RenderSettings s;
    s.width = w;
    s.height = h;
    s.supersample = ss;
    s.ground = false;
    const render::Image image = render::Render(cam, {&mesh, 1}, {}, s);
    int covered = 0;
    for (int y = 0; y < h; ++y) {
      const glm::vec4 last = image.at(w - 1, y);
      for (int x = 0; x < w; ++x) {
        if (std::isfinite(image.depth[image.index(x, y)])) {
          ++covered;
          continue;
        }
        ASSERT_EQ(image.at(x, y), last) << "ss " << ss << " pixel " << x << "," << y;
      }
    }
    EXPECT_GT(covered, 5);
  }
}

// ShadeSurface4 (four lanes) gives ShadeSurface's bits in every lane: whole and
// fractional exponents, no specular, lights behind the surface, a shadowed key.
TEST(ShadingTest, ShadeSurface4IsShadeSurfaceBitForBit) {
  std::uint32_t seed = 99u;
  auto next = [&seed] {  // deterministic LCG in [-1, 1)
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 8388608.0f - 1.0f;
  };
  const glm::mat4 view = glm::lookAt(glm::vec3(0.5f, 1.2f, 3.0f), glm::vec3(0.0f, 0.8f, 0.0f),
                                     glm::vec3(0.0f, 1.0f, 0.0f));
  for (const float shininess : {32.0f, 7.0f, 12.5f}) {
    for (const float specular : {0.25f, 0.0f}) {
      render::LightRig rig;
      rig.shininess = shininess;
      rig.specular = specular;
      const render::ShadingContext ctx =
          render::MakeShadingContext(rig, render::LightingModel::kBlinnPhong, view);
      int lit = 0;
      for (int trial = 0; trial < 500; ++trial) {
        render::SurfacePoints4 in;
        glm::vec3 albedo[4], normal[4], position[4];
        float key[4];
        for (int k = 0; k < 4; ++k) {
          // Half the trials in partial shadow (the key light scaled), half lit.
          key[k] = trial % 2 == 0 ? 1.0f : 0.5f + 0.5f * next();
          in.key_visibility[k] = key[k];
          albedo[k] = glm::abs(glm::vec3(next(), next(), next()));
          normal[k] = glm::normalize(glm::vec3(next(), next(), next()) + glm::vec3(0.0f, 0.0f, 0.3f));
          position[k] = glm::vec3(next(), next() + 1.0f, next());
          for (int c = 0; c < 3; ++c) {
            in.albedo[c][k] = albedo[k][c];
            in.normal[c][k] = normal[k][c];
            in.position[c][k] = position[k][c];
          }
        }
        float out[3][4];
        render::ShadeSurface4(ctx, in, out);
        for (int k = 0; k < 4; ++k) {
          const glm::vec3 expected = render::ShadeSurface(ctx, albedo[k], normal[k], position[k], key[k]);
          ASSERT_EQ(glm::vec3(out[0][k], out[1][k], out[2][k]), expected) << trial << " lane " << k;
          lit += expected != albedo[k] * ctx.ambient ? 1 : 0;
        }
      }
      EXPECT_GT(lit, 1000);  // most samples got some light, so the lit terms were compared
    }
  }
}

}  // namespace
