// The modal solver's displacement limit (deform/internal/modal_run.h,
// ModalDisplacementLimit) against the limit of ALGORITHMS.md 6 worked out in
// point space in double: e = U eta and e' = U eta' from the modes, every point
// with |e_a| > e_max projected back to the sphere with its outward velocity
// removed, every other point left alone. The function never leaves modal space
// for the whole state, so the test compares what it leaves in the modes, taken
// to point space in double, with that reference.

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "deform/internal/mass_spring_modal.h"
#include "deform/internal/modal_run.h"
#include "deform/mass_spring.h"
#include "support/mass_spring_networks.h"

namespace {

using deform::MassSpringNetwork;
using deform::internal::kMaxModeStride;
using deform::internal::ModalDisplacementLimit;

// A modal field: 3 rows of mode_stride floats, padding lanes 0.
struct Modal {
  alignas(32) float x[3 * kMaxModeStride] = {};
  alignas(32) float v[3 * kMaxModeStride] = {};
};

// Point values of a modal field in double: p[a] = sum_k U[a, k] m_k.
std::vector<glm::dvec3> ToPoints(const MassSpringNetwork& net, const float* m) {
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  std::vector<glm::dvec3> p(n, glm::dvec3(0.0));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t c = 0; c < 3; ++c)
        p[a][static_cast<int>(c)] += double(net.modes[a * n + k]) * double(m[c * stride + k]);
  return p;
}

float SumOfSquares(const MassSpringNetwork& net, const float* m) {
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  float s = 0.0f;
  for (std::size_t k = 0; k < static_cast<std::size_t>(net.num_free); ++k) {
    s += m[k] * m[k] + m[stride + k] * m[stride + k] + m[2 * stride + k] * m[2 * stride + k];
  }
  return s;
}

// A random modal state whose points reach about `reach` e_max at most, with no
// point within 1% of e_max (so float rounding cannot flip a decision).
Modal RandomState(const MassSpringNetwork& net, std::mt19937& rng, double reach) {
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  const double e_max = net.params.max_displacement;
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (;;) {
    Modal s;
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t k = 0; k < n; ++k) {
        s.x[c * stride + k] = normal(rng);
        s.v[c * stride + k] = 50.0f * normal(rng);
      }
    }
    double largest = 0.0;
    for (const glm::dvec3& e : ToPoints(net, s.x)) largest = std::max(largest, glm::length(e));
    const float scale = static_cast<float>(reach * e_max / largest);
    for (std::size_t i = 0; i < 3 * stride; ++i) s.x[i] *= scale;
    bool near = false;
    for (const glm::dvec3& e : ToPoints(net, s.x)) near = near || std::abs(glm::length(e) / e_max - 1.0) < 0.01;
    if (!near) return s;
  }
}

struct Expected {
  std::vector<glm::dvec3> e, v;
  int clamps = 0;
};

Expected ReferenceLimit(const MassSpringNetwork& net, const Modal& s) {
  Expected r{ToPoints(net, s.x), ToPoints(net, s.v), 0};
  const double e_max = net.params.max_displacement;
  for (std::size_t a = 0; a < r.e.size(); ++a) {
    const double len = glm::length(r.e[a]);
    if (len <= e_max) continue;
    ++r.clamps;
    const glm::dvec3 dir = r.e[a] / len;
    r.e[a] = dir * e_max;
    const double outward = glm::dot(r.v[a], dir);
    if (outward > 0.0) r.v[a] -= outward * dir;
  }
  return r;
}

void ExpectLimited(const MassSpringNetwork& net, std::mt19937& rng, double reach, bool allow_avx) {
  const Modal before = RandomState(net, rng, reach);
  const Expected want = ReferenceLimit(net, before);
  Modal s = before;
  const int clamps = ModalDisplacementLimit(net, SumOfSquares(net, s.x), s.x, s.v, allow_avx);
  EXPECT_EQ(clamps, want.clamps);
  const std::vector<glm::dvec3> e = ToPoints(net, s.x), v = ToPoints(net, s.v);
  const double e_max = net.params.max_displacement;
  double v_scale = 0.0;
  for (const glm::dvec3& w : want.v) v_scale = std::max(v_scale, glm::length(w));
  for (std::size_t a = 0; a < e.size(); ++a) {
    // Float state, orthonormal U: round-off of a few ulps of the largest values.
    EXPECT_LT(glm::length(e[a] - want.e[a]), 1e-5 * e_max) << "point " << a;
    EXPECT_LT(glm::length(v[a] - want.v[a]), 1e-5 * v_scale) << "point " << a;
  }
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  for (std::size_t c = 0; c < 3; ++c) {
    for (std::size_t k = static_cast<std::size_t>(net.num_free); k < stride; ++k) {
      EXPECT_EQ(s.x[c * stride + k], 0.0f);
      EXPECT_EQ(s.v[c * stride + k], 0.0f);
    }
  }
  if (want.clamps == 0) {  // nothing to do: not a bit changed
    EXPECT_EQ(std::memcmp(s.x, before.x, sizeof s.x), 0);
    EXPECT_EQ(std::memcmp(s.v, before.v, sizeof s.v), 0);
  }
}

TEST(ModalDisplacementLimit, MatchesThePointSpaceLimit) {
  std::mt19937 rng(7);
  for (int size : {3, 5, 7, 9}) {
    const MassSpringNetwork net = testsupport::CurvedGridNetwork(size, size + (size == 9 ? 1 : 0));
    for (double reach : {0.5, 0.97, 1.3, 2.0, 6.0}) {
      for (int trial = 0; trial < 4; ++trial) {
        SCOPED_TRACE(testing::Message() << "grid " << size << " reach " << reach << " trial " << trial);
        ExpectLimited(net, rng, reach, true);
        ExpectLimited(net, rng, reach, false);
      }
    }
  }
}

// Only the points beyond e_max move: the others keep their displacement and
// velocity (round-off aside), which a limit that rescaled the whole state
// would not do; and the AVX and SSE2 paths give the same bits.
TEST(ModalDisplacementLimit, LeavesOtherPointsAndIsTheSameOnBothPaths) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(7, 7);
  std::mt19937 rng(11);
  int clamped_runs = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Modal before = RandomState(net, rng, 1.5);
    Modal avx = before, sse = before;
    const float sum = SumOfSquares(net, before.x);
    const int a = ModalDisplacementLimit(net, sum, avx.x, avx.v, true);
    const int b = ModalDisplacementLimit(net, sum, sse.x, sse.v, false);
    EXPECT_EQ(a, b);
    EXPECT_EQ(std::memcmp(avx.x, sse.x, sizeof avx.x), 0);
    EXPECT_EQ(std::memcmp(avx.v, sse.v, sizeof avx.v), 0);
    clamped_runs += a > 0 ? 1 : 0;
    const std::vector<glm::dvec3> e0 = ToPoints(net, before.x), e1 = ToPoints(net, avx.x);
    const double e_max = net.params.max_displacement;
    int moved = 0;
    for (std::size_t p = 0; p < e0.size(); ++p) {
      if (glm::length(e0[p]) > e_max) {
        EXPECT_NEAR(glm::length(e1[p]), e_max, 1e-5 * e_max);
        ++moved;
      } else {
        EXPECT_LT(glm::length(e1[p] - e0[p]), 1e-5 * e_max);
      }
    }
    EXPECT_EQ(moved, a);
  }
  EXPECT_GT(clamped_runs, 10);
}

// The cheap exits: below e_max by |eta| or by the per-mode bound, nothing is
// touched even when the sum it is given is large.
TEST(ModalDisplacementLimit, CheapExitsTouchNothing) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 5);
  std::mt19937 rng(3);
  const Modal before = RandomState(net, rng, 0.05);
  Modal s = before;
  const float e_max = net.params.max_displacement;
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  double bound = 0.0;  // the per-mode bound, which must be what lets it exit
  for (std::size_t k = 0; k < static_cast<std::size_t>(net.num_free); ++k) {
    bound += net.mode_max_abs[k] * glm::length(glm::dvec3(s.x[k], s.x[stride + k], s.x[2 * stride + k]));
  }
  ASSERT_LT(bound, 0.9 * e_max);
  ASSERT_GT(SumOfSquares(net, s.x), 0.0f);
  EXPECT_EQ(ModalDisplacementLimit(net, 0.5f * e_max * e_max, s.x, s.v, true), 0);
  EXPECT_EQ(ModalDisplacementLimit(net, 1e30f, s.x, s.v, true), 0);  // the bound decides
  EXPECT_EQ(std::memcmp(s.x, before.x, sizeof s.x), 0);
  EXPECT_EQ(std::memcmp(s.v, before.v, sizeof s.v), 0);
}

}  // namespace
