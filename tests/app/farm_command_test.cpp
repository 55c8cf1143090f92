// `patchskin farm slurm` and `patchskin sheet` without a cluster: the array
// script run by hand once per task (as Slurm would, with SLURM_ARRAY_TASK_ID)
// gives frames byte-identical to one render of the whole range, the sheet
// script then writes the contact sheet and video, and bad arguments are
// refused before anything is written. tests/slurm/ runs the same on a real
// Slurm cluster.

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;
using testsupport::SlurpFile;

ProcessResult PatchskinIn(const fs::path& d, const std::vector<std::string>& args) {
  return testsupport::RunPatchskin(args, d / "logs");
}

// Runs `script` with sh as array task `task` would run it; returns sh's status.
int RunTask(const fs::path& script, int task, const fs::path& log) {
  const std::string cmd = "SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " sh '" + script.string() +
                          "' >'" + log.string() + "' 2>&1";
  return std::system(cmd.c_str());
}

const std::vector<std::string> kRenderArgs{"--", "--size", "64x36", "--supersample", "1"};

std::vector<std::string> FarmArgs(const fs::path& d, const std::string& frames, int chunk) {
  std::vector<std::string> args{"farm",
                                "slurm",
                                testsupport::SampleDataPath("bend.bvh").string(),
                                "--frames",
                                frames,
                                "--chunk",
                                std::to_string(chunk),
                                "--out",
                                (d / "farm/f_####.png").string(),
                                "--partition",
                                "debug",
                                "--sbatch-arg=--time=00:05:00"};
  args.insert(args.end(), kRenderArgs.begin(), kRenderArgs.end());
  return args;
}

void ExpectChunksEqualOneRender(const std::string& frames, int chunk, int tasks,
                                const std::vector<int>& numbers) {
  const fs::path d = TestDir();
  const ProcessResult farm = PatchskinIn(d, FarmArgs(d, frames, chunk));
  ASSERT_EQ(farm.exit_code, 0) << farm.err;
  // Printed: the scripts and the command; nothing rendered yet.
  EXPECT_NE(farm.out.find("#SBATCH --array=0-" + std::to_string(tasks - 1)), std::string::npos) << farm.out;
  EXPECT_NE(farm.out.find("#SBATCH --partition=debug"), std::string::npos);
  EXPECT_NE(farm.out.find("#SBATCH --time=00:05:00"), std::string::npos);
  EXPECT_NE(farm.out.find("--dependency=afterok:"), std::string::npos);
  EXPECT_NE(farm.out.find("sh " + (d / "farm/slurm/submit.sh").string()), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "farm/f_0000.png"));

  std::vector<std::string> single{"render",        testsupport::SampleDataPath("bend.bvh").string(),
                                  "--frames",      frames,
                                  "--out",         (d / "single/f_####.png").string(),
                                  "--quiet",       "--no-video",
                                  "--size",        "64x36",
                                  "--supersample", "1"};
  const ProcessResult one = PatchskinIn(d, single);
  ASSERT_EQ(one.exit_code, 0) << one.err;

  // Tasks in reverse order: chunks are independent of each other.
  for (int k = tasks - 1; k >= 0; --k) {
    ASSERT_EQ(RunTask(d / "farm/slurm/render_array.sbatch", k, d / "logs" / ("task" + std::to_string(k))), 0)
        << SlurpFile(d / "logs" / ("task" + std::to_string(k)));
  }
  ASSERT_EQ(RunTask(d / "farm/slurm/sheet.sbatch", 0, d / "logs/sheet"), 0) << SlurpFile(d / "logs/sheet");
  int files = 0;
  for (const auto& e : fs::directory_iterator(d / "farm")) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, static_cast<int>(numbers.size()) + 2) << "frames + contact sheet + video, nothing else";
  for (const int n : numbers) {
    char name[32];
    std::snprintf(name, sizeof name, "f_%04d.png", n);
    ASSERT_TRUE(fs::exists(d / "farm" / name)) << name;
    EXPECT_EQ(SlurpFile(d / "farm" / name), SlurpFile(d / "single" / name)) << name;
  }
  EXPECT_GT(fs::file_size(d / "farm/preview.mp4"), 0u);
  // The same frames on the sheet. Not the same bytes: `sheet` shrinks the 8-bit
  // frame files, render the float frames before quantizing, so thumbnails
  // differ by a few 8-bit levels (measured: at most 5/255 on 0.07% of values).
  const ProcessResult sheets =
      PatchskinIn(d, {"compare", (d / "single/contact_sheet.png").string(),
                      (d / "farm/contact_sheet.png").string(), "--fail", "0.004", "--failpercent",
                      "1", "--hardfail", "0.03"});
  EXPECT_EQ(sheets.exit_code, 0) << sheets.out;
}

TEST(FarmSlurm, ChunksRunByHandEqualOneRender) {
  ExpectChunksEqualOneRender("0:6", 2, 4, {0, 1, 2, 3, 4, 5, 6});
}

TEST(FarmSlurm, ChunksHonourTheStep) {
  ExpectChunksEqualOneRender("3:12:3", 3, 2, {3, 6, 9, 12});
}

TEST(FarmSlurm, RefusesBadArguments) {
  const fs::path d = TestDir();
  std::vector<std::string> args = FarmArgs(d, "0:6", 0);
  ProcessResult r = PatchskinIn(d, args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("--chunk"), std::string::npos) << r.err;

  args = FarmArgs(d, "0:6", 2);
  args.insert(args.end(), {"--frames", "0:3"});  // after "--": a render option farm sets itself
  r = PatchskinIn(d, args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("--frames: error: farm sets this render option itself"),
            std::string::npos)
      << r.err;

  r = PatchskinIn(d, FarmArgs(d, "0:99999", 2));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("--frames"), std::string::npos) << r.err;

  // The framing range of a chunk must hold the chunk's frames.
  r = PatchskinIn(d, {"render", testsupport::SampleDataPath("bend.bvh").string(), "--frames", "0:5",
                      "--framing", "2:3", "--quiet", "--out", (d / "farm/f_####.png").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("--framing: error: expected a range holding every output frame"),
            std::string::npos)
      << r.err;

  args = FarmArgs(d, "0:6", 2);
  args.insert(args.begin() + 3, "--wait");
  r = PatchskinIn(d, args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(d / "farm")) << "nothing written for bad arguments";
}

TEST(SheetCommand, RefusesMissingFramesAndExistingSheet) {
  const fs::path d = TestDir();
  const ProcessResult one =
      PatchskinIn(d, {"render", testsupport::SampleDataPath("bend.bvh").string(), "--frames", "0:3",
                      "--out", (d / "f_####.png").string(), "--quiet", "--no-video", "--no-sheet",
                      "--size", "64x36", "--supersample", "1"});
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ProcessResult r = PatchskinIn(d, {"sheet", (d / "f_####.png").string(), "--frames", "0:5"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("f_0004.png: error: frame missing (2 of 6"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "contact_sheet.png"));
  EXPECT_FALSE(fs::exists(d / "preview.mp4"));

  r = PatchskinIn(d, {"sheet", (d / "f_####.png").string(), "--frames", "0:3", "--no-video"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(d / "contact_sheet.png"));
  r = PatchskinIn(d, {"sheet", (d / "f_####.png").string(), "--frames", "0:3", "--no-video"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.FirstErrLine().find("--overwrite"), std::string::npos) << r.err;
  // A sheet needs a closed range: open ends, empty parts and stray characters are refused
  // with the option named; a step is accepted.
  for (const char* bad : {"0:", ":3", "0:3:", "0::2", "a:b", "0:3:1:1", "0:3 ", ""}) {
    r = PatchskinIn(
        d, {"sheet", (d / "f_####.png").string(), "--frames", bad, "--no-video", "--overwrite"});
    EXPECT_EQ(r.exit_code, 2) << "'" << bad << "'";
    EXPECT_NE(r.FirstErrLine().find("--frames"), std::string::npos) << "'" << bad << "': " << r.err;
  }
  r = PatchskinIn(
      d, {"sheet", (d / "f_####.png").string(), "--frames", "0:3:3", "--no-video", "--overwrite"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

}  // namespace
