// `patchskin check`, run as a process on a small manifest (160x90 frames): the
// missing references, --update-all, a clean pass, frames byte-identical to
// `render`, a case broken on purpose (a patch radius changed in its rig), the
// summary, the exit codes, the JUnit file (parsed with tinyxml2), --update, and
// the HTML report opened in headless Chromium (skipped where it is absent).

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyxml2.h>

#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;

fs::path Samples(const std::string& name) {
  return fs::weakly_canonical(testsupport::TestDataPath("../../samples/" + name));
}

// A fresh folder per test (ctest runs the tests of this file as parallel processes).
void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// A folder holding a rig (elbow_knee with its motion), its manifest (three
// cases: two BVH renders, the rig) and the rig's path.
struct Project {
  fs::path dir, manifest, rig, out, references;
};

Project MakeProject() {
  Project p;
  p.dir = TestDir();
  fs::remove_all(p.dir);
  fs::create_directories(p.dir / "rigs");
  fs::copy_file(Samples("data/elbow_knee.json"), p.dir / "rigs/elbow_knee.json");
  fs::copy_file(Samples("data/bend.bvh"), p.dir / "rigs/bend.bvh");
  p.rig = p.dir / "rigs/elbow_knee.json";
  p.manifest = p.dir / "manifest.json";
  p.out = p.dir / "out";
  p.references = p.dir / "reference";
  const std::string walk = Samples("data/demo_walk.bvh").string();
  WriteText(p.manifest, R"({
  "thresholds": {"fail": 0.004, "failpercent": 0.02},
  "cases": [
    {"name": "walk_ssd", "input": ")" + walk + R"(",
     "options": "--size 160x90 --camera fixed", "frames": "0:40:20"},
    {"name": "walk_dqs", "input": ")" + walk + R"(",
     "options": ["--size", "160x90", "--global", "dqs"], "frames": "10:30:20"},
    {"name": "rig_elbows", "input": "rigs/elbow_knee.json",
     "options": "--size 160x90", "frames": "20:60:40"}
  ]
})");
  return p;
}

ProcessResult Check(const Project& p, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"check", p.manifest.string(), "--out", p.out.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  static int run = 0;
  return testsupport::RunPatchskin(args, p.dir / ("log" + std::to_string(run++)));
}

// Widens the rig's elbow patches (a rig parameter a user would change).
void BreakRig(const Project& p) {
  std::ifstream in(p.rig);
  nlohmann::json rig = nlohmann::json::parse(in);
  rig["patches"][0]["region"]["radius"] = 30;
  rig["patches"][1]["region"]["radius"] = 30;
  WriteText(p.rig, rig.dump(2));
}

std::string Slurp(const fs::path& p) { return testsupport::SlurpFile(p); }

// The project with references made by --update-all and the rig then broken.
Project BrokenProject() {
  Project p = MakeProject();
  const ProcessResult made = Check(p, {"--update-all"});
  EXPECT_EQ(made.exit_code, 0) << made.out << made.err;
  BreakRig(p);
  return p;
}

TEST(CheckCommand, MissingReferencesThenUpdateAllThenPass) {
  const Project p = MakeProject();
  const fs::path junit = p.dir / "junit.xml";
  ProcessResult r = Check(p, {"--junit", junit.string()});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.out.find("MISSING  walk_ssd    3 frames, 3 without a reference"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("check: 3 cases: 0 passed, 0 failed, 0 with warnings, 3 missing references, "
                       "0 errors"),
            std::string::npos)
      << r.out;
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(junit.c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(doc.FirstChildElement("testsuites")->IntAttribute("failures"), 3);

  r = Check(p, {"--update-all"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("references updated (0 replaced, 3 added)"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(p.references / "rig_elbows/frame_0060.png"));
  EXPECT_TRUE(fs::exists(p.references / "walk_dqs/frame_0030.png"));

  r = Check(p);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("PASS     rig_elbows  2 frames, all identical"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 passed, 0 failed"), std::string::npos) << r.out;
}

TEST(CheckCommand, FramesAreByteIdenticalToRender) {
  const Project p = MakeProject();
  ASSERT_EQ(Check(p).exit_code, 2);
  const fs::path own = p.dir / "render";
  const ProcessResult r = testsupport::RunPatchskin(
      {"render", Samples("data/demo_walk.bvh").string(), "--size", "160x90", "--global", "dqs",
       "--frames", "10:30:20", "--out", (own / "frame_####.png").string(), "--no-sheet",
       "--no-video", "--quiet"},
      p.dir / "render_log");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"frame_0010.png", "frame_0030.png"}) {
    const std::string ours = Slurp(p.out / "walk_dqs" / f);
    EXPECT_FALSE(ours.empty()) << f;
    EXPECT_EQ(ours, Slurp(own / f)) << f;
  }
}

TEST(CheckCommand, ABrokenCaseFailsInTheSummaryExitCodeAndJUnit) {
  const Project p = BrokenProject();
  const fs::path junit = p.dir / "junit.xml";
  const ProcessResult r = Check(p, {"--junit", junit.string()});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.out.find("PASS     walk_ssd    3 frames, all identical"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FAIL     rig_elbows  2 frames, 2 failing; worst frame"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("check: 3 cases: 2 passed, 1 failed, 0 with warnings, 0 missing references, "
                       "0 errors"),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(fs::exists(p.out / "rig_elbows/diff_0060.png"));

  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(junit.c_str()), tinyxml2::XML_SUCCESS) << Slurp(junit);
  const tinyxml2::XMLElement* suites = doc.FirstChildElement("testsuites");
  ASSERT_NE(suites, nullptr);
  const tinyxml2::XMLElement* suite = suites->FirstChildElement("testsuite");
  ASSERT_NE(suite, nullptr);
  EXPECT_STREQ(suite->Attribute("name"), "manifest");
  EXPECT_EQ(suite->IntAttribute("tests"), 3);
  EXPECT_EQ(suite->IntAttribute("failures"), 1);
  EXPECT_EQ(suite->IntAttribute("errors"), 0);
  int cases = 0;
  for (const tinyxml2::XMLElement* tc = suite->FirstChildElement("testcase"); tc != nullptr;
       tc = tc->NextSiblingElement("testcase")) {
    ++cases;
    const tinyxml2::XMLElement* failure = tc->FirstChildElement("failure");
    if (std::string(tc->Attribute("name")) == "rig_elbows") {
      ASSERT_NE(failure, nullptr);
      EXPECT_STREQ(failure->Attribute("type"), "ImageDifference");
      EXPECT_NE(std::string(failure->GetText()).find("frame 60: FAILURE"), std::string::npos);
    } else {
      EXPECT_EQ(tc->FirstChildElement(), nullptr) << tc->Attribute("name");
    }
  }
  EXPECT_EQ(cases, 3);

  // The report is one page that needs nothing else: images are data: URIs.
  const std::string html = Slurp(p.out / "report.html");
  EXPECT_EQ(html.find("http"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("src=\"data:image/png;base64,"), html.find("src=\""));
  EXPECT_LT(html.find("case-rig_elbows"), html.find("case-walk_ssd"));

  // The same results give the same bytes (no times in either file).
  const fs::path junit2 = p.dir / "junit2.xml", html2 = p.dir / "report2.html";
  EXPECT_EQ(Check(p, {"--junit", junit2.string(), "--html", html2.string()}).exit_code, 2);
  EXPECT_EQ(Slurp(junit2), Slurp(junit));
  EXPECT_EQ(Slurp(html2), html);
}

TEST(CheckCommand, UpdateReplacesOnlyTheCasesThatDiffer) {
  const Project p = BrokenProject();
  const std::string walk_before = Slurp(p.references / "walk_ssd/frame_0020.png");
  const std::string rig_before = Slurp(p.references / "rig_elbows/frame_0060.png");
  fs::remove(p.references / "walk_ssd/frame_0020.png");
  ProcessResult r = Check(p, {"--update"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("FAIL     rig_elbows  2 frames, 2 failing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("references updated (2 replaced, 0 added)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("MISSING  walk_ssd    3 frames, 1 without a reference"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("references updated (2 replaced, 1 added)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("walk_dqs    2 frames, all identical -> references updated"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(Slurp(p.references / "walk_ssd/frame_0020.png"), walk_before);
  EXPECT_NE(Slurp(p.references / "rig_elbows/frame_0060.png"), rig_before);
  r = Check(p);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  // A reference of a frame no longer rendered is named in the case's line.
  fs::copy_file(p.references / "walk_ssd/frame_0020.png", p.references / "walk_ssd/frame_0099.png");
  r = Check(p);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("walk_ssd    3 frames (1 reference frames not rendered), all identical"),
            std::string::npos)
      << r.out;
}

TEST(CheckCommand, WarningsErrorsAndBadManifests) {
  const Project p = BrokenProject();
  // Failing pixels allowed for the rig: a warning, exit 1. The rig's camera is
  // aimed at its patch, so the wider region also moves the camera and about
  // half of the pixels change: allow 60 %.
  std::string text = Slurp(p.manifest);
  const std::string rig_frames = R"("frames": "20:60:40"})";
  text.replace(text.find(rig_frames), rig_frames.size(),
               R"("frames": "20:60:40", "thresholds": {"failpercent": 60, "warn": 0.004}})");
  WriteText(p.manifest, text);
  ProcessResult r = Check(p);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("WARN     rig_elbows"), std::string::npos) << r.out;

  // An unreadable reference: an error, exit 4, named.
  WriteText(p.references / "walk_ssd/frame_0020.png", "not a png");
  r = Check(p);
  EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
  EXPECT_NE(r.out.find("ERROR    walk_ssd    cannot compare: "), std::string::npos) << r.out;

  // A missing input: the render's error, exit 4.
  fs::remove(p.rig);
  r = Check(p);
  EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
  EXPECT_NE(r.out.find("ERROR    rig_elbows  the render failed (exit 2): "), std::string::npos)
      << r.out;

  // Bad manifests: exit 4, the file and the field named.
  WriteText(p.manifest, R"({"cases": [{"name": "a", "input": "x.bvh", "options": "--out y"}]})");
  r = Check(p);
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(r.FirstErrLine(), p.manifest.string() +
                                  ": cases[0].options: error: render option --out is set by check "
                                  "(use the case's \"frames\" for frames)");
  WriteText(p.manifest, R"({"cases": [{"name": "a b", "input": "x.bvh"}]})");
  EXPECT_EQ(Check(p).FirstErrLine(),
            p.manifest.string() +
                ": cases[0].name: error: expected a name of letters, digits, '_', '-' and '.', "
                "found \"a b\"");
  WriteText(p.manifest, R"({"cases": [{"name": "a", "input": "x.bvh", "options": "--sise 3"}]})");
  r = Check(p);
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.FirstErrLine().find("cases[0].options: error: render options: "), std::string::npos)
      << r.err;
  WriteText(p.manifest, R"({"cases": [{"name": "a", "input": "x.bvh"}], "case": []})");
  EXPECT_EQ(Check(p).FirstErrLine(),
            p.manifest.string() +
                ": case: error: unknown field (expected one of: references, thresholds, cases)");
  WriteText(p.manifest, R"({"cases": [{"name": "a", "input": "x.bvh", "options": "--help"}]})");
  EXPECT_EQ(Check(p).FirstErrLine(),
            p.manifest.string() + ": cases[0].options: error: render option --help is not a render setting");
  WriteText(p.manifest, "{\"cases\": [\n  {\"name\": \"a\",}\n]}");
  r = Check(p);
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(r.FirstErrLine().rfind(p.manifest.string() + ":2:", 0), 0u) << r.err;
  EXPECT_EQ(Check(p, {"--update", "--update-all"}).exit_code, 4);
  // 10^5 nested arrays where a case belongs: the message describes the value
  // without serializing it (dump() recurses once per level).
  WriteText(p.manifest, "{\"cases\": [" + std::string(100000, '[') + std::string(100000, ']') + "]}");
  r = Check(p);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_EQ(r.FirstErrLine(),
            p.manifest.string() + ": cases[0]: error: expected an object, found an array (1 item)");
}

// The README's sample: the first run writes its references, the second passes.
TEST(CheckCommand, SampleManifestRunsAsDocumented) {
  const fs::path dir = TestDir();
  fs::remove_all(dir);
  const std::vector<std::string> base{"check", Samples("check/manifest.json").string(), "--out",
                                      (dir / "out").string(), "--references",
                                      (dir / "reference").string()};
  std::vector<std::string> update = base;
  update.push_back("--update-all");
  ProcessResult r = testsupport::RunPatchskin(update, dir / "log_update");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(fs::exists(dir / "reference/elbow_knee_patches/frame_0030.png")) << r.out;
  r = testsupport::RunPatchskin(base, dir / "log_check");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("check: 3 cases: 3 passed, 0 failed"), std::string::npos) << r.out;
}

// The HTML report as a browser shows it: headless Chromium's screenshot must show
// the failing case (its red heading) above the passing ones (green headings).
TEST(CheckCommand, ReportInChromiumShowsTheFailingCaseFirst) {
  std::string chromium = testsupport::FindProgram("chromium");
  if (chromium.empty()) chromium = testsupport::FindProgram("chromium-browser");
  const std::string timeout = testsupport::FindProgram("timeout");
  if (chromium.empty() || timeout.empty()) {
    GTEST_SKIP() << "chromium is not installed (Debian package chromium; scripts/setup.sh "
                    "installs it): the report is not opened in a browser";
  }
  const Project p = BrokenProject();
  ASSERT_EQ(Check(p).exit_code, 2);
  const std::string url = "file://" + fs::absolute(p.out / "report.html").string();
  const fs::path shot = p.dir / "screenshot.png";
  const std::vector<std::string> common{
      chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
      "--user-data-dir=" + (p.dir / "chromium-profile").string(), "--window-size=1000,800"};
  std::vector<std::string> args{"60"};
  args.insert(args.end(), common.begin(), common.end());
  std::vector<std::string> shot_args = args;
  shot_args.push_back("--screenshot=" + shot.string());
  shot_args.push_back(url);
  const ProcessResult s = testsupport::RunProgram(timeout, shot_args, p.dir / "chromium_shot");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  std::vector<std::string> dom_args = args;
  dom_args.push_back("--dump-dom");
  dom_args.push_back(url);
  const ProcessResult d = testsupport::RunProgram(timeout, dom_args, p.dir / "chromium_dom");
  ASSERT_EQ(d.exit_code, 0) << d.err;

  // The DOM as Chromium built it: the failing case's section comes first.
  const std::string first = "<section class=\"case status-";
  const std::size_t a = d.out.find(first);
  ASSERT_NE(a, std::string::npos) << d.out.substr(0, 2000);
  EXPECT_EQ(d.out.compare(a, first.size() + 26, first + "fail\" id=\"case-rig_elbows\""), 0)
      << d.out.substr(a, 200);
  EXPECT_NE(d.out.find("type=\"range\""), std::string::npos);

  // The screenshot: down the left edge of the cases, the first status colour is
  // the failure's red (#c62828), and a pass's green (#2e7d32) follows below it.
  base::Result<render::Image> img = render::ReadImage(shot.string());
  ASSERT_TRUE(img.ok()) << img.error().ToString();
  ASSERT_EQ(img->width, 1000);
  int first_red = -1, first_green = -1;
  for (int y = 0; y < img->height; ++y) {
    const glm::vec4 c = img->at(24, y);
    const int r = render::LinearToSrgb8(c.r), g = render::LinearToSrgb8(c.g),
              b = render::LinearToSrgb8(c.b);
    const bool red = r > 170 && g < 70 && b < 70;
    const bool green = g > 100 && r < 80 && b < 80;
    if (red && first_red < 0) first_red = y;
    if (green && first_green < 0) first_green = y;
  }
  EXPECT_GE(first_red, 0) << "no red heading in " << shot;
  EXPECT_GT(first_green, first_red) << "the pass's green heading must follow the failure's red, in "
                                    << shot;
}

}  // namespace
