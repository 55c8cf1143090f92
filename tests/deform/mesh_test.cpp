// IsClosedOutward: a closed sphere and two disjoint ones pass; the same with
// its winding reversed, a triangle removed, or a triangle doubled does not.

#include "deform/mesh.h"

#include <algorithm>
#include <utility>

#include <gtest/gtest.h>

#include "tests/render/render_fixtures.h"

namespace {

TEST(MeshTest, ClosedOutwardSurfacesAreRecognised) {
  const rendertest::TriMesh sphere = rendertest::MakeSphere({0.3f, 1.0f, -0.2f}, 0.5f, 8, 16);
  EXPECT_TRUE(deform::IsClosedOutward(sphere.positions, sphere.triangles));

  // Two separate closed pieces (the tube mannequin is many) are still closed.
  rendertest::TriMesh two = sphere;
  const rendertest::TriMesh other = rendertest::MakeSphere({2.0f, 1.0f, 0.0f}, 0.3f, 6, 12);
  const auto base = static_cast<unsigned>(two.positions.size());
  two.positions.insert(two.positions.end(), other.positions.begin(), other.positions.end());
  for (const glm::uvec3& t : other.triangles) two.triangles.push_back(t + glm::uvec3(base));
  EXPECT_TRUE(deform::IsClosedOutward(two.positions, two.triangles));

  rendertest::TriMesh inward = sphere;
  for (glm::uvec3& t : inward.triangles) std::swap(t.y, t.z);
  EXPECT_FALSE(deform::IsClosedOutward(inward.positions, inward.triangles));

  rendertest::TriMesh holed = sphere;
  holed.triangles.pop_back();
  EXPECT_FALSE(deform::IsClosedOutward(holed.positions, holed.triangles));

  rendertest::TriMesh doubled = sphere;
  doubled.triangles.push_back(doubled.triangles.front());
  EXPECT_FALSE(deform::IsClosedOutward(doubled.positions, doubled.triangles));

  // One triangle turned over: its edges no longer meet their neighbours' reverses.
  rendertest::TriMesh flipped = sphere;
  std::swap(flipped.triangles[5].y, flipped.triangles[5].z);
  EXPECT_FALSE(deform::IsClosedOutward(flipped.positions, flipped.triangles));

  EXPECT_FALSE(deform::IsClosedOutward(sphere.positions, {}));
  const std::vector<glm::uvec3> out_of_range = {{0u, 1u, 999u}};
  EXPECT_FALSE(deform::IsClosedOutward(sphere.positions, out_of_range));
}

}  // namespace
