// The key light's shadow map: analytic shadow extents (a box and a sphere
// lit from straight above, a sphere lit at 45 degrees), the ground colour in
// and out of the shadow against a render without it, and determinism.

#include "render/raster/shadow_map.h"

#include <cmath>
#include <cstring>
#include <utility>
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
  // The soft edge: the filter's reach plus the bilinear texel on either side.
  const float edge = map.soft_edge();
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

// Every texel against an independent per-texel search in double precision:
// the largest light depth of the triangles whose closed area holds the
// texel's centre. Centres within `slack` texels of a triangle's edge may take
// its depth or not; none may take a depth no nearby triangle has. A soup of
// random triangles (slivers, edge-on ones, both windings) and a sphere.
TEST(ShadowMap, EveryTexelIsTheNearestTriangleAtItsCentre) {
  std::uint32_t seed = 7u;
  auto next = [&seed] {  // deterministic LCG in [0, 1)
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 16777216.0f;
  };
  rendertest::TriMesh soup = rendertest::MakeSphere({0.2f, 1.0f, -0.1f}, 0.4f, 12, 24);
  for (int k = 0; k < 300; ++k) {
    const glm::vec3 c(next() * 2.0f - 1.0f, next() * 2.0f, next() * 2.0f - 1.0f);
    const auto base = static_cast<unsigned>(soup.positions.size());
    for (int v = 0; v < 3; ++v) {
      // Every fifth triangle a sliver: its third vertex nearly on the first edge.
      const float s = (k % 5 == 0 && v == 2) ? 0.002f : 0.3f;
      soup.positions.push_back(v == 2 && k % 5 == 0
                                   ? 0.5f * (soup.positions[base] + soup.positions[base + 1]) +
                                         s * glm::vec3(next(), next(), next())
                                   : c + s * glm::vec3(next() - 0.5f, next() - 0.5f, next() - 0.5f));
    }
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  for (const glm::vec3 light : {glm::vec3(0, 1, 0), glm::vec3(-0.45f, 0.6f, 0.65f), glm::vec3(1, 0.2f, 0)}) {
    render::ShadowMap map;
    const render::ShadowCaster caster{soup.positions, soup.triangles};
    map.Build(light, {&caster, 1}, {.resolution = 96, .threads = 3});
    ASSERT_FALSE(map.empty());
    std::vector<glm::dvec3> q;
    for (const glm::vec3& p : soup.positions) q.push_back(glm::dvec3(map.ToTexel(p)));
    const double slack = 0.01;  // texels
    int covered = 0;
    for (int j = 0; j < map.resolution(); ++j) {
      for (int i = 0; i < map.resolution(); ++i) {
        const double px = i + 0.5, py = j + 0.5;
        double strict = -INFINITY, loose = -INFINITY;
        for (const glm::uvec3& t : soup.triangles) {
          const glm::dvec3 a = q[t.x], b = q[t.y], c = q[t.z];
          const double area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
          if (area == 0.0) continue;
          // Barycentric weights and each edge's length, for a distance in texels.
          const double w[3] = {((b.x - px) * (c.y - py) - (c.x - px) * (b.y - py)) / area,
                               ((c.x - px) * (a.y - py) - (a.x - px) * (c.y - py)) / area,
                               ((a.x - px) * (b.y - py) - (b.x - px) * (a.y - py)) / area};
          const double len[3] = {std::hypot(c.x - b.x, c.y - b.y), std::hypot(a.x - c.x, a.y - c.y),
                                 std::hypot(b.x - a.x, b.y - a.y)};
          double dist = 0.0;  // how far outside the closest violated edge, texels
          for (int k = 0; k < 3; ++k) dist = std::max(dist, -w[k] * std::abs(area) / len[k]);
          const double z = w[0] * a.z + w[1] * b.z + w[2] * c.z;
          const double lo = std::min({a.z, b.z, c.z}), hi = std::max({a.z, b.z, c.z});
          if (dist == 0.0) strict = std::max(strict, z);
          if (dist <= slack) loose = std::max(loose, std::clamp(z, lo, hi));
        }
        const double got = map.Depth(i, j);
        const double tol = 1e-4;
        if (strict > -INFINITY) ++covered;
        ASSERT_GE(got, strict - tol) << "texel " << i << ", " << j;
        ASSERT_LE(got, loose + tol) << "texel " << i << ", " << j;
      }
    }
    EXPECT_GT(covered, 1000);
  }
}

// A closed caster draws only its triangles facing the light, and the map is
// the same as drawing both windings (the far side is never nearest the light).
TEST(ShadowMap, ClosedCasterSkipsItsFarSideWithTheSameMap) {
  const rendertest::TriMesh sphere = rendertest::MakeSphere({0.0f, 1.0f, 0.0f}, 0.5f, 24, 48);
  for (const glm::vec3 light : {glm::vec3(0, 1, 0), glm::vec3(-0.45f, 0.6f, 0.65f)}) {
    render::ShadowMap both, front;
    const render::ShadowCaster open{sphere.positions, sphere.triangles, false};
    const render::ShadowCaster closed{sphere.positions, sphere.triangles, true};
    both.Build(light, {&open, 1}, {.resolution = 128});
    front.Build(light, {&closed, 1}, {.resolution = 128});
    int covered = 0;
    for (int j = 0; j < 128; ++j)
      for (int i = 0; i < 128; ++i) {
        const float a = both.Depth(i, j), b = front.Depth(i, j);
        if (a == -INFINITY) {
          EXPECT_EQ(b, -INFINITY) << i << ", " << j;
          continue;
        }
        ++covered;
        EXPECT_NEAR(b, a, 1e-4f) << i << ", " << j;
      }
    EXPECT_GT(covered, 5000);
    // Turned inside out, the same flag keeps only the far side: a deeper map.
    rendertest::TriMesh inward = sphere;
    for (glm::uvec3& t : inward.triangles) std::swap(t.y, t.z);
    render::ShadowMap back;
    const render::ShadowCaster wrong{inward.positions, inward.triangles, true};
    back.Build(light, {&wrong, 1}, {.resolution = 128});
    EXPECT_LT(back.Depth(64, 64), both.Depth(64, 64) - 0.5f);
  }
}

// Four ground points at once give Visibility's bits per lane: in the umbra,
// the penumbra, lit, and outside the map.
TEST(ShadowMap, VisibilityOfFourIsVisibilityOfEach) {
  const rendertest::TriMesh sphere = rendertest::MakeSphere({0.0f, 1.5f, 0.0f}, 0.5f, 32, 64);
  const render::ShadowMap map = BuildMap(sphere, {1.0f, 1.0f, 0.0f});
  int partial = 0;
  for (int row = 0; row < 200; ++row) {
    const float z = -0.8f + 0.008f * static_cast<float>(row);
    for (int col = 0; col < 200; col += 4) {
      float x[4], zz[4], out[4];
      for (int k = 0; k < 4; ++k) {
        x[k] = -3.0f + 0.01f * static_cast<float>(col + k);
        zz[k] = z;
      }
      map.Visibility4(x, 0.0f, zz, out);
      for (int k = 0; k < 4; ++k) {
        const float one = map.Visibility({x[k], 0.0f, zz[k]});
        ASSERT_EQ(std::memcmp(&out[k], &one, sizeof(float)), 0) << x[k] << ", " << z;
        partial += one > 0.0f && one < 1.0f ? 1 : 0;
      }
    }
  }
  EXPECT_GT(partial, 100);  // the soft edge was crossed, not only 0 and 1
}

// The same for points on a caster's own surface: a sphere over a box, points
// on the sphere's lit and dark sides and on the box in its shadow.
TEST(ShadowMap, SurfaceVisibilityOfFourIsSurfaceVisibilityOfEach) {
  rendertest::TriMesh scene = rendertest::MakeSphere({0.0f, 1.5f, 0.0f}, 0.5f, 32, 64);
  const rendertest::TriMesh box = MakeBox({-1.0f, 0.0f, -1.0f}, {1.0f, 0.5f, 1.0f});
  const auto base = static_cast<unsigned>(scene.positions.size());
  scene.positions.insert(scene.positions.end(), box.positions.begin(), box.positions.end());
  for (const glm::uvec3& t : box.triangles) scene.triangles.push_back(t + glm::uvec3(base));
  const render::ShadowMap map = BuildMap(scene, {0.3f, 1.0f, 0.2f});
  std::uint32_t seed = 3u;
  auto next = [&seed] {  // deterministic LCG in [-1, 1)
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 8388608.0f - 1.0f;
  };
  int lit = 0, dark = 0, partial = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    float p[3][4], n[3][4], out[4];
    const int lanes = trial % 16;
    for (int k = 0; k < 4; ++k) {
      glm::vec3 pk, nk;
      if (k % 2 == 0) {  // on the sphere, its outward normal
        nk = glm::normalize(glm::vec3(next(), next(), next()));
        pk = glm::vec3(0.0f, 1.5f, 0.0f) + 0.5f * nk;
      } else {  // on the box top, partly under the sphere
        pk = glm::vec3(next() * 0.9f, 0.5f, next() * 0.9f);
        nk = glm::vec3(0.0f, 1.0f, 0.0f);
      }
      for (int c = 0; c < 3; ++c) {
        p[c][k] = pk[c];
        n[c][k] = nk[c];
      }
    }
    map.SurfaceVisibility4(p, n, lanes, out);
    for (int k = 0; k < 4; ++k) {
      const float one = ((lanes >> k) & 1) != 0
                            ? map.SurfaceVisibility({p[0][k], p[1][k], p[2][k]}, {n[0][k], n[1][k], n[2][k]})
                            : 1.0f;
      ASSERT_EQ(std::memcmp(&out[k], &one, sizeof(float)), 0) << trial << " lane " << k;
      lit += one == 1.0f ? 1 : 0;
      dark += one == 0.0f ? 1 : 0;
      partial += one > 0.0f && one < 1.0f ? 1 : 0;
    }
  }
  EXPECT_GT(lit, 1000);
  EXPECT_GT(dark, 500);
  EXPECT_GT(partial, 20);
}

// A lit surface does not shadow itself: every point of a sphere facing the
// light (away from the terminator) is fully lit; points well round the far
// side are dark (the near side reaches the light first).
TEST(ShadowMap, SphereDoesNotShadowItsOwnLitSide) {
  const rendertest::TriMesh sphere = rendertest::MakeSphere({0.0f, 1.5f, 0.0f}, 0.5f, 48, 96);
  const glm::vec3 light = glm::normalize(glm::vec3(-0.45f, 0.6f, 0.65f));
  const render::ShadowMap map = BuildMap(sphere, light);
  std::uint32_t seed = 11u;
  auto next = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 8388608.0f - 1.0f;
  };
  int lit = 0, dark = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const glm::vec3 n = glm::normalize(glm::vec3(next(), next(), next()));
    // On the facets (a chord inside the round sphere), as the renderer sees them.
    const glm::vec3 p = glm::vec3(0.0f, 1.5f, 0.0f) + 0.4985f * n;
    const float cos_l = glm::dot(n, light);
    if (cos_l > 0.1f) {
      ASSERT_EQ(map.SurfaceVisibility(p, n), 1.0f) << "cos " << cos_l;
      ++lit;
    } else if (cos_l < -0.5f) {
      ASSERT_EQ(map.SurfaceVisibility(p, n), 0.0f) << "cos " << cos_l;
      ++dark;
    }
  }
  EXPECT_GT(lit, 5000);
  EXPECT_GT(dark, 2000);
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
