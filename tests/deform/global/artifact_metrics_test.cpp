#include "deform/global/artifact_metrics.h"

#include <cmath>
#include <cstdio>
#include <numeric>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/arm_fixture.h"
#include "support/tolerances.h"

namespace {

using base::ErrorCode;
using deform::ArtifactRing;
using deform::RingPlane;
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
  const auto arm = testfixture::MakeArm(24, 1);
  const auto& elbow = arm.rings[static_cast<std::size_t>(arm.elbow_ring)];
  const RingPlane plane{glm::dvec3(arm.joint_rest[1]), glm::dvec3(1, 0, 0)};
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
  const auto arm = testfixture::MakeArm(24, 1);
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

TEST(ArtifactMetrics, CappedVolumeOfARestSectionIsAPolygonalFrustum) {
  const auto arm = testfixture::MakeArm(24, 2);
  const auto section = testfixture::SectionBetween(arm, 40, 80);  // x from 20 to 40
  const auto volume = deform::CappedVolume(arm.mesh.positions, section.triangles, section.caps);
  ASSERT_TRUE(volume.ok()) << volume.error().ToString();
  auto polygon_area = [](double radius) { return 12.0 * radius * radius * std::sin(2 * kPi / 24); };
  const double a1 = polygon_area(4.0 - 0.03 * 20), a2 = polygon_area(4.0 - 0.03 * 40);
  EXPECT_NEAR(*volume, 20.0 / 3.0 * (a1 + a2 + std::sqrt(a1 * a2)), 1e-3);
  // Without the caps the surface is open.
  EXPECT_FALSE(deform::CappedVolume(arm.mesh.positions, section.triangles, {}).ok());
  EXPECT_FALSE(deform::CappedVolume(arm.mesh.positions, {}, section.caps).ok());
}

struct Figures {
  double ssd = 0, dqs = 0, swd = 0, swd_volume = 0;  // swd_volume: SWD with keep_volume
};

struct LimbSetup {
  testfixture::Arm limb;
  deform::SweepChain chain;
  std::vector<deform::SweepVertexBinding> bindings;
};

LimbSetup SetUpLimb(const testfixture::LimbShape& shape) {
  LimbSetup s;
  s.limb = testfixture::MakeLimb(shape, 24, 1);
  const auto chain = deform::BuildSweepChain(testfixture::ArmChainSpec(s.limb));
  EXPECT_TRUE(chain.ok());
  s.chain = *chain;
  const std::vector<deform::SweepChain> chains = {s.chain};
  const auto bindings = deform::BindToSweeps(chains, {}, s.limb.mesh.positions);
  EXPECT_TRUE(bindings.ok());
  s.bindings = *bindings;
  return s;
}

// The table for the closing note: collapse of the joint ring and volume within 8 units
// of the joint at elbow and knee bends, candy-wrapper under forearm twists.
TEST(ArtifactMetrics, SsdCollapsesWhileDqsAndSwdKeepTheirArea) {
  std::printf("%-34s %7s %7s %7s %7s\n", "figure (deformed / rest)", "SSD", "DQS", "SWD",
              "SWD+vol");
  for (const auto& [name, shape] : {std::pair{"elbow", testfixture::kArmShape},
                                    std::pair{"knee", testfixture::kLegShape}}) {
    const LimbSetup s = SetUpLimb(shape);
    const auto& rest = s.limb.mesh.positions;
    const auto swd_ring = deform::RingNearParameter(
        s.bindings, 0, static_cast<float>(s.chain.joint_parameter(1)));
    ASSERT_EQ(swd_ring, s.limb.rings[static_cast<std::size_t>(s.limb.elbow_ring)]);
    const auto section = testfixture::SectionAroundElbow(s.limb, 8.0f);
    for (const float deg : {90.0f, 120.0f, 150.0f}) {
      const auto pose = testfixture::BendPose(s.limb, deg);
      const auto ring = testfixture::ElbowRing(s.limb, pose, swd_ring);
      const auto ssd = testfixture::SkinSsd(s.limb, pose);
      const auto dqs = testfixture::SkinDqs(s.limb, pose);
      const auto swd = testfixture::SkinSwd(s.chain, s.bindings, pose);
      const auto swd_volume = testfixture::SkinSwd(s.chain, s.bindings, pose, true);
      ASSERT_FALSE(swd.empty() || swd_volume.empty());
      Figures collapse, volume;
      collapse.ssd = *deform::CollapseFigure(rest, ssd, ring);
      collapse.dqs = *deform::CollapseFigure(rest, dqs, ring);
      collapse.swd = *deform::CollapseFigure(rest, swd, ring);
      collapse.swd_volume = *deform::CollapseFigure(rest, swd_volume, ring);
      volume.ssd = *deform::VolumeFigure(rest, ssd, section.triangles, section.caps);
      volume.dqs = *deform::VolumeFigure(rest, dqs, section.triangles, section.caps);
      volume.swd = *deform::VolumeFigure(rest, swd, section.triangles, section.caps);
      volume.swd_volume = *deform::VolumeFigure(rest, swd_volume, section.triangles, section.caps);
      std::printf("collapse, %-5s bend %3.0f deg        %7.3f %7.3f %7.3f %7.3f\n", name,
                  double(deg), collapse.ssd, collapse.dqs, collapse.swd, collapse.swd_volume);
      std::printf("volume +-8, %-5s bend %3.0f deg      %7.3f %7.3f %7.3f %7.3f\n", name,
                  double(deg), volume.ssd, volume.dqs, volume.swd, volume.swd_volume);
      EXPECT_LT(collapse.ssd, 0.75) << "SSD should collapse at " << name << " " << deg;
      EXPECT_NEAR(collapse.dqs, 1.0, 0.1) << name << " " << deg;
      EXPECT_NEAR(collapse.swd, 1.0, 0.05) << name << " " << deg;
      EXPECT_GE(collapse.swd, collapse.ssd);
      EXPECT_GE(collapse.swd_volume, 1.0);  // volume keeping widens the joint's section
      // Volume near the joint: DQS keeps more than SSD. Plain SWD loses volume because
      // the rounded centre curve is shorter than the bones' corner (Pappus: rigid sections
      // along a shorter path); volume keeping (sqrt(l0/l) scaling) wins most of it back.
      EXPECT_LT(volume.ssd, volume.dqs) << name << " " << deg;
      EXPECT_LT(std::abs(1.0 - volume.swd_volume), std::abs(1.0 - volume.swd)) << name << " " << deg;
      EXPECT_GT(volume.swd_volume, 0.8) << name << " " << deg;
    }
  }
  const LimbSetup s = SetUpLimb(testfixture::kArmShape);
  for (const float deg : {90.0f, 180.0f}) {
    const auto pose = testfixture::ElbowTwistPose(s.limb, deg);
    const auto rings = testfixture::ForearmRings(s.limb, pose);
    const auto& rest = s.limb.mesh.positions;
    const auto swd = testfixture::SkinSwd(s.chain, s.bindings, pose);
    const auto swd_volume = testfixture::SkinSwd(s.chain, s.bindings, pose, true);
    ASSERT_FALSE(swd.empty() || swd_volume.empty());
    Figures f;
    f.ssd = *deform::CandyWrapperFigure(rest, testfixture::SkinSsd(s.limb, pose), rings);
    f.dqs = *deform::CandyWrapperFigure(rest, testfixture::SkinDqs(s.limb, pose), rings);
    f.swd = *deform::CandyWrapperFigure(rest, swd, rings);
    f.swd_volume = *deform::CandyWrapperFigure(rest, swd_volume, rings);
    std::printf("candy-wrapper, forearm twist %3.0f   %7.3f %7.3f %7.3f %7.3f\n", double(deg),
                f.ssd, f.dqs, f.swd, f.swd_volume);
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
  const auto arm = testfixture::MakeArm(24, 1);
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
