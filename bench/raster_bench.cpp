// Frames per second of the software renderer on a ~50k-triangle body-like
// mesh (eleven subdivided ellipsoids) covering about a third of the screen,
// depth-tested and lit, resolved into a float RGBA + depth Image.
//
// Reference (same machine, Mesa llvmpipe, pixels read back): ~110 fps at
// 1280x720 on one core, 140 on two; 67 and 104 at 1920x1080. The same scene
// drawn by llvmpipe, to run side by side: bench/llvmpipe_bench.cpp.
//
// Args: width, height, threads, supersample, lighting (0 Lambert, 1 Blinn-Phong + ground).
// BM_RenderCesiumMan: a textured glTF character against the same without texture.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/glm.hpp>

#include "bench/harness/body_scene.h"
#include "deform/io/gltf_import.h"
#include "render/renderer.h"

namespace {

// One render of `mesh` per benchmark iteration, into `image`.
void RenderEachIteration(benchmark::State& state, render::Renderer& renderer, const render::Camera& camera,
                         const render::SceneMesh& mesh, const render::RenderSettings& settings,
                         render::Image& image) {
  for (auto _ : state) {
    const base::JobStatus status = renderer.Render(camera, {&mesh, 1}, {}, settings, image);
    if (!status.ok()) state.SkipWithError(status.what);
    benchmark::DoNotOptimize(image.rgba.data());
    benchmark::ClobberMemory();
  }
}

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
  RenderEachIteration(state, renderer, camera, mesh, settings, image);
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

// CesiumMan (glTF, ../shared/data) in its bind pose, the demo's look
// (Blinn-Phong, ground, 2x2 supersampling, 1280x720): with its base colour
// texture (trilinear, perspective-correct) against the same frame without it,
// in the same run. Arg: textured (0 / 1), threads.
void BM_RenderCesiumMan(benchmark::State& state) {
  static const auto model = deform::ReadGltf(std::string(PATCHSKIN_DATA_DIR) + "/gltf/CesiumMan.glb");
  if (!model.ok()) {
    state.SkipWithError(("CesiumMan not readable: " + model.error().ToString()).c_str());
    return;
  }
  const deform::SkinnedMesh& m = model->mesh;
  static const render::Texture texture(*m.materials.images.at(0), m.materials.materials.at(0).wrap_s,
                                       m.materials.materials.at(0).wrap_t);
  render::RenderSettings settings;
  settings.width = 1280;
  settings.height = 720;
  settings.supersample = 2;
  settings.threads = static_cast<int>(state.range(1));
  const render::Camera camera = render::FrameBounds(deform::ComputeBounds(m.bind.positions), 40.0f,
                                                    16.0f / 9.0f, {-0.4f, -0.3f, -1.0f});
  render::SceneMesh mesh{.positions = m.bind.positions, .normals = m.bind.normals,
                         .triangles = m.bind.triangles};
  if (state.range(0) != 0) {
    mesh.uvs = m.bind.uvs;
    mesh.textures = {&texture, 1};
  }
  render::Renderer renderer;
  render::Image image;
  RenderEachIteration(state, renderer, camera, mesh, settings, image);
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderCesiumMan)
    ->ArgNames({"textured", "threads"})
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Building CesiumMan's mip pyramid (once per character, not per frame).
void BM_BuildCesiumManTexture(benchmark::State& state) {
  static const auto model = deform::ReadGltf(std::string(PATCHSKIN_DATA_DIR) + "/gltf/CesiumMan.glb");
  if (!model.ok()) {
    state.SkipWithError(("CesiumMan not readable: " + model.error().ToString()).c_str());
    return;
  }
  const deform::TextureImage& image = *model->mesh.materials.images.at(0);
  for (auto _ : state) {
    const render::Texture texture(image, deform::TextureWrap::kRepeat, deform::TextureWrap::kRepeat);
    benchmark::DoNotOptimize(texture.num_levels());
  }
  state.counters["texels"] = static_cast<double>(image.width) * image.height;
}
BENCHMARK(BM_BuildCesiumManTexture)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
