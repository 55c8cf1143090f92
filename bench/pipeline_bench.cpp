// FramePipeline::Evaluate per frame on the built-in demo's mannequin (the walk,
// samples/data/demo_walk.bvh) for SSD, DQS and SWD with 1 and 2 threads. Items =
// vertices, so items/s is the deformation rate including sampling, forward
// kinematics, palettes and normal renormalization.
// BM_EvaluateBelly: the sample rig samples/data/belly_jump.json (SSD, one 6x6
// belly patch on the mannequin, the jump) with and without its elastic layer,
// frame after frame, so the difference is the elastic layer's cost per frame.
// BM_BellyFrameShare: that cost as a share of a whole rendered frame.

#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

#include <benchmark/benchmark.h>

#include "app/bench_scenes.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"

namespace {

const app::Character& DemoCharacter() {
  static const app::Character character = [] {
    auto c = app::bench::LoadDemoCharacter();
    if (!c.ok()) std::abort();
    return std::move(*c);
  }();
  return character;
}

void BM_Evaluate(benchmark::State& state, deform::GlobalMethod method) {
  const app::Character& c = DemoCharacter();
  auto pipeline = deform::FramePipeline::Create(c, method, static_cast<int>(state.range(0)));
  if (!pipeline.ok()) {
    state.SkipWithError(pipeline.error().ToString().c_str());
    return;
  }
  deform::DeformedFrame frame;
  const double duration = c.motion.duration_s();
  double t = 0.0;
  for (auto _ : state) {
    if (!pipeline->Evaluate(t, frame).ok()) {
      state.SkipWithError("Evaluate failed");
      return;
    }
    benchmark::DoNotOptimize(frame.positions.data());
    t += 1.0 / 30.0;
    if (t > duration) t = 0.0;
  }
  state.SetItemsProcessed(state.iterations() * c.mesh.bind.num_vertices());
  state.counters["vertices"] = c.mesh.bind.num_vertices();
}

BENCHMARK_CAPTURE(BM_Evaluate, ssd, deform::GlobalMethod::kSsd)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Evaluate, dqs, deform::GlobalMethod::kDqs)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Evaluate, swd, deform::GlobalMethod::kSwd)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// The belly_jump sample rig on the mannequin: its character, patches and
// resolved elastic specs. Skips the benchmark if the rig is missing.
std::optional<app::bench::SampleRigScene> LoadBelly(benchmark::State& state) {
  auto scene = app::bench::LoadSampleRig(std::string(PATCHSKIN_SAMPLES_DIR) + "/belly_jump.json");
  if (!scene.ok()) {
    state.SkipWithError(scene.error().ToString().c_str());
    return std::nullopt;
  }
  return std::move(*scene);
}

void BM_EvaluateBelly(benchmark::State& state, bool elastic) {
  std::optional<app::bench::SampleRigScene> scene = LoadBelly(state);
  if (!scene) return;
  const app::Character* c = &scene->character;
  auto pipeline = deform::FramePipeline::Create(*c, deform::GlobalMethod::kSsd, 1);
  if (!pipeline.ok()) std::abort();
  if (!pipeline->SetPatches(std::move(scene->layers.patches)).ok()) std::abort();
  if (elastic && !pipeline->SetElastic(std::move(scene->layers.elastic)).ok()) std::abort();
  deform::DeformedFrame frame;
  const double dt = c->motion.frame_time_s;
  int f = 0;
  for (auto _ : state) {
    if (!pipeline->Evaluate(f * dt, frame).ok()) {
      state.SkipWithError("Evaluate failed");
      return;
    }
    benchmark::DoNotOptimize(frame.positions.data());
    f = f + 1 < c->motion.num_frames ? f + 1 : 0;  // a restart re-simulates from t = 0
  }
  state.SetItemsProcessed(state.iterations());  // frames
}

BENCHMARK_CAPTURE(BM_EvaluateBelly, patch_only, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EvaluateBelly, patch_elastic, true)->Unit(benchmark::kMicrosecond);

// The elastic layer's cost per output frame as a share of the whole frame: the
// belly_jump rig at 30 fps, each iteration one frame of (a) the layered
// pipeline with the elastic patch (Evaluate) and its render at 1280 x 720,
// supersample 2, one thread (as `patchskin render` draws; PNG encoding not
// included), while a separate ElasticLayer advances a copy of the same network
// to the same time (b): app::bench::ElasticShareProbe, which `patchskin bench`'s
// row elastic_share_two_patches also uses. Counters (thread CPU time per
// frame): elastic_us = (b), frame_us = (a), elastic_share = (b) / (a).
void BM_BellyFrameShare(benchmark::State& state) {
  std::optional<app::bench::SampleRigScene> scene = LoadBelly(state);
  if (!scene) return;
  const app::Character* c = &scene->character;
  auto pipeline = deform::FramePipeline::Create(*c, deform::GlobalMethod::kSsd, 1);
  if (!pipeline.ok()) std::abort();
  if (!pipeline->SetPatches(scene->layers.patches).ok()) std::abort();
  if (!pipeline->SetElastic(scene->layers.elastic).ok()) std::abort();
  auto probe = app::bench::ElasticShareProbe::Create(*c, *pipeline, scene->layers, "belly",
                                                     /*png=*/false);
  if (!probe.ok()) std::abort();
  const double dt = 1.0 / 30.0;
  const int frames = static_cast<int>(c->motion.duration_s() / dt);
  double elastic_s = 0.0, frame_s = 0.0;
  int f = 0;
  for (auto _ : state) {
    auto split = (*probe)->Frame(f);
    if (!split.ok()) std::abort();
    frame_s += split->frame_s;
    elastic_s += split->elastic_s;
    f = f + 1 < frames ? f + 1 : 0;  // a restart re-simulates from t = 0
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["elastic_us"] = 1e6 * elastic_s / n;
  state.counters["frame_us"] = 1e6 * frame_s / n;
  state.counters["elastic_share"] = elastic_s / frame_s;
}

BENCHMARK(BM_BellyFrameShare)->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
