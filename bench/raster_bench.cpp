// Frames per second of the software renderer on a ~50k-triangle body-like
// mesh (eleven subdivided ellipsoids) covering about a third of the screen,
// depth-tested and lit, resolved into a float RGBA + depth Image.
//
// Reference (same machine, Mesa llvmpipe, pixels read back): ~110 fps at
// 1280x720 on one core, 140 on two; 67 and 104 at 1920x1080.
//
// Args: width, height, threads, supersample, lighting (0 Lambert, 1 Blinn-Phong + ground).

#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/glm.hpp>

#include "render/renderer.h"

namespace {

struct BodyMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
};

// Appends an ellipsoid (UV sphere scaled by `radii`) centred at `centre`.
void AddEllipsoid(BodyMesh& mesh, glm::vec3 centre, glm::vec3 radii, int rings, int segments) {
  const auto base = static_cast<unsigned>(mesh.positions.size());
  const double pi = 3.14159265358979323846;
  for (int i = 0; i <= rings; ++i) {
    for (int j = 0; j <= segments; ++j) {
      const double theta = pi * i / rings, phi = 2.0 * pi * j / segments;
      const glm::vec3 unit(static_cast<float>(std::sin(theta) * std::cos(phi)),
                           static_cast<float>(std::cos(theta)),
                           static_cast<float>(-std::sin(theta) * std::sin(phi)));
      mesh.positions.push_back(centre + radii * unit);
      mesh.normals.push_back(glm::normalize(unit / radii));
    }
  }
  const auto at = [&](int i, int j) {
    return base + static_cast<unsigned>(i * (segments + 1) + j);
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      if (i > 0) mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i + 1 < rings) mesh.triangles.push_back({at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  }
}

BodyMesh MakeBody() {
  BodyMesh body;
  const int r = 32, s = 72;  // 2 * 72 * 31 = 4464 triangles per part, 11 parts
  AddEllipsoid(body, {0.0f, 1.32f, 0.0f}, {0.30f, 0.32f, 0.17f}, r, s);    // chest
  AddEllipsoid(body, {0.0f, 0.95f, 0.0f}, {0.27f, 0.18f, 0.16f}, r, s);    // pelvis
  AddEllipsoid(body, {0.0f, 1.76f, 0.02f}, {0.13f, 0.15f, 0.14f}, r, s);   // head
  for (float side : {-1.0f, 1.0f}) {
    AddEllipsoid(body, {side * 0.50f, 1.45f, 0.0f}, {0.22f, 0.085f, 0.085f}, r, s);  // upper arm
    AddEllipsoid(body, {side * 0.90f, 1.45f, 0.0f}, {0.20f, 0.07f, 0.07f}, r, s);    // forearm
    AddEllipsoid(body, {side * 0.15f, 0.62f, 0.0f}, {0.12f, 0.25f, 0.12f}, r, s);    // thigh
    AddEllipsoid(body, {side * 0.15f, 0.22f, 0.0f}, {0.09f, 0.22f, 0.09f}, r, s);    // shin
  }
  return body;
}

void BM_RenderBody(benchmark::State& state) {
  static const BodyMesh body = MakeBody();
  render::RenderSettings settings;
  settings.width = static_cast<int>(state.range(0));
  settings.height = static_cast<int>(state.range(1));
  settings.threads = static_cast<int>(state.range(2));
  settings.supersample = static_cast<int>(state.range(3));
  const bool full = state.range(4) != 0;
  settings.lighting = full ? render::LightingModel::kBlinnPhong : render::LightingModel::kLambert;
  settings.ground = full;
  settings.cull_back_faces = true;
  render::Camera camera;
  camera.eye = glm::vec3(0.3f, 1.2f, 1.55f);
  camera.target = glm::vec3(0.0f, 1.05f, 0.0f);
  camera.aspect = static_cast<float>(settings.width) / static_cast<float>(settings.height);
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
