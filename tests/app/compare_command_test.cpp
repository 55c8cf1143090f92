// `patchskin compare`, run as a process: exit 0 pass, 1 fail, 2 error, and what it prints.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "render/output/image_io.h"
#include "support/data_paths.h"

namespace {

namespace fs = std::filesystem;

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// One folder per test: ctest runs the tests of this file as parallel processes.
fs::path Dir() {
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path d = testsupport::TestOutputPath("compare_command/" + test + "/x").parent_path();
  static std::string cleaned;
  if (cleaned != test) {
    fs::remove_all(d);
    fs::create_directories(d);
    cleaned = test;
  }
  return d;
}

ProcessResult Patchskin(const std::string& args) {
  const fs::path out = Dir() / "stdout.txt";
  const fs::path err = Dir() / "stderr.txt";
  const std::string cmd = std::string("'") + PATCHSKIN_BINARY + "' " + args + " >'" +
                          out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  ProcessResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = Slurp(out);
  r.err = Slurp(err);
  return r;
}

// 100x100 mid grey, with `changed` pixels brightened by `steps` 8-bit codes.
std::string MakePng(const std::string& name, int changed, int steps) {
  render::Image img(100, 100, glm::vec4(render::Srgb8ToLinear(128), render::Srgb8ToLinear(128),
                                        render::Srgb8ToLinear(128), 1.0f));
  for (int i = 0; i < changed; ++i) {
    img.at(i, 7).r = render::Srgb8ToLinear(static_cast<std::uint8_t>(128 + steps));
  }
  const std::string path = (Dir() / name).string();
  EXPECT_TRUE(render::WriteImage(img, path));
  return path;
}

std::string Quote(const std::string& s) { return "'" + s + "'"; }

TEST(CompareCommand, IdenticalImagesPass) {
  const std::string a = MakePng("same_a.png", 0, 0);
  const std::string b = MakePng("same_b.png", 0, 0);
  const ProcessResult r = Patchskin("compare " + Quote(a) + " " + Quote(b));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Max error  = 0 @"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Peak SNR = inf"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("PASS"), std::string::npos);
}

TEST(CompareCommand, SmallDifferencesWithinFailPercentPass) {
  // Two pixels two codes brighter (2/255 = 0.0078: over --fail, under --hardfail);
  // 2 of 10000 pixels is exactly the allowed 0.02 %.
  const std::string a = MakePng("two_a.png", 0, 0);
  const std::string b = MakePng("two_b.png", 2, 2);
  const ProcessResult r = Patchskin("compare " + Quote(a) + " " + Quote(b));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("2 pixels (0.02%) over 0.004"), std::string::npos) << r.out;
}

TEST(CompareCommand, DifferentImagesFailAndWriteADiff) {
  const std::string a = MakePng("diff_a.png", 0, 0);
  const std::string b = MakePng("diff_b.png", 3, 2);  // 3 pixels: 0.03 % > 0.02 %
  const std::string d = (Dir() / "d.png").string();
  const ProcessResult r = Patchskin("compare " + Quote(a) + " " + Quote(b) + " --diff " + Quote(d));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("FAIL"), std::string::npos);
  EXPECT_NE(r.out.find("@ (0, 7, R)"), std::string::npos) << r.out;
  ASSERT_TRUE(fs::exists(d));
  auto diff = render::ReadImage(d);
  ASSERT_TRUE(diff.ok());
  EXPECT_GT(diff->at(1, 7).r, 0.0f);
  EXPECT_EQ(diff->at(50, 50).r, 0.0f);
  // A looser --failpercent lets the same pair pass; a tight --hardfail fails it again.
  EXPECT_EQ(Patchskin("compare " + Quote(a) + " " + Quote(b) + " --failpercent 0.05").exit_code,
            0);
  EXPECT_EQ(Patchskin("compare " + Quote(a) + " " + Quote(b) +
                      " --failpercent 0.05 --hardfail 0.005")
                .exit_code,
            1);
}

TEST(CompareCommand, MissingFileIsAnError) {
  const std::string a = MakePng("missing_a.png", 0, 0);
  const std::string missing = (Dir() / "nope.png").string();
  const ProcessResult r = Patchskin("compare " + Quote(a) + " " + Quote(missing));
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  const std::string first_line = r.err.substr(0, r.err.find('\n'));
  EXPECT_EQ(first_line, missing + ": error: no such image file");
}

TEST(CompareCommand, SizeMismatchIsAnError) {
  const std::string a = MakePng("size_a.png", 0, 0);
  const std::string small = (Dir() / "size_b.png").string();
  ASSERT_TRUE(render::WriteImage(render::Image(10, 10), small));
  const ProcessResult r = Patchskin("compare " + Quote(a) + " " + Quote(small));
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("differ in size: 100x100 and 10x10"), std::string::npos) << r.err;
}

TEST(CompareCommand, BadOptionIsAnError) {
  const std::string a = MakePng("opt_a.png", 0, 0);
  EXPECT_EQ(Patchskin("compare " + Quote(a) + " " + Quote(a) + " --fail -1").exit_code, 2);
  EXPECT_EQ(Patchskin("compare " + Quote(a)).exit_code, 2);
}

}  // namespace
