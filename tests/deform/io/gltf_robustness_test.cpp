// ReadGltf never crashes, hangs or throws on corrupted input: every number of a
// small valid file is replaced in turn by hostile values (negative, zero,
// past-the-end, huge), and the GLB form is cut at many lengths. Each load must
// either succeed with a consistent model or return an error naming the file.

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "deform/io/gltf_import.h"
#include "support/data_paths.h"

namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A loaded model must be internally consistent, or the error must name the file.
void ExpectSane(const base::Result<deform::GltfModel>& model, const std::string& path,
                const std::string& what) {
  if (!model.ok()) {
    EXPECT_EQ(model.error().loc.file, path) << what;
    EXPECT_FALSE(model.error().message.empty()) << what;
    return;
  }
  const deform::SkinnedMesh& mesh = model->mesh;
  EXPECT_TRUE(model->skeleton.Check().ok()) << what;
  EXPECT_TRUE(mesh.bind.Check().ok()) << what;
  EXPECT_EQ(mesh.weights.num_vertices(), mesh.bind.num_vertices()) << what;
  EXPECT_EQ(mesh.skin_joints.size(), mesh.joint_from_bind.size()) << what;
  for (std::uint16_t j : mesh.weights.joints) ASSERT_LT(j, mesh.skin_joints.size()) << what;
  for (int s : mesh.skin_joints) ASSERT_LT(s, model->skeleton.num_joints()) << what;
}

TEST(GltfRobustness, EveryNumberReplacedByHostileValues) {
  // The valid base of the bad files (make_bad_files.py), restored from one of them.
  const std::string source = testsupport::TestDataPath("gltf/bad/node_cycle.gltf").string();
  nlohmann::json base = nlohmann::json::parse(ReadText(source));
  base["nodes"][1].erase("children");
  const std::string dir = testsupport::TestOutputPath("gltf/robust/x").parent_path().string();
  {
    const std::string path = dir + "/base.gltf";
    std::ofstream(path) << base.dump();
    auto model = deform::ReadGltf(path);
    ASSERT_TRUE(model.ok()) << model.error().ToString();
  }
  const nlohmann::json flat = base.flatten();
  const std::vector<double> hostile = {-1, 0, 1, 2, 3, 5123, 1e3, 2147483647.0, 4294967295.0, 1e19, 0.5};
  int loads = 0;
  for (auto it = flat.begin(); it != flat.end(); ++it) {
    if (!it.value().is_number()) continue;
    for (double value : hostile) {
      nlohmann::json mutated = flat;
      if (value == std::floor(value) && std::abs(value) < 1e18) {
        mutated[it.key()] = static_cast<std::int64_t>(value);
      } else {
        mutated[it.key()] = value;
      }
      const std::string path = dir + "/mutated.gltf";
      std::ofstream(path) << mutated.unflatten().dump();
      ExpectSane(deform::ReadGltf(path), path, it.key() + " = " + std::to_string(value));
      ++loads;
    }
  }
  EXPECT_GT(loads, 100);
}

TEST(GltfRobustness, GlbCutAtEveryLength) {
  const std::string source = testsupport::TestDataPath("gltf/bad/truncated.glb").string();
  const std::string bytes = ReadText(source);
  const std::string path = testsupport::TestOutputPath("gltf/robust/cut.glb").string();
  for (std::size_t n = 0; n < bytes.size(); n += 7) {  // every 7th length keeps the test fast
    std::ofstream(path, std::ios::binary) << bytes.substr(0, n);
    auto model = deform::ReadGltf(path);
    EXPECT_FALSE(model.ok()) << "a truncated GLB must not load (" << n << " bytes)";
    ExpectSane(model, path, std::to_string(n) + " bytes");
  }
}

}  // namespace
