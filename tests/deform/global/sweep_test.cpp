#include "deform/global/sweep.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "support/arm_fixture.h"
#include "support/tolerances.h"

namespace {

using base::ErrorCode;
using deform::BasicSweepPose;
using deform::SweepChain;
using deform::SweepChainSpec;
using testsupport::kCurveDirectionTol;
using testsupport::kCurveStep;
using testsupport::kDoubleTol;
using testsupport::kFloatTol;

SweepChainSpec StraightSpec(std::vector<float> lengths, float half_width) {
  SweepChainSpec spec;
  float x = 0.0f;
  spec.rest_points.push_back(glm::vec3(0.0f));
  for (std::size_t k = 0; k < lengths.size(); ++k) {
    spec.joints.push_back(static_cast<int>(k));
    x += lengths[k];
    spec.rest_points.push_back(glm::vec3(x, 0, 0));
  }
  spec.half_widths.assign(lengths.size() + 1, half_width);
  return spec;
}

// A pose in double from per-bone rotations, J_0 at the rest root.
BasicSweepPose<double> PoseOf(const SweepChain& chain, const std::vector<glm::quat>& rotations) {
  std::vector<glm::vec3> positions(rotations.size(), glm::vec3(0.0f));
  positions[0] = glm::vec3(chain.rest_pose().points[0]);
  BasicSweepPose<double> pose;
  deform::PoseSweepChain<double>(chain, rotations, positions, false, &pose);
  return pose;
}

TEST(SweepChain, RejectsBadSpecs) {
  SweepChainSpec none;
  EXPECT_EQ(deform::BuildSweepChain(none).error().code, ErrorCode::kLimitExceeded);
  SweepChainSpec too_long = StraightSpec(std::vector<float>(deform::kMaxSweepBones + 1, 10.0f), 2);
  EXPECT_EQ(deform::BuildSweepChain(too_long).error().code, ErrorCode::kLimitExceeded);
  SweepChainSpec missing_point = StraightSpec({10, 10}, 2);
  missing_point.rest_points.pop_back();
  EXPECT_EQ(deform::BuildSweepChain(missing_point).error().code, ErrorCode::kInvalidArgument);
  SweepChainSpec zero_bone = StraightSpec({10, 10}, 2);
  zero_bone.rest_points[2] = zero_bone.rest_points[1];
  EXPECT_EQ(deform::BuildSweepChain(zero_bone).error().code, ErrorCode::kInvalidArgument);
  SweepChainSpec wide = StraightSpec({10, 10}, 10.5f);
  EXPECT_EQ(deform::BuildSweepChain(wide).error().code, ErrorCode::kInvalidArgument);
  // Joints 1 and 2 both claim 6 of the 10 units of the middle bone.
  SweepChainSpec overlapping = StraightSpec({10, 10, 10}, 6.0f);
  const auto overlap = deform::BuildSweepChain(overlapping);
  ASSERT_FALSE(overlap.ok());
  EXPECT_NE(overlap.error().message.find("bone 1"), std::string::npos) << overlap.error().message;
  SweepChainSpec nan_point = StraightSpec({10, 10}, 2);
  nan_point.rest_points[1].y = std::nanf("");
  EXPECT_EQ(deform::BuildSweepChain(nan_point).error().code, ErrorCode::kInvalidArgument);
}

TEST(SweepChain, DefaultHalfWidthFollowsTheClampedRule) {
  EXPECT_DOUBLE_EQ(deform::DefaultHalfWidth(2.0, 2.62, 30.0, 25.0), 0.75 * 2.0 * 2.62);
  EXPECT_DOUBLE_EQ(deform::DefaultHalfWidth(0.1, 2.62, 30.0, 25.0), 2.5);    // 0.1 Lmin
  EXPECT_DOUBLE_EQ(deform::DefaultHalfWidth(50.0, 2.62, 30.0, 25.0), 11.25); // 0.45 Lmin
}

TEST(SweepChain, RegionsFollowHalfWidths) {
  const auto chain = deform::BuildSweepChain(StraightSpec({30, 25, 10}, 4.0f));
  ASSERT_TRUE(chain.ok()) << chain.error().ToString();
  EXPECT_DOUBLE_EQ(chain->region_end(0), 0.0);
  EXPECT_DOUBLE_EQ(chain->region_start(1), 1.0 - 4.0 / 30.0);
  EXPECT_DOUBLE_EQ(chain->region_end(1), 1.0 + 4.0 / 25.0);
  EXPECT_DOUBLE_EQ(chain->region_start(2), 2.0 - 4.0 / 25.0);
  EXPECT_DOUBLE_EQ(chain->region_end(2), 2.0 + 4.0 / 10.0);
  EXPECT_DOUBLE_EQ(chain->region_start(3), 3.0);
  EXPECT_NEAR(chain->rest_region_length(1), 8.0, kDoubleTol);
}

TEST(SweepCentre, CollinearEqualBonesGiveAStraightUniformSpeedCurve) {
  const auto chain = deform::BuildSweepChain(StraightSpec({20, 20, 20}, 7.0f));
  ASSERT_TRUE(chain.ok());
  const auto& rest = chain->rest_pose();
  for (int i = 0; i <= 300; ++i) {
    const double u = 3.0 * i / 300.0;
    glm::dvec3 d;
    const glm::dvec3 c = deform::SweepCentre(*chain, rest, u, &d);
    EXPECT_NEAR(c.x, 20.0 * u, kDoubleTol * 100) << "u " << u;
    EXPECT_NEAR(glm::length(glm::dvec3(0, c.y, c.z)), 0.0, kDoubleTol);
    EXPECT_NEAR(d.x, 20.0, kDoubleTol * 100) << "u " << u;
  }
}

TEST(SweepCentre, CollinearUnequalBonesHaveUniformSpeedInsideEachRegion) {
  const auto chain = deform::BuildSweepChain(StraightSpec({30, 10}, 4.0f));
  ASSERT_TRUE(chain.ok());
  const auto& rest = chain->rest_pose();
  const double start = chain->region_start(1), end = chain->region_end(1);
  const double speed = 8.0 / (end - start);  // region length l over its width in u
  for (int i = 0; i <= 50; ++i) {
    const double u = start + (end - start) * i / 50.0;
    glm::dvec3 d;
    const glm::dvec3 c = deform::SweepCentre(*chain, rest, u, &d);
    EXPECT_NEAR(d.x, speed, kDoubleTol * 100);
    EXPECT_NEAR(c.x, 26.0 + speed * (u - start), kDoubleTol * 100);
    EXPECT_NEAR(c.y, 0.0, kDoubleTol);
  }
}

TEST(SweepCentre, PositionTangentAndFrameAreContinuousAtRegionEnds) {
  const auto chain = deform::BuildSweepChain(StraightSpec({30, 25, 10}, 4.0f));
  ASSERT_TRUE(chain.ok());
  const glm::quat bend = glm::angleAxis(glm::radians(120.0f), glm::vec3(0, 0, 1));
  const glm::quat twist = glm::angleAxis(glm::radians(70.0f), glm::vec3(1, 0, 0));
  const glm::quat hand = bend * twist * glm::angleAxis(glm::radians(-40.0f), glm::vec3(0, 1, 0));
  const auto pose = PoseOf(*chain, {glm::angleAxis(0.3f, glm::vec3(0, 1, 0)), bend * twist, hand});
  for (int k = 1; k <= 2; ++k) {
    for (const double u : {chain->region_start(k), chain->region_end(k)}) {
      glm::dvec3 d_lo, d_hi;
      const glm::dvec3 lo = deform::SweepCentre(*chain, pose, u - kCurveStep, &d_lo);
      const glm::dvec3 hi = deform::SweepCentre(*chain, pose, u + kCurveStep, &d_hi);
      const double speed = std::max(glm::length(d_lo), glm::length(d_hi));
      EXPECT_LT(glm::length(hi - lo), 2.0 * kCurveStep * speed * 1.01) << "joint " << k;
      const double cosine = glm::dot(glm::normalize(d_lo), glm::normalize(d_hi));
      EXPECT_LT(std::acos(std::min(1.0, cosine)), kCurveDirectionTol) << "joint " << k;
      const glm::dquat f_lo = deform::SweepFrame(*chain, pose, u - kCurveStep);
      const glm::dquat f_hi = deform::SweepFrame(*chain, pose, u + kCurveStep);
      EXPECT_GT(std::abs(glm::dot(f_lo, f_hi)), 1.0 - kCurveDirectionTol) << "joint " << k;
    }
  }
  // The region's ends sit on the bones: c(ub_k) = J_k + hp a_k.
  const glm::dvec3 end1 = deform::SweepCentre<double>(*chain, pose, chain->region_end(1), nullptr);
  const glm::dvec3 expected = pose.points[1] + 4.0 * pose.axes[1];
  EXPECT_NEAR(glm::length(end1 - expected), 0.0, kDoubleTol * 100);
}

TEST(SweepFrame, ElbowTwistIsSpreadAlongTheForearm) {
  const auto chain = deform::BuildSweepChain(StraightSpec({30, 25, 10}, 4.0f));
  ASSERT_TRUE(chain.ok());
  const double angle = glm::radians(120.0);
  const glm::quat twist = glm::angleAxis(static_cast<float>(angle), glm::vec3(1, 0, 0));
  const auto pose = PoseOf(*chain, {glm::quat(1, 0, 0, 0), twist, twist});
  const glm::dvec3 axis(1, 0, 0);
  // Region 1 is the pure swing (none here); the forearm turns from 0 to the full twist.
  const double start = chain->region_end(1), end = chain->region_start(2);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, start), axis), 0.0, 1e-6);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, 0.5 * (start + end)), axis),
              0.5 * angle, 1e-6);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, end), axis), angle, 1e-6);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, 2.8), axis), angle, 1e-6);
}

TEST(SweepFrame, UpstreamWristTwistIsSpreadBackAlongTheForearm) {
  SweepChainSpec spec = StraightSpec({30, 25, 10}, 4.0f);
  spec.twist_spread = {deform::TwistSpread::kDownstream, deform::TwistSpread::kDownstream,
                       deform::TwistSpread::kUpstream, deform::TwistSpread::kDownstream};
  const auto chain = deform::BuildSweepChain(spec);
  ASSERT_TRUE(chain.ok());
  const double angle = glm::radians(-90.0);
  const glm::quat twist = glm::angleAxis(static_cast<float>(angle), glm::vec3(1, 0, 0));
  const auto pose = PoseOf(*chain, {glm::quat(1, 0, 0, 0), glm::quat(1, 0, 0, 0), twist});
  const glm::dvec3 axis(1, 0, 0);
  const double start = chain->region_end(1), end = chain->region_start(2);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, start), axis), 0.0, 1e-6);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, 0.5 * (start + end)), axis),
              0.5 * angle, 1e-6);
  EXPECT_NEAR(deform::TwistAngle(deform::SweepFrame(*chain, pose, 2.0), axis), angle, 1e-6);
}

TEST(SweepQuaternions, TwistAndSlerpHelpersMatchClosedForms) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1, 2, 2));
  const glm::dquat twist = deform::TwistQuat(axis, 0.7);
  const glm::dquat swing = glm::angleAxis(0.5, glm::normalize(glm::cross(axis, glm::dvec3(0, 0, 1))));
  EXPECT_NEAR(deform::TwistAngle(swing * twist, axis), 0.7, kDoubleTol);
  EXPECT_NEAR(deform::TwistAngle(twist * swing, axis), 0.7, kDoubleTol);
  EXPECT_NEAR(deform::TwistAngle(-(swing * twist), axis), 0.7, kDoubleTol);
  const glm::dquat q1 = glm::angleAxis(1.2, axis);
  const glm::dquat half = deform::SlerpShort(glm::dquat(1, 0, 0, 0), -q1, 0.5);  // short arc
  EXPECT_NEAR(std::abs(glm::dot(half, glm::angleAxis(0.6, axis))), 1.0, kDoubleTol);
  EXPECT_NEAR(deform::TwistAngle(half, axis), 0.6, kDoubleTol);
}

TEST(SweepBinding, FindsTheOrthogonalFootAndClampsBeyondTheEnds) {
  const auto chain = deform::BuildSweepChain(StraightSpec({30, 25, 10}, 4.0f));
  ASSERT_TRUE(chain.ok());
  const deform::SweepBinding at_elbow = deform::BindToSweep(*chain, 0, glm::dvec3(30, 3, 1));
  EXPECT_NEAR(at_elbow.u, chain->joint_parameter(1), kFloatTol);
  EXPECT_NEAR(chain->joint_parameter(1),
              0.5 * (chain->region_start(1) + chain->region_end(1)), kDoubleTol);
  EXPECT_NEAR(glm::length(at_elbow.offset - glm::vec3(0, 3, 1)), 0.0f, kFloatTol);
  const deform::SweepBinding mid = deform::BindToSweep(*chain, 0, glm::dvec3(42.5, -2, 0));
  EXPECT_NEAR(mid.u, 1.5f, kFloatTol);
  EXPECT_EQ(deform::BindToSweep(*chain, 0, glm::dvec3(-3, 1, 0)).u, 0.0f);
  EXPECT_EQ(deform::BindToSweep(*chain, 0, glm::dvec3(70, 1, 0)).u, 3.0f);
}

TEST(SweepBinding, OffsetsAreOrthogonalToABentRestCurve) {
  SweepChainSpec spec;
  spec.joints = {0, 1};
  spec.rest_points = {glm::vec3(0), glm::vec3(20, 0, 0), glm::vec3(20, 20, 0)};  // L-shaped rest
  spec.half_widths = {0, 6, 0};
  const auto chain = deform::BuildSweepChain(spec);
  ASSERT_TRUE(chain.ok());
  for (const glm::dvec3 p : {glm::dvec3(17, 2, 1), glm::dvec3(21, 1, -1), glm::dvec3(16, 4, 0.5)}) {
    const deform::SweepBinding b = deform::BindToSweep(*chain, 0, p);
    glm::dvec3 tangent;
    const glm::dvec3 c = deform::SweepCentre(*chain, chain->rest_pose(), double(b.u), &tangent);
    EXPECT_GT(b.u, chain->region_start(1));
    EXPECT_LT(b.u, chain->region_end(1));
    EXPECT_NEAR(glm::dot(p - c, glm::normalize(tangent)), 0.0, 1e-5);
    EXPECT_NEAR(glm::length(glm::dvec3(b.offset) - (p - c)), 0.0, 1e-5);
  }
}

TEST(SweepBinding, PointBeyondTheEndBindsToTheEndNotToAFarRoot) {
  // An L: bone 0 along +x, bone 1 along +y. p lies past the end of bone 1, but also in
  // the normal plane of bone 0 at x = 4 (a root of g, 11 away); the end is 6.08 away.
  SweepChainSpec spec;
  spec.joints = {0, 1};
  spec.rest_points = {glm::vec3(0, 0, 0), glm::vec3(10, 0, 0), glm::vec3(10, 10, 0)};
  spec.half_widths = {0.0f, 2.0f, 0.0f};
  const auto chain = deform::BuildSweepChain(spec);
  ASSERT_TRUE(chain.ok()) << chain.error().ToString();
  const glm::dvec3 p(4, 11, 0);
  const deform::SweepBinding b = deform::BindToSweep(*chain, 0, p);
  EXPECT_EQ(b.u, 2.0f);
  EXPECT_NEAR(glm::length(glm::dvec3(b.offset) - (p - glm::dvec3(10, 10, 0))), 0.0, kFloatTol);
}

TEST(SweepBinding, ChainsNotOkAsPrimaryOnlyBlendThroughJunctions) {
  const auto arm = testfixture::MakeArm(8, 1);
  const auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(arm));
  ASSERT_TRUE(chain.ok());
  const std::vector<SweepChain> chains = {*chain, *chain};
  const std::vector<std::uint8_t> second_only = {0, 1};
  const auto b = deform::BindToSweeps(chains, {}, arm.mesh.positions, second_only);
  ASSERT_TRUE(b.ok()) << b.error().ToString();
  for (const deform::SweepVertexBinding& v : *b) EXPECT_EQ(v.primary.chain, 1);
  const std::vector<std::uint8_t> none = {0, 0}, short_list = {1};
  EXPECT_EQ(deform::BindToSweeps(chains, {}, arm.mesh.positions, none).error().code,
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(deform::BindToSweeps(chains, {}, arm.mesh.positions, short_list).error().code,
            ErrorCode::kInvalidArgument);
}

TEST(SweepBinding, RejectsBadJunctionsAndPoints) {
  const auto arm = testfixture::MakeArm(8, 1);
  const auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(arm));
  ASSERT_TRUE(chain.ok());
  const std::vector<SweepChain> chains = {*chain, *chain};
  const std::vector<glm::vec3> points = {glm::vec3(1, 2, 3)};
  const std::vector<deform::SweepJunction> self = {{.branch = 0, .trunk = 0}};
  EXPECT_FALSE(deform::BindToSweeps(chains, self, points).ok());
  const std::vector<deform::SweepJunction> reversed = {
      {.branch = 0, .trunk = 1, .u_start = 1, .u_end = 0.5f}};
  EXPECT_FALSE(deform::BindToSweeps(chains, reversed, points).ok());
  const std::vector<glm::vec3> bad = {glm::vec3(std::nanf(""), 0, 0)};
  EXPECT_FALSE(deform::BindToSweeps(chains, {}, bad).ok());
  EXPECT_FALSE(deform::BindToSweeps({}, {}, points).ok());
}

}  // namespace
