// Rasterizer core: fill rule, coverage, depth order, clipping, interpolation,
// determinism. Geometry is placed with w = 1 and dyadic coordinates where the
// test needs exact sample-space positions.

#include "render/raster/rasterizer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "render/raster/internal/tile_draw.h"
#include "render/renderer.h"
#include "support/tolerances.h"
#include "support/sample_space.h"
#include "tests/render/render_fixtures.h"

namespace {

using render::ClipMesh;
using render::Rasterizer;
using render::RasterSettings;
using testsupport::AtSample;

// Fragments per sample over all triangles (no depth test).
std::vector<int> CountFragments(std::span<const ClipMesh> meshes, int width, int height, bool cull) {
  Rasterizer raster;
  RasterSettings settings{.width = width, .height = height, .cull_back_faces = cull, .threads = 1};
  EXPECT_TRUE(raster.Setup(meshes, settings));
  std::vector<int> counts(static_cast<std::size_t>(width * height), 0);
  raster.ForEachTriangle([&](const render::RasterTriangle& tri) {
    Rasterizer::ForEachSample(tri, 0, 0, width, height, [&](int x, int y, const auto&) {
      ++counts[static_cast<std::size_t>(y * width + x)];
    });
  });
  return counts;
}

TEST(RasterizerTest, AxisAlignedSquareCoverageEqualsAnalyticPixelSet) {
  const int w = 48, h = 40;
  // Corners on pixel centres (fill rule decides), between centres, and on pixel edges.
  const float boxes[][4] = {{10.5f, 5.5f, 20.5f, 15.5f}, {3.25f, 7.75f, 30.125f, 33.0f},
                            {0.0f, 0.0f, 48.0f, 40.0f}, {12.0f, 12.0f, 13.0f, 13.0f}};
  for (const auto& box : boxes) {
    const std::vector<glm::vec4> clip = {AtSample(box[0], box[1], w, h), AtSample(box[2], box[1], w, h),
                                         AtSample(box[2], box[3], w, h), AtSample(box[0], box[3], w, h)};
    const std::vector<glm::uvec3> tris = {{0u, 2u, 1u}, {0u, 3u, 2u}};
    const ClipMesh mesh{clip, tris};
    const std::vector<int> counts = CountFragments({&mesh, 1}, w, h, false);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        // Top-left rule: left and top edges inclusive, right and bottom exclusive.
        const float cx = static_cast<float>(x) + 0.5f, cy = static_cast<float>(y) + 0.5f;
        const int expected = (cx >= box[0] && cx < box[2] && cy >= box[1] && cy < box[3]) ? 1 : 0;
        ASSERT_EQ(counts[static_cast<std::size_t>(y * w + x)], expected)
            << "pixel " << x << "," << y << " box " << box[0] << "," << box[1];
      }
    }
  }
}

// Even-odd point-in-polygon, for the fan test.
bool InsidePolygon(const std::vector<glm::vec2>& poly, glm::vec2 p) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if ((poly[i].y > p.y) != (poly[j].y > p.y) &&
        p.x < (poly[j].x - poly[i].x) * (p.y - poly[i].y) / (poly[j].y - poly[i].y) + poly[i].x)
      inside = !inside;
  }
  return inside;
}

TEST(RasterizerTest, SharedEdgesAndFanCoverEachPixelExactlyOnce) {
  const int w = 64, h = 64;
  // A fan of 7 triangles around an off-grid centre, with irregular rim points,
  // some on pixel centres and some on exact horizontal/vertical edges.
  const glm::vec2 centre(31.5f, 30.5f);
  const std::vector<glm::vec2> rim = {{55.5f, 30.5f}, {50.3f, 50.7f}, {31.5f, 58.5f}, {12.2f, 47.9f},
                                      {5.5f, 30.5f},  {14.0f, 8.0f},  {40.6f, 4.1f}};
  std::vector<glm::vec4> clip = {AtSample(centre.x, centre.y, w, h)};
  for (const glm::vec2& p : rim) clip.push_back(AtSample(p.x, p.y, w, h));
  std::vector<glm::uvec3> tris;
  for (unsigned i = 0; i < rim.size(); ++i)
    tris.push_back({0u, 1u + i, 1u + (i + 1) % static_cast<unsigned>(rim.size())});
  const ClipMesh mesh{clip, tris};
  const std::vector<int> counts = CountFragments({&mesh, 1}, w, h, false);
  int covered = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int c = counts[static_cast<std::size_t>(y * w + x)];
      ASSERT_LE(c, 1) << "double coverage at " << x << "," << y;
      const glm::vec2 p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      // Inside the outer polygon (not on its boundary) means covered exactly once.
      bool clearly_inside = InsidePolygon(rim, p);
      for (std::size_t i = 0; i < rim.size() && clearly_inside; ++i) {
        const glm::vec2 a = rim[i], b = rim[(i + 1) % rim.size()];
        const float dist = std::abs((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) /
                           glm::length(b - a);
        clearly_inside = dist > 0.01f;
      }
      if (clearly_inside) {
        EXPECT_EQ(c, 1) << "hole at " << x << "," << y;
      }
      covered += c;
    }
  }
  EXPECT_GT(covered, 1000);
}

TEST(RasterizerTest, ClosedMeshCoversSilhouetteOnceWithCullingTwiceWithout) {
  const int w = 160, h = 120;
  const rendertest::TriMesh sphere = rendertest::MakeSphere(glm::vec3(0.2f, -0.1f, 0.0f), 1.0f, 24, 40);
  render::Camera cam;
  cam.eye = glm::vec3(0.5f, 0.8f, 4.0f);
  cam.target = glm::vec3(0.0f);
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  const glm::mat4 clip_from_world = cam.ClipFromWorld();
  std::vector<glm::vec4> clip;
  for (const glm::vec3& p : sphere.positions) clip.push_back(clip_from_world * glm::vec4(p, 1.0f));
  const ClipMesh mesh{clip, sphere.triangles};
  const std::vector<int> front = CountFragments({&mesh, 1}, w, h, true);
  const std::vector<int> both = CountFragments({&mesh, 1}, w, h, false);
  int inside = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * w + x);
      const rendertest::Ray ray = rendertest::PixelRay(cam, w, h, x, y);
      // The polyhedron lies between the inscribed and the circumscribed sphere.
      const bool hits_inner = rendertest::HitSphere(ray, glm::dvec3(0.2, -0.1, 0.0), 0.985).has_value();
      const bool hits_outer = rendertest::HitSphere(ray, glm::dvec3(0.2, -0.1, 0.0), 1.0001).has_value();
      if (hits_inner) {
        ++inside;
        ASSERT_EQ(front[i], 1) << x << "," << y;
        ASSERT_EQ(both[i], 2) << x << "," << y;
      } else if (!hits_outer) {
        ASSERT_EQ(both[i], 0) << x << "," << y;
      } else {
        ASSERT_LE(front[i], 1);
        ASSERT_EQ(both[i], 2 * front[i]);
      }
    }
  }
  EXPECT_GT(inside, 2000);
  // The tiled z-buffer pass covers exactly the samples the fill rule assigns.
  render::RenderSettings s;
  s.width = w;
  s.height = h;
  s.ground = false;
  s.cull_back_faces = true;
  s.lighting = render::LightingModel::kUnlit;
  const render::SceneMesh scene_mesh{.positions = sphere.positions, .triangles = sphere.triangles};
  const render::Image image = render::Render(cam, {&scene_mesh, 1}, {}, s);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * w + x);
      ASSERT_EQ(std::isfinite(image.depth[i]), front[i] == 1) << x << "," << y;
    }
  }
}

// Renders unlit geometry on a transparent background, no ground.
render::Image RenderUnlit(const render::Camera& cam, std::span<const render::SceneMesh> meshes, int w,
                          int h, int threads = 1, int supersample = 1) {
  render::RenderSettings s;
  s.width = w;
  s.height = h;
  s.threads = threads;
  s.supersample = supersample;
  s.lighting = render::LightingModel::kUnlit;
  s.ground = false;
  s.background.transparent = true;
  return render::Render(cam, meshes, {}, s);
}

TEST(RasterizerTest, InterpenetratingTrianglesResolveByDepthPerPixel) {
  const int w = 96, h = 72;
  render::Camera cam;
  cam.eye = glm::vec3(0.0f, 0.0f, 3.0f);
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  // Two large triangles tilted in opposite directions that cross along x = 0.1.
  const std::vector<glm::vec3> pa = {{-1.5f, -1.2f, -0.8f}, {1.5f, -1.2f, 0.6f}, {0.0f, 1.3f, -0.1f}};
  const std::vector<glm::vec3> pb = {{-1.4f, -1.1f, 0.7f}, {1.4f, -1.0f, -0.7f}, {0.1f, 1.2f, 0.0f}};
  const std::vector<glm::uvec3> tri = {{0u, 1u, 2u}};
  const std::vector<glm::vec3> red = {glm::vec3(1, 0, 0)}, green = {glm::vec3(0, 1, 0)};
  const render::SceneMesh meshes[2] = {{.positions = pa, .triangles = tri, .triangle_colors = red},
                                       {.positions = pb, .triangles = tri, .triangle_colors = green}};
  const render::Image image = RenderUnlit(cam, meshes, w, h);
  int red_count = 0, green_count = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const rendertest::Ray ray = rendertest::PixelRay(cam, w, h, x, y);
      auto hit = [&](const std::vector<glm::vec3>& p) -> std::optional<double> {
        const auto r = rendertest::HitTriangle(ray, p[0], p[1], p[2]);
        const double margin = 0.02;
        if (!r || r->u < margin || r->v < margin || r->u + r->v > 1.0 - margin) return std::nullopt;
        return r->t;
      };
      const auto ta = hit(pa), tb = hit(pb);
      if (!ta || !tb || std::abs(*ta - *tb) < 0.01) continue;  // single cover or near the crossing
      const bool a_nearer = *ta < *tb;
      const glm::vec4 c = image.at(x, y);
      EXPECT_EQ(c, a_nearer ? glm::vec4(1, 0, 0, 1) : glm::vec4(0, 1, 0, 1)) << x << "," << y;
      (a_nearer ? red_count : green_count)++;
    }
  }
  EXPECT_GT(red_count, 200);
  EXPECT_GT(green_count, 200);
}

// A quad whose vertex colour encodes world position: c = (x, y, z) * k + 0.5.
glm::vec3 PositionColor(glm::dvec3 p) { return glm::vec3(p * 0.2 + 0.5); }

TEST(RasterizerTest, PerspectiveCorrectInterpolationMatchesRayHit) {
  const int w = 120, h = 90;
  render::Camera cam;
  cam.eye = glm::vec3(0.3f, 0.4f, 2.5f);
  cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  // A strongly receding floor-like triangle: depth ranges from 1.3 to ~7.
  const std::vector<glm::vec3> p = {{-1.5f, -0.8f, 1.0f}, {1.5f, -0.8f, 1.0f}, {0.0f, 0.5f, -4.0f}};
  const std::vector<glm::vec3> colors = {PositionColor(p[0]), PositionColor(p[1]), PositionColor(p[2])};
  const std::vector<glm::uvec3> tri = {{0u, 1u, 2u}};
  const render::SceneMesh mesh{.positions = p, .triangles = tri, .vertex_colors = colors};
  const render::Image image = RenderUnlit(cam, {&mesh, 1}, w, h);
  int checked = 0;
  float worst_affine_error = 0.0f;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const rendertest::Ray ray = rendertest::PixelRay(cam, w, h, x, y);
      const auto r = rendertest::HitTriangle(ray, p[0], p[1], p[2]);
      if (!r || r->u < 0.01 || r->v < 0.01 || r->u + r->v > 0.99) continue;
      const glm::dvec3 hit = ray.origin + r->t * ray.dir;
      const glm::vec3 expected = PositionColor(hit);
      const glm::vec4 got = image.at(x, y);
      ASSERT_NEAR(got.r, expected.r, testsupport::kRenderTol) << x << "," << y;
      ASSERT_NEAR(got.g, expected.g, testsupport::kRenderTol) << x << "," << y;
      ASSERT_NEAR(got.b, expected.b, testsupport::kRenderTol) << x << "," << y;
      ++checked;
      // What screen-space (affine) interpolation would give, to show the test can fail.
      const glm::vec4 c0 = cam.ClipFromWorld() * glm::vec4(p[0], 1), c1 = cam.ClipFromWorld() * glm::vec4(p[1], 1),
                      c2 = cam.ClipFromWorld() * glm::vec4(p[2], 1);
      const glm::vec2 s0 = glm::vec2(c0) / c0.w, s1 = glm::vec2(c1) / c1.w, s2 = glm::vec2(c2) / c2.w;
      const glm::vec2 q(static_cast<float>((x + 0.5) / w * 2 - 1), static_cast<float>(1 - (y + 0.5) / h * 2));
      const float area = (s1.x - s0.x) * (s2.y - s0.y) - (s1.y - s0.y) * (s2.x - s0.x);
      const float l1 = ((q.x - s0.x) * (s2.y - s0.y) - (q.y - s0.y) * (s2.x - s0.x)) / area;
      const float l2 = ((s1.x - s0.x) * (q.y - s0.y) - (s1.y - s0.y) * (q.x - s0.x)) / area;
      const glm::vec3 affine = (1 - l1 - l2) * colors[0] + l1 * colors[1] + l2 * colors[2];
      worst_affine_error = std::max(worst_affine_error, std::abs(affine.b - expected.b));
    }
  }
  EXPECT_GT(checked, 1500);
  EXPECT_GT(worst_affine_error, 50.0f * testsupport::kRenderTol);
}

TEST(RasterizerTest, TriangleCrossingNearPlaneIsClippedNotWrapped) {
  const int w = 100, h = 80;
  render::Camera cam;
  cam.eye = glm::vec3(0.0f, 0.0f, 0.0f);
  cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.near_plane = 0.5f;
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  // One vertex far in front, two behind the eye (w < 0): a naive projection
  // would wrap them through infinity.
  const std::vector<glm::vec3> p = {{0.0f, -0.3f, -6.0f}, {-2.0f, -1.0f, 2.0f}, {2.5f, -0.6f, 1.5f}};
  const std::vector<glm::vec3> colors = {PositionColor(p[0]), PositionColor(p[1]), PositionColor(p[2])};
  const std::vector<glm::uvec3> tri = {{0u, 1u, 2u}};
  const render::SceneMesh mesh{.positions = p, .triangles = tri, .vertex_colors = colors};
  const render::Image image = RenderUnlit(cam, {&mesh, 1}, w, h);
  int covered = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const rendertest::Ray ray = rendertest::PixelRay(cam, w, h, x, y);
      const auto r = rendertest::HitTriangle(ray, p[0], p[1], p[2]);
      // ray.dir has unit view depth, so t is the view depth of the hit.
      const bool inside = r && r->u > 0 && r->v > 0 && r->u + r->v < 1 && r->t > 0.5;
      const bool clearly = r && r->u > 0.01 && r->v > 0.01 && r->u + r->v < 0.99 && r->t > 0.52;
      const bool clearly_out = !r || r->u < -0.01 || r->v < -0.01 || r->u + r->v > 1.01 || r->t < 0.48;
      const glm::vec4 got = image.at(x, y);
      if (clearly) {
        ASSERT_EQ(got.a, 1.0f) << x << "," << y;
        const glm::vec3 expected = PositionColor(ray.origin + r->t * ray.dir);
        ASSERT_NEAR(got.r, expected.r, testsupport::kRenderTol);
        ASSERT_NEAR(got.b, expected.b, testsupport::kRenderTol);
        ASSERT_NEAR(image.depth[image.index(x, y)], static_cast<float>(r->t), 1e-3f * static_cast<float>(r->t));
      } else if (clearly_out) {
        ASSERT_EQ(got.a, 0.0f) << x << "," << y;
      }
      covered += inside ? 1 : 0;
    }
  }
  EXPECT_GT(covered, 1000);
}

TEST(RasterizerTest, SupersampledHalfPlaneHasAnalyticCoverage) {
  const int w = 40, h = 30;
  // Camera at the origin looking down -Z with a 90 degree field of view: the
  // plane z = -1 maps world (X, Y) to NDC (X / aspect, Y).
  render::Camera cam;
  cam.eye = glm::vec3(0.0f);
  cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.fov_y_deg = 90.0f;
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  const auto at_pixel = [&](double px, double py) {
    return glm::vec3(static_cast<float>((px / w * 2.0 - 1.0) * w / h), static_cast<float>(1.0 - py / h * 2.0), -1.0f);
  };
  // The edge a-b in output pixels, offset by 1/256 pixel so no sample centre
  // lies on it; the third vertex closes a huge triangle to its right.
  const glm::dvec2 a(3.0 + 1.0 / 256, -20.0), b(31.0 + 1.0 / 256, 50.0), c(400.0, 15.0);
  const std::vector<glm::vec3> p = {at_pixel(a.x, a.y), at_pixel(b.x, b.y), at_pixel(c.x, c.y)};
  const std::vector<glm::uvec3> tri = {{0u, 1u, 2u}};
  const render::SceneMesh mesh{.positions = p, .triangles = tri, .base_color = glm::vec3(1.0f)};
  for (int ss : {2, 4}) {
    const render::Image image = RenderUnlit(cam, {&mesh, 1}, w, h, 1, ss);
    int partial = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        int expected = 0;
        for (int j = 0; j < ss; ++j) {
          for (int i = 0; i < ss; ++i) {
            const glm::dvec2 s(x + (i + 0.5) / ss, y + (j + 0.5) / ss);
            expected += ((b.x - a.x) * (s.y - a.y) - (b.y - a.y) * (s.x - a.x)) < 0.0 ? 1 : 0;
          }
        }
        const float coverage = static_cast<float>(expected) / static_cast<float>(ss * ss);
        ASSERT_EQ(image.at(x, y).a, coverage) << "ss " << ss << " pixel " << x << "," << y;
        if (expected > 0) {
          ASSERT_EQ(glm::vec3(image.at(x, y)), glm::vec3(1.0f));
        }
        partial += (expected > 0 && expected < ss * ss) ? 1 : 0;
      }
    }
    EXPECT_GT(partial, h / 2);  // the edge gives fractional coverage along its length
  }
}

TEST(RasterizerTest, FarPlaneClipsOnlyWhenAsked) {
  const int w = 80, h = 60;
  render::Camera cam;
  cam.eye = glm::vec3(0.0f);
  cam.target = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.near_plane = 0.1f;
  cam.far_plane = 10.0f;
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  // A floor y = -1 from z = -1 to z = -100 (crossing the far plane), and a
  // triangle wholly beyond it, in front of the floor's horizon.
  const std::vector<glm::vec3> p = {{-60.0f, -1.0f, -1.0f}, {60.0f, -1.0f, -1.0f},
                                    {60.0f, -1.0f, -100.0f}, {-60.0f, -1.0f, -100.0f},
                                    {-3.0f, 0.5f, -20.0f},   {3.0f, 0.5f, -20.0f},
                                    {0.0f, 4.0f, -20.0f}};
  const std::vector<glm::uvec3> tri = {{0u, 1u, 2u}, {0u, 2u, 3u}, {4u, 5u, 6u}};
  const render::SceneMesh mesh{.positions = p, .triangles = tri, .base_color = glm::vec3(1.0f)};
  for (bool clip_far : {false, true}) {
    render::RenderSettings s;
    s.width = w;
    s.height = h;
    s.lighting = render::LightingModel::kUnlit;
    s.ground = false;
    s.background.transparent = true;
    s.clip_far = clip_far;
    const render::Image image = render::Render(cam, {&mesh, 1}, {}, s);
    int near_floor = 0, far_floor = 0, far_triangle = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const rendertest::Ray ray = rendertest::PixelRay(cam, w, h, x, y);
        const bool covered = image.at(x, y).a > 0.0f;
        // The triangle at view depth 20: where the ray crosses z = -20.
        const glm::dvec3 q = ray.origin + 20.0 * ray.dir;
        const bool on_triangle = q.y > 0.6 && q.y < 3.8 && std::abs(q.x) < 2.9 * (4.0 - q.y) / 3.5;
        if (on_triangle) {
          ASSERT_EQ(covered, !clip_far) << x << "," << y;
          far_triangle += covered ? 1 : 0;
          continue;
        }
        if (ray.dir.y >= 0.0) continue;
        const double t = -1.0 / ray.dir.y;  // view depth where the ray meets the floor
        if (t < 1.1 || t > 99.0) continue;  // near the floor's own ends
        if (t < cam.far_plane * 0.98) {
          ASSERT_TRUE(covered) << x << "," << y;
          ASSERT_NEAR(image.depth[image.index(x, y)], static_cast<float>(t), 1e-3f * static_cast<float>(t));
          ++near_floor;
        } else if (t > cam.far_plane * 1.02) {
          ASSERT_EQ(covered, !clip_far) << x << "," << y << " depth " << t;
          far_floor += covered ? 1 : 0;
        }
      }
    }
    EXPECT_GT(near_floor, 200);
    if (clip_far) {
      EXPECT_EQ(far_floor + far_triangle, 0);
      for (float d : image.depth) {
        if (std::isfinite(d)) {
          ASSERT_LE(d, cam.far_plane * (1.0f + testsupport::kClipDepthRelTol));
        }
      }
    } else {
      EXPECT_GT(far_floor, 20);
      EXPECT_GT(far_triangle, 20);
    }
  }
}

// RasterizeTile's fast paths (four samples per step: int32 lanes for small
// triangles, exact double lanes for large ones) and the reference walk against
// the plain per-sample definition: edge values from EdgeValue with the top-left bias, z = sum of
// float(E_i) * inv_w_i / area, nearest wins, ties keep the earlier triangle.
TEST(RasterizerTest, TileWalksEqualThePerSampleDefinition) {
  const int w = 230, h = 170;  // partial tiles at the right and bottom
  std::vector<glm::vec4> clip;
  std::vector<glm::uvec3> tris;
  std::uint32_t seed = 12345u;
  auto next = [&seed] {  // deterministic LCG in [0, 1)
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 16777216.0f;
  };
  for (int t = 0; t < 120; ++t) {
    const float size = t % 3 == 0 ? 1.6f : 0.12f;  // large (> 48 samples) and small
    const glm::vec2 c(next() * 2.0f - 1.0f, next() * 2.0f - 1.0f);
    for (int k = 0; k < 3; ++k) {
      const float wv = 0.5f + 2.0f * next();  // perspective: w differs per vertex
      const glm::vec2 q = c + size * glm::vec2(next() - 0.5f, next() - 0.5f);
      clip.emplace_back(q.x * wv, q.y * wv, 0.0f, wv);
    }
    const auto b = static_cast<unsigned>(3 * t);
    tris.push_back({b, b + 1, b + 2});
  }
  const ClipMesh mesh{.clip_positions = clip, .triangles = tris};
  Rasterizer raster;
  ASSERT_TRUE(raster.Setup({&mesh, 1}, {.width = w, .height = h, .threads = 1}));
  // Reference over the whole raster, in setup order (with one thread, id = index).
  std::vector<float> ref_depth(static_cast<std::size_t>(w * h), 0.0f);
  std::vector<std::uint32_t> ref_ids(static_cast<std::size_t>(w * h), render::kNoTriangle);
  std::uint32_t id = 0;
  int large = 0;
  raster.ForEachTriangle([&](const render::RasterTriangle& tri) {
    const std::int64_t area2 = std::int64_t{tri.x[1] - tri.x[0]} * (tri.y[2] - tri.y[0]) -
                               std::int64_t{tri.y[1] - tri.y[0]} * (tri.x[2] - tri.x[0]);
    const float inv_area = 1.0f / static_cast<float>(area2);
    large += tri.max_x - tri.min_x > 48 ? 1 : 0;
    Rasterizer::ForEachSample(tri, 0, 0, w, h, [&](int x, int y, const auto&) {
      float z = 0.0f;
      for (int i = 0; i < 3; ++i) {
        const int a = (i + 1) % 3, b = (i + 2) % 3;
        const std::int32_t dx = tri.x[b] - tri.x[a], dy = tri.y[b] - tri.y[a];
        const bool top_left = dy < 0 || (dy == 0 && dx > 0);
        const std::int64_t e =
            render::EdgeValue(tri.x[a], tri.y[a], tri.x[b], tri.y[b], x, y) - (top_left ? 0 : 1);
        z = i == 0 ? static_cast<float>(e) * (tri.inv_w[0] * inv_area)
                   : z + static_cast<float>(e) * (tri.inv_w[i] * inv_area);
      }
      const auto at = static_cast<std::size_t>(y * w + x);
      if (z > ref_depth[at]) {
        ref_depth[at] = z;
        ref_ids[at] = id;
      }
    });
    ++id;
  });
  ASSERT_GT(large, 10);
  std::vector<float> depth(render::kTileBufferSize);
  std::vector<std::uint32_t> ids(render::kTileBufferSize);
  for (const bool reference : {false, true}) {  // RasterizeTile, RasterizeTileReference
    int covered = 0;
    for (int tile = 0; tile < raster.num_tiles(); ++tile) {
      if (reference) {
        raster.RasterizeTileReference(tile, depth, ids);
      } else {
        raster.RasterizeTile(tile, depth, ids);
      }
      const int x0 = (tile % raster.tiles_x()) * render::kTileSize;
      const int y0 = (tile / raster.tiles_x()) * render::kTileSize;
      for (int y = y0; y < std::min(y0 + render::kTileSize, h); ++y) {
        for (int x = x0; x < std::min(x0 + render::kTileSize, w); ++x) {
          const auto local = static_cast<std::size_t>((y - y0) * render::kTileSize + (x - x0));
          const auto at = static_cast<std::size_t>(y * w + x);
          ASSERT_EQ(ids[local], ref_ids[at]) << x << "," << y << " reference " << reference;
          ASSERT_EQ(depth[local], ref_depth[at]) << x << "," << y << " reference " << reference;
          covered += ids[local] != render::kNoTriangle ? 1 : 0;
        }
      }
    }
    EXPECT_GT(covered, w * h / 2);
  }
}

// Triangles of every kind RasterizeTile's fast path treats differently, in
// clip space with a different w per vertex: tiny to large (both sides of
// kSmallTriangleExtent), slivers, a grid whose shared edges pass through
// sample centres (the top-left rule decides), a duplicated patch (depth ties),
// and triangles crossing tile and raster edges.
std::vector<glm::vec4> MixedTriangleSoup(int w, int h, std::vector<glm::uvec3>& tris) {
  std::vector<glm::vec4> clip;
  std::uint32_t seed = 2024u;
  auto next = [&seed] {  // deterministic LCG in [0, 1)
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 16777216.0f;
  };
  // A vertex at sample-space (sx, sy) with a random w (the same projected point).
  auto vertex = [&](float sx, float sy) {
    const float wv = 0.5f + 2.0f * next();
    clip.push_back(AtSample(sx, sy, w, h) * wv);
    return static_cast<unsigned>(clip.size() - 1);
  };
  // Grid of 7.5-sample cells from sample centre (2.5, 3.5): its vertical,
  // horizontal and diagonal edges cross sample centres; twice over its first
  // rows, so equal depths tie.
  const int cells_x = static_cast<int>((static_cast<float>(w) - 5.0f) / 7.5f);
  const int cells_y = static_cast<int>((static_cast<float>(h) - 5.0f) / 7.5f);
  const auto first = static_cast<unsigned>(clip.size());
  for (int j = 0; j <= cells_y; ++j)
    for (int i = 0; i <= cells_x; ++i)
      vertex(2.5f + 7.5f * static_cast<float>(i), 3.5f + 7.5f * static_cast<float>(j));
  const auto at = [&](int i, int j) {
    return first + static_cast<unsigned>(j * (cells_x + 1) + i);
  };
  for (int copy = 0; copy < 2; ++copy) {
    for (int j = 0; j < (copy == 0 ? cells_y : 3); ++j) {
      for (int i = 0; i < cells_x; ++i) {
        if ((i + j) % 2 == 0) {  // both diagonals
          tris.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
          tris.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        } else {
          tris.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
          tris.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
        }
      }
    }
  }
  // Random triangles over and past the raster: sizes log-uniform from 0.3 to
  // 300 samples, every 4th a sliver (its third vertex within a sample of the
  // line through the other two).
  for (int t = 0; t < 600; ++t) {
    const float size = 0.3f * std::pow(1000.0f, next());
    const glm::vec2 c(-20.0f + (static_cast<float>(w) + 40.0f) * next(),
                      -20.0f + (static_cast<float>(h) + 40.0f) * next());
    const glm::vec2 a = c + size * glm::vec2(next() - 0.5f, next() - 0.5f);
    const glm::vec2 b = c + size * glm::vec2(next() - 0.5f, next() - 0.5f);
    const glm::vec2 q = t % 4 == 0 ? a + next() * (b - a) + glm::vec2(next() - 0.5f, next() - 0.5f)
                                   : c + size * glm::vec2(next() - 0.5f, next() - 0.5f);
    tris.push_back({vertex(a.x, a.y), vertex(b.x, b.y), vertex(q.x, q.y)});
  }
  return clip;
}

// The fast path (SSE2 lanes, tail masks) against the scalar reference walk,
// every tile, every sample, bit for bit; raster sizes leave partial tiles and
// rows of every length mod 4.
TEST(RasterizerTest, FastTileWalkEqualsTheReferenceBitForBit) {
  for (const glm::ivec2 size : {glm::ivec2(197, 133), glm::ivec2(64, 64), glm::ivec2(131, 67)}) {
    // Plain names, not a structured binding: clang 15 cannot capture those in a lambda.
    const int w = size.x, h = size.y;
    std::vector<glm::uvec3> tris;
    const std::vector<glm::vec4> clip = MixedTriangleSoup(w, h, tris);
    const ClipMesh mesh{.clip_positions = clip, .triangles = tris};
    Rasterizer raster;
    ASSERT_TRUE(raster.Setup({&mesh, 1}, {.width = w, .height = h, .threads = 1}));
    // What the soup exercises: both lane types, tails, samples on owned edges.
    int small = 0, large = 0, tails = 0, on_edge = 0;
    raster.ForEachTriangle([&](const render::RasterTriangle& tri) {
      const std::int32_t extent = std::max(
          std::max({tri.x[0], tri.x[1], tri.x[2]}) - std::min({tri.x[0], tri.x[1], tri.x[2]}),
          std::max({tri.y[0], tri.y[1], tri.y[2]}) - std::min({tri.y[0], tri.y[1], tri.y[2]}));
      ++(extent < render::internal::kSmallTriangleExtent ? small : large);
      tails += (tri.max_x - tri.min_x + 1) % 4 != 0 ? 1 : 0;
      Rasterizer::ForEachSample(tri, 0, 0, w, h, [&](int, int, const std::int64_t(&e)[3]) {
        on_edge += (e[0] == 0 || e[1] == 0 || e[2] == 0) ? 1 : 0;
      });
    });
    EXPECT_GT(small, 200) << w << "x" << h;
    EXPECT_GT(large, 50) << w << "x" << h;
    EXPECT_GT(tails, 100) << w << "x" << h;
    EXPECT_GT(on_edge, 500) << w << "x" << h;
    std::vector<float> depth(render::kTileBufferSize), ref_depth(render::kTileBufferSize);
    std::vector<std::uint32_t> ids(render::kTileBufferSize), ref_ids(render::kTileBufferSize);
    int covered = 0;
    for (int tile = 0; tile < raster.num_tiles(); ++tile) {
      raster.RasterizeTile(tile, depth, ids);
      raster.RasterizeTileReference(tile, ref_depth, ref_ids);
      for (int k = 0; k < render::kTileSize * render::kTileSize; ++k) {
        const auto i = static_cast<std::size_t>(k);
        const int x = (tile % raster.tiles_x()) * render::kTileSize + k % render::kTileSize;
        const int y = (tile / raster.tiles_x()) * render::kTileSize + k / render::kTileSize;
        ASSERT_EQ(ids[i], ref_ids[i]) << w << "x" << h << " sample " << x << "," << y;
        ASSERT_EQ(std::memcmp(&depth[i], &ref_depth[i], sizeof(float)), 0)
            << w << "x" << h << " sample " << x << "," << y << ": " << depth[i] << " vs "
            << ref_depth[i];
        covered += ids[i] != render::kNoTriangle ? 1 : 0;
      }
    }
    EXPECT_GT(covered, w * h / 2) << w << "x" << h;
  }
}

TEST(RasterizerTest, OutputIsIdenticalFor1And2And8Threads) {
  const int w = 200, h = 150;
  const rendertest::TriMesh a = rendertest::MakeSphere(glm::vec3(0.0f, 1.0f, 0.0f), 1.0f, 30, 50);
  const rendertest::TriMesh b = rendertest::MakeSphere(glm::vec3(0.9f, 0.6f, 0.3f), 0.6f, 20, 30);
  std::vector<glm::vec3> colors;
  for (const glm::vec3& q : a.positions) colors.push_back(q * 0.3f + 0.5f);
  const render::SceneMesh meshes[2] = {
      {.positions = a.positions, .normals = a.normals, .triangles = a.triangles, .vertex_colors = colors},
      {.positions = b.positions, .normals = b.normals, .triangles = b.triangles}};
  render::Camera cam;
  cam.eye = glm::vec3(1.5f, 2.0f, 4.0f);
  cam.target = glm::vec3(0.0f, 0.8f, 0.0f);
  cam.aspect = static_cast<float>(w) / static_cast<float>(h);
  render::Overlays overlays;
  overlays.wireframe = true;
  overlays.lines.push_back({.endpoints = {glm::vec3(0, 0, 0), glm::vec3(0, 2, 0)}});
  overlays.points.push_back({.points = {glm::vec3(0, 2, 0)}});
  overlays.text.push_back({.text = "frame 12"});
  for (int ss : {1, 2}) {
    std::vector<render::Image> images;
    for (int threads : {1, 2, 8}) {
      render::RenderSettings s;
      s.width = w;
      s.height = h;
      s.supersample = ss;
      s.threads = threads;
      images.push_back(render::Render(cam, meshes, overlays, s));
    }
    for (const render::Image& image : images) {
      ASSERT_EQ(image.rgba.size(), images[0].rgba.size());
      EXPECT_EQ(std::memcmp(image.rgba.data(), images[0].rgba.data(), image.rgba.size() * sizeof(glm::vec4)), 0);
      EXPECT_EQ(std::memcmp(image.depth.data(), images[0].depth.data(), image.depth.size() * sizeof(float)), 0);
    }
  }
}

}  // namespace
