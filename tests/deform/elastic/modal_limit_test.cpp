// The modal solver's displacement limit (deform/elastic/internal/modal_run.h,
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

#include "deform/elastic/internal/mass_spring_modal.h"
#include "deform/elastic/internal/modal_run.h"
#include "deform/elastic/mass_spring.h"
#include "support/mass_spring_networks.h"

namespace {

using deform::MassSpringNetwork;
using deform::internal::kMaxModeStride;
using deform::internal::AddPointChanges;
using deform::internal::ModalDisplacementLimit;
using deform::internal::PointVelocities;

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

// sum_k max_a |U[a, k]| |m_k| in double: the limit's per-mode bound.
double DoubleModeBound(const MassSpringNetwork& net, const float* m) {
  const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
  double bound = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(net.num_free); ++k) {
    bound += net.mode_max_abs[k] * glm::length(glm::dvec3(m[k], m[stride + k], m[2 * stride + k]));
  }
  return bound;
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
  const double bound = DoubleModeBound(net, s.x);  // what must let it exit
  ASSERT_LT(bound, 0.9 * e_max);
  ASSERT_GT(SumOfSquares(net, s.x), 0.0f);
  EXPECT_EQ(ModalDisplacementLimit(net, 0.5f * e_max * e_max, s.x, s.v, true), 0);
  EXPECT_EQ(ModalDisplacementLimit(net, 1e30f, s.x, s.v, true), 0);  // the bound decides
  EXPECT_EQ(std::memcmp(s.x, before.x, sizeof s.x), 0);
  EXPECT_EQ(std::memcmp(s.v, before.v, sizeof s.v), 0);
}

// The limit's cheap exits as the kernels test them: ModeBound is the same on
// both paths, and bounds every point's |e_a| (computed in double).
TEST(ModalDisplacementLimit, ModeBoundIsTheSameOnBothPathsAndBoundsEveryPoint) {
  for (const auto& [rows, cols] : testsupport::kModalGrids) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    const MassSpringNetwork net = testsupport::CurvedGridNetwork(rows, cols);
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
    Modal s;
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t k = 0; k < n; ++k) {
        s.x[c * stride + k] = std::sin(1.7f * static_cast<float>(k) + static_cast<float>(c)) /
                              static_cast<float>(1 + k);
      }
    }
    const float avx = deform::internal::ModeBound(net, s.x, true);
    const float sse = deform::internal::ModeBound(net, s.x, false);
    EXPECT_EQ(std::memcmp(&avx, &sse, sizeof avx), 0);
    const double bound = DoubleModeBound(net, s.x);
    double largest = 0.0;
    for (const glm::dvec3& e : ToPoints(net, s.x)) largest = std::max(largest, glm::length(e));
    EXPECT_NEAR(avx, bound, 1e-5 * bound);
    EXPECT_LE(largest, bound * (1.0 + 1e-6));
  }
}

// The limit's two products on their own, for every stride (8 lanes, 16 with
// an 8-lane tail, ...): PointVelocities against (U v)_p in double, and
// AddPointChanges against x + sum_j U[p_j, .] dx_j in double; the AVX and SSE2
// paths give the same bits, and the padding lanes stay 0.
TEST(ModalLimitProducts, MatchDoublesAndAreTheSameOnBothPaths) {
  std::mt19937 rng(5);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (int size : {3, 4, 5, 6, 7, 9, 12, 16}) {
    SCOPED_TRACE(testing::Message() << "grid " << size);
    const MassSpringNetwork net = testsupport::CurvedGridNetwork(size, size);
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
    Modal s = RandomState(net, rng, 2.0);
    // Points in ascending order, some skipped; each one's change.
    std::vector<std::size_t> points;
    for (std::size_t a = 0; a < n; ++a) {
      if (a % 3 != 1) points.push_back(a);
    }
    const int count = static_cast<int>(points.size());
    std::vector<float> dx(3 * points.size()), dv(3 * points.size());
    for (float& d : dx) d = normal(rng);
    for (float& d : dv) d = 30.0f * normal(rng);

    std::vector<float> vel_avx(3 * points.size()), vel_sse(3 * points.size());
    PointVelocities(net, points.data(), count, s.v, vel_avx.data(), true);
    PointVelocities(net, points.data(), count, s.v, vel_sse.data(), false);
    EXPECT_EQ(std::memcmp(vel_avx.data(), vel_sse.data(), vel_avx.size() * sizeof(float)), 0);
    const std::vector<glm::dvec3> v_points = ToPoints(net, s.v);
    for (int j = 0; j < count; ++j) {
      const glm::dvec3 want = v_points[points[static_cast<std::size_t>(j)]];
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(vel_avx[3 * j + c], want[c], 1e-5 * (1.0 + glm::length(want)));
      }
    }

    Modal avx = s, sse = s;
    AddPointChanges(net, points.data(), count, dx.data(), dv.data(), avx.x, avx.v, true);
    AddPointChanges(net, points.data(), count, dx.data(), dv.data(), sse.x, sse.v, false);
    EXPECT_EQ(std::memcmp(avx.x, sse.x, sizeof avx.x), 0);
    EXPECT_EQ(std::memcmp(avx.v, sse.v, sizeof avx.v), 0);
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::size_t k = 0; k < stride; ++k) {
        double want_x = s.x[c * stride + k], want_v = s.v[c * stride + k];
        for (std::size_t j = 0; j < points.size(); ++j) {
          const double u = k < n ? double(net.modes[points[j] * n + k]) : 0.0;
          want_x += u * dx[3 * j + c];
          want_v += u * dv[3 * j + c];
        }
        if (k >= n) {
          EXPECT_EQ(avx.x[c * stride + k], 0.0f);
          EXPECT_EQ(avx.v[c * stride + k], 0.0f);
          continue;
        }
        EXPECT_NEAR(avx.x[c * stride + k], want_x, 1e-5 * (1.0 + std::abs(want_x)));
        EXPECT_NEAR(avx.v[c * stride + k], want_v, 1e-5 * (30.0 + std::abs(want_v)));
      }
    }
  }
}

}  // namespace
