#include "deform/patch/fold_measure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {

// Two triangles hinged on the edge (0,0,0)-(1,0,0): the first in the plane
// z = 0, the second turned about the x axis by `angle_deg`; the normals then
// differ by exactly that angle.
std::vector<glm::vec3> Hinge(double angle_deg) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  return {{0, 0, 0}, {1, 0, 0}, {0.5f, -1, 0},
          {0.5f, static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))}};
}
const std::vector<glm::uvec3> kHingeTriangles{{0, 2, 1}, {0, 1, 3}};

TEST(FoldMeasure, HingeGivesItsAngle) {
  for (double angle : {0.0, 10.0, 45.0, 90.0, 150.0}) {
    const std::vector<glm::vec3> p = Hinge(angle);
    const std::vector<int> both{0, 1};
    EXPECT_NEAR(deform::MaxFoldAngleDeg(p, kHingeTriangles, both), angle, 1e-3) << angle;
  }
}

TEST(FoldMeasure, OnlyTrianglesOfTheSubsetAndSharedEdgesCount) {
  const std::vector<glm::vec3> p = Hinge(60.0);
  const std::vector<int> one{0};
  EXPECT_EQ(deform::MaxFoldAngleDeg(p, kHingeTriangles, one), 0.0);
  // A region without vertex 3 holds only the first triangle.
  const std::vector<int> region{0, 1, 2};
  EXPECT_EQ(deform::RegionTriangles(kHingeTriangles, region, 4), std::vector<int>{0});
  const std::vector<int> all{3, 2, 1, 0, 7};
  EXPECT_EQ(deform::RegionTriangles(kHingeTriangles, all, 4), (std::vector<int>{0, 1}));
}

TEST(FoldMeasure, SkipsDegenerateTriangles) {
  std::vector<glm::vec3> p = Hinge(80.0);
  p[3] = {0.5f, 0.0f, 0.0f};  // on the hinge edge: zero area
  const std::vector<int> both{0, 1};
  EXPECT_EQ(deform::MaxFoldAngleDeg(p, kHingeTriangles, both), 0.0);
}

// A prism of n sides (each side two triangles): neighbouring sides' normals
// differ by 360/n degrees, the two triangles of one side by 0.
TEST(FoldMeasure, PrismSidesDifferByTheirTurn) {
  for (int n : {6, 12, 40}) {
    std::vector<glm::vec3> p;
    std::vector<glm::uvec3> tris;
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * k / n;
      p.emplace_back(std::cos(a), std::sin(a), 0.0);
      p.emplace_back(std::cos(a), std::sin(a), 1.0);
    }
    for (unsigned k = 0; k < static_cast<unsigned>(n); ++k) {
      const unsigned a = 2 * k, b = 2 * ((k + 1) % static_cast<unsigned>(n));
      tris.push_back({a, b, b + 1});
      tris.push_back({a, b + 1, a + 1});
    }
    std::vector<int> all(tris.size());
    for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<int>(t);
    EXPECT_NEAR(deform::MaxFoldAngleDeg(p, tris, all), 360.0 / n, 1e-3) << n;
  }
}

}  // namespace

namespace {

// Two separate hinges in one mesh: the first stays at 90 degrees, the second
// turns from flat to `second_deg`.
std::vector<glm::vec3> TwoHinges(double second_deg) {
  std::vector<glm::vec3> p = Hinge(90.0);
  for (const glm::vec3& q : Hinge(second_deg)) p.push_back(q + glm::vec3(5, 0, 0));
  return p;
}
const std::vector<glm::uvec3> kTwoHinges{{0, 2, 1}, {0, 1, 3}, {4, 6, 5}, {4, 5, 7}};

// The added fold is local: a new 30-degree crease beside an unchanged 90-degree
// edge is 30 added, though the region's largest angle stays 90.
TEST(FoldMeasure, AddedFoldIsPerEdgeNotPerRegion) {
  const std::vector<int> all{0, 1, 2, 3};
  const std::vector<glm::vec3> before = TwoHinges(0.0), after = TwoHinges(30.0);
  EXPECT_NEAR(deform::MaxFoldAngleDeg(before, kTwoHinges, all), 90.0, 1e-3);
  EXPECT_NEAR(deform::MaxFoldAngleDeg(after, kTwoHinges, all), 90.0, 1e-3);
  EXPECT_NEAR(deform::MaxAddedFoldAngleDeg(before, after, kTwoHinges, all), 30.0, 1e-3);
  // Smoothing only: the largest change is negative.
  EXPECT_NEAR(deform::MaxAddedFoldAngleDeg(after, before, kTwoHinges, all), 0.0, 1e-3);  // the 90 stays
  const std::vector<int> second{2, 3};
  EXPECT_NEAR(deform::MaxAddedFoldAngleDeg(after, before, kTwoHinges, second), -30.0, 1e-3);
  EXPECT_EQ(deform::MaxAddedFoldAngleDeg(after, before, kTwoHinges, std::vector<int>{0}), 0.0);
}

}  // namespace
