// GroundShader: the four-wide ground colour against the scalar reference
// functions (GroundAlbedo, ContactShadowFactor) at the ray-ground hit found
// independently in double precision, and lane independence.

#include "render/raster/ground_shader.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "render/camera.h"
#include "support/tolerances.h"
#include "tests/render/render_fixtures.h"

namespace {

struct GroundScene {
  render::Camera camera;
  int width = 320, height = 180;
  float ground_y = -0.4f;
  float spacing = 0.45f;
  render::GroundStyle style;
  std::vector<render::ContactShadow> shadows;
  glm::vec3 light{0.9f, 0.85f, 0.8f};

  GroundScene() {
    camera.eye = glm::vec3(0.7f, 1.6f, 4.0f);
    camera.target = glm::vec3(0.0f, -0.2f, 0.0f);
    camera.aspect = static_cast<float>(width) / static_cast<float>(height);
    style.line_width = 0.08f;  // wide lines: many samples on their soft edges
    shadows.push_back({.centre_xz = {0.1f, -0.2f}, .radius_xz = {0.6f, 0.4f}, .strength = 0.6f});
    shadows.push_back({.centre_xz = {-0.9f, 0.5f}, .radius_xz = {0.3f, 0.5f}, .strength = 0.3f});
  }

  render::GroundShader Shader(float grid_spacing) const {
    return render::GroundShader::Create({.clip_from_world = camera.ClipFromWorld(),
                                         .eye = camera.eye,
                                         .raster_width = width,
                                         .raster_height = height,
                                         .ground_y = ground_y,
                                         .grid_spacing = grid_spacing,
                                         .style = style,
                                         .shadows = shadows,
                                         .light = light});
  }

  // Where the ray through sample (x, y) meets the ground, in double, or false
  // when it points away from it.
  bool Hit(int x, int y, glm::vec3& p) const {
    const rendertest::Ray ray = rendertest::PixelRay(camera, width, height, x, y);
    if (!(ray.dir.y < 0.0)) return false;
    const double t = (static_cast<double>(ground_y) - ray.origin.y) / ray.dir.y;
    p = glm::vec3(ray.origin + t * ray.dir);
    p.y = ground_y;
    return true;
  }
};

TEST(GroundShader, MatchesGroundAlbedoTimesContactShadowAtTheRayHit) {
  const GroundScene scene;
  for (const float spacing : {scene.spacing, 0.0f}) {  // with and without grid lines
    const render::GroundShader shader = scene.Shader(spacing);
    int checked = 0, on_lines = 0, shadowed = 0;
    double worst = 0.0;
    for (int y = 0; y < scene.height; ++y) {
      for (int x = 0; x + 4 <= scene.width; x += 4) {
        float r[4], g[4], b[4];
        shader.Shade4(x, y, r, g, b);
        for (int k = 0; k < 4; ++k) {
          glm::vec3 p;
          if (!scene.Hit(x + k, y, p)) continue;
          // Far samples: a float ray parameter cannot place them to 1e-5 of a
          // grid spacing any more; the lines have faded out there anyway.
          if (glm::length(p - scene.camera.eye) > 30.0f) continue;
          const glm::vec3 albedo = render::GroundAlbedo(scene.style, spacing, p, scene.camera.eye);
          const float shadow = render::ContactShadowFactor(scene.shadows, p);
          const glm::vec3 expected = albedo * scene.light * shadow;
          const glm::vec3 got(r[k], g[k], b[k]);
          for (int c = 0; c < 3; ++c) {
            ASSERT_NEAR(got[c], expected[c], testsupport::kGroundShaderTol)
                << "sample " << x + k << "," << y << " spacing " << spacing;
            worst = std::max(worst, static_cast<double>(std::abs(got[c] - expected[c])));
          }
          ++checked;
          on_lines += albedo != scene.style.color ? 1 : 0;
          shadowed += shadow < 0.99f ? 1 : 0;
        }
      }
    }
    EXPECT_GT(checked, scene.width * scene.height / 3);
    if (spacing > 0.0f) {
      EXPECT_GT(on_lines, 1000);  // the lines and their soft edges were tested
    }
    EXPECT_GT(shadowed, 1000);                       // so were both shadows (and the exp)
    RecordProperty("worst_error", std::to_string(worst));
  }
}

TEST(GroundShader, EachLaneEqualsThatSampleShadedAlone) {
  const GroundScene scene;
  const render::GroundShader shader = scene.Shader(scene.spacing);
  for (int y = 60; y < scene.height; y += 7) {
    for (int x = 0; x + 4 <= scene.width; x += 3) {  // groups at every alignment
      float r[4], g[4], b[4];
      shader.Shade4(x, y, r, g, b);
      for (int k = 0; k < 4; ++k) {
        const glm::vec3 alone = shader.Shade(x + k, y);
        ASSERT_EQ(alone, glm::vec3(r[k], g[k], b[k])) << x + k << "," << y;
      }
    }
  }
}

TEST(GroundShader, WithoutShadowsOrLinesTheGroundIsItsColourTimesTheLight) {
  GroundScene scene;
  scene.shadows.clear();
  const render::GroundShader shader = scene.Shader(0.0f);
  const glm::vec3 expected = scene.style.color * scene.light;
  for (int x = 0; x < scene.width; x += 17) EXPECT_EQ(shader.Shade(x, scene.height - 1), expected);
}

}  // namespace
