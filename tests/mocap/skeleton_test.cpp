#include "mocap/skeleton.h"

#include <gtest/gtest.h>

#include "mocap/motion.h"

namespace {

TEST(NominalFps, SnapsNearIntegerRates) {
  EXPECT_EQ(mocap::NominalFps(0.0333333), 30.0);
  EXPECT_EQ(mocap::NominalFps(0.0083333), 120.0);
  EXPECT_EQ(mocap::NominalFps(0.016667), 60.0);
  EXPECT_NEAR(mocap::NominalFps(0.037), 27.027, 1e-3);
  EXPECT_EQ(mocap::NominalFps(0.0), 0.0);
}

TEST(Skeleton, CheckRejectsChildBeforeParent) {
  mocap::Skeleton s;
  s.names = {"a", "b"};
  s.parents = {1, mocap::kNoParent};
  s.rest_translations.assign(2, glm::vec3(0.0f));
  s.rest_rotations.assign(2, glm::quat(1, 0, 0, 0));
  s.rest_scales.assign(2, glm::vec3(1.0f));
  s.channels.resize(2);
  EXPECT_FALSE(s.Check().ok());
  s.parents = {mocap::kNoParent, 0};
  EXPECT_TRUE(s.Check().ok());
  EXPECT_EQ(s.FindJoint("b"), 1);
  EXPECT_EQ(s.FindJoint("c"), -1);
}

}  // namespace
