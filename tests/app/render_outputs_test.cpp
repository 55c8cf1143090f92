// Safe outputs and determinism of `patchskin render`, run as a process:
// existing frames are refused without --overwrite, an interrupted render
// leaves only complete frames and --resume finishes it with the same bytes as
// an uninterrupted render, and the thread count never changes a frame.

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;
using testsupport::ProcessResult;
using testsupport::SlurpFile;

fs::path Dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = testsupport::TestOutputPath(std::string("render_outputs/") + info->name() + "/x")
                         .parent_path();
  static std::string cleaned;
  if (cleaned != d.string()) {
    fs::remove_all(d);
    fs::create_directories(d / "logs");
    cleaned = d.string();
  }
  return d;
}

// Renders the built-in demo into `folder`/f_####.png at 320x180.
std::vector<std::string> DemoArgs(const fs::path& folder, const std::string& frames,
                                  std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"render",     "--size",    "320x180", "--frames", frames,
                                "--quiet",    "--no-video", "--no-sheet",
                                "--out",      (folder / "f_####.png").string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

ProcessResult Patchskin(const std::vector<std::string>& args) {
  return testsupport::RunPatchskin(args, Dir() / "logs");
}

// Regular files in `folder`, sorted by name.
std::vector<fs::path> Files(const fs::path& folder) {
  std::vector<fs::path> out;
  if (!fs::exists(folder)) return out;
  for (const auto& e : fs::directory_iterator(folder)) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

void ExpectSameFrames(const fs::path& a, const fs::path& b) {
  const std::vector<fs::path> fa = Files(a), fb = Files(b);
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t i = 0; i < fa.size(); ++i) {
    EXPECT_EQ(fa[i].filename(), fb[i].filename());
    EXPECT_TRUE(SlurpFile(fa[i]) == SlurpFile(fb[i])) << fa[i] << " differs from " << fb[i];
  }
}

TEST(RenderOutputs, SameBytesWithOneTwoAndEightThreads) {
  const fs::path d = Dir();
  for (const char* t : {"1", "2", "8"}) {
    const ProcessResult r = Patchskin(DemoArgs(d / (std::string("threads_") + t), "0:5", {"--threads", t}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(Files(d / "threads_1").size(), 6u);
  ExpectSameFrames(d / "threads_1", d / "threads_2");
  ExpectSameFrames(d / "threads_1", d / "threads_8");
  // And across runs.
  ASSERT_EQ(Patchskin(DemoArgs(d / "again", "0:5", {"--threads", "2"})).exit_code, 0);
  ExpectSameFrames(d / "threads_1", d / "again");
}

TEST(RenderOutputs, RefusesExistingFramesWithoutOverwrite) {
  const fs::path out = Dir() / "out";
  ASSERT_EQ(Patchskin(DemoArgs(out, "0:2")).exit_code, 0);
  const std::string before = SlurpFile(out / "f_0001.png");
  const auto stamp = fs::last_write_time(out / "f_0001.png");

  ProcessResult again = Patchskin(DemoArgs(out, "0:2"));
  EXPECT_EQ(again.exit_code, 2) << again.err;
  EXPECT_EQ(again.FirstErrLine().rfind((out / "f_0000.png").string() + ": error: ", 0), 0u)
      << again.err;
  EXPECT_NE(again.FirstErrLine().find("--overwrite"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(out / "f_0001.png"), stamp);

  // A larger range that includes existing frames is refused as a whole.
  EXPECT_EQ(Patchskin(DemoArgs(out, "0:4")).exit_code, 2);
  EXPECT_FALSE(fs::exists(out / "f_0004.png"));

  ProcessResult forced = Patchskin(DemoArgs(out, "0:2", {"--overwrite"}));
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_EQ(SlurpFile(out / "f_0001.png"), before);
}

TEST(RenderOutputs, FolderNamedLikeAFrameIsAnError) {
  const fs::path out = Dir() / "out";
  fs::create_directories(out / "f_0001.png");
  const ProcessResult r = Patchskin(DemoArgs(out, "0:2", {"--overwrite"}));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.FirstErrLine().rfind((out / "f_0001.png").string() + ": error: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out / "f_0000.png"));
}

TEST(RenderOutputs, InterruptedRenderResumesToTheSameFrames) {
  const fs::path d = Dir();
  const std::string range = "0:89";  // the whole demo: long enough to interrupt
  ASSERT_EQ(Patchskin(DemoArgs(d / "reference", range)).exit_code, 0);
  const std::size_t total = Files(d / "reference").size();
  ASSERT_EQ(total, 90u);

  const fs::path out = d / "interrupted";
  testsupport::RunningProcess p = testsupport::StartPatchskin(DemoArgs(out, range), d / "logs");
  ASSERT_GT(p.pid, 0);
  // Wait for a few finished frames, then interrupt as Ctrl-C would.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (Files(out).size() < 3 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(kill(p.pid, SIGINT), 0);
  const ProcessResult stopped = testsupport::WaitFor(p);
  if (stopped.exit_code == 0) GTEST_SKIP() << "the render finished before the signal arrived";
  EXPECT_EQ(stopped.exit_code, 128 + SIGINT) << stopped.err;
  EXPECT_NE(stopped.err.find("interrupted by SIGINT after frame"), std::string::npos) << stopped.err;
  EXPECT_NE(stopped.err.find("--resume"), std::string::npos) << stopped.err;

  // Only complete frames under final names, no temporary file left behind.
  const std::vector<fs::path> partial = Files(out);
  ASSERT_LT(partial.size(), total);
  for (const fs::path& f : partial) {
    EXPECT_EQ(f.filename().string().rfind(".", 0), std::string::npos) << "temporary file " << f;
    EXPECT_EQ(SlurpFile(f), SlurpFile(d / "reference" / f.filename())) << f;
  }

  // Without --resume the existing frames are refused; with it the rest is rendered.
  EXPECT_EQ(Patchskin(DemoArgs(out, range)).exit_code, 2);
  const auto first_stamp = fs::last_write_time(partial.front());
  const ProcessResult resumed = Patchskin(DemoArgs(out, range, {"--resume"}));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(fs::last_write_time(partial.front()), first_stamp) << "a finished frame was redone";
  ExpectSameFrames(d / "reference", out);
}

}  // namespace
