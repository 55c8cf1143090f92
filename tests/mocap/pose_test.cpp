#include "mocap/pose.h"

#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "support/tolerances.h"

namespace {

using mocap::ChannelType;

mocap::Skeleton TwoJointChain() {
  mocap::Skeleton s;
  s.names = {"root", "child"};
  s.parents = {mocap::kNoParent, 0};
  s.rest_translations = {glm::vec3(1, 2, 3), glm::vec3(0, 10, 0)};
  s.rest_rotations.assign(2, glm::quat(1, 0, 0, 0));
  s.rest_scales.assign(2, glm::vec3(1));
  s.channels.resize(2);
  s.channels[0] = {0, 6, {ChannelType::kXPosition, ChannelType::kYPosition, ChannelType::kZPosition,
                          ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}};
  s.channels[1] = {6, 3, {ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}};
  s.num_channels = 9;
  return s;
}

TEST(LocalPoseJob, Validity) {
  const mocap::Skeleton s = TwoJointChain();
  std::vector<float> frame(9, 0.0f);
  std::vector<mocap::JointTransform> locals(2);
  EXPECT_EQ((mocap::LocalPoseJob{nullptr, frame, locals}).Validate().code,
            base::JobStatus::kMissingInput);
  EXPECT_EQ(
      (mocap::LocalPoseJob{&s, std::span<const float>(frame).first(8), locals}).Validate().code,
      base::JobStatus::kSizeMismatch);
  EXPECT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
}

TEST(LocalPoseJob, EulerOrderIsChannelOrder) {
  const mocap::Skeleton s = TwoJointChain();
  // Child rotates Z 90 then X 90 (intrinsic): R = Rz(90) * Rx(90).
  std::vector<float> frame = {0, 0, 0, 0, 0, 0, 90, 90, 0};
  std::vector<mocap::JointTransform> locals(2);
  ASSERT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
  const glm::vec3 y = locals[1].rotation * glm::vec3(0, 1, 0);
  // Rx(90) maps +Y to +Z, Rz(90) leaves +Z: expect (0,0,1).
  EXPECT_NEAR(y.x, 0.0f, testsupport::kFloatTol);
  EXPECT_NEAR(y.y, 0.0f, testsupport::kFloatTol);
  EXPECT_NEAR(y.z, 1.0f, testsupport::kFloatTol);
  const glm::vec3 x = locals[1].rotation * glm::vec3(1, 0, 0);
  // Rx leaves +X, Rz(90) maps +X to +Y.
  EXPECT_NEAR(x.y, 1.0f, testsupport::kFloatTol);
}

TEST(LocalPoseJob, PositionChannelsReplaceOrAddToOffset) {
  mocap::Skeleton s = TwoJointChain();
  std::vector<float> frame = {5, 6, 7, 0, 0, 0, 0, 0, 0};
  std::vector<mocap::JointTransform> locals(2);
  ASSERT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
  EXPECT_EQ(locals[0].translation, glm::vec3(5, 6, 7));
  EXPECT_EQ(locals[1].translation, glm::vec3(0, 10, 0));
  s.position_mode = mocap::PositionChannelMode::kAddToOffset;
  ASSERT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
  EXPECT_EQ(locals[0].translation, glm::vec3(6, 8, 10));
}

TEST(LocalToModelJob, ComposesParentFirst) {
  const mocap::Skeleton s = TwoJointChain();
  std::vector<float> frame = {0, 0, 0, 90, 0, 0, 0, 0, 0};  // root Z 90
  std::vector<mocap::JointTransform> locals(2);
  std::vector<glm::mat4> model(2);
  ASSERT_TRUE((mocap::LocalPoseJob{&s, frame, locals}).Run().ok());
  ASSERT_TRUE((mocap::LocalToModelJob{.parents = s.parents, .locals = locals,
                                      .model_from_joint = model}).Run().ok());
  // Root at (0,0,0) rotated Z 90: child offset (0,10,0) goes to (-10,0,0).
  const glm::vec3 child = glm::vec3(model[1][3]);
  EXPECT_NEAR(child.x, -10.0f, testsupport::kFloatTol);
  EXPECT_NEAR(child.y, 0.0f, testsupport::kFloatTol);
}

}  // namespace
