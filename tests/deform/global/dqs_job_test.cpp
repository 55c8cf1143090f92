#include "deform/global/dqs_job.h"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "deform/global/skinning_job.h"
#include "support/tolerances.h"

namespace {

using base::JobStatus;
using deform::DqsJob;
using deform::DualQuat;

glm::mat4 RandomRigid(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const glm::vec3 axis = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f);
  return glm::rotate(glm::translate(glm::mat4(1.0f), 5.0f * glm::vec3(u(rng), u(rng), u(rng))),
                     3.0f * u(rng), axis);
}

std::vector<DualQuat> ToDq(const std::vector<glm::mat4>& m) {
  std::vector<DualQuat> dq(m.size());
  EXPECT_TRUE(deform::BuildDualQuatPalette(m, dq).ok());
  return dq;
}

TEST(DqsJob, ValidityChecksSizesAndRanges) {
  const std::vector<DualQuat> palette(2);
  const std::vector<glm::vec3> rest(3), rest_n(3);
  const std::vector<std::uint16_t> joints(6, 0);
  const std::vector<float> weights(6, 0.5f);
  std::vector<glm::vec3> out(3), out_n(3);
  const DqsJob job{.palette = palette, .influences = 2, .joint_indices = joints,
                   .joint_weights = weights, .rest_positions = rest, .rest_normals = rest_n,
                   .positions = out, .normals = out_n};
  EXPECT_TRUE(job.Validate().ok());
  DqsJob bad = job;
  bad.influences = 9;
  EXPECT_EQ(bad.Validate().code, JobStatus::kOutOfRange);
  bad = job;
  bad.palette = {};
  EXPECT_EQ(bad.Run().code, JobStatus::kMissingInput);
  bad = job;
  bad.joint_indices = bad.joint_indices.first(5);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.joint_weights = bad.joint_weights.first(5);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.positions = bad.positions.first(2);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.normals = {};
  EXPECT_EQ(bad.Validate().code, JobStatus::kMissingOutput);
  std::vector<DualQuat> short_palette(1);
  EXPECT_EQ(deform::BuildDualQuatPalette(std::vector<glm::mat4>(2), short_palette).code,
            JobStatus::kSizeMismatch);
}

TEST(DqsJob, SingleRigidTransformIsReproduced) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const glm::mat4 m = RandomRigid(rng);
    // Two copies of the same transform, one with the antipodal quaternion: the
    // blend must still be exactly that transform.
    std::vector<DualQuat> palette = ToDq({m, m});
    palette[1].real = -palette[1].real;
    palette[1].dual = -palette[1].dual;
    const std::vector<glm::vec3> rest = {{1, 2, 3}, {-4, 0.5f, 2}};
    const std::vector<glm::vec3> rest_n = {glm::normalize(glm::vec3(1, 1, 0)), {0, 0, 1}};
    const std::vector<std::uint16_t> joints = {0, 1, 1, 0};
    const std::vector<float> weights = {0.5f, 0.5f, 0.7f, 0.3f};
    std::vector<glm::vec3> out(2), out_n(2);
    ASSERT_TRUE((DqsJob{.palette = palette, .influences = 2, .joint_indices = joints,
                        .joint_weights = weights, .rest_positions = rest, .rest_normals = rest_n,
                        .positions = out, .normals = out_n})
                    .Run()
                    .ok());
    for (std::size_t v = 0; v < 2; ++v) {
      const glm::vec3 expected(m * glm::vec4(rest[v], 1.0f));
      const glm::vec3 expected_n(m * glm::vec4(rest_n[v], 0.0f));
      EXPECT_NEAR(glm::distance(out[v], expected), 0.0f, testsupport::kSkinningTol);
      EXPECT_NEAR(glm::distance(out_n[v], expected_n), 0.0f, testsupport::kSkinningTol);
    }
  }
}

TEST(DqsJob, ResultBlendsTranslationsLinearly) {
  const std::vector<DualQuat> palette =
      ToDq({glm::mat4(1.0f), glm::translate(glm::mat4(1.0f), glm::vec3(2, 0, 0))});
  const std::vector<glm::vec3> rest = {{0, 1, 0}};
  const std::vector<std::uint16_t> joints = {0, 1};
  const std::vector<float> weights = {0.25f, 0.75f};
  std::vector<glm::vec3> out(1);
  ASSERT_TRUE((DqsJob{.palette = palette, .influences = 2, .joint_indices = joints,
                      .joint_weights = weights, .rest_positions = rest, .rest_normals = {}, .positions = out, .normals = {}})
                  .Run()
                  .ok());
  EXPECT_NEAR(out[0].x, 1.5f, testsupport::kFloatTol);
  EXPECT_NEAR(out[0].y, 1.0f, testsupport::kFloatTol);
  EXPECT_NEAR(out[0].z, 0.0f, testsupport::kFloatTol);
}

// A cylinder along x bent 90 degrees about z at the origin, weights blending
// over x in [-0.5, 0.5]. The ring at x = 0 (weights 1/2, 1/2) is measured in
// the plane through the joint normal to the bisector of the two bone axes
// (ALGORITHMS.md 2.3, collapse figure): polygon area / rest area.
float MidRingAreaRatio(bool dqs) {
  constexpr int kRing = 64;
  constexpr float kRadius = 0.2f;
  std::vector<glm::vec3> rest;
  std::vector<std::uint16_t> joints;
  std::vector<float> weights;
  for (int k = 0; k < kRing; ++k) {
    const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / kRing;
    rest.emplace_back(0.0f, kRadius * std::cos(a), kRadius * std::sin(a));
    joints.insert(joints.end(), {0, 1});
    weights.insert(weights.end(), {0.5f, 0.5f});
  }
  const std::vector<glm::mat4> mats = {
      glm::mat4(1.0f), glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 0, 1))};
  std::vector<glm::vec3> out(rest.size());
  if (dqs) {
    const std::vector<DualQuat> palette = ToDq(mats);
    EXPECT_TRUE((DqsJob{.palette = palette, .influences = 2, .joint_indices = joints,
                        .joint_weights = weights, .rest_positions = rest, .rest_normals = {}, .positions = out, .normals = {}})
                    .Run()
                    .ok());
  } else {
    EXPECT_TRUE((deform::SkinningJob{.model_from_bind = mats, .influences = 2,
                                     .joint_indices = joints, .joint_weights = weights,
                                     .rest_positions = rest, .rest_normals = {}, .positions = out, .normals = {}})
                    .Run()
                    .ok());
  }
  const glm::vec3 normal = glm::normalize(glm::vec3(1, 0, 0) + glm::vec3(0, 1, 0));
  const auto area = [&](const std::vector<glm::vec3>& ring) {
    glm::vec3 sum(0.0f);
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const glm::vec3 a = ring[k] - glm::dot(ring[k], normal) * normal;  // project to the plane
      const glm::vec3 b0 = ring[(k + 1) % ring.size()];
      const glm::vec3 b = b0 - glm::dot(b0, normal) * normal;
      sum += glm::cross(a, b);
    }
    return 0.5f * std::abs(glm::dot(sum, normal));
  };
  const float rest_area = 0.5f * kRing * kRadius * kRadius *
                          std::sin(2.0f * std::numbers::pi_v<float> / kRing);
  return area(out) / rest_area;
}

TEST(DqsJob, KeepsMoreCrossSectionThanSsdAtA90DegreeBend) {
  const float ssd = MidRingAreaRatio(false);
  const float dqs = MidRingAreaRatio(true);
  RecordProperty("ssd_area_ratio", std::to_string(ssd));
  RecordProperty("dqs_area_ratio", std::to_string(dqs));
  std::printf("mid-ring area / rest area at a 90 degree bend: SSD %.4f, DQS %.4f\n", ssd, dqs);
  // SSD halves the bend: the ring shrinks by cos(45 deg) in the bend plane.
  EXPECT_NEAR(ssd, std::cos(std::numbers::pi_v<float> / 4.0f), testsupport::kPolygonAreaRatioTol);
  // DQS rotates the ring rigidly by 45 degrees: its projection keeps the area.
  EXPECT_NEAR(dqs, 1.0f, testsupport::kPolygonAreaRatioTol);
}

}  // namespace
