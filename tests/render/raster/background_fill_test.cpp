// BackgroundFill: its row-run units cover exactly the pixels of the tiles with
// no triangle, each once; Drain writes the background colour (the mean of the
// pixel's sample rows, summed in sample order) and +inf depth there and
// nothing elsewhere, from any number of threads; Renderer::Render uses it.

#include "render/raster/background_fill.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "render/raster/shading.h"
#include "support/sample_space.h"

namespace {

using render::BackgroundFill;
using render::kTileSize;
using testsupport::AtSample;

struct Scene {
  int width, height, ss;  // output pixels, samples per axis
  std::vector<glm::vec4> clip;
  std::vector<glm::uvec3> triangles;
  std::vector<glm::vec3> sample_rows;
  render::Rasterizer raster;

  Scene(int w, int h, int supersample) : width(w), height(h), ss(supersample) {
    const int sw = w * ss, sh = h * ss;
    // Two small triangles: one in the second tile row, one near the
    // bottom-right corner, so background runs start, stop and span rows.
    const float s = static_cast<float>(ss);
    clip = {AtSample(70 * s, 70 * s, sw, sh),   AtSample(90 * s, 72 * s, sw, sh),
            AtSample(75 * s, 100 * s, sw, sh),  AtSample(static_cast<float>(sw) - 3.0f, static_cast<float>(sh) - 20.0f, sw, sh),
            AtSample(static_cast<float>(sw) - 2.0f, static_cast<float>(sh) - 2.0f, sw, sh),
            AtSample(static_cast<float>(sw) - 30.0f, static_cast<float>(sh) - 4.0f, sw, sh)};
    triangles = {{0u, 2u, 1u}, {3u, 5u, 4u}};
    const render::ClipMesh mesh{.clip_positions = clip, .triangles = triangles};
    EXPECT_TRUE(raster.Setup({&mesh, 1}, {.width = sw, .height = sh, .threads = 1}));
    render::Background background;
    for (int y = 0; y < sh; ++y)
      sample_rows.push_back(render::BackgroundColor(
          background, (static_cast<float>(y) + 0.5f) / static_cast<float>(sh)));
  }

  // Whether output pixel (x, y) lies in a tile with no triangle.
  bool InBackgroundTile(int x, int y) const {
    const int per_tile = kTileSize / ss;
    return raster.tile_triangle_count((y / per_tile) * raster.tiles_x() + x / per_tile) == 0;
  }
};

TEST(BackgroundFillTest, UnitsCoverTheBackgroundTilesOnceInMaximalRuns) {
  for (int ss : {1, 2, 4}) {
    const Scene scene(300, 170, ss);  // not multiples of the tile size
    BackgroundFill fill;
    std::atomic<std::size_t> cursor{0};
    fill.Plan(scene.raster, ss, scene.sample_rows, false, scene.width, scene.height, cursor);
    std::vector<int> hits(static_cast<std::size_t>(scene.width * scene.height), 0);
    for (std::size_t u = 0; u < fill.units(); ++u) {
      const BackgroundFill::Unit& unit = fill.unit(u);
      ASSERT_LT(unit.x0, unit.x1);
      ASSERT_LE(unit.x1, scene.width);
      ASSERT_LT(unit.y, scene.height);
      // Maximal: the pixels just outside the run belong to tiles with triangles.
      if (unit.x0 > 0) {
        EXPECT_FALSE(scene.InBackgroundTile(unit.x0 - 1, unit.y));
      }
      if (unit.x1 < scene.width) {
        EXPECT_FALSE(scene.InBackgroundTile(unit.x1, unit.y));
      }
      for (int x = unit.x0; x < unit.x1; ++x) ++hits[static_cast<std::size_t>(unit.y * scene.width + x)];
    }
    int background = 0;
    for (int y = 0; y < scene.height; ++y) {
      for (int x = 0; x < scene.width; ++x) {
        const bool expected = scene.InBackgroundTile(x, y);
        background += expected ? 1 : 0;
        ASSERT_EQ(hits[static_cast<std::size_t>(y * scene.width + x)], expected ? 1 : 0)
            << "ss " << ss << " pixel " << x << "," << y;
      }
    }
    EXPECT_GT(background, scene.width * scene.height / 2);
    EXPECT_LT(background, scene.width * scene.height);
  }
}

TEST(BackgroundFillTest, DrainWritesTheMeanOfTheSampleRowsAndInfiniteDepthOnly) {
  const float inf = std::numeric_limits<float>::infinity();
  for (int ss : {1, 2, 4}) {
    for (bool transparent : {false, true}) {
      const Scene scene(300, 170, ss);
      BackgroundFill fill;
      std::atomic<std::size_t> cursor{0};
      fill.Plan(scene.raster, ss, scene.sample_rows, transparent, scene.width, scene.height, cursor);
      const glm::vec4 sentinel(-1.0f, -2.0f, -3.0f, -4.0f);
      render::Image image(scene.width, scene.height, sentinel);
      image.depth.assign(image.rgba.size(), -5.0f);
      // Two threads draining the same cursor write every unit exactly once.
      std::size_t written[2] = {0, 0};
      std::thread other([&] { written[1] = fill.Drain(fill.units(), image); });
      written[0] = fill.Drain(fill.units(), image);
      other.join();
      EXPECT_EQ(written[0] + written[1], fill.units());
      EXPECT_EQ(fill.Drain(1, image), 0u);  // nothing left
      for (int y = 0; y < scene.height; ++y) {
        // Independent of BackgroundFill: the sum of the pixel's ss x ss
        // samples in row-major order, times 1 / ss^2.
        glm::vec3 sum(0.0f);
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i) sum += scene.sample_rows[static_cast<std::size_t>(y * ss + j)];
        const glm::vec4 expected =
            transparent ? glm::vec4(0.0f)
            : ss == 1   ? glm::vec4(scene.sample_rows[static_cast<std::size_t>(y)], 1.0f)
                        : glm::vec4(sum * (1.0f / static_cast<float>(ss * ss)), 1.0f);
        for (int x = 0; x < scene.width; ++x) {
          const bool background = scene.InBackgroundTile(x, y);
          ASSERT_EQ(image.at(x, y), background ? expected : sentinel)
              << "ss " << ss << " pixel " << x << "," << y;
          ASSERT_EQ(image.depth[image.index(x, y)], background ? inf : -5.0f);
        }
      }
    }
  }
}

// Through Renderer::Render: background-tile pixels get the mean of their
// sample rows and +inf depth (nothing else writes them), shaded tiles are
// untouched by the fill, and the bytes do not depend on the thread count or on
// whether a depth plane is kept.
TEST(BackgroundFillTest, RenderedFrameHasTheBackgroundInEmptyTilesForAnyThreadCount) {
  const std::vector<glm::vec3> p = {{-0.2f, -0.15f, -2.0f}, {0.25f, -0.1f, -2.5f}, {0.0f, 0.3f, -2.2f}};
  const std::vector<glm::uvec3> t = {{0u, 1u, 2u}};
  const render::SceneMesh mesh{.positions = p, .triangles = t};
  render::Camera cam;
  cam.eye = glm::vec3(0.0f);
  cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.aspect = 333.0f / 201.0f;
  for (int ss : {1, 2}) {
    render::RenderSettings s;
    s.width = 333;
    s.height = 201;
    s.supersample = ss;
    s.ground = false;
    s.threads = 1;
    render::Renderer renderer;
    render::Image one;
    ASSERT_TRUE(renderer.Render(cam, {&mesh, 1}, {}, s, one).ok());
    const render::Rasterizer& raster = renderer.rasterizer();
    const int sh = s.height * ss, per_tile = kTileSize / ss;
    int background = 0, covered = 0;
    for (int y = 0; y < s.height; ++y) {
      glm::vec3 sum(0.0f);
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i)
          sum += render::BackgroundColor(
              s.background, (static_cast<float>(y * ss + j) + 0.5f) / static_cast<float>(sh));
      const glm::vec4 expected(sum * (1.0f / static_cast<float>(ss * ss)), 1.0f);
      for (int x = 0; x < s.width; ++x) {
        covered += std::isfinite(one.depth[one.index(x, y)]) ? 1 : 0;
        if (raster.tile_triangle_count((y / per_tile) * raster.tiles_x() + x / per_tile) != 0) continue;
        ++background;
        ASSERT_EQ(one.at(x, y), expected) << "ss " << ss << " pixel " << x << "," << y;
        ASSERT_TRUE(std::isinf(one.depth[one.index(x, y)]));
      }
    }
    EXPECT_GT(background, s.width * s.height / 2);
    EXPECT_GT(covered, 1000);
    s.threads = 3;
    const render::Image three = render::Render(cam, {&mesh, 1}, {}, s);
    ASSERT_EQ(one.rgba.size(), three.rgba.size());
    EXPECT_EQ(std::memcmp(one.rgba.data(), three.rgba.data(), one.rgba.size() * sizeof(glm::vec4)), 0);
    EXPECT_EQ(std::memcmp(one.depth.data(), three.depth.data(), one.depth.size() * sizeof(float)), 0);
    s.write_depth = false;
    s.threads = 2;
    const render::Image no_depth = render::Render(cam, {&mesh, 1}, {}, s);
    EXPECT_TRUE(no_depth.depth.empty());
    EXPECT_EQ(std::memcmp(one.rgba.data(), no_depth.rgba.data(), one.rgba.size() * sizeof(glm::vec4)), 0);
  }
}

}  // namespace
