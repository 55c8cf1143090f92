// Resolving samples into pixels: the tent filter against the analytic profile
// of a straight edge, and the single-sample Lambert path (which shades a row
// four samples at a time) against the supersampled one, sample by sample.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "support/tolerances.h"
#include "tests/render/render_fixtures.h"

namespace {

// A white unlit quad covering x < edge_px (output pixels) over the whole
// height, on black, seen by a camera whose plane z = -1 maps world (X, Y) to
// NDC (X / aspect, Y).
struct EdgeScene {
  int w = 24, h = 8;
  render::Camera cam;
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles = {{0u, 1u, 2u}, {0u, 2u, 3u}};

  explicit EdgeScene(double edge_px) {
    cam.eye = glm::vec3(0.0f);
    cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
    cam.fov_y_deg = 90.0f;
    cam.aspect = static_cast<float>(w) / static_cast<float>(h);
    const auto at_pixel = [&](double px, double py) {
      return glm::vec3(static_cast<float>((px / w * 2.0 - 1.0) * w / h),
                       static_cast<float>(1.0 - py / h * 2.0), -1.0f);
    };
    positions = {at_pixel(-10.0, h + 10.0), at_pixel(edge_px, h + 10.0), at_pixel(edge_px, -10.0),
                 at_pixel(-10.0, -10.0)};
  }
  render::Image Render(int ss, render::ResolveFilter filter, bool transparent, int threads = 1) const {
    const render::SceneMesh mesh{.positions = positions, .triangles = triangles,
                                 .base_color = glm::vec3(1.0f)};
    render::RenderSettings s;
    s.width = w;
    s.height = h;
    s.supersample = ss;
    s.resolve = filter;
    s.threads = threads;
    s.lighting = render::LightingModel::kUnlit;
    s.ground = false;
    s.background.top = s.background.bottom = glm::vec3(0.0f);
    s.background.transparent = transparent;
    return render::Render(cam, {&mesh, 1}, {}, s);
  }
};

// Integral of the unit tent max(0, 1 - |t|) over t < x.
double TentCdf(double x) {
  if (x <= -1.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return x < 0.0 ? 0.5 * (1.0 + x) * (1.0 + x) : 1.0 - 0.5 * (1.0 - x) * (1.0 - x);
}

TEST(ResolveTest, TentGivesTheAnalyticProfileOfAnEdgeOnAPixelBoundary) {
  const EdgeScene scene(10.0);
  for (int ss : {2, 4}) {
    const render::Image tent = scene.Render(ss, render::ResolveFilter::kTent, false);
    const render::Image box = scene.Render(ss, render::ResolveFilter::kBox, false);
    for (int y = 0; y < scene.h; ++y) {
      for (int x = 0; x < scene.w; ++x) {
        // The tent centred on the pixel centre, integrated over the covered side.
        // With the edge on a pixel boundary the sampled sum is exact: the
        // samples' midpoint rule integrates each linear piece of the tent exactly.
        const float expected = static_cast<float>(TentCdf(10.0 - (x + 0.5)));
        ASSERT_FLOAT_EQ(tent.at(x, y).r, expected) << "ss " << ss << " pixel " << x << "," << y;
        ASSERT_EQ(tent.at(x, y).a, 1.0f);
        ASSERT_EQ(box.at(x, y).r, x < 10 ? 1.0f : 0.0f);  // the box keeps a hard step
      }
      EXPECT_EQ(tent.at(9, y).r, 0.875f);
      EXPECT_EQ(tent.at(10, y).r, 0.125f);
      EXPECT_EQ(tent.at(0, y).r, 1.0f);  // border: weights renormalized over the raster
    }
  }
}

TEST(ResolveTest, TentOnTransparentBackgroundFiltersCoverageNotColour) {
  const EdgeScene scene(10.0);
  const render::Image image = scene.Render(2, render::ResolveFilter::kTent, true);
  for (int x = 0; x < scene.w; ++x) {
    const glm::vec4 p = image.at(x, 3);
    ASSERT_FLOAT_EQ(p.a, static_cast<float>(TentCdf(10.0 - (x + 0.5)))) << x;
    if (p.a > 0.0f) {
      ASSERT_EQ(glm::vec3(p), glm::vec3(1.0f)) << x;  // straight colour of the covered samples
    } else {
      ASSERT_EQ(p, glm::vec4(0.0f)) << x;
    }
  }
}

TEST(ResolveTest, TentIsTheSameForAnyThreadCountAndIdentityAtOneSample) {
  const EdgeScene scene(10.3);
  const render::Image one = scene.Render(4, render::ResolveFilter::kTent, false, 1);
  const render::Image three = scene.Render(4, render::ResolveFilter::kTent, false, 3);
  ASSERT_EQ(one.rgba.size(), three.rgba.size());
  EXPECT_EQ(std::memcmp(one.rgba.data(), three.rgba.data(), one.rgba.size() * sizeof(glm::vec4)), 0);
  const render::Image tent1 = scene.Render(1, render::ResolveFilter::kTent, false);
  const render::Image box1 = scene.Render(1, render::ResolveFilter::kBox, false);
  EXPECT_EQ(std::memcmp(tent1.rgba.data(), box1.rgba.data(), box1.rgba.size() * sizeof(glm::vec4)), 0);
}

// Lambert shading of plain-albedo triangles runs through a four-wide row path
// at one sample per pixel and a per-sample path when supersampling. Rendering
// at twice the size with one sample must give exactly the samples the 2x2
// render averages: the same raster, the same arithmetic. The vertex-coloured
// sphere and the ground take the general path inside the same rows.
TEST(ResolveTest, LambertRowPathMatchesPerSamplePathBitForBit) {
  const int w = 96, h = 72;
  const rendertest::TriMesh a = rendertest::MakeSphere(glm::vec3(0.0f, 1.0f, 0.0f), 1.0f, 24, 40);
  const rendertest::TriMesh b = rendertest::MakeSphere(glm::vec3(1.1f, 0.6f, 0.3f), 0.6f, 16, 24);
  std::vector<glm::vec3> colors;
  for (const glm::vec3& q : b.positions) colors.push_back(q * 0.3f + 0.5f);
  const std::vector<glm::vec3> flat_p = {{-2.0f, 0.2f, 0.5f}, {-1.2f, 0.2f, 0.8f}, {-1.6f, 1.4f, 0.6f}};
  const std::vector<glm::uvec3> flat_t = {{0u, 1u, 2u}};
  const render::SceneMesh meshes[3] = {
      {.positions = a.positions, .normals = a.normals, .triangles = a.triangles},
      {.positions = b.positions, .normals = b.normals, .triangles = b.triangles, .vertex_colors = colors},
      {.positions = flat_p, .triangles = flat_t, .base_color = glm::vec3(0.3f, 0.8f, 0.4f)}};
  render::Camera cam;
  cam.eye = glm::vec3(0.8f, 1.8f, 4.5f);
  cam.target = glm::vec3(0.0f, 0.8f, 0.0f);
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  render::RenderSettings s;
  s.lighting = render::LightingModel::kLambert;
  s.width = 2 * w;
  s.height = 2 * h;
  s.supersample = 1;
  s.threads = 1;
  const render::Image fine = render::Render(cam, meshes, {}, s);
  s.threads = 2;
  const render::Image fine2 = render::Render(cam, meshes, {}, s);
  ASSERT_EQ(fine.rgba.size(), fine2.rgba.size());
  EXPECT_EQ(std::memcmp(fine.rgba.data(), fine2.rgba.data(), fine.rgba.size() * sizeof(glm::vec4)), 0);
  s.width = w;
  s.height = h;
  s.supersample = 2;
  s.antialias = render::AntiAlias::kSupersample;  // every sample shaded, as the 1x1 render
  const render::Image coarse = render::Render(cam, meshes, {}, s);
  int lit = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // The 2x2 path sums its samples in row-major order, then scales.
      glm::vec4 acc(0.0f);
      float nearest = std::numeric_limits<float>::infinity();
      for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
          acc += glm::vec4(glm::vec3(fine.at(2 * x + i, 2 * y + j)), 0.0f);
          nearest = std::min(nearest, fine.depth[fine.index(2 * x + i, 2 * y + j)]);
        }
      }
      const glm::vec4 expected(glm::vec3(acc) * 0.25f, 1.0f);
      ASSERT_EQ(coarse.at(x, y), expected) << x << "," << y;
      ASSERT_EQ(coarse.depth[coarse.index(x, y)], nearest) << x << "," << y;
      lit += std::isfinite(nearest) ? 1 : 0;
    }
  }
  EXPECT_GT(lit, w * h / 4);
}

}  // namespace
