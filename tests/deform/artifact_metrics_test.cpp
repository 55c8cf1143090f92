#include "deform/artifact_metrics.h"

#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "deform/arm_fixture.h"
#include "support/tolerances.h"

namespace {

using deform::ArtifactRing;
using deform::RingPlane;
using mocap::ErrorCode;
using testsupport::kAreaRatioTol;

constexpr double kPi = 3.14159265358979323846;

TEST(ArtifactMetrics, ProjectedAreaOfAShuffledTiltedPolygon) {
  const glm::dvec3 n = glm::normalize(glm::dvec3(1, 2, -1));
  const glm::dvec3 e1 = glm::normalize(glm::cross(n, glm::dvec3(0, 0, 1)));
  const glm::dvec3 e2 = glm::cross(n, e1);
  const glm::dvec3 centre(3, -1, 2);
  std::vector<glm::vec3> points;
  constexpr int kSides = 9;
  const std::vector<std::uint32_t> order = {4, 0, 7, 2, 8, 1, 5, 3, 6};
  for (int i = 0; i < kSides; ++i) {
    const double angle = 2 * kPi * order[static_cast<std::size_t>(i)] / kSides;
    // Off the plane along n: the projection must drop that component.
    points.push_back(glm::vec3(centre + 2.0 * (std::cos(angle) * e1 + std::sin(angle) * e2) +
                               (0.3 * i) * n));
  }
  std::vector<std::uint32_t> ring(kSides);
  std::iota(ring.begin(), ring.end(), 0u);
  const double expected = 0.5 * kSides * 4.0 * std::sin(2 * kPi / kSides);
  EXPECT_NEAR(deform::ProjectedRingArea(points, ring, {centre, 5.0 * n}), expected, 1e-5);
  EXPECT_EQ(deform::ProjectedRingArea(points, std::span(ring).first(2), {centre, n}), 0.0);
}

TEST(ArtifactMetrics, RejectsBadRings) {
  const std::vector<glm::vec3> rest = {glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
  const std::vector<glm::vec3> shorter = {glm::vec3(0), glm::vec3(1, 0, 0)};
  ArtifactRing ring{.vertices = {0, 1, 2}, .rest_plane = {}, .plane = {}};
  EXPECT_TRUE(deform::RingAreaRatio(rest, rest, ring).ok());
  EXPECT_EQ(deform::RingAreaRatio(rest, shorter, ring).error().code, ErrorCode::kInvalidArgument);
  ArtifactRing small = ring;
  small.vertices.pop_back();
  EXPECT_FALSE(deform::RingAreaRatio(rest, rest, small).ok());
  ArtifactRing past = ring;
  past.vertices[1] = 7;
  EXPECT_FALSE(deform::RingAreaRatio(rest, rest, past).ok());
  ArtifactRing edge_on = ring;
  edge_on.rest_plane.normal = glm::dvec3(1, 0, 0);  // the triangle projects to a segment
  EXPECT_FALSE(deform::RingAreaRatio(rest, rest, edge_on).ok());
  EXPECT_FALSE(deform::CandyWrapperFigure(rest, rest, {}).ok());
}

TEST(ArtifactMetrics, RingSelectorsFindTheElbowRing) {
  const auto arm = testfixture::MakeArm(24, 5);
  const auto& elbow = arm.rings[static_cast<std::size_t>(arm.elbow_ring)];
  const RingPlane plane{glm::dvec3(testfixture::kElbowX, 0, 0), glm::dvec3(1, 0, 0)};
  EXPECT_EQ(deform::RingNearPlane(arm.mesh.positions, plane, 0.1), elbow);
  const auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(arm));
  ASSERT_TRUE(chain.ok());
  const std::vector<deform::SweepChain> chains = {*chain};
  const auto bindings = deform::BindToSweeps(chains, {}, arm.mesh.positions);
  ASSERT_TRUE(bindings.ok());
  EXPECT_EQ(deform::RingNearParameter(*bindings, 0, static_cast<float>(chain->joint_parameter(1))),
            elbow);
}

// The reference SSD at the elbow ring (weights 1/2, 1/2) applies (I + R)/2, which keeps the
// ring in the bisector plane and shrinks it by cos(theta/2) across the bend; a twist by phi
// shrinks it by cos(phi/2) both ways, so the area ratio is cos^2(phi/2).
TEST(ArtifactMetrics, ReferenceSsdMatchesTheClosedForms) {
  const auto arm = testfixture::MakeArm(24, 5);
  const auto& elbow = arm.rings[static_cast<std::size_t>(arm.elbow_ring)];
  for (const float deg : {90.0f, 120.0f, 150.0f}) {
    const auto pose = testfixture::BendPose(arm, deg);
    const auto ratio = deform::CollapseFigure(arm.mesh.positions, testfixture::SkinSsd(arm, pose),
                                              testfixture::ElbowRing(arm, pose, elbow));
    ASSERT_TRUE(ratio.ok());
    EXPECT_NEAR(*ratio, std::cos(0.5 * glm::radians(double(deg))), kAreaRatioTol) << deg;
  }
  for (const float deg : {90.0f, 180.0f}) {
    const auto pose = testfixture::ElbowTwistPose(arm, deg);
    const auto ratio = deform::CandyWrapperFigure(
        arm.mesh.positions, testfixture::SkinSsd(arm, pose), testfixture::ForearmRings(arm, pose));
    ASSERT_TRUE(ratio.ok());
    const double c = std::cos(0.5 * glm::radians(double(deg)));
    EXPECT_NEAR(*ratio, c * c, kAreaRatioTol) << deg;
  }
}

struct Figures {
  double ssd = 0, dqs = 0, swd = 0;
};

TEST(ArtifactMetrics, SsdCollapsesWhileDqsAndSwdKeepTheirArea) {
  const auto arm = testfixture::MakeArm(24, 5);
  const auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(arm));
  ASSERT_TRUE(chain.ok());
  const std::vector<deform::SweepChain> chains = {*chain};
  const auto bindings = deform::BindToSweeps(chains, {}, arm.mesh.positions);
  ASSERT_TRUE(bindings.ok());
  const auto swd_ring =
      deform::RingNearParameter(*bindings, 0, static_cast<float>(chain->joint_parameter(1)));
  ASSERT_EQ(swd_ring.size(), 24u);
  const auto& elbow = arm.rings[static_cast<std::size_t>(arm.elbow_ring)];
  std::printf("%-28s %8s %8s %8s\n", "figure (area / rest area)", "SSD", "DQS", "SWD");
  for (const float deg : {90.0f, 120.0f, 150.0f}) {
    const auto pose = testfixture::BendPose(arm, deg);
    const auto swd = testfixture::SkinSwd(*chain, *bindings, pose);
    ASSERT_FALSE(swd.empty());
    Figures f;
    f.ssd = *deform::CollapseFigure(arm.mesh.positions, testfixture::SkinSsd(arm, pose),
                                    testfixture::ElbowRing(arm, pose, elbow));
    f.dqs = *deform::CollapseFigure(arm.mesh.positions, testfixture::SkinDqs(arm, pose),
                                    testfixture::ElbowRing(arm, pose, elbow));
    f.swd = *deform::CollapseFigure(arm.mesh.positions, swd,
                                    testfixture::ElbowRing(arm, pose, swd_ring));
    std::printf("collapse, elbow bend %3.0f     %8.3f %8.3f %8.3f\n", double(deg), f.ssd, f.dqs,
                f.swd);
    EXPECT_LT(f.ssd, 0.75) << "SSD should collapse at " << deg;
    EXPECT_NEAR(f.dqs, 1.0, 0.1) << deg;
    EXPECT_NEAR(f.swd, 1.0, 0.05) << deg;
    EXPECT_GE(f.swd, f.ssd);
  }
  for (const float deg : {90.0f, 180.0f}) {
    const auto pose = testfixture::ElbowTwistPose(arm, deg);
    const auto rings = testfixture::ForearmRings(arm, pose);
    const auto swd = testfixture::SkinSwd(*chain, *bindings, pose);
    ASSERT_FALSE(swd.empty());
    Figures f;
    f.ssd = *deform::CandyWrapperFigure(arm.mesh.positions, testfixture::SkinSsd(arm, pose), rings);
    f.dqs = *deform::CandyWrapperFigure(arm.mesh.positions, testfixture::SkinDqs(arm, pose), rings);
    f.swd = *deform::CandyWrapperFigure(arm.mesh.positions, swd, rings);
    std::printf("candy-wrapper, twist %3.0f     %8.3f %8.3f %8.3f\n", double(deg), f.ssd, f.dqs,
                f.swd);
    EXPECT_LT(f.ssd, 0.75) << "SSD should candy-wrap at " << deg;
    EXPECT_NEAR(f.dqs, 1.0, 0.1) << deg;
    EXPECT_NEAR(f.swd, 1.0, 0.05) << deg;
    EXPECT_GE(f.swd, f.ssd);
  }
}

// Under a 180 degree twist, SWD turns cross-sections gradually: no ring along the forearm
// falls below 0.8 of its rest area, whether the elbow (downstream) or the wrist (upstream)
// carries the twist.
TEST(ArtifactMetrics, SwdSpreadsA180DegreeTwistAlongTheForearm) {
  const auto arm = testfixture::MakeArm(24, 5);
  const auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(arm));
  ASSERT_TRUE(chain.ok());
  const std::vector<deform::SweepChain> chains = {*chain};
  const auto bindings = deform::BindToSweeps(chains, {}, arm.mesh.positions);
  ASSERT_TRUE(bindings.ok());
  for (const auto& pose :
       {testfixture::ElbowTwistPose(arm, 180.0f), testfixture::WristTwistPose(arm, 180.0f)}) {
    const auto swd = testfixture::SkinSwd(*chain, *bindings, pose);
    const auto rings = testfixture::ForearmRings(arm, pose);
    for (const auto& ring : rings) {
      const auto ratio = deform::RingAreaRatio(arm.mesh.positions, swd, ring);
      ASSERT_TRUE(ratio.ok());
      EXPECT_GE(*ratio, 0.8) << "ring at x " << ring.rest_plane.point.x;
    }
    // The ring halfway along the forearm has turned by about half the twist (not 0 or 180).
    const std::size_t mid = rings.size() / 2 + 2;
    const std::uint32_t v = rings[mid].vertices[0];
    const glm::vec3 radial_rest = arm.mesh.positions[v] - glm::vec3(rings[mid].rest_plane.point);
    const glm::vec3 radial = swd[v] - glm::vec3(rings[mid].plane.point);
    const double angle = std::acos(glm::dot(glm::normalize(radial_rest), glm::normalize(radial)));
    EXPECT_GT(angle, glm::radians(30.0));
    EXPECT_LT(angle, glm::radians(150.0));
  }
}

}  // namespace
