#include "deform/body/bind_pose.h"

#include <gtest/gtest.h>

#include "tools/synthetic.h"
#include "support/test_skeletons.h"
#include "support/tolerances.h"

namespace {

TEST(BindPose, StandingRestPoseIsKept) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  auto walk = synthetic::MakeWalkMotion(s);
  ASSERT_TRUE(walk.ok());
  auto choice = deform::ChooseBindPose(s, *walk);
  ASSERT_TRUE(choice.ok()) << choice.error().ToString();
  EXPECT_EQ(choice->frame, -1);
  EXPECT_GT(choice->rest_height, 0.0f);
  EXPECT_GT(choice->first_height, 0.0f);
}

TEST(BindPose, HeightLeavesOutARootThatOnlyPositionsTheBody) {
  // Bandai-like: a root on the floor at the origin, the body lying flat along +x at hip
  // height (legs along the spine). Its body height is the spread of the body's joints
  // in y (86..97), not the root's 0..97.
  const testsupport::BuiltSkeleton b = testsupport::SkeletonFrom(
      {{"root", -1, {0, 0, 0}},        {"hips", 0, {5, 91, 0}},       {"spine", 1, {20, 92, 0}},
       {"chest", 2, {30, 92, 0}},      {"head", 3, {52, 93, 0}},      {"arm_l", 3, {35, 92, 5}},
       {"fore_l", 5, {60, 92, 5}},     {"hand_l", 6, {82, 92, 5}},    {"arm_r", 3, {35, 92, -5}},
       {"fore_r", 8, {60, 92, -5}},    {"hand_r", 9, {82, 92, -5}},   {"leg_l", 1, {3, 86, 4}},
       {"shin_l", 11, {42, 86, 4}},    {"foot_l", 12, {83, 86, 4}},   {"leg_r", 1, {3, 86, -4}},
       {"shin_r", 14, {42, 86, -4}},   {"foot_r", 15, {83, 97, -4}}},
      false, 0.0f);
  auto choice = deform::ChooseBindPose(b.skeleton, mocap::Motion{});
  ASSERT_TRUE(choice.ok()) << choice.error().ToString();
  EXPECT_EQ(choice->frame, -1);  // no frame to bind at
  EXPECT_NEAR(choice->rest_height, 97.0f - 86.0f, testsupport::kPositionTol);
  EXPECT_EQ(choice->first_height, 0.0f);
}

}  // namespace
