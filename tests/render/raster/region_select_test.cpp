#include "render/raster/region_select.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace {

struct Scene {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  // Adds an n x n grid in the plane z, counter-clockwise seen from +z when
  // `facing_plus_z`, and returns its first vertex index.
  int AddGrid(int n, glm::vec2 lo, glm::vec2 hi, float z, bool facing_plus_z = true) {
    const auto base = static_cast<unsigned>(positions.size());
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float u = static_cast<float>(i) / static_cast<float>(n - 1);
        const float v = static_cast<float>(j) / static_cast<float>(n - 1);
        positions.emplace_back(lo.x + u * (hi.x - lo.x), lo.y + v * (hi.y - lo.y), z);
      }
    }
    for (unsigned j = 0; j + 1 < static_cast<unsigned>(n); ++j) {
      for (unsigned i = 0; i + 1 < static_cast<unsigned>(n); ++i) {
        const unsigned a = base + j * static_cast<unsigned>(n) + i, b = a + 1,
                       c = a + static_cast<unsigned>(n), d = c + 1;
        if (facing_plus_z) {
          triangles.emplace_back(a, b, d);
          triangles.emplace_back(a, d, c);
        } else {
          triangles.emplace_back(a, d, b);
          triangles.emplace_back(a, c, d);
        }
      }
    }
    return static_cast<int>(base);
  }
};

render::Camera LookDownZ(glm::vec3 target) {
  render::Camera c;
  c.eye = target + glm::vec3(0, 0, 10);
  c.target = target;
  c.fov_y_deg = 45.0f;
  c.aspect = 1.0f;
  c.near_plane = 1.0f;
  c.far_plane = 100.0f;
  return c;
}

TEST(SelectScreenRegion, KeepsTheComponentUnderTheCentreAndDropsHiddenAndBackFaces) {
  Scene s;
  const int front = s.AddGrid(11, {-1, -1}, {1, 1}, 1.0f);
  const int back = s.AddGrid(21, {-3, -3}, {3, 3}, 0.0f);
  const int away = s.AddGrid(5, {-0.5f, -0.5f}, {0.5f, 0.5f}, 1.5f, false);  // faces -z
  const auto sel = render::SelectScreenRegion(LookDownZ({0, 0, 0}), s.positions, {}, s.triangles,
                                              {.rect = {0, 0, 1, 1}});
  ASSERT_TRUE(sel.ok()) << sel.error().ToString();
  // The centre projects onto the front grid, so the back grid (visible around
  // it, but another component) is dropped. The grid facing away is not
  // selected, yet it hides the front grid's middle in the z-buffer: only the
  // front grid's outer part remains.
  for (const int v : *sel) {
    EXPECT_GE(v, front);
    EXPECT_LT(v, back);
    const glm::vec3 p = s.positions[static_cast<std::size_t>(v)];
    EXPECT_FALSE(std::abs(p.x) < 0.4f && std::abs(p.y) < 0.4f) << "hidden vertex " << v;
  }
  EXPECT_GT(sel->size(), 11u * 4u - 4u);  // the outer ring of the front grid at least
  EXPECT_LT(*std::max_element(sel->begin(), sel->end()), away);
}

TEST(SelectScreenRegion, VisibleVerticesOfAPartlyHiddenSurface) {
  Scene s;
  s.AddGrid(11, {-1, -1}, {1, 1}, 1.0f);
  const int back = s.AddGrid(31, {-3, -3}, {3, 3}, 0.0f);
  // Image centre on the back grid at x = 2, outside the front grid's shadow.
  const auto sel = render::SelectScreenRegion(LookDownZ({2, 0, 0}), s.positions, {}, s.triangles,
                                              {.rect = {0, 0, 1, 1}});
  ASSERT_TRUE(sel.ok()) << sel.error().ToString();
  int seen_right = 0;
  for (const int v : *sel) {
    ASSERT_GE(v, back);
    const glm::vec3 p = s.positions[static_cast<std::size_t>(v)];
    EXPECT_FALSE(std::abs(p.x) < 0.8f && std::abs(p.y) < 0.8f) << "hidden vertex " << v;
    seen_right += p.x > 1.5f;
  }
  EXPECT_GT(seen_right, 31);
  // A rectangle in the top-left corner only: vertices all project there.
  const render::Camera cam = LookDownZ({2, 0, 0});
  const auto corner = render::SelectScreenRegion(cam, s.positions, {}, s.triangles,
                                                 {.rect = {0.0f, 0.0f, 0.3f, 0.3f}});
  ASSERT_TRUE(corner.ok());
  for (const int v : *corner) {
    const glm::vec4 c = cam.ClipFromWorld() * glm::vec4(s.positions[static_cast<std::size_t>(v)], 1);
    EXPECT_LE(c.x / c.w, -0.4f + 1e-3f);  // x <= 0.3 of the width
    EXPECT_GE(c.y / c.w, 0.4f - 1e-3f);   // y <= 0.3 of the height from the top
  }
}

TEST(SelectScreenRegion, Errors) {
  Scene s;
  s.AddGrid(3, {-1, -1}, {1, 1}, 0.0f);
  EXPECT_EQ(render::SelectScreenRegion(LookDownZ({0, 0, 0}), s.positions, {}, s.triangles,
                                       {.rect = {0.5f, 0, 0.2f, 1}})
                .error()
                .code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(render::SelectScreenRegion(LookDownZ({100, 0, 0}), s.positions, {}, s.triangles,
                                       {.rect = {0.4f, 0.4f, 0.6f, 0.6f}})
                .error()
                .code,
            base::ErrorCode::kNotFound);
}

}  // namespace
