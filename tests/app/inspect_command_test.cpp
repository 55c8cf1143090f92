// `patchskin inspect --json --frame N` against an independent reader: a
// minimal BVH tokenizer and forward kinematics in double precision with
// explicit rotation matrices, written here without any patchskin code.

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/data_paths.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;

struct RefJoint {
  std::string name;
  int parent = -1;
  double offset[3] = {0, 0, 0};
  std::vector<std::string> channels;
  int first_channel = 0;
};

struct RefBvh {
  std::vector<RefJoint> joints;
  std::vector<std::vector<double>> frames;
};

// Whitespace tokens; enough for well-formed files (the real reader's own tests
// cover the dialects). Joint names are single tokens in the files used here.
RefBvh ReadReference(const fs::path& path) {
  std::istringstream in(testsupport::SlurpFile(path));
  RefBvh bvh;
  std::vector<int> stack;
  int channels = 0;
  bool in_end_site = false;
  for (std::string tok; in >> tok;) {
    if (tok == "ROOT" || tok == "JOINT") {
      RefJoint j;
      in >> j.name;
      j.parent = stack.empty() ? -1 : stack.back();
      bvh.joints.push_back(j);
      stack.push_back(static_cast<int>(bvh.joints.size()) - 1);
    } else if (tok == "End") {
      in >> tok;  // "Site"
      in_end_site = true;
    } else if (tok == "OFFSET") {
      double o[3];
      in >> o[0] >> o[1] >> o[2];
      if (!in_end_site) std::copy(o, o + 3, bvh.joints.back().offset);
    } else if (tok == "CHANNELS") {
      int n = 0;
      in >> n;
      RefJoint& j = bvh.joints.back();
      j.first_channel = channels;
      for (int c = 0; c < n; ++c) {
        std::string name;
        in >> name;
        j.channels.push_back(name);
      }
      channels += n;
    } else if (tok == "}") {
      if (in_end_site) {
        in_end_site = false;
      } else if (!stack.empty()) {
        stack.pop_back();
      }
    } else if (tok == "MOTION") {
      break;
    }
  }
  std::string word;
  int frames = 0;
  in >> word >> frames;            // Frames: N
  in >> word >> word;              // Frame Time:
  double frame_time = 0;
  in >> frame_time;
  for (int f = 0; f < frames; ++f) {
    std::vector<double> row(static_cast<std::size_t>(channels));
    for (double& v : row) in >> v;
    bvh.frames.push_back(row);
  }
  return bvh;
}

using Mat = std::array<double, 16>;  // column-major 4x4

Mat Mul(const Mat& a, const Mat& b) {
  Mat r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row)
      for (int k = 0; k < 4; ++k) r[c * 4 + row] += a[k * 4 + row] * b[c * 4 + k];
  return r;
}

Mat Identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat Rotation(char axis, double deg) {
  const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  Mat m = Identity();
  const int i = axis == 'X' ? 1 : axis == 'Y' ? 2 : 0;  // the two axes that turn
  const int k = axis == 'X' ? 2 : axis == 'Y' ? 0 : 1;
  m[i * 4 + i] = c;
  m[k * 4 + i] = -s;
  m[i * 4 + k] = s;
  m[k * 4 + k] = c;
  return m;
}

// World positions of every joint at `frame`: position channels replace the
// offset (the default mode); rotations compose in channel order.
std::vector<std::array<double, 3>> ReferencePositions(const RefBvh& bvh, int frame) {
  std::vector<Mat> world(bvh.joints.size());
  std::vector<std::array<double, 3>> out;
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    const RefJoint& joint = bvh.joints[j];
    double t[3] = {joint.offset[0], joint.offset[1], joint.offset[2]};
    Mat rot = Identity();
    for (std::size_t c = 0; c < joint.channels.size(); ++c) {
      const double v = bvh.frames[static_cast<std::size_t>(frame)]
                                 [static_cast<std::size_t>(joint.first_channel) + c];
      const std::string& name = joint.channels[c];
      if (name.find("position") != std::string::npos) t[name[0] - 'X'] = v;
      if (name.find("rotation") != std::string::npos) rot = Mul(rot, Rotation(name[0], v));
    }
    Mat local = rot;
    local[12] = t[0];
    local[13] = t[1];
    local[14] = t[2];
    world[j] = joint.parent < 0 ? local : Mul(world[static_cast<std::size_t>(joint.parent)], local);
    out.push_back({world[j][12], world[j][13], world[j][14]});
  }
  return out;
}

class InspectAgainstReference : public ::testing::TestWithParam<const char*> {};

TEST_P(InspectAgainstReference, WorldPositionsMatch) {
  const fs::path file = testsupport::SharedDataPath(GetParam());
  PATCHSKIN_REQUIRE_SHARED_FILE(file);
  const RefBvh ref = ReadReference(file);
  ASSERT_FALSE(ref.frames.empty());
  const fs::path scratch = testsupport::TestOutputPath(
      std::string("inspect/") + fs::path(GetParam()).stem().string() + "/x").parent_path();
  for (int frame : {0, static_cast<int>(ref.frames.size()) / 2,
                    static_cast<int>(ref.frames.size()) - 1}) {
    const testsupport::ProcessResult r = testsupport::RunPatchskin(
        {"inspect", "--json", "--frame", std::to_string(frame), file.string()}, scratch);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["frames"].get<int>(), static_cast<int>(ref.frames.size()));
    const auto expected = ReferencePositions(ref, frame);
    ASSERT_EQ(doc["positions"].size(), ref.joints.size());
    // Size of the figure, for a relative tolerance (float chains vs double).
    double extent = 1.0;
    for (const auto& p : expected) extent = std::max({extent, std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
    for (std::size_t j = 0; j < ref.joints.size(); ++j) {
      const nlohmann::json& got = doc["positions"][ref.joints[j].name];
      ASSERT_TRUE(got.is_array()) << ref.joints[j].name;
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(got[static_cast<std::size_t>(a)].get<double>(), expected[j][static_cast<std::size_t>(a)],
                    testsupport::kInspectRelTol * extent)
            << GetParam() << " frame " << frame << " joint " << ref.joints[j].name << " axis " << a;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedData, InspectAgainstReference,
                         ::testing::Values("bvh/cmu_cgspeed/01_01.bvh",
                                           "bvh/bandai_namco/dataset-1_walk_normal_001.bvh",
                                           "bvh/bvh_python/test_mocapbank.bvh",
                                           "bvh/lafan1_resolved/Geno_stance.bvh"));

TEST(InspectCommand, TextListsTimingAndUnits) {
  const fs::path file = testsupport::SharedDataPath("bvh/bandai_namco/dataset-2_run_active_034.bvh");
  PATCHSKIN_REQUIRE_SHARED_FILE(file);
  const testsupport::ProcessResult r = testsupport::RunPatchskin(
      {"inspect", file.string()}, testsupport::TestOutputPath("inspect/text/x").parent_path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames:      75"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(30 fps)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("units:       cm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("    Hips  offset (4.5925, 91.4895, -427.239)"), std::string::npos) << r.out;
}

TEST(InspectCommand, BadInputExitsTwoNamingTheFile) {
  const fs::path scratch = testsupport::TestOutputPath("inspect/bad/x").parent_path();
  const fs::path bad = scratch / "short.bvh";
  {
    std::ofstream out(bad);
    out << "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n}\n"
           "MOTION\nFrames: 2\nFrame Time: 0.1\n1 2 3\n4 5\n";
  }
  const testsupport::ProcessResult r = testsupport::RunPatchskin({"inspect", bad.string()}, scratch);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind(bad.string() + ":11:4: error: expected 3 values in frame 2, found 2", 0), 0u)
      << r.err;
  // Fewer data lines than declared: an error naming both counts, or with
  // --allow-short the frames present and a warning.
  const fs::path fewer = scratch / "fewer.bvh";
  {
    std::ofstream out(fewer);
    out << "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n}\n"
           "MOTION\nFrames: 3\nFrame Time: 0.1\n1 2 3\n4 5 6\n";
  }
  const testsupport::ProcessResult strict = testsupport::RunPatchskin({"inspect", fewer.string()}, scratch);
  EXPECT_EQ(strict.exit_code, 2);
  const testsupport::ProcessResult shortened =
      testsupport::RunPatchskin({"inspect", "--allow-short", fewer.string()}, scratch);
  EXPECT_EQ(shortened.exit_code, 0) << shortened.err;
  EXPECT_NE(shortened.out.find("frames:      2\n"), std::string::npos) << shortened.out;
  EXPECT_NE(shortened.err.find("warning"), std::string::npos) << shortened.err;
  const testsupport::ProcessResult dir = testsupport::RunPatchskin({"inspect", scratch.string()}, scratch);
  EXPECT_EQ(dir.exit_code, 2);
  EXPECT_NE(dir.err.find("found a directory"), std::string::npos) << dir.err;
  const testsupport::ProcessResult frame = testsupport::RunPatchskin(
      {"inspect", "--frame", "9", (scratch / "missing.bvh").string()}, scratch);
  EXPECT_EQ(frame.exit_code, 2);
}

}  // namespace
