// `patchskin elastic`, run as a process: writes the response plot, reports the
// limits, and answers bad input with exit 2 and a located message.

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
  std::string out, err;
};

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

ProcessResult Patchskin(const std::string& args, const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = std::string("'") + PATCHSKIN_BINARY + "' " + args + " >'" +
                          out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  ProcessResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = Slurp(out);
  r.err = Slurp(err);
  return r;
}

TEST(ElasticCommand, PlotsTheBuiltInJump) {
  const fs::path dir = testsupport::TestOutputPath("elastic_command/jump/x").parent_path();
  const fs::path png = dir / "elastic.png";
  fs::remove(png);
  const ProcessResult r = Patchskin("elastic --out '" + png.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("peak |e|"), std::string::npos) << r.out;
  // The run always says whether it had to limit anything (the default 3 Hz belly
  // reaches e_max on the landing).
  EXPECT_NE(r.out.find("limits: 0 acceleration clamps"), std::string::npos) << r.out;
  auto image = render::ReadImage(png.string());
  ASSERT_TRUE(image.ok()) << image.error().ToString();
  EXPECT_EQ(image->width, 960);
  EXPECT_EQ(image->height, 540);
}

TEST(ElasticCommand, UnknownJointIsBadInput) {
  const fs::path dir = testsupport::TestOutputPath("elastic_command/bad/x").parent_path();
  const ProcessResult r = Patchskin("elastic --joint Tail --out '" + (dir / "x.png").string() + "'",
                                    dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error: no joint named 'Tail'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

}  // namespace
