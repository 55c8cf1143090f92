#include "deform/global/swd_job.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "support/arm_fixture.h"
#include "support/tolerances.h"

namespace {

using base::JobStatus;
using deform::SwdJob;
using deform::SweepChain;
using deform::SweepVertexBinding;
using testsupport::kAreaRatioTol;
using testsupport::kFloatTol;
using testsupport::kSwdRebuildRelTol;

struct ArmSetup {
  testfixture::Arm arm;
  SweepChain chain;
  std::vector<SweepVertexBinding> bindings;
};

ArmSetup MakeArmSetup(int segments = 24, int per_unit = 1) {
  ArmSetup setup;
  setup.arm = testfixture::MakeArm(segments, per_unit);
  auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(setup.arm));
  EXPECT_TRUE(chain.ok()) << chain.error().ToString();
  setup.chain = *chain;
  const std::vector<SweepChain> chains = {setup.chain};
  auto bindings = deform::BindToSweeps(chains, {}, setup.arm.mesh.positions);
  EXPECT_TRUE(bindings.ok()) << bindings.error().ToString();
  setup.bindings = *bindings;
  return setup;
}

TEST(SwdJob, Validity) {
  const ArmSetup s = MakeArmSetup(8, 1);
  const auto pose = testfixture::BendPose(s.arm, 30.0f);
  const std::vector<glm::vec3> joints(pose.joints.begin(), pose.joints.begin() + 3);
  std::vector<glm::vec3> out(s.bindings.size()), normals(s.bindings.size());
  const SwdJob good{.chains = std::span<const SweepChain>(&s.chain, 1),
                    .joint_rotations = pose.rotations,
                    .joint_positions = joints,
                    .bindings = s.bindings,
                    .rest_normals = {},
                    .keep_volume = false,
                    .section_scales = {},
                    .positions = out,
                    .normals = {}};
  EXPECT_EQ(good.Validate().code, JobStatus::kOk);
  SwdJob job = good;
  job.chains = {};
  EXPECT_EQ(job.Validate().code, JobStatus::kMissingInput);
  job = good;
  job.joint_positions = std::span<const glm::vec3>(joints).first(2);
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  job = good;
  job.joint_rotations = std::span<const glm::quat>(pose.rotations).first(2);
  job.joint_positions = std::span<const glm::vec3>(joints).first(2);
  EXPECT_EQ(job.Validate().code, JobStatus::kOutOfRange);  // chain uses joint 2
  job = good;
  job.positions = std::span<glm::vec3>(out).first(out.size() - 1);
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  job = good;
  job.rest_normals = s.arm.mesh.normals;
  EXPECT_EQ(job.Validate().code, JobStatus::kMissingOutput);
  job.normals = std::span<glm::vec3>(normals).first(3);
  EXPECT_EQ(job.Validate().code, JobStatus::kSizeMismatch);
  job = good;
  job.normals = normals;
  EXPECT_EQ(job.Validate().code, JobStatus::kMissingInput);
  std::vector<SweepVertexBinding> bad = s.bindings;
  bad[3].primary.chain = 1;
  job = good;
  job.bindings = bad;
  EXPECT_EQ(job.Validate().code, JobStatus::kOk);  // Validate reads no per-vertex data
  EXPECT_EQ(job.Run().code, JobStatus::kOutOfRange);
}

TEST(SwdJob, BindPoseReproducesEveryVertex) {
  const ArmSetup s = MakeArmSetup();
  const auto rest = testfixture::MakePose(
      s.arm, {glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0)},
      s.arm.joint_rest[0]);
  for (const bool keep_volume : {false, true}) {
    std::vector<glm::vec3> normals;
    const auto out = testfixture::SkinSwd(s.chain, s.bindings, rest, keep_volume, &normals,
                                          s.arm.mesh.normals);
    ASSERT_EQ(out.size(), s.arm.mesh.positions.size());
    const float size = testfixture::kArmLength;
    for (std::size_t v = 0; v < out.size(); ++v) {
      ASSERT_LE(glm::length(out[v] - s.arm.mesh.positions[v]), kSwdRebuildRelTol * size)
          << "vertex " << v << " u " << s.bindings[v].primary.u;
      ASSERT_LE(glm::length(normals[v] - s.arm.mesh.normals[v]), kFloatTol) << "vertex " << v;
    }
  }
}

TEST(SwdJob, RigidMotionOfTheWholeChainMovesVerticesRigidly) {
  const ArmSetup s = MakeArmSetup();
  const glm::quat r = glm::normalize(glm::quat(0.3f, -0.5f, 0.7f, 0.2f));
  const glm::vec3 t(4.0f, -7.0f, 12.0f);
  const auto pose = testfixture::MakePose(s.arm, {r, r, r}, r * s.arm.joint_rest[0] + t);
  std::vector<glm::vec3> normals;
  const auto out = testfixture::SkinSwd(s.chain, s.bindings, pose, true, &normals,
                                        s.arm.mesh.normals);
  ASSERT_EQ(out.size(), s.arm.mesh.positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    const glm::vec3 expected = r * s.arm.mesh.positions[v] + t;
    ASSERT_LE(glm::length(out[v] - expected), 4.0f * kSwdRebuildRelTol * testfixture::kArmLength)
        << "vertex " << v;
    ASSERT_LE(glm::length(normals[v] - r * s.arm.mesh.normals[v]), 4.0f * kFloatTol);
  }
}

TEST(SwdJob, SubRangesGiveBitIdenticalResults) {
  const ArmSetup s = MakeArmSetup();
  const auto pose = testfixture::BendPose(s.arm, 110.0f);
  const std::vector<glm::vec3> joints(pose.joints.begin(), pose.joints.begin() + 3);
  const std::size_t n = s.bindings.size();
  std::vector<glm::vec3> whole(n), split(n), whole_n(n), split_n(n);
  SwdJob job{.chains = std::span<const SweepChain>(&s.chain, 1),
             .joint_rotations = pose.rotations,
             .joint_positions = joints,
             .bindings = s.bindings,
             .rest_normals = s.arm.mesh.normals,
             .keep_volume = true,
             .section_scales = {},
             .positions = whole,
             .normals = whole_n};
  ASSERT_TRUE(job.Run());
  const std::size_t cut = n / 3 + 1;
  for (const auto& [begin, end] : {std::pair{std::size_t{0}, cut}, std::pair{cut, n}}) {
    SwdJob part = job;
    part.bindings = std::span<const SweepVertexBinding>(s.bindings).subspan(begin, end - begin);
    part.rest_normals = std::span<const glm::vec3>(s.arm.mesh.normals).subspan(begin, end - begin);
    part.positions = std::span<glm::vec3>(split).subspan(begin, end - begin);
    part.normals = std::span<glm::vec3>(split_n).subspan(begin, end - begin);
    ASSERT_TRUE(part.Run());
  }
  EXPECT_EQ(std::memcmp(whole.data(), split.data(), n * sizeof(glm::vec3)), 0);
  EXPECT_EQ(std::memcmp(whole_n.data(), split_n.data(), n * sizeof(glm::vec3)), 0);
}

TEST(SwdJob, VolumeKeepingScalesTheElbowRingByTheArcLengthRatio) {
  const ArmSetup s = MakeArmSetup();
  const auto pose = testfixture::BendPose(s.arm, 120.0f);
  const auto plain = testfixture::SkinSwd(s.chain, s.bindings, pose, false);
  const auto kept = testfixture::SkinSwd(s.chain, s.bindings, pose, true);
  const auto ring = testfixture::ElbowRing(s.arm, pose, s.arm.rings[s.arm.elbow_ring]);
  const auto plain_ratio = deform::CollapseFigure(s.arm.mesh.positions, plain, ring);
  const auto kept_ratio = deform::CollapseFigure(s.arm.mesh.positions, kept, ring);
  ASSERT_TRUE(plain_ratio.ok() && kept_ratio.ok());
  // Independent arc lengths: fine polylines through the current and rest centre curves.
  deform::BasicSweepPose<double> current;
  const std::array<glm::vec3, 3> joints = {pose.joints[0], pose.joints[1], pose.joints[2]};
  deform::PoseSweepChain<double>(s.chain, pose.rotations, joints, false, &current);
  const double a = s.chain.region_start(1), b = s.chain.region_end(1);
  double length = 0.0, rest_length = 0.0;
  for (int i = 0; i < 4000; ++i) {
    const double u0 = a + (b - a) * i / 4000.0, u1 = a + (b - a) * (i + 1) / 4000.0;
    length += glm::length(deform::SweepCentre<double>(s.chain, current, u1, nullptr) -
                          deform::SweepCentre<double>(s.chain, current, u0, nullptr));
    rest_length += glm::length(deform::SweepCentre<double>(s.chain, s.chain.rest_pose(), u1, nullptr) -
                               deform::SweepCentre<double>(s.chain, s.chain.rest_pose(), u0, nullptr));
  }
  EXPECT_LT(length, rest_length);  // the bent region's centre is shorter
  // At the joint x = 1/2: s^2 = 1 + (l0/l - 1) * 6 * 1/4.
  const double expected = *plain_ratio * (1.0 + (rest_length / length - 1.0) * 1.5);
  EXPECT_NEAR(*kept_ratio, expected, 1e-3);
  EXPECT_GT(*kept_ratio, *plain_ratio);
}

// A trunk (pelvis-chest, up +y) and a branch starting at its end (clavicle, upper arm,
// along +x); the clavicle interval [0, 1] is the junction zone.
TEST(SwdJob, JunctionBlendIsContinuousAcrossTheZoneBoundaries) {
  deform::SweepChainSpec trunk_spec;
  trunk_spec.joints = {0, 1};
  trunk_spec.rest_points = {glm::vec3(0), glm::vec3(0, 20, 0), glm::vec3(0, 36, 0)};
  trunk_spec.half_widths = {0, 5, 0};
  deform::SweepChainSpec branch_spec;
  branch_spec.joints = {2, 3};
  branch_spec.rest_points = {glm::vec3(0, 36, 0), glm::vec3(10, 36, 0), glm::vec3(35, 36, 0)};
  branch_spec.half_widths = {0, 3, 0};
  const auto trunk = deform::BuildSweepChain(trunk_spec);
  const auto branch = deform::BuildSweepChain(branch_spec);
  ASSERT_TRUE(trunk.ok() && branch.ok());
  const std::vector<SweepChain> chains = {*branch, *trunk};
  const std::vector<deform::SweepJunction> junctions = {{.branch = 0, .trunk = 1}};
  std::vector<glm::vec3> points;  // a line of skin points above the clavicle
  constexpr float kSpacing = 0.02f;
  for (float x = -3.0f; x <= 14.0f; x += kSpacing) points.emplace_back(x, 38.5f, 0.7f);
  const auto bindings = deform::BindToSweeps(chains, junctions, points);
  ASSERT_TRUE(bindings.ok()) << bindings.error().ToString();
  int blended = 0;
  for (const SweepVertexBinding& b : *bindings) {
    if (b.weight > 0.0f && b.weight < 1.0f) ++blended;
    if (b.primary.chain == 0 && b.primary.u >= 1.0f) {
      EXPECT_EQ(b.weight, 1.0f);
    }
  }
  EXPECT_GT(blended, 100);
  // Skeleton: 0 pelvis (0,0,0), 1 chest (0,20,0), 2 clavicle (0,36,0), 3 shoulder (10,36,0).
  const std::array<glm::vec3, 4> rest_joints = {glm::vec3(0), glm::vec3(0, 20, 0),
                                                glm::vec3(0, 36, 0), glm::vec3(10, 36, 0)};
  const std::array<int, 4> parents = {-1, 0, 1, 2};
  std::array<glm::quat, 4> rotations = {
      glm::quat(1, 0, 0, 0), glm::angleAxis(0.25f, glm::vec3(0, 0, 1)),
      glm::angleAxis(0.25f, glm::vec3(0, 0, 1)) * glm::angleAxis(0.5f, glm::vec3(0, 1, 0)),
      glm::angleAxis(1.2f, glm::vec3(0, 0, -1))};
  std::array<glm::vec3, 4> joints{};
  for (std::size_t j = 0; j < 4; ++j) {
    joints[j] = parents[j] < 0 ? rest_joints[j]
                               : joints[static_cast<std::size_t>(parents[j])] +
                                     rotations[static_cast<std::size_t>(parents[j])] *
                                         (rest_joints[j] - rest_joints[static_cast<std::size_t>(parents[j])]);
  }
  std::vector<glm::vec3> out(points.size());
  const SwdJob job{.chains = chains,
                   .joint_rotations = rotations,
                   .joint_positions = joints,
                   .bindings = *bindings,
                   .rest_normals = {},
                   .keep_volume = false,
                   .section_scales = {},
                   .positions = out,
                   .normals = {}};
  ASSERT_TRUE(job.Run());
  // No jump: neighbouring points stay neighbours (a jump would be a whole step of the
  // difference between the two sweeps, several units here).
  float worst = 0.0f;
  for (std::size_t i = 1; i < out.size(); ++i) {
    worst = std::max(worst, glm::length(out[i] - out[i - 1]) / kSpacing);
  }
  EXPECT_LT(worst, 4.0f);
}

}  // namespace

namespace {

// A straight 2-bone elliptic tube along +x (y radius 4, z radius 2), rings every unit.
struct EllipticTube {
  SweepChain chain;
  std::vector<glm::vec3> positions;
  std::vector<float> ring_x;  // #V: x of each vertex's ring
  std::vector<SweepVertexBinding> bindings;
};

EllipticTube MakeEllipticTube() {
  EllipticTube tube;
  deform::SweepChainSpec spec;
  spec.joints = {0, 1};
  spec.rest_points = {glm::vec3(0), glm::vec3(20, 0, 0), glm::vec3(40, 0, 0)};
  spec.half_widths = {0, 6, 0};
  tube.chain = *deform::BuildSweepChain(spec);
  for (int x = 0; x <= 40; ++x) {
    for (int i = 0; i < 16; ++i) {
      const float angle = 6.2831853f * static_cast<float>(i) / 16.0f;
      tube.positions.emplace_back(static_cast<float>(x), 4.0f * std::cos(angle),
                                  2.0f * std::sin(angle));
      tube.ring_x.push_back(static_cast<float>(x));
    }
  }
  const std::vector<SweepChain> chains = {tube.chain};
  tube.bindings = *deform::BindToSweeps(chains, {}, tube.positions);
  return tube;
}

std::vector<glm::vec3> RunTube(const EllipticTube& tube,
                               std::span<const deform::SectionScale> scales) {
  const std::array<glm::quat, 2> rotations = {glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0)};
  const std::array<glm::vec3, 2> joints = {glm::vec3(0), glm::vec3(20, 0, 0)};
  std::vector<glm::vec3> out(tube.positions.size());
  const SwdJob job{.chains = std::span<const SweepChain>(&tube.chain, 1),
                   .joint_rotations = rotations,
                   .joint_positions = joints,
                   .bindings = tube.bindings,
                   .rest_normals = {},
                   .keep_volume = false,
                   .section_scales = scales,
                   .positions = out,
                   .normals = {}};
  if (!job.Run()) out.clear();
  return out;
}

TEST(SwdJob, BindingFindsTheEllipseAxisOfTheSection) {
  const EllipticTube tube = MakeEllipticTube();
  int in_region = 0;
  for (const SweepVertexBinding& b : tube.bindings) {
    int joint = 0;
    float x = 0.0f;
    if (deform::SweepRegionAt(tube.chain, b.primary.u, &joint, &x)) {
      ++in_region;
      EXPECT_NEAR(std::abs(b.primary.section_axis.y), 1.0f, kFloatTol) << "u " << b.primary.u;
    } else {
      EXPECT_EQ(b.primary.section_axis, glm::vec3(0.0f)) << "u " << b.primary.u;
    }
  }
  EXPECT_GE(in_region, 11 * 16);  // the rings within 6 units of the joint
}

TEST(SwdJob, EllipticScalingStretchesTheJointSectionAlongItsAxes) {
  const EllipticTube tube = MakeEllipticTube();
  const std::vector<deform::SectionScale> unit = {{.chain = 0, .joint = 1}};
  const auto plain = RunTube(tube, {});
  EXPECT_EQ(RunTube(tube, unit), plain);  // unit scales change nothing
  const std::vector<deform::SectionScale> bulge = {
      {.chain = 0, .joint = 1, .scale_a = 2.0f, .scale_b = 0.5f}};
  const auto out = RunTube(tube, bulge);
  ASSERT_EQ(out.size(), tube.positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    int joint = 0;
    float x = 0.0f;
    const glm::vec3& p0 = tube.positions[v];
    if (!deform::SweepRegionAt(tube.chain, tube.bindings[v].primary.u, &joint, &x)) {
      EXPECT_NEAR(glm::length(out[v] - p0), 0.0f, 1e-4f) << "outside the region, x " << p0.x;
      continue;
    }
    const float bump = 4.0f * x * (1.0f - x);
    const glm::vec3 expected(p0.x, p0.y * (1.0f + bump), p0.z * (1.0f - 0.5f * bump));
    EXPECT_NEAR(glm::length(out[v] - expected), 0.0f, 1e-4f) << "x " << p0.x;
  }
}

TEST(SwdJob, RejectsSectionScalesOutsideInteriorJoints) {
  const EllipticTube tube = MakeEllipticTube();
  for (const deform::SectionScale bad :
       {deform::SectionScale{.chain = 0, .joint = 0}, deform::SectionScale{.chain = 0, .joint = 2},
        deform::SectionScale{.chain = 1, .joint = 1},
        deform::SectionScale{.chain = 0, .joint = 1, .scale_a = -1.0f}}) {
    const std::array<glm::quat, 2> rotations = {glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0)};
    const std::array<glm::vec3, 2> joints = {glm::vec3(0), glm::vec3(20, 0, 0)};
    std::vector<glm::vec3> out(tube.positions.size());
    const SwdJob job{.chains = std::span<const SweepChain>(&tube.chain, 1),
                     .joint_rotations = rotations,
                     .joint_positions = joints,
                     .bindings = tube.bindings,
                     .rest_normals = {},
                     .keep_volume = false,
                     .section_scales = std::span<const deform::SectionScale>(&bad, 1),
                     .positions = out,
                     .normals = {}};
    EXPECT_EQ(job.Validate().code, JobStatus::kOutOfRange);
  }
}

}  // namespace

namespace {

// Worst ratio of deformed to rest spacing along a line of points crossing the boundary
// between a trunk (pelvis-chest-neck, up +y) and a clavicle branch that starts part-way
// up it (at the neck base), with the clavicle raised.
float WorstStretchNearMidTrunkJunction(float seam_band) {
  deform::SweepChainSpec trunk_spec;
  trunk_spec.joints = {0, 1, 2};
  trunk_spec.rest_points = {glm::vec3(0), glm::vec3(0, 20, 0), glm::vec3(0, 40, 0),
                            glm::vec3(0, 52, 0)};
  trunk_spec.half_widths = {0, 5, 4, 0};
  deform::SweepChainSpec branch_spec;
  branch_spec.joints = {3, 4};
  branch_spec.rest_points = {glm::vec3(0, 40, 0), glm::vec3(12, 40, 0), glm::vec3(37, 40, 0)};
  branch_spec.half_widths = {0, 4, 0};
  const std::vector<SweepChain> chains = {*deform::BuildSweepChain(branch_spec),
                                          *deform::BuildSweepChain(trunk_spec)};
  const std::vector<deform::SweepJunction> junctions = {
      {.branch = 0, .trunk = 1, .u_start = 0.0f, .u_end = 1.0f, .seam_band = seam_band}};
  std::vector<glm::vec3> points;
  constexpr float kSpacing = 0.02f;
  for (float x = -3.0f; x <= 16.0f; x += kSpacing) points.emplace_back(x, 44.5f, 1.0f);
  const auto bindings = deform::BindToSweeps(chains, junctions, points);
  if (!bindings.ok()) return -1.0f;
  // Skeleton: 0 pelvis, 1 chest, 2 neck (0,40,0), 3 clavicle (0,40,0), 4 shoulder (12,40,0).
  const std::array<glm::vec3, 5> rest_joints = {glm::vec3(0), glm::vec3(0, 20, 0),
                                                glm::vec3(0, 40, 0), glm::vec3(0, 40, 0),
                                                glm::vec3(12, 40, 0)};
  const std::array<int, 5> parents = {-1, 0, 1, 1, 3};
  const glm::quat chest = glm::angleAxis(0.1f, glm::vec3(0, 0, 1));
  const glm::quat clavicle = chest * glm::angleAxis(0.6f, glm::vec3(0, 0, 1));
  const std::array<glm::quat, 5> rotations = {
      glm::quat(1, 0, 0, 0), chest, chest, clavicle,
      clavicle * glm::angleAxis(0.8f, glm::vec3(0, 0, 1))};
  std::array<glm::vec3, 5> joints{};
  for (std::size_t j = 0; j < 5; ++j) {
    const int parent = parents[j];
    joints[j] = parent < 0 ? rest_joints[j]
                           : joints[static_cast<std::size_t>(parent)] +
                                 rotations[static_cast<std::size_t>(parent)] *
                                     (rest_joints[j] - rest_joints[static_cast<std::size_t>(parent)]);
  }
  std::vector<glm::vec3> out(points.size());
  const SwdJob job{.chains = chains,
                   .joint_rotations = rotations,
                   .joint_positions = joints,
                   .bindings = *bindings,
                   .rest_normals = {},
                   .keep_volume = false,
                   .section_scales = {},
                   .positions = out,
                   .normals = {}};
  if (!job.Run()) return -1.0f;
  float worst = 0.0f;
  for (std::size_t i = 1; i < out.size(); ++i) {
    worst = std::max(worst, glm::length(out[i] - out[i - 1]) / kSpacing);
  }
  return worst;
}

TEST(SwdJob, SeamBandRemovesTheJumpWhereTheTrunkBecomesNearest) {
  const float plain = WorstStretchNearMidTrunkJunction(0.0f);
  const float banded = WorstStretchNearMidTrunkJunction(12.0f);
  ASSERT_GT(plain, 0.0f);
  ASSERT_GT(banded, 0.0f);
  std::printf("worst spacing stretch across the junction seam: plain %.2f, seam band %.2f\n",
              double(plain), double(banded));
  EXPECT_GT(plain, 20.0f) << "the plain rule should tear at the nearest-chain boundary";
  EXPECT_LT(banded, 4.0f);
}

}  // namespace

namespace {

// No tears anywhere along the limb: under a strong combined pose (elbow bent 150 deg,
// forearm twisted 90, hand pronated 60 and bent) no mesh edge stretches more than 2x.
TEST(SwdJob, CombinedPoseStretchesNoEdgeMuch) {
  const ArmSetup s = MakeArmSetup(24, 2);
  const glm::quat bend = glm::angleAxis(glm::radians(150.0f), glm::vec3(0, 0, 1));
  const glm::quat forearm = bend * glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0));
  const glm::quat hand = forearm * glm::angleAxis(glm::radians(60.0f), glm::vec3(1, 0, 0)) *
                         glm::angleAxis(glm::radians(40.0f), glm::vec3(0, 1, 0));
  const auto pose = testfixture::MakePose(s.arm, {glm::quat(1, 0, 0, 0), forearm, hand},
                                          s.arm.joint_rest[0]);
  for (const bool keep_volume : {false, true}) {
    const auto out = testfixture::SkinSwd(s.chain, s.bindings, pose, keep_volume);
    ASSERT_EQ(out.size(), s.arm.mesh.positions.size());
    float worst = 0.0f;
    for (const glm::uvec3& t : s.arm.mesh.triangles) {
      for (int e = 0; e < 3; ++e) {
        const unsigned a = t[e], b = t[(e + 1) % 3];
        const float rest = glm::length(s.arm.mesh.positions[a] - s.arm.mesh.positions[b]);
        worst = std::max(worst, glm::length(out[a] - out[b]) / rest);
      }
    }
    std::printf("combined pose, keep_volume %d: worst edge stretch %.3f\n", int(keep_volume),
                double(worst));
    EXPECT_LT(worst, 2.0f) << "keep_volume " << keep_volume;
  }
}

}  // namespace
