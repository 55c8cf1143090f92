#pragma once
// Random rotations and SSD-style rotation blends for the polar-decomposition
// tests (tests/deform/polar_rotation*_test.cpp).

#include <cstddef>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace testsupport {

// A rotation uniform over SO(3) (a normalized 4-D Gaussian).
inline glm::dquat RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return glm::normalize(glm::dquat(n(rng), n(rng), n(rng), n(rng)));
}

// A control point's SSD blend sum_b w_b R_b: `bones` rotations within
// `spread_rad` of a random base rotation, positive weights summing to 1.
inline glm::dmat3 RandomBlend(std::mt19937& rng, int bones, double spread_rad) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const glm::dquat base = RandomRotation(rng);
  std::vector<double> w(static_cast<std::size_t>(bones));
  double sum = 0.0;
  for (double& x : w) sum += (x = 0.05 + uni(rng));
  glm::dmat3 m(0.0);
  for (int b = 0; b < bones; ++b) {
    const glm::dvec3 axis = glm::normalize(glm::dvec3(RandomRotation(rng) * glm::dvec3(1, 0, 0)));
    m += (w[static_cast<std::size_t>(b)] / sum) *
         glm::mat3_cast(base * glm::angleAxis(spread_rad * uni(rng), axis));
  }
  return m;
}

}  // namespace testsupport
