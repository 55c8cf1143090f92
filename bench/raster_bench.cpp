// Frames per second of the software renderer on a ~50k-triangle body-like
// mesh (eleven subdivided ellipsoids) covering about a third of the screen,
// depth-tested and lit, resolved into a float RGBA + depth Image.
//
// Reference (same machine, Mesa llvmpipe, pixels read back): ~110 fps at
// 1280x720 on one core, 140 on two; 67 and 104 at 1920x1080. The same scene
// drawn by llvmpipe, to run side by side: bench/llvmpipe_bench.cpp.
//
// Args: width, height, threads, supersample, lighting (0 Lambert, 1 Blinn-Phong + ground).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/glm.hpp>

#include "bench/body_scene.h"
#include "render/renderer.h"

namespace {

void BM_RenderBody(benchmark::State& state) {
  static const bench::BodyMesh body = bench::MakeBody();
  render::RenderSettings settings;
  settings.width = static_cast<int>(state.range(0));
  settings.height = static_cast<int>(state.range(1));
  settings.threads = static_cast<int>(state.range(2));
  settings.supersample = static_cast<int>(state.range(3));
  const bool full = state.range(4) != 0;
  settings.lighting = full ? render::LightingModel::kBlinnPhong : render::LightingModel::kLambert;
  settings.ground = full;
  settings.cull_back_faces = true;
  const render::Camera camera = bench::BodyCamera(settings.width, settings.height);
  const render::SceneMesh mesh{.positions = body.positions, .normals = body.normals,
                               .triangles = body.triangles};
  render::Renderer renderer;
  render::Image image;
  for (auto _ : state) {
    const mocap::JobStatus status = renderer.Render(camera, {&mesh, 1}, {}, settings, image);
    if (!status.ok()) state.SkipWithError(status.what);
    benchmark::DoNotOptimize(image.rgba.data());
    benchmark::ClobberMemory();
  }
  std::size_t covered = 0;
  for (float d : image.depth) covered += std::isfinite(d) ? 1 : 0;
  if (const std::string path = bench::SnapshotPath("raster_" + std::to_string(settings.width) + "x" +
                                                   std::to_string(settings.height));
      !path.empty() && settings.supersample == 1 && !full && settings.threads == 1) {
    std::vector<std::uint8_t> rgb;
    rgb.reserve(image.rgba.size() * 3);
    for (const glm::vec4& p : image.rgba) {
      for (int c = 0; c < 3; ++c) {
        rgb.push_back(static_cast<std::uint8_t>(std::lround(std::clamp(p[c], 0.0f, 1.0f) * 255.0f)));
      }
    }
    if (!bench::WritePpm(path, image.width, image.height, rgb)) state.SkipWithError("snapshot");
  }
  state.counters["triangles"] = static_cast<double>(body.triangles.size());
  state.counters["coverage"] = static_cast<double>(covered) / static_cast<double>(image.depth.size());
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_RenderBody)
    ->ArgNames({"w", "h", "threads", "ss", "full"})
    ->ArgsProduct({{1280}, {720}, {1, 2}, {1, 2}, {0}})
    ->ArgsProduct({{1920}, {1080}, {1, 2}, {1, 2}, {0}})
    ->Args({1280, 720, 1, 1, 1})
    ->Args({1280, 720, 2, 1, 1})
    ->Args({1280, 720, 2, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
