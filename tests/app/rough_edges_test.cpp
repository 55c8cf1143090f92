// Rough edges a new user hits (issue 27), each run as a process the way a user
// runs it: an odd --size, a Latin-1 joint name, Ctrl-C during export, exit
// codes, an unwritable output folder, the turntable command's options on a rig
// and --start-number.

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::RunPatchskin;
using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;

std::vector<std::string> Names(const fs::path& folder) {
  std::vector<std::string> out;
  if (!fs::is_directory(folder)) return out;
  for (const auto& e : fs::directory_iterator(folder)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

// 101x57 is within 16..16384: the frames keep that size, the preview video is
// cropped to 100x56 and the render succeeds (it failed on the video before).
TEST(RoughEdges, OddSizeRendersFramesAndVideo) {
  const fs::path out = TestDir() / "odd";
  const ProcessResult r = RunPatchskin({"render", "--size", "101x57", "--frames", "0:3", "--quiet",
                                        "--out", (out / "f_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "preview.mp4"));
  const base::Result<render::Image> frame = render::ReadImage((out / "f_0003.png").string());
  ASSERT_TRUE(frame.ok()) << frame.error().ToString();
  EXPECT_EQ(frame->width, 101);
  EXPECT_EQ(frame->height, 57);
}

// A joint named in Latin-1 bytes ("Épaule", 0xC9) is written by inspect --json
// as valid UTF-8 JSON (the internal error, exit 3, came from the JSON writer).
TEST(RoughEdges, Latin1JointNameGivesValidJson) {
  const fs::path bvh = TestDir() / "latin1.bvh";
  std::ofstream(bvh, std::ios::binary)
      << "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition "
         "Zrotation Xrotation Yrotation\n  JOINT \xC9paule\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 "
         "Zrotation Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 5 0\n    }\n  }\n}\n"
         "MOTION\nFrames: 1\nFrame Time: 0.033333\n0 0 0 0 0 0 0 0 0\n";
  const ProcessResult r = RunPatchskin({"inspect", bvh.string(), "--json", "--frame", "0"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("Latin-1"), std::string::npos) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out, nullptr, /*allow_exceptions=*/false);
  ASSERT_FALSE(doc.is_discarded()) << r.out;
  EXPECT_EQ(doc["joints"][1]["name"], "\xC3\x89paule");
  EXPECT_TRUE(doc["positions"].contains("\xC3\x89paule"));
}

// Ctrl-C during an export stops it as render does: a message naming the
// signal, exit 130, and no temporary or partial file (the .glb is written only
// at the end; OBJ meshes are written whole under their final names).
TEST(RoughEdges, InterruptedExportLeavesNoTemporaries) {
  int interrupted = 0;
  for (const std::string ext : {"obj", "glb"}) {
    SCOPED_TRACE(ext);
    const fs::path out = TestDir() / ext;
    const std::string target = ext == "obj" ? (out / "m_####.obj").string() : (out / "a.glb").string();
    // The demo resampled to 900 frames: long enough to interrupt.
    testsupport::RunningProcess p = testsupport::StartPatchskin(
        {"export", "--fps", "300", "--threads", "1", "--out", target}, TestDir() / ("logs_" + ext));
    ASSERT_GT(p.pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    // Interrupt once the export is under way (its progress line is on stderr).
    while (testsupport::SlurpFile(p.err).find("frame") == std::string::npos &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_EQ(kill(p.pid, SIGINT), 0);
    const ProcessResult r = testsupport::WaitFor(p);
    if (r.exit_code == 0) continue;  // finished before the signal arrived
    ++interrupted;
    EXPECT_EQ(r.exit_code, 130) << r.err;
    EXPECT_NE(r.err.find("interrupted by SIGINT"), std::string::npos) << r.err;
    if (ext == "obj") {
      EXPECT_NE(r.err.find("frames are complete; run the same command with --resume to write the other"),
                std::string::npos)
          << r.err;
    } else {
      EXPECT_NE(r.err.find("the .glb was not written; run the same command again"), std::string::npos) << r.err;
    }
    for (const std::string& name : Names(out)) {
      EXPECT_NE(name.front(), '.') << "temporary file " << name;
      EXPECT_NE(name, "a.glb") << "a .glb of part of the frames";
    }
  }
  if (interrupted == 0) GTEST_SKIP() << "both exports finished before their signal arrived";
}

// export --resume keeps the OBJ frames already there and writes the missing
// ones, the same bytes as one uninterrupted export even with the elastic layer
// (whose state every frame hands the next: skipped frames are still evaluated).
// A kept file is not rewritten; a .glb cannot be resumed.
TEST(RoughEdges, ExportResumeWritesTheMissingFramesOnly) {
  const std::string rig = testsupport::SampleDataPath("belly_jump.json").string();
  const fs::path full = TestDir() / "resume_full", part = TestDir() / "resume_part";
  fs::remove_all(full);
  fs::remove_all(part);
  const std::vector<std::string> args = {"export", rig, "--frames", "44:52", "--quiet"};
  auto with_out = [&](const fs::path& dir, std::vector<std::string> extra) {
    std::vector<std::string> a = args;
    a.push_back("--out");
    a.push_back((dir / "m_####.obj").string());
    a.insert(a.end(), extra.begin(), extra.end());
    return RunPatchskin(a);
  };
  ProcessResult r = with_out(full, {});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = with_out(part, {});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // As an interrupted run would leave it: the later frames missing, one kept
  // frame marked so that a rewrite would show.
  for (const int n : {49, 50, 51, 52}) fs::remove(part / ("m_00" + std::to_string(n) + ".obj"));
  std::ofstream(part / "m_0045.obj", std::ios::trunc) << "kept\n";
  r = with_out(part, {"--resume"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(testsupport::SlurpFile(part / "m_0045.obj"), "kept\n");
  for (int n = 44; n <= 52; ++n) {
    if (n == 45) continue;
    const std::string name = "m_00" + std::to_string(n) + ".obj";
    ASSERT_TRUE(fs::exists(part / name)) << name;
    EXPECT_EQ(testsupport::SlurpFile(part / name), testsupport::SlurpFile(full / name)) << name;
  }
  // Without --resume the marked file is replaced again.
  r = with_out(part, {});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(testsupport::SlurpFile(part / "m_0045.obj"), testsupport::SlurpFile(full / "m_0045.obj"));

  const ProcessResult glb = RunPatchskin({"export", "--frames", "0:2", "--quiet", "--resume",
                                          "--out", (TestDir() / "resume.glb").string()});
  EXPECT_EQ(glb.exit_code, 2);
  EXPECT_NE(glb.err.find("--resume"), std::string::npos) << glb.err;
  EXPECT_FALSE(fs::exists(TestDir() / "resume.glb"));
}

// inspect reads what export writes: a .glb of plain meshes (no skin) is
// described (its frames and mesh), not refused with "the file has no skin".
TEST(RoughEdges, InspectDescribesAnExportedGlb) {
  const fs::path glb = TestDir() / "exported.glb";
  const ProcessResult made =
      RunPatchskin({"export", "--frames", "0:5", "--quiet", "--out", glb.string()});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const ProcessResult r = RunPatchskin({"inspect", glb.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out, nullptr, /*allow_exceptions=*/false);
  ASSERT_FALSE(doc.is_discarded()) << r.out;
  EXPECT_EQ(doc["frames"], 6) << r.out;
  const ProcessResult text = RunPatchskin({"inspect", glb.string()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("mesh:"), std::string::npos) << text.out;
}

// One rule: 2 whenever the command cannot run as given, whether the parser
// (an unknown option, a missing value) or the command (a bad value) finds it.
TEST(RoughEdges, UsageErrorsAndBadValuesExitTwoInEveryCommand) {
  const std::vector<std::vector<std::string>> cases = {
      {"render", "--bogus"},
      {"render", "--size", "8x8"},
      {"render", "--size"},
      {"turntable", "--bogus"},
      {"turntable", "--turntable-frames", "0"},
      {"export", "--bogus"},
      {"export", "--scale", "-1"},
      {"inspect"},
      {"inspect", "x.bvh", "--frame", "abc"},
      {"elastic", "--bogus"},
      {"sheet", "--bogus"},
      {"farm", "--bogus"},
      {"bench", "--bogus"},
      {"--bogus"},
      {"nosuchcommand"},
  };
  for (const std::vector<std::string>& args : cases) {
    std::string line;
    for (const std::string& a : args) line += a + " ";
    const ProcessResult r = RunPatchskin(args);
    EXPECT_EQ(r.exit_code, 2) << line << "\n" << r.err;
  }
  // compare and check exit as idiff does: 4 for anything but a verdict.
  for (const char* command : {"compare", "check"}) {
    const ProcessResult r = RunPatchskin({command, "--bogus"});
    EXPECT_EQ(r.exit_code, 4) << command << "\n" << r.err;
  }
}

// An output folder the user may not write to: the first stderr line names the
// folder and says "permission denied", before any rendering. As root (which
// may write anywhere) the command runs as user nobody through setpriv.
TEST(RoughEdges, UnwritableOutputFolderSaysPermissionDenied) {
  const fs::path locked = TestDir() / "locked";
  fs::create_directories(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                              fs::perms::group_exec | fs::perms::others_read |
                              fs::perms::others_exec);
  for (const fs::path& out : {locked, locked / "new"}) {
    for (const std::string command : {"render", "export"}) {
      SCOPED_TRACE(command + " into " + out.string());
      const std::string pattern =
          (out / (command == "render" ? "f_####.png" : "m_####.obj")).string();
      std::vector<std::string> args{command, "--frames", "0:1", "--out", pattern};
      if (command == "render") args.insert(args.end(), {"--size", "64x36", "--quiet"});
      ProcessResult r;
      if (geteuid() == 0) {
        if (std::system("setpriv --version > /dev/null 2>&1") != 0) {
          GTEST_SKIP() << "running as root without setpriv: cannot drop the permission to write";
        }
        const fs::path err = TestDir() / "logs" / "setpriv_err.txt";
        std::string line = "setpriv --reuid=65534 --regid=65534 --clear-groups '" +
                           std::string(PATCHSKIN_BINARY) + "'";
        for (const std::string& a : args) line += " '" + a + "'";
        line += " > /dev/null 2> '" + err.string() + "'";
        const int status = std::system(line.c_str());
        r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        r.err = testsupport::SlurpFile(err);
      } else {
        r = RunPatchskin(args);
      }
      EXPECT_EQ(r.exit_code, 2) << r.err;
      const std::string first = r.FirstErrLine();
      EXPECT_EQ(first.rfind(out.string() + ": error: permission denied", 0), 0u) << r.err;
      EXPECT_TRUE(Names(locked).empty() || Names(locked) == std::vector<std::string>{});
    }
  }
  fs::permissions(locked, fs::perms::owner_all);
}

// turntable RIG.json honours --frames, --turntable-frames, --size and --out
// (the rig's settings rendered its whole motion before), and --start-number
// numbers the files. The motion frame matters: frames 0 and 40 of the rig
// differ in the picture, not only in the label.
TEST(RoughEdges, TurntableOfARigHonoursItsOptions) {
  const fs::path rig = testsupport::TestDataPath("../../samples/data/belly_jump.json");
  ASSERT_TRUE(fs::exists(rig)) << rig;
  for (const std::string frame : {"0", "40"}) {
    const fs::path out = TestDir() / ("f" + frame);
    const ProcessResult r =
        RunPatchskin({"turntable", rig.string(), "--frames", frame, "--turntable-frames", "3",
                      "--size", "96x64", "--out", (out / "t_####.png").string(), "--start-number",
                      "1001", "--quiet", "--no-video", "--no-sheet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(Names(out), (std::vector<std::string>{"t_1001.png", "t_1002.png", "t_1003.png"}));
    const base::Result<render::Image> img = render::ReadImage((out / "t_1001.png").string());
    ASSERT_TRUE(img.ok()) << img.error().ToString();
    EXPECT_EQ(img->width, 96);
    EXPECT_EQ(img->height, 64);
  }
  const render::Image a = *render::ReadImage((TestDir() / "f0" / "t_1001.png").string());
  const render::Image b = *render::ReadImage((TestDir() / "f40" / "t_1001.png").string());
  int differ = 0;  // pixels above the label row that differ
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < a.width; ++x) differ += a.at(x, y) != b.at(x, y) ? 1 : 0;
  }
  EXPECT_GT(differ, 20) << "the two motion frames look the same";
}

// --start-number 1001: motion frame 0 is file 1001 (render and export).
TEST(RoughEdges, StartNumberNumbersTheFiles) {
  const ProcessResult r = RunPatchskin({"render", "--frames", "2:4", "--size", "64x36", "--quiet",
                                        "--no-video", "--no-sheet", "--start-number", "1001",
                                        "--out", (TestDir() / "r" / "f_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Names(TestDir() / "r"),
            (std::vector<std::string>{"f_1003.png", "f_1004.png", "f_1005.png"}));
  const ProcessResult e =
      RunPatchskin({"export", "--frames", "0:1", "--quiet", "--start-number", "1001", "--out",
                    (TestDir() / "e" / "m_####.obj").string()});
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_EQ(Names(TestDir() / "e"), (std::vector<std::string>{"m_1001.obj", "m_1002.obj"}));
  EXPECT_EQ(RunPatchskin({"render", "--start-number", "-1"}).exit_code, 2);
}

}  // namespace
