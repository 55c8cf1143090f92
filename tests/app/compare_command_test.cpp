// `patchskin compare` as a drop-in for OpenImageIO 2.4's idiff: exit 0 pass,
// 1 warning, 2 failure, 4 error, every channel compared (Z included). Where idiff
// is installed (openimageio-tools), every pair is also given to idiff and the
// verdict, exit code and figures must be the same.

#include <cmath>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/output/image_io.h"
#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::ProcessResult;

// One folder per test: ctest runs the tests of this file as parallel processes.
ProcessResult RunCompare(const std::vector<std::string>& args) {
  std::vector<std::string> all{"compare"};
  all.insert(all.end(), args.begin(), args.end());
  return testsupport::RunPatchskin(all, TestDir() / "patchskin_log");
}

// 100x100 mid grey, with `changed` pixels of row 7 brightened by `steps` 8-bit codes.
std::string MakePng(const std::string& name, int changed, int steps, int width = 100) {
  render::Image img(width, 100, glm::vec4(render::Srgb8ToLinear(128), render::Srgb8ToLinear(128),
                                          render::Srgb8ToLinear(128), 1.0f));
  for (int i = 0; i < changed; ++i) {
    img.at(i, 7).r = render::Srgb8ToLinear(static_cast<std::uint8_t>(128 + steps));
  }
  const std::string path = (TestDir() / name).string();
  EXPECT_TRUE(render::WriteImage(img, path));
  return path;
}

// A 40x30 EXR (half RGBA + float Z) of a grey ramp at depth `z`.
std::string MakeExr(const std::string& name, float z) {
  render::Image img(40, 30, glm::vec4(0.25f, 0.5f, 0.75f, 1.0f));
  img.depth.assign(img.rgba.size(), z);
  for (int x = 0; x < 40; ++x) img.at(x, 3).g = 0.01f * static_cast<float>(x);
  const std::string path = (TestDir() / name).string();
  EXPECT_TRUE(render::WriteImage(img, path));
  return path;
}

// The figure lines (two-space indented) that idiff prints, in order, and the
// verdict (the last line).
struct Report {
  std::vector<std::string> figures;
  std::string verdict;
};

Report ParseReport(const std::string& out) {
  Report r;
  std::size_t start = 0;
  while (start < out.size()) {
    const std::size_t end = std::min(out.find('\n', start), out.size());
    const std::string line = out.substr(start, end - start);
    if (line.rfind("  ", 0) == 0) r.figures.push_back(line);
    if (!line.empty()) r.verdict = line;
    start = end + 1;
  }
  return r;
}

// The numbers in `line` and the text between them.
void SplitNumbers(const std::string& line, std::vector<double>& numbers, std::string& text) {
  static const std::regex kNumber(R"([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|inf)");
  text.clear();
  numbers.clear();
  std::size_t last = 0;
  for (auto it = std::sregex_iterator(line.begin(), line.end(), kNumber);
       it != std::sregex_iterator(); ++it) {
    text += line.substr(last, static_cast<std::size_t>(it->position()) - last) + "#";
    numbers.push_back(it->str() == "inf" ? INFINITY : std::stod(it->str()));
    last = static_cast<std::size_t>(it->position() + it->length());
  }
  text += line.substr(last);
}

// Runs idiff -v and patchskin compare on the same pair with the same options and
// requires the same exit code, verdict and figures (the numbers to 1e-5 relative:
// idiff sums on several threads, patchskin on one).
void ExpectSameAsIdiff(const std::string& a, const std::string& b,
                       const std::vector<std::string>& options, int expected_exit) {
  std::vector<std::string> ours = options;
  ours.push_back(a);
  ours.push_back(b);
  const ProcessResult p = RunCompare(ours);
  EXPECT_EQ(p.exit_code, expected_exit) << p.out << p.err;
  const std::string idiff = testsupport::FindProgram("idiff");
  if (idiff.empty()) {
    std::printf("idiff not installed (Debian openimageio-tools): checked patchskin alone\n");
    return;
  }
  std::vector<std::string> theirs{"-v"};
  theirs.insert(theirs.end(), ours.begin(), ours.end());
  const ProcessResult i = testsupport::RunProgram(idiff, theirs, TestDir() / "idiff_log");
  ASSERT_EQ(p.exit_code, i.exit_code) << "patchskin:\n" << p.out << p.err << "idiff:\n" << i.out << i.err;
  if (expected_exit == 4) return;  // an unreadable file: no figures to compare
  const Report rp = ParseReport(p.out), ri = ParseReport(i.out);
  EXPECT_EQ(rp.verdict, ri.verdict);
  // idiff's six figure lines come first in ours, in its order and format.
  ASSERT_GE(rp.figures.size(), ri.figures.size()) << p.out;
  ASSERT_EQ(ri.figures.size(), 6u) << i.out;
  for (std::size_t k = 0; k < ri.figures.size(); ++k) {
    std::vector<double> np, ni;
    std::string tp, ti;
    SplitNumbers(rp.figures[k], np, tp);
    SplitNumbers(ri.figures[k], ni, ti);
    EXPECT_EQ(tp, ti) << rp.figures[k] << "\n" << ri.figures[k];
    ASSERT_EQ(np.size(), ni.size()) << rp.figures[k] << "\n" << ri.figures[k];
    for (std::size_t n = 0; n < np.size(); ++n) {
      if (std::isinf(ni[n])) {
        EXPECT_TRUE(std::isinf(np[n])) << rp.figures[k];
      } else {
        EXPECT_NEAR(np[n], ni[n], 1e-5 * std::fabs(ni[n]) + 1e-12)
            << rp.figures[k] << "\n" << ri.figures[k];
      }
    }
  }
}

TEST(CompareCommand, IdenticalImagesPass) {
  const std::string a = MakePng("same_a.png", 0, 0);
  const std::string b = MakePng("same_b.png", 0, 0);
  ExpectSameAsIdiff(a, b, {}, 0);
  const ProcessResult r = RunCompare({a, b});
  EXPECT_NE(r.out.find("Max error  = 0\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Peak SNR = inf"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nPASS\n"), std::string::npos);
}

TEST(CompareCommand, SlightDifferenceFailsAtIdiffsDefaults) {
  // Two pixels two codes brighter: idiff's default (any value over 1e-6) fails them.
  const std::string a = MakePng("two_a.png", 0, 0);
  const std::string b = MakePng("two_b.png", 2, 2);
  ExpectSameAsIdiff(a, b, {}, 2);
  const ProcessResult r = RunCompare({a, b});
  EXPECT_NE(r.out.find("2 pixels (0.02%) over 1e-06"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("@ (0, 7, R)  values are 0.5019608, 0.5019608, 0.5019608, 1 vs "
                       "0.50980395, 0.5019608, 0.5019608, 1"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\nFAILURE\n"), std::string::npos);
}

TEST(CompareCommand, ThresholdsInBothSpellingsGiveIdiffsVerdicts) {
  const std::string a = MakePng("thr_a.png", 0, 0);
  const std::string b = MakePng("thr_b.png", 3, 2);  // 3 pixels (0.03 %) 2/255 = 0.0078 brighter
  // Failures allowed, warnings not: a warning (exit 1).
  ExpectSameAsIdiff(a, b, {"-failpercent", "0.05"}, 1);
  ExpectSameAsIdiff(a, b, {"-failpercent", "0.05", "-warnpercent", "0.02"}, 1);
  ExpectSameAsIdiff(a, b, {"-failpercent", "100", "-hardwarn", "0.001"}, 1);
  // Both allowed: pass; a hard limit under the largest error: failure again.
  ExpectSameAsIdiff(a, b, {"-failpercent", "0.05", "-warnpercent", "0.05"}, 0);
  ExpectSameAsIdiff(a, b, {"-failpercent", "0.05", "-warnpercent", "0.05", "-hardfail", "0.005"}, 2);
  // idiff 2.4 warns only when some pixel fails: values between warn and fail pass.
  ExpectSameAsIdiff(a, b, {"-fail", "0.01", "-warn", "0.005"}, 0);
  ExpectSameAsIdiff(a, b, {"-fail", "0.01", "-warn", "0.01", "-hardwarn", "0.005"}, 0);
  // -allowfailures N passes up to N failing pixels, even over -hardfail.
  ExpectSameAsIdiff(a, b, {"-allowfailures", "3"}, 0);
  ExpectSameAsIdiff(a, b, {"-allowfailures", "3", "-hardfail", "0.001"}, 0);
  ExpectSameAsIdiff(a, b, {"-allowfailures", "2"}, 2);
  // The double-dash spelling means the same.
  EXPECT_EQ(RunCompare({"--failpercent", "0.05", a, b}).exit_code, 1);
  EXPECT_EQ(RunCompare({"--fail", "0.01", "--warn", "0.01", a, b}).exit_code, 0);
  EXPECT_EQ(RunCompare({"--hardfail", "0.005", "--failpercent", "0.05", a, b}).exit_code, 2);
}

TEST(CompareCommand, VeryDifferentImagesFailAndWriteADiff) {
  const std::string a = MakePng("diff_a.png", 0, 0);
  const std::string b = MakePng("diff_b.png", 100, 120);
  ExpectSameAsIdiff(a, b, {"-failpercent", "0.5", "-warnpercent", "0.5"}, 2);
  const std::string d = (TestDir() / "d.png").string();
  const ProcessResult r = RunCompare({a, b, "--diff", d});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  ASSERT_TRUE(fs::exists(d));
  auto diff = render::ReadImage(d);
  ASSERT_TRUE(diff.ok());
  EXPECT_GT(diff->at(1, 7).r, 0.0f);
  EXPECT_EQ(diff->at(50, 50).r, 0.0f);
}

TEST(CompareCommand, DifferentSizesAreComparedOverBothAsIdiffDoes) {
  // The 60 columns only one image has count as black: a failure.
  const std::string a = MakePng("size_a.png", 0, 0);
  const std::string b = MakePng("size_b.png", 0, 0, 40);
  ExpectSameAsIdiff(a, b, {}, 2);
  const ProcessResult r = RunCompare({a, b});
  EXPECT_NE(r.out.find("Sizes differ: 100x100 and 40x100"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("6000 pixels (60%) over 1e-06"), std::string::npos) << r.out;
}

TEST(CompareCommand, DifferentChannelsAreComparedEveryOne) {
  // RGBA against RGB (JPEG drops alpha... use a 3-channel TIFF): A is 1 against 0.
  const std::string a = MakePng("ch_a.png", 0, 0);
  render::Image rgb(100, 100, glm::vec4(render::Srgb8ToLinear(128), render::Srgb8ToLinear(128),
                                        render::Srgb8ToLinear(128), 1.0f));
  const std::string b = (TestDir() / "ch_b.jpg").string();
  ASSERT_TRUE(render::WriteImage(rgb, b));
  ExpectSameAsIdiff(a, b, {"-fail", "0.01", "-warn", "0.01"}, 2);
  const ProcessResult r = RunCompare({a, b});
  EXPECT_NE(r.out.find("Channels differ: 4 and 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" A 1\n"), std::string::npos) << r.out;
}

TEST(CompareCommand, ExrWithChangedDepthFails) {
  // Same colour, Z doubled: before issue 28 this passed (depth was ignored).
  const std::string a = MakeExr("z_a.exr", 2.0f);
  const std::string b = MakeExr("z_b.exr", 4.0f);
  ExpectSameAsIdiff(a, b, {}, 2);
  const ProcessResult r = RunCompare({a, b});
  EXPECT_NE(r.out.find("Max error  = 2 @ (0, 0, Z)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Max error per channel: R 0 G 0 B 0 A 0 Z 2\n"), std::string::npos) << r.out;
  // The same depth: a pass, also through idiff.
  ExpectSameAsIdiff(a, MakeExr("z_c.exr", 2.0f), {}, 0);
}

TEST(CompareCommand, MissingFileIsAnError) {
  const std::string a = MakePng("missing_a.png", 0, 0);
  const std::string missing = (TestDir() / "nope.png").string();
  ExpectSameAsIdiff(a, missing, {}, 4);
  const ProcessResult r = RunCompare({a, missing});
  EXPECT_EQ(r.FirstErrLine(), missing + ": error: no such image file");
}

TEST(CompareCommand, UnreadableFileIsAnError) {
  const std::string a = MakePng("bad_a.png", 0, 0);
  const std::string bad = (TestDir() / "bad.png").string();
  { std::FILE* f = std::fopen(bad.c_str(), "w"); std::fputs("not a png", f); std::fclose(f); }
  ExpectSameAsIdiff(a, bad, {}, 4);
}

TEST(CompareCommand, BadOptionIsAnError) {
  // idiff exits 1 here; patchskin 4, so that CI never takes a typo for a warning.
  const std::string a = MakePng("opt_a.png", 0, 0);
  EXPECT_EQ(RunCompare({a, a, "--fail", "-1"}).exit_code, 4);
  EXPECT_EQ(RunCompare({a}).exit_code, 4);
}

}  // namespace
