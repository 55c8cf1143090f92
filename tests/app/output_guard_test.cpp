// app::OutputGuard and CheckRigOutputPattern in-process: which outputs a
// render may write, and the stop message after a signal.

#include "app/output_guard.h"

#include <csignal>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "support/data_paths.h"

namespace {

namespace fs = std::filesystem;

TEST(CheckRigOutputPattern, AcceptsRelativePatternsInsideTheFolder) {
  const base::FileLoc where{"walk.rig.json", 0, 0, "render.output"};
  EXPECT_TRUE(app::CheckRigOutputPattern("frames/walk_####.png", where).ok());
  EXPECT_TRUE(app::CheckRigOutputPattern("walk..v2_####.png", where).ok());
  EXPECT_TRUE(app::CheckRigOutputPattern("a/..b/####.png", where).ok());
}

TEST(CheckRigOutputPattern, RefusesEscapes) {
  const base::FileLoc where{"walk.rig.json", 0, 0, "render.output"};
  for (const char* bad : {"../####.png", "frames/../../####.png", "frames/..", "..\\x\\####.png",
                          "/tmp/####.png", "~/####.png", "C:/x/####.png", ""}) {
    SCOPED_TRACE(bad);
    const base::Status s = app::CheckRigOutputPattern(bad, where);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, base::ErrorCode::kInvalidArgument);
    EXPECT_EQ(s.error().loc.field_path, "render.output");
    EXPECT_NE(s.error().message.find("expected a relative path inside"), std::string::npos);
  }
  EXPECT_NE(app::CheckRigOutputPattern("a/../b_####.png", where).error().message.find("'..'"),
            std::string::npos);
}

class OutputGuardTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testsupport::TestOutputPath(std::string("output_guard/") +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                                       "/x")
               .parent_path();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (int i = 0; i < 4; ++i) paths_.push_back((dir_ / ("f_" + std::to_string(i) + ".png")).string());
  }
  void Touch(const std::string& p) { std::ofstream(p) << "x"; }
  fs::path dir_;
  std::vector<std::string> paths_;
};

TEST_F(OutputGuardTest, FreshOutputsRenderEverything) {
  app::OutputGuard guard({});
  ASSERT_TRUE(guard.Plan(paths_, {(dir_ / "sheet.png").string()}).ok());
  for (std::size_t i = 0; i < paths_.size(); ++i) EXPECT_FALSE(guard.skip(i));
  EXPECT_EQ(guard.num_skipped(), 0);
}

TEST_F(OutputGuardTest, ExistingFrameIsRefusedWithCount) {
  Touch(paths_[1]);
  Touch(paths_[3]);
  app::OutputGuard guard({});
  const base::Status s = guard.Plan(paths_, {});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().loc.file, paths_[1]);
  EXPECT_NE(s.error().message.find("2 of this render's 4 outputs"), std::string::npos)
      << s.error().message;
}

TEST_F(OutputGuardTest, ExistingSheetIsRefusedButResumeRebuildsIt) {
  const std::string sheet = (dir_ / "sheet.png").string();
  Touch(sheet);
  EXPECT_FALSE(app::OutputGuard({}).Plan(paths_, {sheet}).ok());
  EXPECT_TRUE(app::OutputGuard({.overwrite = true}).Plan(paths_, {sheet}).ok());
  EXPECT_TRUE(app::OutputGuard({.resume = true}).Plan(paths_, {sheet}).ok());
}

TEST_F(OutputGuardTest, ResumeSkipsExactlyTheExistingFrames) {
  Touch(paths_[0]);
  Touch(paths_[2]);
  app::OutputGuard guard({.resume = true});
  ASSERT_TRUE(guard.Plan(paths_, {}).ok());
  EXPECT_TRUE(guard.skip(0));
  EXPECT_FALSE(guard.skip(1));
  EXPECT_TRUE(guard.skip(2));
  EXPECT_FALSE(guard.skip(3));
  EXPECT_FALSE(guard.skip(99));
  EXPECT_EQ(guard.num_skipped(), 2);
}

TEST_F(OutputGuardTest, SignalIsRecordedAndReported) {
  app::OutputGuard guard({});
  EXPECT_FALSE(guard.interrupted());
  app::OutputGuard::SimulateSignal(SIGTERM);
  EXPECT_TRUE(guard.interrupted());
  EXPECT_EQ(guard.exit_code(), 128 + SIGTERM);
  EXPECT_EQ(guard.StopMessage(11, 12, 48),
            "interrupted by SIGTERM after frame 11: 12 of 48 frames are complete; run the same "
            "command with --resume to render the other 36");
  EXPECT_EQ(guard.StopMessage(-1, 0, 5),
            "interrupted by SIGTERM before any frame was complete; run the same command with "
            "--resume to render the other 5");
  EXPECT_EQ(guard.StopMessage(11, 12, 48, "the .glb was not written"),
            "interrupted by SIGTERM after frame 11: 12 of 48 frames are complete; the .glb was not written");
}

TEST_F(OutputGuardTest, RealSignalSetsTheFlagInsteadOfEndingTheProcess) {
  app::OutputGuard guard({});
  ASSERT_EQ(std::raise(SIGINT), 0);  // would end the test binary without the guard's handler
  EXPECT_TRUE(guard.interrupted());
  EXPECT_EQ(guard.signal_number(), SIGINT);
}

}  // namespace
