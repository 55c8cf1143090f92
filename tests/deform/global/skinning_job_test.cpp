#include "deform/global/skinning_job.h"

#include <cstring>
#include <random>
#include <thread>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "deform/simd.h"
#include "support/tolerances.h"

namespace {

using base::JobStatus;
using deform::SkinningJob;
using deform::SkinWeights;

// A random mesh with random weights over `joints` joints, normalized the way
// the importers and the mannequin do it.
struct RandomSkin {
  std::vector<glm::vec3> positions, normals;
  SkinWeights weights;
};

RandomSkin MakeRandomSkin(int vertices, int influences, int joints, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-10.0f, 10.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::uniform_int_distribution<int> joint(0, joints - 1);
  RandomSkin s;
  s.weights.influences = influences;
  for (int v = 0; v < vertices; ++v) {
    s.positions.emplace_back(coord(rng), coord(rng), coord(rng));
    s.normals.push_back(glm::normalize(glm::vec3(coord(rng), coord(rng), coord(rng)) + 1e-3f));
    for (int i = 0; i < influences; ++i) {
      s.weights.joints.push_back(static_cast<std::uint16_t>(joint(rng)));
      s.weights.weights.push_back(unit(rng));
    }
  }
  deform::NormalizeSkinWeights(s.weights);
  return s;
}

glm::mat4 RandomRigid(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const glm::vec3 axis = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f);
  return glm::rotate(glm::translate(glm::mat4(1.0f), 5.0f * glm::vec3(u(rng), u(rng), u(rng))),
                     3.0f * u(rng), axis);
}

SkinningJob MakeJob(const RandomSkin& s, std::span<const glm::mat4> palette,
                    std::vector<glm::vec3>& out_p, std::vector<glm::vec3>& out_n) {
  out_p.assign(s.positions.size(), glm::vec3(0.0f));
  out_n.assign(s.positions.size(), glm::vec3(0.0f));
  return SkinningJob{.model_from_bind = palette,
                     .influences = s.weights.influences,
                     .joint_indices = s.weights.joints,
                     .joint_weights = s.weights.weights,
                     .rest_positions = s.positions,
                     .rest_normals = s.normals,
                     .positions = out_p,
                     .normals = out_n};
}

// Validity: every misconfiguration names its reason.
TEST(SkinningJob, ValidityRejectsBadInfluenceCount) {
  SkinningJob job;
  job.influences = 0;
  EXPECT_EQ(job.Validate().code, JobStatus::kOutOfRange);
  job.influences = deform::kMaxInfluences + 1;
  EXPECT_EQ(job.Run().code, JobStatus::kOutOfRange);
}

TEST(SkinningJob, ValidityChecksSizes) {
  const RandomSkin s = MakeRandomSkin(5, 4, 3, 1);
  const std::vector<glm::mat4> palette(3, glm::mat4(1.0f));
  std::vector<glm::vec3> p, n;
  SkinningJob job = MakeJob(s, palette, p, n);
  EXPECT_TRUE(job.Validate().ok());
  SkinningJob bad = job;
  bad.joint_indices = bad.joint_indices.first(19);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.joint_weights = bad.joint_weights.first(19);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.positions = bad.positions.first(4);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.normals = {};
  EXPECT_EQ(bad.Validate().code, JobStatus::kMissingOutput);
  bad = job;
  bad.normals = bad.normals.first(4);
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.model_from_bind = {};
  EXPECT_EQ(bad.Run().code, JobStatus::kMissingInput);
  bad = job;
  bad.influences = 8;  // arrays hold 4 per vertex
  EXPECT_EQ(bad.Validate().code, JobStatus::kSizeMismatch);
  bad = job;
  bad.rest_normals = {};
  bad.normals = {};
  EXPECT_TRUE(bad.Run().ok());  // normals are optional
  EXPECT_TRUE(SkinningJob{}.Run().ok());  // nothing to do is fine
}

TEST(SkinningJob, CheckSkinWeightsFindsBadRows) {
  RandomSkin s = MakeRandomSkin(4, 4, 3, 2);
  EXPECT_TRUE(deform::CheckSkinWeights(s.weights, 3, 4).ok());
  EXPECT_FALSE(deform::CheckSkinWeights(s.weights, 3, 5).ok());
  s.weights.joints[5] = 3;
  EXPECT_EQ(deform::CheckSkinWeights(s.weights, 3).error().code, base::ErrorCode::kInvalidArgument);
  s.weights.joints[5] = 0;
  s.weights.weights[6] += 0.5f;
  EXPECT_EQ(deform::CheckSkinWeights(s.weights, 3).error().code, base::ErrorCode::kInvalidArgument);
}

// Result: small cases worked out by hand.
TEST(SkinningJob, ResultTwoInfluencesTranslation) {
  const std::vector<glm::mat4> palette = {glm::mat4(1.0f),
                                          glm::translate(glm::mat4(1.0f), glm::vec3(0, 2, 0))};
  const std::vector<glm::vec3> rest = {{1, 0, 0}, {0, 0, 3}};
  const std::vector<glm::vec3> rest_n = {{1, 0, 0}, {0, 0, 1}};
  const std::vector<std::uint16_t> joints = {0, 1, 0, 1};
  const std::vector<float> weights = {0.5f, 0.5f, 0.25f, 0.75f};
  std::vector<glm::vec3> out(2), out_n(2);
  ASSERT_TRUE((SkinningJob{.model_from_bind = palette, .influences = 2, .joint_indices = joints,
                           .joint_weights = weights, .rest_positions = rest,
                           .rest_normals = rest_n, .positions = out, .normals = out_n})
                  .Run()
                  .ok());
  EXPECT_EQ(out[0], glm::vec3(1, 1, 0));    // half of the 2-unit lift
  EXPECT_EQ(out[1], glm::vec3(0, 1.5, 3));  // three quarters of it
  EXPECT_EQ(out_n[0], glm::vec3(1, 0, 0));  // translations leave normals alone
}

TEST(SkinningJob, ResultTwoInfluencesRotationShrinks) {
  // Halfway between identity and a 90 degree turn about z: (1,0,0) -> (0.5,0.5,0),
  // the linear blend's well-known shortening to cos(45) of the length.
  const std::vector<glm::mat4> palette = {
      glm::mat4(1.0f), glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 0, 1))};
  const std::vector<glm::vec3> rest = {{1, 0, 0}};
  const std::vector<std::uint16_t> joints = {0, 1};
  const std::vector<float> weights = {0.5f, 0.5f};
  std::vector<glm::vec3> out(1);
  ASSERT_TRUE((SkinningJob{.model_from_bind = palette, .influences = 2, .joint_indices = joints,
                           .joint_weights = weights, .rest_positions = rest, .rest_normals = {}, .positions = out, .normals = {}})
                  .Run()
                  .ok());
  EXPECT_NEAR(out[0].x, 0.5f, testsupport::kFloatTol);
  EXPECT_NEAR(out[0].y, 0.5f, testsupport::kFloatTol);
  EXPECT_NEAR(out[0].z, 0.0f, testsupport::kFloatTol);
}

// Property: identity palette reproduces the bind mesh bit for bit.
class SkinningJobInfluences : public testing::TestWithParam<int> {};

TEST_P(SkinningJobInfluences, IdentityPaletteIsExact) {
  const RandomSkin s = MakeRandomSkin(1000, GetParam(), 7, 3);
  const std::vector<glm::mat4> palette(7, glm::mat4(1.0f));
  std::vector<glm::vec3> p, n;
  ASSERT_TRUE(MakeJob(s, palette, p, n).Run().ok());
  for (std::size_t v = 0; v < p.size(); ++v) {
    ASSERT_EQ(p[v], s.positions[v]) << "vertex " << v;
    ASSERT_EQ(n[v], s.normals[v]) << "vertex " << v;
  }
}

TEST_P(SkinningJobInfluences, RigidPaletteKeepsEdgeLengths) {
  std::mt19937 rng(4);
  const glm::mat4 m = RandomRigid(rng);
  const std::vector<glm::mat4> palette(5, m);
  const RandomSkin s = MakeRandomSkin(500, GetParam(), 5, 5);
  std::vector<glm::vec3> p, n;
  ASSERT_TRUE(MakeJob(s, palette, p, n).Run().ok());
  for (std::size_t v = 1; v < p.size(); ++v) {
    EXPECT_NEAR(glm::distance(p[v], p[v - 1]), glm::distance(s.positions[v], s.positions[v - 1]),
                testsupport::kSkinningTol);
    EXPECT_NEAR(glm::length(n[v]), 1.0f, testsupport::kSkinningTol);
    const glm::vec3 expected(m * glm::vec4(s.positions[v], 1.0f));
    EXPECT_NEAR(glm::distance(p[v], expected), 0.0f, testsupport::kSkinningTol);
  }
}

TEST_P(SkinningJobInfluences, SplitRunsEqualOneRunBitForBit) {
  const int k = GetParam();
  const RandomSkin s = MakeRandomSkin(3001, k, 9, 6);
  std::mt19937 rng(7);
  std::vector<glm::mat4> palette;
  for (int j = 0; j < 9; ++j) palette.push_back(RandomRigid(rng));
  std::vector<glm::vec3> p, n;
  ASSERT_TRUE(MakeJob(s, palette, p, n).Run().ok());
  std::vector<glm::vec3> p2(p.size()), n2(n.size());
  const std::size_t cuts[] = {0, 17, 1500, 2999, 3001};
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i) {
    const std::size_t b = cuts[i], e = cuts[i + 1], kk = static_cast<std::size_t>(k);
    threads.emplace_back([&, b, e, kk] {
      const SkinningJob part{
          .model_from_bind = palette,
          .influences = k,
          .joint_indices = std::span(s.weights.joints).subspan(b * kk, (e - b) * kk),
          .joint_weights = std::span(s.weights.weights).subspan(b * kk, (e - b) * kk),
          .rest_positions = std::span(s.positions).subspan(b, e - b),
          .rest_normals = std::span(s.normals).subspan(b, e - b),
          .positions = std::span(p2).subspan(b, e - b),
          .normals = std::span(n2).subspan(b, e - b)};
      EXPECT_TRUE(part.Run().ok());
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(std::memcmp(p.data(), p2.data(), p.size() * sizeof(glm::vec3)), 0);
  EXPECT_EQ(std::memcmp(n.data(), n2.data(), n.size() * sizeof(glm::vec3)), 0);
}

TEST_P(SkinningJobInfluences, SimdPathsAgreeBitForBit) {
  const RandomSkin s = MakeRandomSkin(777, GetParam(), 9, 12);
  std::mt19937 rng(13);
  std::vector<glm::mat4> palette;
  for (int j = 0; j < 9; ++j) palette.push_back(RandomRigid(rng));
  std::vector<glm::vec3> p, n, p2, n2;
  ASSERT_TRUE(MakeJob(s, palette, p, n).Run().ok());
  RecordProperty("simd_path", deform::SkinningSimdPath());
  // The same job with the process capped to the baseline (SSE2 on x86-64).
  deform::SetSimdCap(deform::SimdLevel::kBaseline);
  EXPECT_STRNE(deform::SkinningSimdPath(), "avx");
  const bool ran = MakeJob(s, palette, p2, n2).Run().ok();
  deform::SetSimdCap(deform::SimdLevel::kAvx);
  ASSERT_TRUE(ran);
  EXPECT_EQ(std::memcmp(p.data(), p2.data(), p.size() * sizeof(glm::vec3)), 0);
  EXPECT_EQ(std::memcmp(n.data(), n2.data(), n.size() * sizeof(glm::vec3)), 0);
}

INSTANTIATE_TEST_SUITE_P(Counts, SkinningJobInfluences, testing::Values(1, 2, 3, 4, 5, 8));

TEST(SkinningJob, FourAndEightInfluencesAgreeWhenExtraWeightsAreZero) {
  const RandomSkin s4 = MakeRandomSkin(2000, 4, 6, 8);
  RandomSkin s8 = s4;
  s8.weights.influences = 8;
  s8.weights.joints.clear();
  s8.weights.weights.clear();
  for (std::size_t v = 0; v < s4.positions.size(); ++v) {
    for (std::size_t i = 0; i < 8; ++i) {
      s8.weights.joints.push_back(i < 4 ? s4.weights.joints[4 * v + i] : static_cast<std::uint16_t>(i % 6));
      s8.weights.weights.push_back(i < 4 ? s4.weights.weights[4 * v + i] : 0.0f);
    }
  }
  std::mt19937 rng(9);
  std::vector<glm::mat4> palette;
  for (int j = 0; j < 6; ++j) palette.push_back(RandomRigid(rng));
  std::vector<glm::vec3> p4, n4, p8, n8;
  ASSERT_TRUE(MakeJob(s4, palette, p4, n4).Run().ok());
  ASSERT_TRUE(MakeJob(s8, palette, p8, n8).Run().ok());
  for (std::size_t v = 0; v < p4.size(); ++v) {
    ASSERT_EQ(p4[v], p8[v]) << "vertex " << v;
    ASSERT_EQ(n4[v], n8[v]) << "vertex " << v;
  }
}

TEST(SkinningJob, PaletteComposesModelAndInverseBind) {
  std::mt19937 rng(10);
  deform::SkinnedMesh mesh;
  mesh.skin_joints = {2, 0};
  const std::vector<glm::mat4> model = {RandomRigid(rng), RandomRigid(rng), RandomRigid(rng)};
  mesh.joint_from_bind = {glm::inverse(model[2]), glm::inverse(model[0])};
  std::vector<glm::mat4> palette(2);
  ASSERT_TRUE(deform::BuildSkinningPalette(model, mesh, palette).ok());
  for (const glm::mat4& m : palette) {
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) {
        EXPECT_NEAR(m[c][r], c == r ? 1.0f : 0.0f, testsupport::kSkinningTol);
      }
    }
  }
  mesh.skin_joints[1] = 3;
  EXPECT_EQ(deform::BuildSkinningPalette(model, mesh, palette).code, JobStatus::kOutOfRange);
  EXPECT_EQ(deform::BuildSkinningPalette(model, mesh, std::span(palette).first(1)).code,
            JobStatus::kSizeMismatch);
}

}  // namespace
