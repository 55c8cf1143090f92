#include "deform/shapes/corrective_example.h"

#include <gtest/gtest.h>

#include <random>

namespace {

// A closed tetrahedron, counter-clockwise from outside: its region volume is
// the tetrahedron's whatever the centre (divergence theorem).
TEST(RegionVolume, ClosedTetrahedronIndependentOfCentre) {
  const std::vector<glm::dvec3> p{{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}};
  const std::vector<glm::uvec3> t{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const std::vector<int> all{0, 1, 2, 3};
  for (const glm::dvec3& c : {glm::dvec3(0.0), glm::dvec3(5, -1, 2), glm::dvec3(0.3, 0.3, 0.3)}) {
    EXPECT_NEAR(deform::RegionVolume(p, t, all, c), 2.0 * 3.0 * 4.0 / 6.0, 1e-12);
  }
}

// The analytic gradient against central differences on an open, irregular
// patch of triangles (V is cubic in the positions: differences of step h
// err by O(h^2)).
TEST(RegionVolume, GradientMatchesFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<glm::dvec3> p;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) p.emplace_back(i + jitter(rng), j + jitter(rng), jitter(rng));
  }
  std::vector<glm::uvec3> t;
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) {
      const unsigned a = i * 4 + j;
      t.push_back({a, a + 4, a + 5});
      t.push_back({a, a + 5, a + 1});
    }
  }
  std::vector<int> subset;
  for (int k = 0; k < static_cast<int>(t.size()); k += 1) subset.push_back(k);
  const glm::dvec3 centre(1.2, 1.7, -2.0);
  std::vector<glm::dvec3> grad(p.size());
  deform::RegionVolumeGradient(p, t, subset, centre, grad);
  const double h = 1e-5;
  double worst = 0.0;
  for (std::size_t v = 0; v < p.size(); ++v) {
    for (int d = 0; d < 3; ++d) {
      std::vector<glm::dvec3> q = p;
      q[v][d] += h;
      const double up = deform::RegionVolume(q, t, subset, centre);
      q[v][d] -= 2 * h;
      const double down = deform::RegionVolume(q, t, subset, centre);
      worst = std::max(worst, std::abs((up - down) / (2 * h) - grad[v][d]));
    }
  }
  EXPECT_LT(worst, 1e-8);
}

}  // namespace
