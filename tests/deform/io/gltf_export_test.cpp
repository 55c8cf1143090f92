// glTF sequence export: the file read back with tinygltf and evaluated the way
// a viewer does gives each exported frame at its key time, for both layouts;
// the automatic layout picks the smaller file; bad input is refused.

#include "deform/io/gltf_export.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/exported_geometry.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;
using testsupport::kMorphRoundTripTol;

// A flag of nx x ny vertices waving in time: frame k of `frames`.
struct Flag {
  int nx = 0, ny = 0;
  std::vector<glm::uvec3> triangles;
  std::vector<glm::vec3> colors;
  std::vector<glm::vec3> Positions(int k) const {
    std::vector<glm::vec3> p;
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const float x = 0.1f * static_cast<float>(i), y = 0.1f * static_cast<float>(j);
        p.push_back({x, y, 0.2f * std::sin(3.0f * x + 0.4f * static_cast<float>(k))});
      }
    }
    return p;
  }
  std::vector<glm::vec3> Normals(int k) const {
    std::vector<glm::vec3> n;
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const float x = 0.1f * static_cast<float>(i);
        const float dz = 0.6f * std::cos(3.0f * x + 0.4f * static_cast<float>(k));
        n.push_back(glm::normalize(glm::vec3(-dz, 0.0f, 1.0f)));
      }
    }
    return n;
  }
};

Flag MakeFlag(int nx, int ny) {
  Flag f{nx, ny, {}, {}};
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const auto a = static_cast<unsigned>(j * nx + i), b = a + 1,
                 c = a + static_cast<unsigned>(nx), d = c + 1;
      f.triangles.push_back({a, b, d});
      f.triangles.push_back({a, d, c});
    }
  }
  for (int v = 0; v < nx * ny; ++v) f.colors.push_back({0.8f, 0.5f, 0.2f});
  return f;
}

fs::path Write(const Flag& flag, int frames, deform::GltfExportOptions options, const fs::path& path,
               deform::GltfExportLayout* chosen = nullptr) {
  auto w = deform::GltfSequenceWriter::Create(flag.triangles, flag.colors, flag.nx * flag.ny,
                                              frames, options);
  EXPECT_TRUE(w.ok());
  if (!w.ok()) return path;
  for (int k = 0; k < frames; ++k) {
    EXPECT_TRUE(w->AddFrame(flag.Positions(k), flag.Normals(k)));
  }
  EXPECT_EQ(w->frames_added(), frames);
  const base::Status s = w->Finish(path.string());
  EXPECT_TRUE(s) << (s ? "" : s.error().ToString());
  if (chosen) *chosen = w->layout();
  return path;
}

void ExpectFramesAtKeyTimes(const Flag& flag, int frames, double frame_time, const fs::path& path,
                            float tol) {
  tinygltf::Model m;
  std::string msg;
  ASSERT_TRUE(testsupport::LoadGlb(path.string(), m, msg)) << msg;
  EXPECT_EQ(m.asset.version, "2.0");
  for (int k = 0; k < frames; ++k) {
    const testsupport::GlbFrame g = testsupport::EvaluateGlb(m, k * frame_time);
    ASSERT_EQ(g.visible_meshes, 1) << "frame " << k;
    const std::vector<glm::vec3> p = flag.Positions(k), n = flag.Normals(k);
    ASSERT_EQ(g.positions.size(), p.size());
    float worst = 0.0f, worst_n = 0.0f;
    for (std::size_t i = 0; i < p.size(); ++i) {
      worst = std::max(worst, glm::length(g.positions[i] - p[i]));
      worst_n = std::max(worst_n, glm::length(g.normals[i] - n[i]));
    }
    EXPECT_LE(worst, tol) << "frame " << k;
    EXPECT_LE(worst_n, tol) << "frame " << k;
  }
}

TEST(GltfExport, MorphTargetsGiveEveryFrameAtItsKeyTime) {
  const Flag flag = MakeFlag(9, 5);
  const fs::path path = testsupport::FreshOutputDir("gltf_export/morph") / "flag.glb";
  const double dt = 1.0 / 24.0;
  Write(flag, 12, {.frame_time_s = dt, .layout = deform::GltfExportLayout::kMorphTargets}, path);
  ExpectFramesAtKeyTimes(flag, 12, dt, path, kMorphRoundTripTol);

  tinygltf::Model m;
  std::string msg;
  ASSERT_TRUE(testsupport::LoadGlb(path.string(), m, msg)) << msg;
  ASSERT_EQ(m.meshes.size(), 1u);
  EXPECT_EQ(m.meshes[0].primitives[0].targets.size(), 12u);
  EXPECT_EQ(m.animations[0].samplers[0].interpolation, "LINEAR");
  // Target 0 (frame 0 = the base) costs no data: an accessor without a view.
  EXPECT_LT(m.accessors[static_cast<std::size_t>(
                            m.meshes[0].primitives[0].targets[0].at("POSITION"))]
                .bufferView,
            0);
  // Every POSITION accessor has min/max (required by the specification).
  EXPECT_FALSE(m.accessors[static_cast<std::size_t>(
                               m.meshes[0].primitives[0].attributes.at("POSITION"))]
                   .minValues.empty());
  for (const auto& t : m.meshes[0].primitives[0].targets) {
    EXPECT_EQ(m.accessors[static_cast<std::size_t>(t.at("POSITION"))].maxValues.size(), 3u);
  }
  // LINEAR: halfway between keys 3 and 4 the mesh is the average of the two frames.
  const testsupport::GlbFrame mid = testsupport::EvaluateGlb(m, 3.5 * dt);
  const std::vector<glm::vec3> a = flag.Positions(3), b = flag.Positions(4);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LE(glm::length(mid.positions[i] - 0.5f * (a[i] + b[i])), 2 * kMorphRoundTripTol);
  }
}

TEST(GltfExport, StepMorphHoldsEachFrame) {
  const Flag flag = MakeFlag(6, 4);
  const fs::path path = testsupport::FreshOutputDir("gltf_export/step") / "flag.glb";
  const double dt = 1.0 / 30.0;
  Write(flag, 7,
        {.frame_time_s = dt, .layout = deform::GltfExportLayout::kMorphTargets,
         .step_interpolation = true},
        path);
  ExpectFramesAtKeyTimes(flag, 7, dt, path, kMorphRoundTripTol);
  tinygltf::Model m;
  std::string msg;
  ASSERT_TRUE(testsupport::LoadGlb(path.string(), m, msg)) << msg;
  const testsupport::GlbFrame held = testsupport::EvaluateGlb(m, 2.9 * dt);
  const std::vector<glm::vec3> p2 = flag.Positions(2);
  for (std::size_t i = 0; i < p2.size(); ++i) {
    EXPECT_LE(glm::length(held.positions[i] - p2[i]), kMorphRoundTripTol);
  }
}

TEST(GltfExport, BakedMeshesShowExactlyOneExactFrame) {
  const Flag flag = MakeFlag(5, 5);
  const fs::path path = testsupport::FreshOutputDir("gltf_export/baked") / "flag.glb";
  const double dt = 1.0 / 25.0;
  Write(flag, 6, {.frame_time_s = dt, .layout = deform::GltfExportLayout::kBakedMeshes}, path);
  ExpectFramesAtKeyTimes(flag, 6, dt, path, 0.0f);  // baked vertices are the frames' own floats
  tinygltf::Model m;
  std::string msg;
  ASSERT_TRUE(testsupport::LoadGlb(path.string(), m, msg)) << msg;
  EXPECT_EQ(m.meshes.size(), 6u);
  // Between keys the earlier frame stays (STEP).
  const testsupport::GlbFrame g = testsupport::EvaluateGlb(m, 4.5 * dt);
  EXPECT_EQ(g.visible_meshes, 1);
  EXPECT_EQ(g.positions, flag.Positions(4));
}

// The automatic choice is the layout whose file is really smaller, and the
// estimates are close to the real sizes.
TEST(GltfExport, AutoPicksTheSmallerFile) {
  struct Case {
    int nx, ny, frames;
  };
  for (const Case c : {Case{20, 10, 1}, Case{20, 10, 30}, Case{4, 3, 400}}) {
    const Flag flag = MakeFlag(c.nx, c.ny);
    std::string name = "auto_";
    name += std::to_string(c.nx);
    name += "_";
    name += std::to_string(c.frames);
    const fs::path dir = testsupport::FreshOutputDir("gltf_export/" + name);
    const fs::path morph = Write(flag, c.frames, {.layout = deform::GltfExportLayout::kMorphTargets},
                                 dir / "morph.glb");
    const fs::path baked = Write(flag, c.frames, {.layout = deform::GltfExportLayout::kBakedMeshes},
                                 dir / "baked.glb");
    deform::GltfExportLayout chosen = deform::GltfExportLayout::kAuto;
    const fs::path autop = Write(flag, c.frames, {}, dir / "auto.glb", &chosen);
    const auto morph_bytes = fs::file_size(morph), baked_bytes = fs::file_size(baked);
    const deform::GltfExportLayout smaller = baked_bytes < morph_bytes
                                                 ? deform::GltfExportLayout::kBakedMeshes
                                                 : deform::GltfExportLayout::kMorphTargets;
    const auto smallest = std::min(morph_bytes, baked_bytes);
    const auto largest = std::max(morph_bytes, baked_bytes);
    // The choice uses the estimates: a near tie may go either way, at no real cost.
    if (static_cast<double>(largest) >
        (1.0 + testsupport::kGlbLayoutTieRelTol) * static_cast<double>(smallest)) {
      EXPECT_EQ(chosen, smaller) << c.nx << "x" << c.ny << " x " << c.frames << ": morph "
                                 << morph_bytes << " B, baked " << baked_bytes << " B";
    }
    EXPECT_LE(static_cast<double>(fs::file_size(autop)),
              (1.0 + testsupport::kGlbLayoutTieRelTol) * static_cast<double>(smallest));
    // Dense weights grow as frames^2: long sequences fall back to baked meshes.
    if (c.frames == 400) {
      EXPECT_EQ(chosen, deform::GltfExportLayout::kBakedMeshes);
    }
    if (c.frames == 30) {
      EXPECT_EQ(chosen, deform::GltfExportLayout::kMorphTargets);
    }
    const deform::GltfExportEstimate e = deform::EstimateGltfExportBytes(
        c.nx * c.ny, static_cast<int>(flag.triangles.size()), c.frames, true);
    EXPECT_NEAR(static_cast<double>(e.morph_bytes), static_cast<double>(morph_bytes),
                testsupport::kGlbSizeEstimateRelTol * static_cast<double>(morph_bytes));
    EXPECT_NEAR(static_cast<double>(e.baked_bytes), static_cast<double>(baked_bytes),
                testsupport::kGlbSizeEstimateRelTol * static_cast<double>(baked_bytes));
  }
}

TEST(GltfExport, BadInputIsRefused) {
  const Flag flag = MakeFlag(3, 3);
  EXPECT_FALSE(deform::GltfSequenceWriter::Create(flag.triangles, flag.colors, 9, 0, {}).ok());
  EXPECT_FALSE(deform::GltfSequenceWriter::Create(flag.triangles, flag.colors, 4, 2, {}).ok());
  EXPECT_FALSE(
      deform::GltfSequenceWriter::Create(flag.triangles, flag.colors, 9, 2, {.frame_time_s = 0}).ok());
  auto w = deform::GltfSequenceWriter::Create(flag.triangles, {}, 9, 2, {});
  ASSERT_TRUE(w.ok());
  std::vector<glm::vec3> p = flag.Positions(0);
  EXPECT_FALSE(w->AddFrame(std::span(p).first(8), flag.Normals(0)));
  p[4].x = NAN;
  EXPECT_FALSE(w->AddFrame(p, flag.Normals(0)));
  ASSERT_TRUE(w->AddFrame(flag.Positions(0), flag.Normals(0)));
  const fs::path dir = testsupport::FreshOutputDir("gltf_export/bad");
  const base::Status s = w->Finish((dir / "short.glb").string());
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().ToString().find("short.glb"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "short.glb"));
  ASSERT_TRUE(w->AddFrame(flag.Positions(1), flag.Normals(1)));
  EXPECT_FALSE(w->AddFrame(flag.Positions(1), flag.Normals(1)));  // more than announced
  EXPECT_TRUE(w->Finish((dir / "ok.glb").string()));
}

}  // namespace
