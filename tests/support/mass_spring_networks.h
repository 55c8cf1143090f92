#pragma once
// A mass-spring network over a gently curved grid (spacing 2, height
// 0.3 i j), for the modal kernel tests: curved so every mode has rest terms
// on all three axes.

#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "deform/mass_spring.h"

namespace testsupport {

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
