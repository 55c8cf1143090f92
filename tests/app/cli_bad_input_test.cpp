// Bad input to the command line, run as a process (PATCHSKIN_BINARY): every
// case must exit 2, say on the first stderr line which file (and line, where
// there is one) is wrong and what was expected, and leave the output folder
// empty. Inputs: the malformed corpora in tests/data/{bvh,gltf}/bad plus files
// written here (binary noise, an empty file, a folder, an unreadable file).

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli_outputs.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::ExpectNoOutput;
using testsupport::kExitBadInput;
using testsupport::OutDir;
using testsupport::RunPatchskin;
using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;

// A fresh folder per test (ctest runs each test as its own process).
ProcessResult RenderInput(const std::string& input, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"render"};
  if (!input.empty()) args.push_back(input);
  if (std::find(extra.begin(), extra.end(), "--size") == extra.end()) {
    args.insert(args.end(), {"--size", "64x36"});
  }
  args.insert(args.end(), {"--quiet", "--out", (OutDir() / "f_####.png").string()});
  args.insert(args.end(), extra.begin(), extra.end());
  return RunPatchskin(args);
}

// No file (not even a temporary one) was created where the frames would go.
// Exit 2; first stderr line "<file>[:line[:col]]: error: ..." holding `expect`.
void ExpectBadInput(const ProcessResult& r, const std::string& file, bool with_line,
                    const std::string& expect) {
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  const std::string first = r.FirstErrLine();
  const std::string loc = with_line ? "(:[0-9]+)(:[0-9]+)?" : "(:[0-9]+)?(:[0-9]+)?(: [^:]+)?";
  // Regex-escape the file name.
  const std::string escaped = std::regex_replace(file, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)");
  EXPECT_TRUE(std::regex_search(first, std::regex("^" + escaped + loc + ": error: ")))
      << "first stderr line: " << first;
  EXPECT_NE(first.find(expect), std::string::npos) << "first stderr line: " << first;
}

std::string BadBvh(const std::string& name) { return testsupport::TestDataPath("bvh/bad/" + name).string(); }
std::string BadGltf(const std::string& name) { return testsupport::TestDataPath("gltf/bad/" + name).string(); }

// Each malformed BVH kind, through both commands.
struct BvhCase {
  const char* file;
  const char* expect;  // part of the message: what was expected or found
};
const BvhCase kBvhCases[] = {
    {"empty.bvh", "HIERARCHY"},
    {"truncated_hierarchy.bvh", "expected"},
    {"truncated_motion.bvh", "expected 9 values"},
    {"offset_nan.bvh", "finite"},
    {"value_nan.bvh", "finite"},
    {"value_inf.bvh", "finite"},
    {"frames_absurd.bvh", "frame count"},
    {"frames_huge_declared.bvh", "frames"},
    {"depth_limit.bvh", "depth"},
    {"channels_count_too_big.bvh", "channel count from 0 to 6"},
};

TEST(CliBadInput, InspectMalformedBvh) {
  for (const BvhCase& c : kBvhCases) {
    SCOPED_TRACE(c.file);
    ExpectBadInput(RunPatchskin({"inspect", BadBvh(c.file)}), BadBvh(c.file), true, c.expect);
  }
}

TEST(CliBadInput, RenderMalformedBvh) {
  for (const BvhCase& c : kBvhCases) {
    SCOPED_TRACE(c.file);
    ExpectBadInput(RenderInput(BadBvh(c.file)), BadBvh(c.file), true, c.expect);
    ExpectNoOutput();
  }
}

TEST(CliBadInput, BinaryNoiseAsBvh) {
  const fs::path noise = TestDir() / "noise.bvh";
  {
    std::mt19937 rng(9);
    std::ofstream f(noise, std::ios::binary);
    for (int i = 0; i < 4096; ++i) f.put(static_cast<char>(rng() & 0xff));
  }
  ExpectBadInput(RunPatchskin({"inspect", noise.string()}), noise.string(), true, "HIERARCHY");
  ExpectBadInput(RenderInput(noise.string()), noise.string(), true, "HIERARCHY");
  ExpectNoOutput();
}

TEST(CliBadInput, MalformedGltf) {
  const std::pair<const char*, const char*> cases[] = {
      {"nan_position.gltf", "accessors[0]"},       {"accessor_out_of_range.gltf", "accessors[0].count"},
      {"uri_dotdot.gltf", "buffers[0].uri"},        {"uri_absolute.gltf", "buffers[0].uri"},
      {"truncated.glb", "glb header.length"},       {"broken_json.gltf", "tinygltf"},
      {"node_cycle.gltf", "nodes"},
  };
  for (const auto& [file, expect] : cases) {
    SCOPED_TRACE(file);
    ExpectBadInput(RunPatchskin({"inspect", BadGltf(file)}), BadGltf(file), false, expect);
    ExpectBadInput(RenderInput(BadGltf(file)), BadGltf(file), false, expect);
    ExpectNoOutput();
  }
}

TEST(CliBadInput, EmptyGltf) {
  const fs::path empty = TestDir() / "empty.gltf";
  std::ofstream(empty).close();
  ExpectBadInput(RenderInput(empty.string()), empty.string(), false, "tinygltf");
  ExpectNoOutput();
}

TEST(CliBadInput, DirectoryWhereAFileBelongs) {
  const fs::path folder = TestDir() / "walk.bvh";
  fs::create_directories(folder);
  ExpectBadInput(RunPatchskin({"inspect", folder.string()}), folder.string(), false,
                 "found a directory");
  ExpectBadInput(RenderInput(folder.string()), folder.string(), false, "found a directory");
  ExpectNoOutput();
}

TEST(CliBadInput, MissingFile) {
  const std::string missing = (TestDir() / "missing.bvh").string();
  ExpectBadInput(RenderInput(missing), missing, false, "no such file");
  ExpectNoOutput();
}

TEST(CliBadInput, UnknownExtension) {
  const fs::path txt = TestDir() / "walk.txt";
  std::ofstream(txt) << "HIERARCHY\n";
  ExpectBadInput(RenderInput(txt.string()), txt.string(), false, "expected a .bvh, .gltf or .glb");
  ExpectNoOutput();
}

TEST(CliBadInput, UnreadableFile) {
  const fs::path locked = TestDir() / "locked.bvh";
  fs::copy_file(testsupport::TestDataPath("../../samples/data/demo_walk.bvh"), locked,
                fs::copy_options::overwrite_existing);
  ASSERT_EQ(chmod(locked.c_str(), 0), 0);
  if (access(locked.c_str(), R_OK) == 0) {
    chmod(locked.c_str(), 0644);
    GTEST_SKIP() << "running as root (or with CAP_DAC_OVERRIDE): a mode-000 file is still readable";
  }
  const ProcessResult inspect = RunPatchskin({"inspect", locked.string()});
  const ProcessResult render = RenderInput(locked.string());
  chmod(locked.c_str(), 0644);
  ExpectBadInput(inspect, locked.string(), false, "open");
  ExpectBadInput(render, locked.string(), false, "open");
  ExpectNoOutput();
}

// Bad options: the option is named where a file would be; nothing is written.
TEST(CliBadInput, BadRenderOptions) {
  const struct {
    std::vector<std::string> args;
    const char* option;
    const char* expect;
  } cases[] = {
      {{"--size", "0x0"}, "--size", "within 16.."},
      {{"--size", "100000x100000"}, "--size", "within 16.."},
      {{"--size", "big"}, "--size", "expected WIDTHxHEIGHT"},
      {{"--size", "16384x16384"}, "--size", "samples per frame"},
      {{"--frames", "5:2"}, "--frames", "A <= B"},
      {{"--frames", "0:100000"}, "--frames", "outside the motion's frames"},
      {{"--frames", "0:5:0"}, "--frames", "STEP must be at least 1"},
      {{"--supersample", "3"}, "--supersample", "expected 1, 2 or 4"},
      {{"--threads", "100000"}, "--threads", "expected 0..256"},
      {{"--turntable-frames", "1000000000"}, "--turntable-frames", "expected 1..100000"},
      {{"--global", "magic"}, "--global", "expected ssd, dqs or swd"},
      {{"--fps", "nan"}, "--fps", "expected 0 < fps"},
      {{"--fps", "inf"}, "--fps", "expected 0 < fps"},
      {{"--fps", "-24"}, "--fps", "expected 0 < fps"},
      {{"--size", "99999x99999"}, "--size", "within 16.."},
      {{"--size", "-64x36"}, "--size", "within 16.."},
      {{"--frames", "-5:2"}, "--frames", "outside the motion's frames"},
      {{"--frames", "0:99999999999"}, "--frames", "expected whole numbers"},
      {{"--threads", "-1"}, "--threads", "expected 0..256"},
      {{"--threads", "10000"}, "--threads", "expected 0..256"},
      {{"--supersample", "0"}, "--supersample", "expected 1, 2 or 4"},
      {{"--png-compression", "10"}, "--png-compression", "expected 0..9"},
      {{"--aa", "fxaa"}, "--aa", "expected ssaa or msaa"},
      {{"--shadows", "soft"}, "--shadows", "expected on or off"},
      {{"--turntable-frames", "0"}, "--turntable-frames", "expected 1..100000"},
      {{"--elevation", "nan"}, "--elevation", "expected degrees in -89..89"},
      {{"--elevation", "90"}, "--elevation", "expected degrees in -89..89"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args[0] + " " + c.args[1]);
    const ProcessResult r = RenderInput("", c.args);
    EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
    EXPECT_EQ(r.FirstErrLine().rfind(std::string(c.option) + ": error: ", 0), 0u) << r.err;
    EXPECT_NE(r.FirstErrLine().find(c.expect), std::string::npos) << r.err;
    ExpectNoOutput();
  }
}

TEST(CliBadInput, OutputPatternWithoutPlaceholder) {
  const ProcessResult r =
      RunPatchskin({"render", "--quiet", "--out", (OutDir() / "frame.png").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  EXPECT_EQ(r.FirstErrLine().rfind("--out: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.FirstErrLine().find("placeholder"), std::string::npos) << r.err;
  ExpectNoOutput();
}

}  // namespace
