// PolarRotationNewton (deform/shapes/polar_rotation.h) against the SVD polar factor,
// and PatchControlRotations' three-or-more-bone path and its skipping of
// control points whose dS is zero.
#include <gtest/gtest.h>

#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/direct_manipulation.h"
#include "deform/shapes/example_shapes.h"
#include "deform/shapes/polar_rotation.h"
#include "support/random_blends.h"
#include "support/rotations.h"
#include "support/tolerances.h"

namespace {

using testsupport::QuatDistance;
using testsupport::RandomBlend;
using testsupport::RandomRotation;

double MaxEntryDiff(const glm::dmat3& a, const glm::dmat3& b) {
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(a[c][r] - b[c][r]));
  }
  return worst;
}

TEST(PolarRotationNewton, MatchesTheSvdOnRandomBlendsOfThreeAndFourBones) {
  std::mt19937 rng(7);
  int taken = 0, most_iterations = 0;
  for (int t = 0; t < 4000; ++t) {
    const glm::dmat3 m = RandomBlend(rng, 3 + t % 2, t % 3 == 0 ? 2.8 : 1.5);
    glm::dmat3 newton;
    int iterations = 0;
    if (!deform::PolarRotationNewton(m, newton, &iterations)) {
      // Only nearly singular blends are left to the SVD.
      EXPECT_LE(glm::determinant(m), deform::kPolarNewtonMinDet) << "blend " << t;
      continue;
    }
    ++taken;
    most_iterations = std::max(most_iterations, iterations);
    EXPECT_LT(MaxEntryDiff(newton, deform::PolarRotationSvd(m)), testsupport::kPolarFactorTol)
        << "blend " << t << ", " << iterations << " iterations";
    EXPECT_NEAR(glm::determinant(newton), 1.0, testsupport::kPolarFactorTol);
  }
  EXPECT_GT(taken, 3900);
  EXPECT_LE(most_iterations, 12);
}

TEST(PolarRotationNewton, RecoversTheRotationOfRotationTimesStretch) {
  // M = R P with P symmetric positive definite: the polar factor is R exactly.
  std::mt19937 rng(3);
  for (int t = 0; t < 200; ++t) {
    const glm::dmat3 r = glm::mat3_cast(RandomRotation(rng));
    const glm::dmat3 v = glm::mat3_cast(RandomRotation(rng));
    const double s0 = 1.0, s1 = 0.3 + 0.01 * t, s2 = 0.02 + 0.004 * t;
    const glm::dmat3 p = v * glm::dmat3(s0, 0, 0, 0, s1, 0, 0, 0, s2) * glm::transpose(v);
    glm::dmat3 newton;
    ASSERT_TRUE(deform::PolarRotationNewton(r * p, newton)) << t;
    EXPECT_LT(MaxEntryDiff(newton, r), testsupport::kPolarFactorTol) << t;
  }
}

TEST(PolarRotationNewton, NearlyDegenerateBlendsConvergeOrAreLeftToTheSvd) {
  // Two bones half a turn apart at equal weight (their blend diag(0, 0, 1) is
  // singular) plus eps of a third: det M ~ 0.92 eps^2 falls towards 0.
  const glm::dmat3 a(1.0);
  const glm::dmat3 b = glm::mat3_cast(glm::angleAxis(std::numbers::pi, glm::dvec3(0, 0, 1)));
  const glm::dmat3 c = glm::mat3_cast(glm::angleAxis(0.4, glm::dvec3(1, 0, 0)));
  int converged = 0;
  for (double eps = 1e-1; eps > 1e-9; eps *= 0.3) {
    const glm::dmat3 m = 0.5 * (1.0 - eps) * (a + b) + eps * c;
    glm::dmat3 newton;
    if (deform::PolarRotationNewton(m, newton)) {
      ++converged;
      EXPECT_GT(glm::determinant(m), deform::kPolarNewtonMinDet);
      EXPECT_LT(MaxEntryDiff(newton, deform::PolarRotationSvd(m)), testsupport::kPolarFactorTol)
          << "eps " << eps;
    } else {
      EXPECT_LE(glm::determinant(m), deform::kPolarNewtonMinDet) << "eps " << eps;
    }
  }
  EXPECT_GE(converged, 3);
  EXPECT_LT(converged, 8);  // of 16: the smaller eps (det <= 1e-6) are refused
}

TEST(PolarRotationNewton, RefusesReflectionsSingularAndNonFiniteMatrices) {
  glm::dmat3 out;
  EXPECT_FALSE(deform::PolarRotationNewton(glm::dmat3(-1.0), out));            // det -1
  EXPECT_FALSE(deform::PolarRotationNewton(glm::dmat3(1, 0, 0, 0, 1, 0, 0, 0, -0.5), out));
  EXPECT_FALSE(deform::PolarRotationNewton(glm::dmat3(0.0), out));
  EXPECT_FALSE(deform::PolarRotationNewton(glm::dmat3(1, 0, 0, 0, 1, 0, 0, 0, 1e-9), out));
  glm::dmat3 nan(1.0);
  nan[1][2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(deform::PolarRotationNewton(nan, out));
  // The caller's fallback (PolarRotation) still gives a proper rotation there.
  EXPECT_NEAR(glm::determinant(deform::PolarRotation(glm::dmat3(-1.0))), 1.0, 1e-12);
}

// A patch of #C control points with 4 influences over `bones` skin joints.
deform::PatchSetup RandomWeightsPatch(std::mt19937& rng, int count, int bones) {
  deform::PatchSetup p;
  p.rest_control.assign(static_cast<std::size_t>(count), glm::vec3(0.0f));
  p.control_weights.influences = 4;
  std::uniform_int_distribution<int> bone(0, bones - 1);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (int c = 0; c < count; ++c) {
    const int used = 1 + c % 4;  // 1, 2, 3 and 4 bones with nonzero weight
    float sum = 0.0f;
    float w[4] = {0, 0, 0, 0};
    for (int i = 0; i < used; ++i) sum += (w[i] = 0.1f + uni(rng));
    for (int i = 0; i < 4; ++i) {
      p.control_weights.joints.push_back(static_cast<std::uint16_t>((bone(rng) + i) % bones));
      p.control_weights.weights.push_back(w[i] / sum);
    }
  }
  return p;
}

TEST(PatchControlRotations, ThreeAndFourBonesMatchTheSvdPolarDecomposition) {
  std::mt19937 rng(11);
  const int bones = 6, count = 400;
  const deform::PatchSetup p = RandomWeightsPatch(rng, count, bones);
  std::vector<glm::mat4> palette(bones);
  std::vector<glm::quat> fast(count), svd(count);
  for (int pose = 0; pose < 20; ++pose) {
    const glm::dquat base = RandomRotation(rng);
    for (glm::mat4& m : palette) {
      const glm::dquat turn = glm::angleAxis(0.15 * pose, glm::dvec3(RandomRotation(rng) * glm::dvec3(0, 1, 0)));
      m = glm::mat4(glm::mat3_cast(glm::quat(base * turn)));
      m[3] = glm::vec4(1.0f, 2.0f, 3.0f, 1.0f);
    }
    ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
    // The reference: every control point through the SVD, one by one.
    for (int c = 0; c < count; ++c) {
      glm::dmat3 blend(0.0);
      for (int i = 0; i < 4; ++i) {
        const auto slot = static_cast<std::size_t>(4 * c + i);
        blend += static_cast<double>(p.control_weights.weights[slot]) *
                 glm::dmat3(glm::mat3(palette[p.control_weights.joints[slot]]));
      }
      svd[static_cast<std::size_t>(c)] = glm::quat(glm::quat_cast(deform::PolarRotationSvd(blend)));
    }
    for (int c = 0; c < count; ++c) {
      const auto k = static_cast<std::size_t>(c);
      EXPECT_LT(QuatDistance(fast[k], svd[k]), testsupport::kRotationTol) << "pose " << pose << " c " << c;
    }
  }
}

TEST(PatchControlRotations, SkipsOnlyControlPointsWhoseDisplacementIsZero) {
  std::mt19937 rng(5);
  const int count = 64;
  const deform::PatchSetup p = RandomWeightsPatch(rng, count, 5);
  std::vector<glm::mat4> palette(5);
  for (glm::mat4& m : palette) m = glm::mat4(glm::mat3_cast(glm::quat(RandomRotation(rng))));
  std::vector<glm::vec3> ds(count), global(count);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  for (int c = 0; c < count; ++c) {
    const auto k = static_cast<std::size_t>(c);
    global[k] = glm::vec3(uni(rng), uni(rng), uni(rng));
    ds[k] = c % 3 == 0 ? glm::vec3(0.0f) : glm::vec3(uni(rng), uni(rng), uni(rng));
  }
  ds[1] = glm::vec3(0.0f, 0.0f, 1e-30f);  // tiny but not zero: computed
  std::vector<glm::quat> all(count), masked(count);
  ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, all));
  ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, masked, ds));
  for (int c = 0; c < count; ++c) {
    const auto k = static_cast<std::size_t>(c);
    if (c % 3 == 0) {
      EXPECT_EQ(masked[k], glm::quat(1.0f, 0.0f, 0.0f, 0.0f)) << c;
    } else {
      EXPECT_EQ(masked[k], all[k]) << c;  // bit for bit: the same path
    }
  }
  // Q = G + A dS is the same with either set of rotations.
  std::vector<glm::vec3> q_all(count), q_masked(count);
  ASSERT_TRUE((deform::PoseSpaceApplyJob{.global = global, .rotations = all, .displacement = ds,
                                         .control = q_all}.Run()));
  ASSERT_TRUE((deform::PoseSpaceApplyJob{.global = global, .rotations = masked,
                                         .displacement = ds, .control = q_masked}.Run()));
  for (int c = 0; c < count; ++c) {
    const auto k = static_cast<std::size_t>(c);
    EXPECT_EQ(q_all[k], q_masked[k]) << c;
  }
  // A displacement span of the wrong size is refused.
  EXPECT_EQ(deform::PatchControlRotations(p, {.model_from_bind = palette}, masked,
                                          std::span(ds).first(10))
                .code,
            base::JobStatus::kSizeMismatch);
}

}  // namespace
