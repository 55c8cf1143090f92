// Command-line options override a rig file's render settings: for each of
// --size, --camera, --overlay, --split, --out, --frames, --global and
// --threads, `render RIG --option X` must give what a rig saying X gives (or,
// where no rig field exists, what the option means), run as a process.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using nlohmann::json;
using testsupport::ProcessResult;
using testsupport::SlurpFile;

// A rig on the mannequin bending its elbows (samples/data/bend.bvh), tiny frames.
json BaseRig(const std::string& output) {
  return {{"character", "mannequin"},
          {"motion", {{"file", testsupport::SampleDataPath("bend.bvh").string()}}},
          {"global", "ssd"},
          {"render",
           {{"size", {64, 36}}, {"camera", "follow"}, {"frames", "30:31"}, {"output", output}}}};
}

json WithElbowPatch(json rig) {
  rig["patches"] = json::array({{{"name", "left_elbow"},
                                 {"region",
                                  {{"joint", "LeftForeArm"}, {"radius", 14}, {"side", {0, 0, 1}}}},
                                 {"grid", {4, 4}},
                                 {"sampling", {6, 6}}}});
  return rig;
}

std::string WriteRig(const fs::path& dir, const std::string& name, const json& rig) {
  const fs::path path = dir / name;
  std::ofstream(path) << rig.dump(1);
  return path.string();
}

ProcessResult RenderRig(const fs::path& dir, const std::string& rig,
                        std::vector<std::string> extra) {
  std::vector<std::string> args{"render", rig, "--quiet", "--no-video", "--no-sheet",
                                "--supersample", "1"};
  args.insert(args.end(), extra.begin(), extra.end());
  return testsupport::RunPatchskin(args, dir / "logs");
}

std::string Bytes(const fs::path& p) {
  EXPECT_TRUE(fs::exists(p)) << p;
  return SlurpFile(p);
}

// Same pixels (the PNG metadata names the rig file, so bytes differ between rigs).
bool SamePixels(const fs::path& a, const fs::path& b) {
  const auto ia = render::ReadImage(a.string());
  const auto ib = render::ReadImage(b.string());
  EXPECT_TRUE(ia.ok()) << a;
  EXPECT_TRUE(ib.ok()) << b;
  return ia.ok() && ib.ok() && ia->width == ib->width && ia->height == ib->height && ia->rgba == ib->rgba;
}

// Renders `a` with `option` and `b` (the rig that says the same) and expects
// the same bytes in frame 30 (and frame 31).
void ExpectSameAsRig(const std::string& name, const json& a, const std::vector<std::string>& option,
                     const json& b) {
  const fs::path d = TestDir();
  const std::string rig_a = WriteRig(d, "a.json", a);
  const std::string rig_b = WriteRig(d, "b.json", b);
  const ProcessResult ra = RenderRig(d, rig_a, option);
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  const ProcessResult rb = RenderRig(d, rig_b, {});
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  for (const char* frame : {"0030", "0031"}) {
    EXPECT_TRUE(SamePixels(d / "out_a" / (std::string("f_") + frame + ".png"),
                           d / "out_b" / (std::string("f_") + frame + ".png")))
        << name << " frame " << frame;
  }
  // And the option really changed something: the rig alone gives other bytes.
  const ProcessResult plain = RenderRig(d, rig_a, {"--out", (d / "plain/f_####.png").string()});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(SamePixels(d / "plain/f_0030.png", d / "out_b/f_0030.png")) << name;
}

TEST(RigOverrides, SizeWins) {
  const fs::path d = TestDir();
  const std::string rig = WriteRig(d, "rig.json", BaseRig("out/f_####.png"));
  const ProcessResult r = RenderRig(d, rig, {"--size", "80x48"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto image = render::ReadImage((d / "out/f_0030.png").string());
  ASSERT_TRUE(image.ok()) << image.error().ToString();
  EXPECT_EQ(image->width, 80);
  EXPECT_EQ(image->height, 48);
}

TEST(RigOverrides, CameraWins) {
  json b = BaseRig("out_b/f_####.png");
  b["render"]["camera"] = "fixed";
  ExpectSameAsRig("camera", BaseRig("out_a/f_####.png"), {"--camera", "fixed"}, b);
}

TEST(RigOverrides, OverlayWins) {
  json b = BaseRig("out_b/f_####.png");
  b["render"]["overlays"] = {"skeleton"};
  ExpectSameAsRig("overlay", BaseRig("out_a/f_####.png"), {"--overlay", "skeleton"}, b);
}

TEST(RigOverrides, GlobalWins) {
  json b = BaseRig("out_b/f_####.png");
  b["global"] = "dqs";
  ExpectSameAsRig("global", BaseRig("out_a/f_####.png"), {"--global", "dqs"}, b);
}

TEST(RigOverrides, SplitWins) {
  // --wipe on the rig: left ssd, right ssd + patches, one view. --split (the
  // old name of --wipe) ssd,dqs: left ssd, right dqs + patches. Same left half,
  // a different right half.
  const fs::path d = TestDir();
  const std::string rig = WriteRig(d, "rig.json", WithElbowPatch(BaseRig("out/f_####.png")));
  ASSERT_EQ(RenderRig(d, rig, {"--size", "96x48", "--wipe"}).exit_code, 0);
  const ProcessResult r = RenderRig(
      d, rig, {"--size", "96x48", "--split", "ssd,dqs", "--out", (d / "cli/f_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto from_rig = render::ReadImage((d / "out/f_0031.png").string());
  const auto from_cli = render::ReadImage((d / "cli/f_0031.png").string());
  ASSERT_TRUE(from_rig.ok() && from_cli.ok());
  ASSERT_EQ(from_rig->width, 96);
  int left_diff = 0, right_diff = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 96; ++x) {
      const bool differs = from_rig->at(x, y) != from_cli->at(x, y);
      (x < 48 ? left_diff : right_diff) += differs ? 1 : 0;
    }
  }
  EXPECT_EQ(left_diff, 0) << "the left half is ssd in both";
  EXPECT_GT(right_diff, 0) << "the right half is dqs + patches from the command line";
}

// A rig with patches compares side by side by default: the same frames as
// --compare ssd,ssd+patches. --compare ssd,ssd shows the same body twice,
// framed alike: the two halves agree pixel for pixel below the labels, apart
// from the frame number (bottom left) and the divider.
TEST(RigOverrides, RigWithPatchesComparesSideBySide) {
  const fs::path d = TestDir();
  const std::string rig = WriteRig(d, "rig.json", WithElbowPatch(BaseRig("out/f_####.png")));
  ASSERT_EQ(RenderRig(d, rig, {"--size", "192x96"}).exit_code, 0);
  ProcessResult r = RenderRig(d, rig,
                              {"--size", "192x96", "--compare", "ssd,ssd + patches", "--out",
                               (d / "cli/f_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RenderRig(
      d, rig,
      {"--size", "192x96", "--compare", "ssd,ssd", "--out", (d / "same/f_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto from_rig = render::ReadImage((d / "out/f_0031.png").string());
  const auto from_cli = render::ReadImage((d / "cli/f_0031.png").string());
  const auto same = render::ReadImage((d / "same/f_0031.png").string());
  ASSERT_TRUE(from_rig.ok() && from_cli.ok() && same.ok());
  EXPECT_EQ(from_rig->rgba, from_cli->rgba);
  int differing = 0, compared = 0;
  for (int y = 34; y < 64; ++y) {  // between the labels
    for (int x = 2; x < 94; ++x) {
      differing += same->at(x, y) != same->at(x + 96, y) ? 1 : 0;
      ++compared;
    }
  }
  EXPECT_EQ(differing, 0) << "of " << compared;
  // A side asking for patches needs a rig that has them.
  const ProcessResult bad = testsupport::RunPatchskin(
      {"render", (testsupport::TestDataPath("../../samples/data/bend.bvh")).lexically_normal().string(),
       "--compare", "ssd,ssd+patches", "--quiet", "--no-video", "--no-sheet", "--out",
       (d / "bad/f_####.png").string()},
      d / "logs_bad");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--compare"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(d / "bad"));
}

TEST(RigOverrides, OutWins) {
  const fs::path d = TestDir();
  const std::string rig = WriteRig(d, "rig.json", BaseRig("out/f_####.png"));
  const ProcessResult r = RenderRig(d, rig, {"--out", (d / "elsewhere/g_####.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(d / "elsewhere/g_0030.png"));
  EXPECT_TRUE(fs::exists(d / "elsewhere/g_0031.png"));
  EXPECT_FALSE(fs::exists(d / "out"));
}

TEST(RigOverrides, FramesWin) {
  const fs::path d = TestDir();
  const std::string rig = WriteRig(d, "rig.json", BaseRig("out/f_####.png"));
  const ProcessResult r = RenderRig(d, rig, {"--frames", "5:7:2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(d / "out")) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"f_0005.png", "f_0007.png"}));
}

TEST(RigOverrides, ThreadsAreRead) {
  const fs::path d = TestDir();
  const std::string rig = WriteRig(d, "rig.json", BaseRig("out/f_####.png"));
  const ProcessResult bad = RenderRig(d, rig, {"--threads", "999"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.FirstErrLine().find("--threads"), std::string::npos) << bad.err;
  ASSERT_EQ(
      RenderRig(d, rig, {"--threads", "1", "--out", (d / "t1/f_####.png").string()}).exit_code, 0);
  ASSERT_EQ(
      RenderRig(d, rig, {"--threads", "2", "--out", (d / "t2/f_####.png").string()}).exit_code, 0);
  EXPECT_TRUE(Bytes(d / "t1/f_0031.png") == Bytes(d / "t2/f_0031.png"));
}

}  // namespace

// --global swd on a rig with example shapes is refused with the rig's field
// path (their frames A exist for SSD and DQS only), not rendered without them.
TEST(RigOverrides, GlobalSwdRefusesExampleShapes) {
  const fs::path dir = TestDir();
  const std::string rig =
      (fs::path(TEST_DATA_DIR) / "../../samples/data/elbow.json").lexically_normal().string();
  const ProcessResult r = RenderRig(
      dir, rig, {"--global", "swd", "--frames", "0:0", "--out", (dir / "f_####.png").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("elbow.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("patches[0].examples"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not available with swd"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "f_0000.png"));
}
