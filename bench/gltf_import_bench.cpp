// glTF import and animation sampling on CesiumMan (3273 vertices, 19 skin
// joints, 57 channels of 48 keys): load time, exact sampling per frame, and
// sampling a whole clip into a Motion.
// Run: build/bench/bench/gltf_import_bench [--benchmark_filter=...]
// The model comes from PATCHSKIN_GLTF_BENCH_FILE or ../shared/data/gltf/CesiumMan.glb.

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "deform/io/gltf_import.h"

namespace {

std::string ModelPath() {
  const char* env = std::getenv("PATCHSKIN_GLTF_BENCH_FILE");
  return env != nullptr ? env : std::string(PATCHSKIN_DATA_DIR) + "/gltf/CesiumMan.glb";
}

void BM_ReadGltf(benchmark::State& state) {
  const std::string path = ModelPath();
  for (auto _ : state) {
    auto model = deform::ReadGltf(path);
    if (!model.ok()) {
      state.SkipWithError(model.error().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(model->mesh.bind.positions.data());
  }
}
BENCHMARK(BM_ReadGltf)->Unit(benchmark::kMillisecond);

void BM_SampleGltfAnimation(benchmark::State& state) {
  auto model = deform::ReadGltf(ModelPath());
  if (!model.ok()) {
    state.SkipWithError(model.error().ToString().c_str());
    return;
  }
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(model->skeleton.num_joints()));
  double t = 0.0;
  for (auto _ : state) {
    deform::SampleGltfAnimation(*model, 0, t, locals);
    benchmark::DoNotOptimize(locals.data());
    t += 1.0 / 60.0;
    if (t > model->animations[0].duration_s) t = 0.0;
  }
}
BENCHMARK(BM_SampleGltfAnimation)->Unit(benchmark::kMicrosecond);

void BM_AnimationToMotion(benchmark::State& state) {
  auto model = deform::ReadGltf(ModelPath());
  if (!model.ok()) {
    state.SkipWithError(model.error().ToString().c_str());
    return;
  }
  const double frame_time_s = 1.0 / static_cast<double>(state.range(0));
  for (auto _ : state) {
    auto motion = deform::AnimationToMotion(*model, 0, frame_time_s);
    benchmark::DoNotOptimize(motion->values.data());
  }
}
BENCHMARK(BM_AnimationToMotion)->Arg(30)->Arg(120)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
