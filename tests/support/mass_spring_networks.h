#pragma once
// A mass-spring network over a gently curved grid (spacing 2, height
// 0.3 i j), for the modal kernel tests: curved so every mode has rest terms
// on all three axes.

#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "deform/elastic/mass_spring.h"

namespace testsupport {

// Grid sizes, their mode counts and lane groups: 3x3: 1 (a lone mode), 4x4: 4
// (one padded 8-lane group), 5x5: 9 (a group and a lone mode beside it), 5x8:
// 18 (two groups and a padded one), 6x9: 28, 8x8: 36 (three and four groups and
// a padded one), 16x16: 196 (24 and a padded one). 7x7 (25: three groups and a
// lone mode) is in MassSpringSimd.BothPathsMatchTheScalarFormulation.
inline constexpr std::pair<int, int> kModalGrids[] = {{3, 3}, {4, 4}, {5, 5}, {5, 8},
                                                      {6, 9}, {8, 8}, {16, 16}};

inline deform::MassSpringNetwork CurvedGridNetwork(int rows, int cols,
                                                   const deform::MassSpringParams& params = {}) {
  std::vector<glm::vec3> points;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      points.emplace_back(2.0f * static_cast<float>(j), 0.3f * static_cast<float>(i * j),
                          2.0f * static_cast<float>(i));
  auto net = deform::BuildMassSpringNetwork(
      {.rows = rows, .cols = cols, .rest_points = points, .max_angular_speed_rad_s = 3.0f},
      params);
  EXPECT_TRUE(net.ok()) << net.error().ToString();
  return std::move(net).value();
}

}  // namespace testsupport
