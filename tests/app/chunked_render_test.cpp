// Chunked renders (issue 8): `render --frames 0:29` and the same frames
// rendered as the chunks 0:9, 10:19 and 20:29 into the same pattern give
// byte-identical images, so a long range can be split across processes or
// machines. Covered: the built-in demo, a BVH with the follow and the fixed
// camera, and a rig with patches. What a frame may depend on: the whole
// motion (framing, ground) and the frames before it (the follow camera's
// window), never the requested range.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::SlurpFile;

// Renders `input` (empty: the demo) frames `frames` into folder/f_####.png.
void Render(const std::string& input, const std::string& frames, const fs::path& folder,
            const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"render"};
  if (!input.empty()) args.push_back(input);
  for (const char* a : {"--frames", frames.c_str(), "--size", "160x90", "--supersample", "1",
                               "--quiet", "--no-video", "--no-sheet", "--out"}) {
    args.push_back(a);
  }
  args.push_back((folder / "f_####.png").string());
  args.insert(args.end(), extra.begin(), extra.end());
  const testsupport::ProcessResult r =
      testsupport::RunPatchskin(args, folder.parent_path() / ("logs_" + folder.filename().string()));
  ASSERT_EQ(r.exit_code, 0) << frames << ": " << r.err;
}

// Whole 0:29 vs chunks of ten; every frame byte-identical.
void ExpectChunksMatchWhole(const std::string& input, const std::vector<std::string>& extra = {}) {
  const fs::path dir = TestDir();
  Render(input, "0:29", dir / "whole", extra);
  for (const char* chunk : {"0:9", "10:19", "20:29"}) Render(input, chunk, dir / "chunks", extra);
  const std::vector<fs::path> whole = testsupport::FilesIn(dir / "whole"),
                              chunks = testsupport::FilesIn(dir / "chunks");
  ASSERT_EQ(whole.size(), 30u);
  ASSERT_EQ(chunks.size(), 30u);
  for (std::size_t i = 0; i < whole.size(); ++i) {
    EXPECT_EQ(whole[i].filename(), chunks[i].filename());
    EXPECT_TRUE(SlurpFile(whole[i]) == SlurpFile(chunks[i]))
        << chunks[i] << " differs from the whole render's " << whole[i];
  }
}

TEST(ChunkedRender, DemoWithTheFollowCameraMatchesTheWholeRender) { ExpectChunksMatchWhole(""); }

TEST(ChunkedRender, BvhWithTheFollowCameraMatchesTheWholeRender) {
  ExpectChunksMatchWhole(testsupport::SampleDataPath("bend.bvh").string(), {"--global", "dqs"});
}

TEST(ChunkedRender, BvhWithTheFixedCameraMatchesTheWholeRender) {
  ExpectChunksMatchWhole(testsupport::SampleDataPath("bend.bvh").string(), {"--camera", "fixed"});
}

TEST(ChunkedRender, RigWithPatchesMatchesTheWholeRender) {
  const fs::path dir = testsupport::TestOutputPath("chunked_render/rig/x").parent_path();
  fs::create_directories(dir);
  const fs::path rig = dir / "patches.json";
  std::ofstream(rig)
      << R"({"character": "mannequin", "motion": {"file": ")"
      << testsupport::SampleDataPath("bend.bvh").string() << R"("}, "global": "ssd", "patches": [)"
      << R"({"name": "left_elbow", "region": {"joint": "LeftForeArm", "radius": 14,)"
      << R"( "side": [0, 0, 1], "half_angle_deg": 120}, "parametrization": "cylinder",)"
      << R"( "sampling": [8, 8], "grid": [6, 6], "border_width": 0.1}],)"
      << R"( "render": {"size": [160, 90], "camera": "follow"}})";
  ExpectChunksMatchWhole(rig.string());
}

// The cameras aimed at an effect (issue 24) keep the property: a look-at
// follow camera smooths over the frames before it only, and a fixed look-at
// camera frames samples of the whole motion. The example-shape demos at their
// own cameras, side by side, with patches and examples.
TEST(ChunkedRender, LookAtTheElbowFromTheSideMatchesTheWholeRender) {
  ExpectChunksMatchWhole(
      testsupport::SampleDataPath("bend.bvh").string(),
      {"--look-at", "LeftForeArm", "--azimuth", "90", "--zoom", "1.5", "--compare", "ssd,dqs"});
}

TEST(ChunkedRender, FixedCameraOnAJointMatchesTheWholeRender) {
  ExpectChunksMatchWhole(
      testsupport::SampleDataPath("bend.bvh").string(),
      {"--camera", "fixed", "--look-at", "LeftLeg", "--elevation", "-10", "--distance", "60"});
}

TEST(ChunkedRender, DemoRigAtItsOwnCameraMatchesTheWholeRender) {
  ExpectChunksMatchWhole(testsupport::SampleDataPath("elbow.json").string(), {"--threads", "2"});
}

// The overlays of the layer (the delta's scale is the frame's own), the
// timecode and a transparent background, on an elastic demo (state carried).
TEST(ChunkedRender, OverlaysLabelsAndTransparencyMatchTheWholeRender) {
  ExpectChunksMatchWhole(testsupport::SampleDataPath("jowl.json").string(),
                         {"--overlay", "delta,patches,wire", "--label", "timecode", "--background",
                          "transparent", "--threads", "3"});
}

}  // namespace
