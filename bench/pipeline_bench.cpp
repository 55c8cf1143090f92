// FramePipeline::Evaluate per frame on the built-in demo's mannequin (the walk,
// samples/data/demo_walk.bvh) for SSD, DQS and SWD with 1 and 2 threads. Items =
// vertices, so items/s is the deformation rate including sampling, forward
// kinematics, palettes and normal renormalization.
// BM_EvaluateBelly: the sample rig samples/data/belly_jump.json (SSD, one 6x6
// belly patch on the mannequin, the jump) with and without its elastic layer,
// frame after frame, so the difference is the elastic layer's cost per frame.

#include <cstdio>
#include <cstdlib>
#include <utility>

#include <benchmark/benchmark.h>

#include "app/demo_data.h"
#include "app/motion_source.h"
#include "app/elastic_layer.h"
#include "app/pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"

namespace {

const app::Character& DemoCharacter() {
  static const app::Character character = [] {
    app::MotionSourceOptions load;
    load.y_up = true;
    auto src = app::LoadBvhText(app::DemoBvhText(), "demo_walk.bvh", load);
    if (!src.ok()) std::abort();
    auto c = app::MakeCharacter(std::move(*src));
    if (!c.ok()) std::abort();
    return std::move(*c);
  }();
  return character;
}

void BM_Evaluate(benchmark::State& state, app::GlobalMethod method) {
  const app::Character& c = DemoCharacter();
  auto pipeline = app::FramePipeline::Create(c, method, static_cast<int>(state.range(0)));
  if (!pipeline.ok()) {
    state.SkipWithError(pipeline.error().ToString().c_str());
    return;
  }
  app::DeformedFrame frame;
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

BENCHMARK_CAPTURE(BM_Evaluate, ssd, app::GlobalMethod::kSsd)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Evaluate, dqs, app::GlobalMethod::kDqs)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Evaluate, swd, app::GlobalMethod::kSwd)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_EvaluateBelly(benchmark::State& state, bool elastic) {
  auto rig = app::LoadRig(std::string(PATCHSKIN_SAMPLES_DIR) + "/belly_jump.json");
  if (!rig.ok()) {
    state.SkipWithError(rig.error().ToString().c_str());
    return;
  }
  auto src = app::LoadMotionSource(rig->motion, {.y_up = true});
  if (!src.ok()) std::abort();
  auto c = app::MakeCharacter(std::move(*src));
  if (!c.ok()) std::abort();
  auto patches = app::BuildRigPatches(*rig, *c);
  auto specs = app::ResolveRigElastic(*rig, *c, *patches);
  auto pipeline = app::FramePipeline::Create(*c, app::GlobalMethod::kSsd, 1);
  if (!patches.ok() || !specs.ok() || !pipeline.ok()) std::abort();
  if (!pipeline->SetPatches(std::move(*patches)).ok()) std::abort();
  if (elastic && !pipeline->SetElastic(std::move(*specs)).ok()) std::abort();
  app::DeformedFrame frame;
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

}  // namespace

BENCHMARK_MAIN();
