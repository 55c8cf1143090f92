// Bad rig files given to `patchskin render`, run as a process: every case of
// the corpus in tests/data/rig/bad (see its README.md) plus files written here
// (a folder named like a rig, an unreadable rig, one over the size limit)
// must exit 2, name the rig file (and the line or field path) and what was
// expected on the first stderr line, and leave the output folder empty.

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/rig_file.h"
#include "support/cli_outputs.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::ExpectNoOutput;
using testsupport::kExitBadInput;
using testsupport::OutDir;
using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;

ProcessResult RenderRig(const std::string& rig) {
  return testsupport::RunPatchskin(
      {"render", rig, "--quiet", "--out", (OutDir() / "f_####.png").string()}, TestDir() / "logs");
}

// Exit 2 and a first stderr line "<file>[:line:col][: field]: error: ..." that
// starts with `file` and holds `expect`.
void ExpectRigRefused(const ProcessResult& r, const std::string& file, const std::string& expect) {
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  const std::string first = r.FirstErrLine();
  EXPECT_EQ(first.rfind(file, 0), 0u) << "first stderr line: " << first;
  EXPECT_NE(first.find(": error: "), std::string::npos) << "first stderr line: " << first;
  EXPECT_NE(first.find(expect), std::string::npos) << "first stderr line: " << first;
}

std::string BadRigPath(const std::string& name) {
  return testsupport::TestDataPath("rig/bad/" + name).lexically_normal().string();
}

struct RigCase {
  const char* file;
  const char* expect;  // as in tests/data/rig/bad/README.md
  // Another file the message names, relative to the rig's folder ("" is the
  // folder itself); nullptr: the rig.
  const char* file_in_message = nullptr;
};

const RigCase kRigCases[] = {
    {"empty.json", "1:1: error: invalid JSON"},
    {"truncated.json", ": error: invalid JSON: syntax error"},
    {"binary.json", "1:1: error: invalid JSON"},
    {"nan_radius.json",
     "12:19: error: invalid JSON: syntax error while parsing value - invalid literal"},
    {"inf_radius.json", "12:19: error: invalid JSON: number overflow parsing '1e999'"},
    {"size_absurd.json", "render.size: error: expected an array of two integers in 16..16384"},
    {"size_zero.json", "render.size: error: expected an array of two integers in 16..16384"},
    {"grid_absurd.json", "patches[0].grid: error: expected an array of two integers in 4..64"},
    {"sampling_absurd.json",
     "patches[0].sampling: error: expected an array of two integers in 4..256"},
    {"radius_negative.json",
     "patches[0].region.radius: error: expected a number in 1e-06..1e+06, found -5"},
    {"radius_string.json",
     "patches[0].region.radius: error: expected a number in 1e-06..1e+06, found \"5\""},
    {"fps_absurd.json", "motion.fps: error: expected a number in 0..10000, found 1000000000.0"},
    {"vertex_index_huge.json", "patches[0].region.vertices[2]: error: expected a vertex index"},
    {"unknown_field.json", "colour: error: unknown field (expected one of: character, motion"},
    {"unknown_render_field.json", "render.fps: error: unknown field (expected one of: size, camera"},
    {"too_many_patches.json", "patches: error: expected at most 64 patches"},
    {"deep_nesting.json", "patches[0]: error: expected an object, found an array (1 item)"},
    {"patches_not_array.json",
     "patches: error: expected an array of patch objects, found an object"},
    {"output_dotdot.json",
     "render.output: error: expected a relative path inside the rig's output folder"},
    {"output_absolute.json",
     "render.output: error: expected a relative path inside the rig's output folder"},
    {"frames_reversed.json", "render.frames: error: range 9:2 is outside the motion's frames"},
    {"motion_missing.json", "no_such.bvh: error: no such file", "no_such.bvh"},
    {"motion_directory.json", "found a directory", ""},
};

TEST(CliBadRig, EveryCorpusFileIsRefusedWithItsMessage) {
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(testsupport::TestDataPath("rig/bad"))) {
    files += e.path().extension() == ".json" ? 1 : 0;
  }
  EXPECT_EQ(files, std::size(kRigCases)) << "every corpus file needs a row here";
  for (const RigCase& c : kRigCases) {
    SCOPED_TRACE(c.file);
    const std::string rig = BadRigPath(c.file);
    const fs::path folder = fs::path(rig).parent_path();
    const std::string named = !c.file_in_message ? rig
                              : *c.file_in_message ? (folder / c.file_in_message).string()
                                                   : folder.string();
    ExpectRigRefused(RenderRig(rig), named, c.expect);
    ExpectNoOutput();
  }
}

TEST(CliBadRig, FolderWhereTheRigBelongs) {
  const fs::path folder = TestDir() / "rig.json";
  fs::create_directories(folder);
  ExpectRigRefused(RenderRig(folder.string()), folder.string(),
                   "error: expected a rig file, found a directory");
  ExpectNoOutput();
}

TEST(CliBadRig, MissingRig) {
  const std::string missing = (TestDir() / "missing.json").string();
  ExpectRigRefused(RenderRig(missing), missing, "error: no such file");
  ExpectNoOutput();
}

TEST(CliBadRig, UnreadableRig) {
  const fs::path locked = TestDir() / "locked.json";
  fs::copy_file(BadRigPath("size_absurd.json"), locked, fs::copy_options::overwrite_existing);
  ASSERT_EQ(chmod(locked.c_str(), 0), 0);
  if (access(locked.c_str(), R_OK) == 0) {
    chmod(locked.c_str(), 0644);
    GTEST_SKIP() << "running as root (or with CAP_DAC_OVERRIDE): a mode-000 file is still readable";
  }
  const ProcessResult r = RenderRig(locked.string());
  chmod(locked.c_str(), 0644);
  ExpectRigRefused(r, locked.string(), "error: cannot open the rig file");
  ExpectNoOutput();
}

TEST(CliBadRig, RigOverTheSizeLimitIsRefusedBeforeReading) {
  const fs::path huge = TestDir() / "huge.json";
  std::ofstream(huge).close();
  fs::resize_file(huge, app::kMaxRigFileBytes + 1);  // sparse: no disk used
  ExpectRigRefused(RenderRig(huge.string()), huge.string(),
                   "error: expected a rig file of at most 16 MiB, found 16777217 bytes");
  ExpectNoOutput();
}

// The in-memory reader on the same corpus: never throws, always names the file.
TEST(CliBadRig, ParseRigAnswersEveryCorpusFileWithAnError) {
  for (const RigCase& c : kRigCases) {
    SCOPED_TRACE(c.file);
    std::ifstream in(BadRigPath(c.file), std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const base::Result<app::Rig> rig = app::ParseRig(text, "r.json");
    // The motion and the frame range are checked when rendering, not parsing.
    const std::string name = c.file;
    if (name.rfind("motion_", 0) == 0 || name == "frames_reversed.json") {
      EXPECT_TRUE(rig.ok());
      continue;
    }
    ASSERT_FALSE(rig.ok());
    EXPECT_EQ(rig.error().ToString().rfind("r.json", 0), 0u) << rig.error().ToString();
  }
}

}  // namespace
