// The golden-image harness itself: pass, fail with files, missing reference, update.

#include "support/golden.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "render/output/image_io.h"
#include "support/data_paths.h"

namespace testsupport {
namespace {

namespace fs = std::filesystem;

GoldenDirs TempDirs(const std::string& name) {
  const fs::path root = TestOutputPath("golden_harness/" + name + "/x").parent_path();
  fs::remove_all(root);
  return GoldenDirs{root / "ref", root / "out", false};
}

render::Image Ramp() {
  render::Image img(32, 16);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 32; ++x) {
      img.at(x, y) = glm::vec4(static_cast<float>(x) / 31.0f, static_cast<float>(y) / 15.0f,
                               0.25f, 1.0f);
    }
  }
  return img;
}

TEST(Golden, MissingReferenceFailsAndSaysHowToCreateIt) {
  const GoldenDirs dirs = TempDirs("missing");
  const GoldenOutcome o = CheckGolden(Ramp(), "ramp", {}, dirs);
  EXPECT_FALSE(o.passed);
  EXPECT_NE(o.message.find("GOLDEN_UPDATE=1"), std::string::npos) << o.message;
  EXPECT_TRUE(fs::exists(o.actual_path));
  EXPECT_FALSE(fs::exists(dirs.ref_dir / "ramp.png")) << "only update mode writes references";
}

TEST(Golden, UpdateThenCompareIsBitExact) {
  GoldenDirs dirs = TempDirs("update");
  dirs.update = true;
  const GoldenOutcome u = CheckGolden(Ramp(), "ramp", {}, dirs);
  ASSERT_TRUE(u.passed) << u.message;
  EXPECT_TRUE(u.updated);
  ASSERT_TRUE(fs::exists(dirs.ref_dir / "ramp.png"));
  dirs.update = false;
  render::CompareThresholds exact;
  exact.fail_thresh = exact.fail_percent = exact.hard_fail = 0.0f;
  const GoldenOutcome o = CheckGolden(Ramp(), "ramp", exact, dirs);
  EXPECT_TRUE(o.passed) << o.message;
  ASSERT_TRUE(o.compare.has_value());
  EXPECT_EQ(o.compare->max_error, 0.0);
  EXPECT_TRUE(o.actual_path.empty()) << "nothing is written on success";
}

TEST(Golden, ChangedImageFailsAndLeavesActualAndDiff) {
  GoldenDirs dirs = TempDirs("changed");
  dirs.update = true;
  ASSERT_TRUE(CheckGolden(Ramp(), "ramp", {}, dirs).passed);
  dirs.update = false;
  render::Image changed = Ramp();
  changed.at(20, 5) = glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
  const GoldenOutcome o = CheckGolden(changed, "ramp", {}, dirs);
  EXPECT_FALSE(o.passed);
  ASSERT_TRUE(o.compare.has_value());
  EXPECT_EQ(o.compare->max_x, 20);
  EXPECT_EQ(o.compare->max_y, 5);
  EXPECT_NE(o.message.find("(20, 5)"), std::string::npos) << o.message;
  EXPECT_NE(o.message.find(o.diff_path.string()), std::string::npos);
  ASSERT_TRUE(fs::exists(o.actual_path));
  ASSERT_TRUE(fs::exists(o.diff_path));
  auto diff = render::ReadImage(o.diff_path.string());
  ASSERT_TRUE(diff.ok());
  EXPECT_GT(diff->at(20, 5).g, 0.5f) << "the changed pixel lights up";
  EXPECT_EQ(diff->at(0, 0).g, 0.0f);
  // The reference is untouched by a failing comparison.
  auto ref = render::ReadImage((dirs.ref_dir / "ramp.png").string());
  ASSERT_TRUE(ref.ok());
  EXPECT_NE(ref->at(20, 5), changed.at(20, 5));
}

TEST(Golden, SizeMismatchFails) {
  GoldenDirs dirs = TempDirs("size");
  dirs.update = true;
  ASSERT_TRUE(CheckGolden(Ramp(), "ramp", {}, dirs).passed);
  dirs.update = false;
  const GoldenOutcome o = CheckGolden(render::Image(8, 8), "ramp", {}, dirs);
  EXPECT_FALSE(o.passed);
  EXPECT_NE(o.message.find("differ in size"), std::string::npos) << o.message;
}

}  // namespace
}  // namespace testsupport
