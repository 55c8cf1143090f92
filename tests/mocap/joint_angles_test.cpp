#include "mocap/joint_angles.h"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/pose.h"
#include "support/tolerances.h"

namespace {

using mocap::ChannelType;
constexpr ChannelType kX = ChannelType::kXRotation;
constexpr ChannelType kY = ChannelType::kYRotation;
constexpr ChannelType kZ = ChannelType::kZRotation;

const std::array<std::array<ChannelType, 3>, 6> kOrders = {
    {{kX, kY, kZ}, {kX, kZ, kY}, {kY, kX, kZ}, {kY, kZ, kX}, {kZ, kX, kY}, {kZ, kY, kX}}};

// Angle between two rotations (radians), sign of the quaternion ignored.
float RotationDistance(const glm::quat& a, const glm::quat& b) {
  const float d = std::min(1.0f, std::abs(glm::dot(glm::normalize(a), glm::normalize(b))));
  return 2.0f * std::acos(d);
}

TEST(QuatToEuler, RoundTripAllOrders) {
  const float samples[][3] = {{10, 20, 30},    {-170, 80, 45}, {179, -89, -179}, {0, 0, 0},
                              {-45, -30, 120}, {90, 45, -90},  {33, 60, 150}};
  for (const auto& order : kOrders) {
    for (const auto& angles : samples) {
      const glm::quat q = mocap::EulerToQuat(order.data(), angles, 3);
      float out[3];
      mocap::QuatToEuler(q, order.data(), 3, out);
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(out[i], angles[i], testsupport::kEulerRoundTripTolDeg);
      EXPECT_LT(RotationDistance(mocap::EulerToQuat(order.data(), out, 3), q),
                testsupport::kRotationTolRad);
    }
  }
}

TEST(QuatToEuler, NearGimbalLockGivesTheSameRotation) {
  // At |middle| = 90 only a combination of the outer angles is defined, so the
  // angles are not compared: the rotation they rebuild is.
  const float middles[] = {90.0f, -90.0f, 89.999f, -89.99f, 89.9f};
  for (const auto& order : kOrders) {
    for (float middle : middles) {
      const float angles[3] = {37.0f, middle, -21.0f};
      const glm::quat q = mocap::EulerToQuat(order.data(), angles, 3);
      float out[3];
      mocap::QuatToEuler(q, order.data(), 3, out);
      EXPECT_LT(RotationDistance(mocap::EulerToQuat(order.data(), out, 3), q),
                testsupport::kGimbalRotationTolRad)
          << "middle " << middle;
      EXPECT_NEAR(std::abs(out[1]), std::abs(middle), testsupport::kGimbalAngleTolDeg);
    }
  }
}

TEST(QuatToEuler, TwoAndOneAxisJoints) {
  for (const auto& order : kOrders) {
    const float two[2] = {-70.0f, 125.0f};
    float out[3];
    mocap::QuatToEuler(mocap::EulerToQuat(order.data(), two, 2), order.data(), 2, out);
    EXPECT_NEAR(out[0], two[0], testsupport::kEulerRoundTripTolDeg);
    EXPECT_NEAR(out[1], two[1], testsupport::kEulerRoundTripTolDeg);
    const float one[1] = {-163.0f};
    mocap::QuatToEuler(mocap::EulerToQuat(order.data(), one, 1), order.data(), 1, out);
    EXPECT_NEAR(out[0], one[0], testsupport::kEulerRoundTripTolDeg);
  }
}

TEST(QuatToEulerNear, AvoidsJumpsAcross180) {
  const ChannelType* zxy = kOrders[4].data();
  // A joint spinning about Z past 180 degrees: the unconstrained extraction wraps
  // to -179, the near one continues to 181.
  float previous[3] = {179.0f, 10.0f, -5.0f};
  const float next[3] = {181.0f, 10.5f, -5.5f};
  float out[3];
  mocap::QuatToEulerNear(mocap::EulerToQuat(zxy, next, 3), zxy, 3, previous, out);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(out[i], next[i], testsupport::kEulerRoundTripTolDeg);
  // The alternative solution (x+180, 180-y, z+180) is picked when it is nearer.
  const float past_pole[3] = {20.0f, 95.0f, 30.0f};
  previous[0] = 20.0f;
  previous[1] = 94.0f;
  previous[2] = 30.0f;
  mocap::QuatToEulerNear(mocap::EulerToQuat(zxy, past_pole, 3), zxy, 3, previous, out);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(out[i], past_pole[i], testsupport::kEulerRoundTripTolDeg);
}

// A root with position channels only, a YXZ joint with a rest rotation, and a
// two-axis XZ joint.
mocap::Skeleton MixedOrderSkeleton() {
  mocap::Skeleton s;
  s.names = {"root", "yxz", "xz"};
  s.parents = {mocap::kNoParent, 0, 1};
  s.rest_translations.assign(3, glm::vec3(0, 10, 0));
  s.rest_rotations = {glm::quat(1, 0, 0, 0),
                      glm::angleAxis(0.5f, glm::normalize(glm::vec3(1, 1, 0))),
                      glm::quat(1, 0, 0, 0)};
  s.rest_scales.assign(3, glm::vec3(1));
  s.channels.resize(3);
  s.channels[0] = {
      0, 3, {ChannelType::kXPosition, ChannelType::kYPosition, ChannelType::kZPosition}};
  s.channels[1] = {3, 3, {kY, kX, kZ}};
  s.channels[2] = {6, 2, {kX, kZ}};
  s.num_channels = 8;
  return s;
}

TEST(JointEulerAngles, GivesBackTheChannelValuesOfAPose) {
  const mocap::Skeleton s = MixedOrderSkeleton();
  const std::vector<float> frame = {1, 2, 3, 40, -25, 130, -60, 75};
  std::vector<mocap::JointTransform> locals(3);
  ASSERT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
  float angles[3];
  EXPECT_EQ(mocap::JointEulerAngles(s, 0, locals[0].rotation, angles), 0);
  ASSERT_EQ(mocap::JointEulerAngles(s, 1, locals[1].rotation, angles), 3);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(angles[i], frame[3 + i], testsupport::kEulerRoundTripTolDeg);
  ASSERT_EQ(mocap::JointEulerAngles(s, 2, locals[2].rotation, angles), 2);
  EXPECT_NEAR(angles[0], -60.0f, testsupport::kEulerRoundTripTolDeg);
  EXPECT_NEAR(angles[1], 75.0f, testsupport::kEulerRoundTripTolDeg);
  const float reference[2] = {300.0f, 75.0f};  // continue a joint that has turned past 180
  ASSERT_EQ(mocap::JointEulerAngles(s, 2, locals[2].rotation, angles, reference), 2);
  EXPECT_NEAR(angles[0], 300.0f, testsupport::kEulerRoundTripTolDeg);
}

TEST(JointRotationFromAngles, ComposesInTheJointsChannelOrder) {
  const mocap::Skeleton s = MixedOrderSkeleton();
  // Where the joint has the channels, the rotation LocalPoseJob builds.
  const std::vector<float> frame = {1, 2, 3, 40, -25, 130, -60, 75};
  std::vector<mocap::JointTransform> locals(3);
  ASSERT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
  EXPECT_LT(
      RotationDistance(mocap::JointRotationFromAngles(s, 1, {-25, 40, 130}), locals[1].rotation),
      1e-6f);
  EXPECT_LT(
      RotationDistance(mocap::JointRotationFromAngles(s, 2, {-60, 0, 75}), locals[2].rotation),
      1e-6f);
  // A missing axis follows the joint's own ones (XZ, then Y); with none, Z X Y.
  const auto r = [](float deg, glm::vec3 axis) { return glm::angleAxis(glm::radians(deg), axis); };
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  EXPECT_LT(RotationDistance(mocap::JointRotationFromAngles(s, 2, {-60, 35, 75}),
                             r(-60, x) * r(75, z) * r(35, y)),
            1e-6f);
  EXPECT_LT(RotationDistance(mocap::JointRotationFromAngles(s, 0, {10, 20, 30}),
                             r(30, z) * r(10, x) * r(20, y)),
            1e-6f);
  // And JointEulerAngles reads the angles back in channel order (Y, X, Z).
  float angles[3];
  ASSERT_EQ(
      mocap::JointEulerAngles(s, 1, mocap::JointRotationFromAngles(s, 1, {15, -70, 100}), angles),
      3);
  EXPECT_NEAR(angles[0], -70.0f, testsupport::kEulerRoundTripTolDeg);
  EXPECT_NEAR(angles[1], 15.0f, testsupport::kEulerRoundTripTolDeg);
  EXPECT_NEAR(angles[2], 100.0f, testsupport::kEulerRoundTripTolDeg);
}

TEST(RotationVector, MatchesAxisAngleAndRoundTrips) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1, -2, 0.5f));
  for (float angle : {0.0f, 1e-7f, 0.3f, 2.0f, 3.1f}) {
    const glm::quat q = glm::angleAxis(angle, axis);
    const glm::vec3 r = mocap::QuatToRotationVector(q);
    EXPECT_NEAR(glm::length(r), angle, testsupport::kRotationTolRad);
    if (angle > 0.1f) {
      EXPECT_NEAR(glm::dot(glm::normalize(r), axis), 1.0f, testsupport::kFloatTol);
    }
    // -q is the same rotation: same vector (w >= 0 first).
    const glm::vec3 r_neg = mocap::QuatToRotationVector(-q);
    EXPECT_NEAR(glm::length(r - r_neg), 0.0f, testsupport::kRotationTolRad);
    EXPECT_LT(RotationDistance(mocap::RotationVectorToQuat(r), q), testsupport::kRotationTolRad);
  }
  // A rotation of more than pi comes back as the shorter one the other way.
  const glm::vec3 r = mocap::QuatToRotationVector(glm::angleAxis(4.0f, axis));
  EXPECT_NEAR(glm::length(r), 2.0f * std::numbers::pi_v<float> - 4.0f,
              testsupport::kRotationTolRad);
  EXPECT_LT(glm::dot(r, axis), 0.0f);
}

TEST(RotationVector, FeatureIsRelativeToRest) {
  const glm::quat rest = glm::angleAxis(0.7f, glm::vec3(0, 1, 0));
  const glm::quat delta = glm::angleAxis(0.4f, glm::vec3(1, 0, 0));
  const glm::vec3 f = mocap::RotationVectorFeature(rest, rest * delta);
  EXPECT_NEAR(f.x, 0.4f, testsupport::kRotationTolRad);
  EXPECT_NEAR(f.y, 0.0f, testsupport::kRotationTolRad);
  EXPECT_NEAR(f.z, 0.0f, testsupport::kRotationTolRad);
  EXPECT_NEAR(glm::length(mocap::RotationVectorFeature(rest, rest)), 0.0f, testsupport::kFloatTol);
}

TEST(SwingTwist, RecomposesAndSeparatesTheParts) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1, 0.2f, 0));
  glm::vec3 u;
  glm::vec3 w;
  mocap::PerpendicularBasis(axis, &u, &w);
  EXPECT_NEAR(glm::dot(glm::cross(u, w), axis), 1.0f, testsupport::kFloatTol);
  const glm::quat swing = glm::angleAxis(0.8f, glm::normalize(0.3f * u + w));
  const glm::quat twist = glm::angleAxis(-1.2f, axis);
  const mocap::SwingTwist st = mocap::DecomposeSwingTwist(swing * twist, axis);
  EXPECT_NEAR(st.twist_angle_rad, -1.2f, testsupport::kRotationTolRad);
  EXPECT_LT(RotationDistance(st.swing, swing), testsupport::kRotationTolRad);
  EXPECT_LT(RotationDistance(st.swing * st.twist, swing * twist), testsupport::kRotationTolRad);
  // The swing has no component about the axis.
  EXPECT_NEAR(glm::dot(mocap::QuatToRotationVector(st.swing), axis), 0.0f,
              testsupport::kRotationTolRad);
  // Upstream order: q = twist * swing.
  const mocap::SwingTwist ts = mocap::DecomposeTwistSwing(twist * swing, axis);
  EXPECT_NEAR(ts.twist_angle_rad, -1.2f, testsupport::kRotationTolRad);
  EXPECT_LT(RotationDistance(ts.swing, swing), testsupport::kRotationTolRad);
  // Feature: gains scale the swing and twist parts.
  const glm::vec3 f = mocap::SwingTwistFeature(swing * twist, axis, 2.0f, 0.5f);
  const glm::vec3 s = mocap::QuatToRotationVector(swing);
  EXPECT_NEAR(f.x, 2.0f * glm::dot(s, u), testsupport::kRotationTolRad);
  EXPECT_NEAR(f.y, 2.0f * glm::dot(s, w), testsupport::kRotationTolRad);
  EXPECT_NEAR(f.z, -0.6f, testsupport::kRotationTolRad);
}

TEST(SwingTwist, HalfTurnSwingHasIdentityTwist) {
  const glm::vec3 axis(0, 1, 0);
  const mocap::SwingTwist st = mocap::DecomposeSwingTwist(
      glm::angleAxis(std::numbers::pi_v<float>, glm::vec3(1, 0, 0)), axis);
  EXPECT_NEAR(st.twist_angle_rad, 0.0f, testsupport::kFloatTol);
  EXPECT_NEAR(st.twist.w, 1.0f, testsupport::kFloatTol);
}

}  // namespace
