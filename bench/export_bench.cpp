// Geometry export throughput: OBJ text formatting (AppendObj, shortest
// round-trip floats) and glb frame appends (GltfSequenceWriter::AddFrame, morph
// deltas), on a 20k-vertex mesh. items/s = vertices per second. File writes are
// left out (they measure the disk, not the code).

#include <cmath>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "deform/io/gltf_export.h"
#include "deform/io/obj_writer.h"

namespace {

constexpr int kSide = 142;  // 142 x 142 ~ 20k vertices

struct Grid {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::uvec3> triangles;
  Grid() {
    for (int j = 0; j < kSide; ++j) {
      for (int i = 0; i < kSide; ++i) {
        const float x = 1.37f * static_cast<float>(i), y = 0.91f * static_cast<float>(j);
        positions.push_back({x, y, 10.0f * std::sin(0.1f * x) * std::cos(0.07f * y)});
        normals.push_back(glm::normalize(glm::vec3(std::cos(0.1f * x), 0.3f, 1.0f)));
        if (i + 1 < kSide && j + 1 < kSide) {
          const auto a = static_cast<unsigned>(j * kSide + i);
          triangles.push_back({a, a + 1, a + kSide + 1});
          triangles.push_back({a, a + kSide + 1, a + kSide});
        }
      }
    }
  }
};

void BM_ObjFormat(benchmark::State& state) {
  const Grid g;
  std::string text;
  for (auto _ : state) {
    text.clear();
    const base::Status s = deform::AppendObj(
        {.positions = g.positions, .normals = g.normals, .triangles = g.triangles}, text);
    if (!s) state.SkipWithError("AppendObj failed");
    benchmark::DoNotOptimize(text.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(g.positions.size()));
  state.counters["bytes_per_frame"] = static_cast<double>(text.size());
}
BENCHMARK(BM_ObjFormat)->Unit(benchmark::kMillisecond);

void BM_GlbMorphAddFrame(benchmark::State& state) {
  const Grid g;
  constexpr int kFrames = 64;
  auto w = deform::GltfSequenceWriter::Create(g.triangles, {}, static_cast<int>(g.positions.size()),
                                              kFrames, {.layout = deform::GltfExportLayout::kMorphTargets});
  int added = 0;
  for (auto _ : state) {
    if (added == kFrames) {
      state.PauseTiming();
      w = deform::GltfSequenceWriter::Create(g.triangles, {}, static_cast<int>(g.positions.size()),
                                             kFrames, {.layout = deform::GltfExportLayout::kMorphTargets});
      added = 0;
      state.ResumeTiming();
    }
    if (!w->AddFrame(g.positions, g.normals)) state.SkipWithError("AddFrame failed");
    ++added;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(g.positions.size()));
}
BENCHMARK(BM_GlbMorphAddFrame)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
