#include "mocap/error.h"

#include <gtest/gtest.h>

#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace {

TEST(Error, FormatsLikeACompiler) {
  const mocap::Error e = mocap::MakeError(mocap::ErrorCode::kSyntax, {"walk.bvh", 12, 5, {}},
                                          "expected '{' after joint name, found 'OFFSET'");
  EXPECT_EQ(e.ToString(), "walk.bvh:12:5: error: expected '{' after joint name, found 'OFFSET'");
}

TEST(Error, FormatsFieldPathsAndWholeFiles) {
  EXPECT_EQ((mocap::FileLoc{"rig.json", 0, 0, "patches[2].sampling"}).ToString(),
            "rig.json: patches[2].sampling");
  EXPECT_EQ((mocap::FileLoc{"a.bvh", 3, 0, {}}).ToString(), "a.bvh:3");
  EXPECT_EQ((mocap::FileLoc{}).ToString(), "<input>");
}

TEST(Result, HoldsValueOrError) {
  mocap::Result<int> good = 3;
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 3);
  mocap::Result<int> bad = mocap::MakeError(mocap::ErrorCode::kIo, {"x", 0, 0, {}}, "gone");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, mocap::ErrorCode::kIo);
}

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
