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
#include "support/run_process.h"

namespace {

using testsupport::ProcessResult;
using testsupport::RunPatchskinLine;

namespace fs = std::filesystem;

TEST(ElasticCommand, PlotsTheBuiltInJump) {
  const fs::path dir = testsupport::TestOutputPath("elastic_command/jump/x").parent_path();
  const fs::path png = dir / "elastic.png";
  fs::remove(png);
  const ProcessResult r = RunPatchskinLine("elastic --out '" + png.string() + "'", dir);
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
  const ProcessResult r =
      RunPatchskinLine("elastic --joint Tail --out '" + (dir / "x.png").string() + "'", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error: no joint named 'Tail'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

}  // namespace
