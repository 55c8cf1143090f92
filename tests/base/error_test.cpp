#include "base/error.h"

#include <gtest/gtest.h>

namespace {

TEST(Error, FormatsLikeACompiler) {
  const base::Error e = base::MakeError(base::ErrorCode::kSyntax, {"walk.bvh", 12, 5, {}},
                                        "expected '{' after joint name, found 'OFFSET'");
  EXPECT_EQ(e.ToString(), "walk.bvh:12:5: error: expected '{' after joint name, found 'OFFSET'");
}

TEST(Error, FormatsFieldPathsAndWholeFiles) {
  EXPECT_EQ((base::FileLoc{"rig.json", 0, 0, "patches[2].sampling"}).ToString(),
            "rig.json: patches[2].sampling");
  EXPECT_EQ((base::FileLoc{"a.bvh", 3, 0, {}}).ToString(), "a.bvh:3");
  EXPECT_EQ((base::FileLoc{}).ToString(), "<input>");
}

TEST(Result, HoldsValueOrError) {
  base::Result<int> good = 3;
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 3);
  base::Result<int> bad = base::MakeError(base::ErrorCode::kIo, {"x", 0, 0, {}}, "gone");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, base::ErrorCode::kIo);
}

}  // namespace
