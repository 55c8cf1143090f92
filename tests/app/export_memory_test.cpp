// Large exports stream: the peak memory of `patchskin export` (a child
// process, its own ru_maxrss from wait4) barely changes between 100 and 1000
// frames, for the OBJ sequence and for the .glb (whose frame data goes to a
// scratch file, not to memory). The input is a skinned grid written here, so
// the size of a frame (24 bytes x #V) is known and the growth that holding the
// frames would cause is large next to the allowance.

#include <sys/resource.h>
#include <sys/wait.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/sanitizer.h"
#include "support/data_paths.h"
#include "support/gltf_writer.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

using testsupport::TestDir;

namespace fs = std::filesystem;
using testsupport::GltfWriter;

// A side x side grid of vertices skinned to one joint that moves along +X
// for 999 / 30 s (1000 frames at 30 fps, detected from the key times).
fs::path WriteGrid(const fs::path& dir, int side) {
  GltfWriter w;
  std::vector<float> positions;
  std::vector<std::uint16_t> joints;
  std::vector<float> weights;
  std::vector<std::uint32_t> indices;
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      positions.insert(positions.end(), {0.01f * static_cast<float>(x), 0.01f * static_cast<float>(y), 0.0f});
      joints.insert(joints.end(), {0, 0, 0, 0});
      weights.insert(weights.end(), {1, 0, 0, 0});
      if (x + 1 < side && y + 1 < side) {
        const auto v = static_cast<std::uint32_t>(y * side + x);
        const auto s = static_cast<std::uint32_t>(side);
        indices.insert(indices.end(), {v, v + 1, v + s, v + 1, v + s + 1, v + s});
      }
    }
  }
  const auto nv = static_cast<std::size_t>(side * side);
  const int pos = w.Accessor(positions, GltfWriter::kFloat, "VEC3", nv);
  const int jnt = w.Accessor(joints, GltfWriter::kUnsignedShort, "VEC4", nv);
  const int wgt = w.Accessor(weights, GltfWriter::kFloat, "VEC4", nv);
  const int idx = w.Accessor(indices, 5125, "SCALAR", indices.size());
  const int times = w.Accessor(std::vector<float>{0.0f, 999.0f / 30.0f}, GltfWriter::kFloat, "SCALAR", 2);
  const int moves = w.Accessor(std::vector<float>{0, 0, 0, 1, 0, 0}, GltfWriter::kFloat, "VEC3", 2);
  w.doc["scenes"] = {{{"nodes", {0, 1}}}};
  w.doc["nodes"] = {{{"name", "joint"}}, {{"name", "grid"}, {"mesh", 0}, {"skin", 0}}};
  w.doc["skins"] = {{{"joints", {0}}}};
  nlohmann::json primitive;
  primitive["attributes"] = {{"POSITION", pos}, {"JOINTS_0", jnt}, {"WEIGHTS_0", wgt}};
  primitive["indices"] = idx;
  w.doc["meshes"] = nlohmann::json::array({{{"primitives", nlohmann::json::array({primitive})}}});
  w.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", moves}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}};
  return w.Write((dir / ("grid" + std::to_string(side) + ".gltf")).string());
}

// Runs `patchskin export` and returns its peak resident set in bytes.
long PeakBytes(const std::vector<std::string>& args, const fs::path& dir) {
  const testsupport::RunningProcess p = testsupport::StartPatchskin(args, dir);
  EXPECT_GT(p.pid, 0);
  int status = 0;
  rusage usage{};
  EXPECT_EQ(wait4(p.pid, &status, 0, &usage), p.pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << testsupport::SlurpFile(p.err);
  return usage.ru_maxrss * 1024L;  // Linux reports kilobytes
}

struct Growth {
  long small = 0, large = 0;
  long growth() const { return large - small; }
};

Growth Measure(const fs::path& input, const std::string& out_name, const std::vector<std::string>& extra,
               const fs::path& dir) {
  Growth g;
  for (const int last : {99, 999}) {
    const fs::path out = dir / std::to_string(last);
    fs::remove_all(out);
    fs::create_directories(out);
    std::vector<std::string> args{"export", input.string(), "--quiet", "--frames", "0:" + std::to_string(last),
                                  "--out", (out / out_name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    (last == 99 ? g.small : g.large) = PeakBytes(args, out);
    EXPECT_TRUE(fs::exists(out / (out_name.find('#') == std::string::npos ? out_name : "mesh_0099.obj")));
    fs::remove_all(out);  // large: do not leave tens of MB in the build tree
  }
  return g;
}

TEST(ExportMemory, ObjSequenceDoesNotGrowWithTheFrameCount) {
  PATCHSKIN_SKIP_MEMORY_BOUND_UNDER_ASAN();
  const fs::path dir = TestDir();
  const int side = 24;  // 576 vertices: 50 KB of OBJ per frame
  const fs::path grid = WriteGrid(dir, side);
  const Growth g = Measure(grid, "mesh_####.obj", {}, dir);
  const long held = 24L * side * side * 900;  // what keeping 900 more frames would cost
  std::printf("obj peak: %ld KB at 100 frames, %ld KB at 1000 (900 frames held would be %ld KB)\n",
              g.small / 1024, g.large / 1024, held / 1024);
  EXPECT_LT(g.growth(), held * testsupport::kStreamingGrowthShare) << g.small << " -> " << g.large;
}

TEST(ExportMemory, GlbDoesNotHoldTheFrames) {
  PATCHSKIN_SKIP_MEMORY_BOUND_UNDER_ASAN();
  const fs::path dir = TestDir();
  const int side = 64;  // 4096 vertices: 98 KB of data per frame (~10 KB of bookkeeping)
  const fs::path grid = WriteGrid(dir, side);
  const long held = 24L * side * side * 900;
  for (const char* layout : {"morph", "baked"}) {
    const Growth g = Measure(grid, "grid.glb", {"--layout", layout}, dir);
    std::printf("glb %s peak: %ld KB at 100 frames, %ld KB at 1000 (900 frames held would be %ld KB)\n",
                layout, g.small / 1024, g.large / 1024, held / 1024);
    EXPECT_LT(g.growth(), held * testsupport::kStreamingGrowthShare) << layout << ": " << g.small << " -> " << g.large;
  }
}

}  // namespace
