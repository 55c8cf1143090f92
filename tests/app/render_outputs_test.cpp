// Safe outputs and determinism of `patchskin render`, run as a process:
// existing frames are refused without --overwrite, an interrupted render
// leaves only complete frames and --resume finishes it with the same bytes as
// an uninterrupted render, and the thread count never changes a frame.

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::RunPatchskin;
using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;
using testsupport::SlurpFile;

// Renders the built-in demo into `folder`/f_####.png at 320x180, without the
// contact sheet unless `extra` holds "--sheet" (taken out here).
std::vector<std::string> DemoArgs(const fs::path& folder, const std::string& frames,
                                  std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"render", "--size",     "320x180", "--frames", frames, "--quiet",
                                "--no-video", "--out", (folder / "f_####.png").string()};
  const auto sheet = std::find(extra.begin(), extra.end(), "--sheet");
  if (sheet != extra.end()) extra.erase(sheet);
  else args.push_back("--no-sheet");
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

void ExpectSameFrames(const fs::path& a, const fs::path& b) {
  const std::vector<fs::path> fa = testsupport::FilesIn(a), fb = testsupport::FilesIn(b);
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t i = 0; i < fa.size(); ++i) {
    EXPECT_EQ(fa[i].filename(), fb[i].filename());
    EXPECT_TRUE(SlurpFile(fa[i]) == SlurpFile(fb[i])) << fa[i] << " differs from " << fb[i];
  }
}

TEST(RenderOutputs, SameBytesWithOneTwoAndEightThreads) {
  const fs::path d = TestDir();
  for (const char* t : {"1", "2", "8"}) {
    const ProcessResult r = RunPatchskin(
        DemoArgs(d / (std::string("threads_") + t), "0:5", {"--threads", t, "--sheet"}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(testsupport::FilesIn(d / "threads_1").size(), 7u);  // 6 frames and the contact sheet
  ExpectSameFrames(d / "threads_1", d / "threads_2");
  ExpectSameFrames(d / "threads_1", d / "threads_8");
  // And across runs.
  ASSERT_EQ(RunPatchskin(DemoArgs(d / "again", "0:5", {"--threads", "2", "--sheet"})).exit_code, 0);
  ExpectSameFrames(d / "threads_1", d / "again");
}

// A rig with B-spline patches (two bodies side by side: global | global +
// patches), the camera following the elbow patch: the patch rebuild runs on
// the worker threads too.
TEST(RenderOutputs, RigWithPatchesGivesTheSameBytesWithOneTwoAndEightThreads) {
  const fs::path d = TestDir();
  const fs::path bend = (testsupport::TestDataPath("../../samples/data/bend.bvh")).lexically_normal();
  ASSERT_TRUE(fs::exists(bend)) << bend;
  const fs::path rig = d / "patches.json";
  std::ofstream(rig) << R"({"character": "mannequin", "motion": {"file": ")" << bend.string()
                     << R"("}, "global": "dqs", "patches": [
      {"name": "left_elbow", "region": {"joint": "LeftForeArm", "radius": 14, "side": [0, 0, 1]},
       "grid": [6, 6], "sampling": [8, 8]},
      {"name": "left_knee", "region": {"joint": "LeftLeg", "radius": 20, "side": [0, 0, -1]},
       "grid": [5, 6], "sampling": [9, 8], "border_width": 0.2}],
    "render": {"size": [192, 108], "camera": "fixed", "split": true, "frames": "40:47"}})";
  for (const char* t : {"1", "2", "8"}) {
    const ProcessResult r =
        RunPatchskin({"render", rig.string(), "--threads", t, "--quiet", "--no-video", "--look-at",
                      "patch:left_elbow", "--azimuth", "150", "--zoom", "1.2", "--out",
                      (d / (std::string("threads_") + t) / "f_####.png").string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(testsupport::FilesIn(d / "threads_1").size(), 9u);  // 8 frames and the contact sheet
  ExpectSameFrames(d / "threads_1", d / "threads_2");
  ExpectSameFrames(d / "threads_1", d / "threads_8");
}

TEST(RenderOutputs, RefusesExistingFramesWithoutOverwrite) {
  const fs::path out = TestDir() / "out";
  ASSERT_EQ(RunPatchskin(DemoArgs(out, "0:2")).exit_code, 0);
  const std::string before = SlurpFile(out / "f_0001.png");
  const auto stamp = fs::last_write_time(out / "f_0001.png");

  ProcessResult again = RunPatchskin(DemoArgs(out, "0:2"));
  EXPECT_EQ(again.exit_code, 2) << again.err;
  EXPECT_EQ(again.FirstErrLine().rfind((out / "f_0000.png").string() + ": error: ", 0), 0u)
      << again.err;
  EXPECT_NE(again.FirstErrLine().find("--overwrite"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(out / "f_0001.png"), stamp);

  // A larger range that includes existing frames is refused as a whole.
  EXPECT_EQ(RunPatchskin(DemoArgs(out, "0:4")).exit_code, 2);
  EXPECT_FALSE(fs::exists(out / "f_0004.png"));

  ProcessResult forced = RunPatchskin(DemoArgs(out, "0:2", {"--overwrite"}));
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_EQ(SlurpFile(out / "f_0001.png"), before);
}

TEST(RenderOutputs, FolderNamedLikeAFrameIsAnError) {
  const fs::path out = TestDir() / "out";
  fs::create_directories(out / "f_0001.png");
  const ProcessResult r = RunPatchskin(DemoArgs(out, "0:2", {"--overwrite"}));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.FirstErrLine().rfind((out / "f_0001.png").string() + ": error: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out / "f_0000.png"));
}

// Killed mid-way by SIGINT (Ctrl-C) and by SIGTERM (kill), then resumed: the
// frames and the contact sheet (rebuilt from the finished frames read back)
// are byte-identical to an uninterrupted render's, and no finished frame is redone.
TEST(RenderOutputs, InterruptedRenderResumesToTheSameFramesAndSheet) {
  const fs::path d = TestDir();
  const std::string range = "0:89";  // the whole demo: long enough to interrupt
  ASSERT_EQ(RunPatchskin(DemoArgs(d / "reference", range, {"--sheet"})).exit_code, 0);
  const std::size_t total = testsupport::FilesIn(d / "reference").size();
  ASSERT_EQ(total, 91u);  // 90 frames and the contact sheet

  int interrupted = 0;
  for (const int sig : {SIGINT, SIGTERM}) {
    const std::string name = sig == SIGINT ? "SIGINT" : "SIGTERM";
    SCOPED_TRACE(name);
    const fs::path out = d / ("interrupted_" + name);
    testsupport::RunningProcess p =
        testsupport::StartPatchskin(DemoArgs(out, range, {"--sheet"}), d / ("logs_" + name));
    ASSERT_GT(p.pid, 0);
    // Wait for a few finished frames, then interrupt.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (testsupport::FilesIn(out).size() < 3 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_EQ(kill(p.pid, sig), 0);
    const ProcessResult stopped = testsupport::WaitFor(p);
    if (stopped.exit_code == 0) continue;  // finished before the signal arrived
    ++interrupted;
    EXPECT_EQ(stopped.exit_code, 128 + sig) << stopped.err;
    EXPECT_NE(stopped.err.find("interrupted by " + name + " after frame"), std::string::npos)
        << stopped.err;
    EXPECT_NE(stopped.err.find("--resume"), std::string::npos) << stopped.err;

    // Only complete frames under final names: no temporary file, no sheet.
    const std::vector<fs::path> partial = testsupport::FilesIn(out);
    ASSERT_LT(partial.size(), total);
    ASSERT_FALSE(partial.empty());
    EXPECT_FALSE(fs::exists(out / "contact_sheet.png"));
    for (const fs::path& f : partial) {
      EXPECT_EQ(f.filename().string().rfind(".", 0), std::string::npos) << "temporary file " << f;
      EXPECT_EQ(SlurpFile(f), SlurpFile(d / "reference" / f.filename())) << f;
    }

    // Without --resume the existing frames are refused; with it the rest is rendered.
    EXPECT_EQ(RunPatchskin(DemoArgs(out, range, {"--sheet"})).exit_code, 2);
    const auto first_stamp = fs::last_write_time(partial.front());
    const ProcessResult resumed = RunPatchskin(DemoArgs(out, range, {"--sheet", "--resume"}));
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    EXPECT_EQ(fs::last_write_time(partial.front()), first_stamp) << "a finished frame was redone";
    ExpectSameFrames(d / "reference", out);  // the 90 frames and contact_sheet.png
  }
  if (interrupted == 0) GTEST_SKIP() << "both renders finished before their signal arrived";
}

}  // namespace
