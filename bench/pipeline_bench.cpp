// FramePipeline::Evaluate per frame on the built-in demo's mannequin (the walk,
// samples/data/demo_walk.bvh) for SSD, DQS and SWD with 1 and 2 threads. Items =
// vertices, so items/s is the deformation rate including sampling, forward
// kinematics, palettes and normal renormalization.
// BM_EvaluateBelly: the sample rig samples/data/belly_jump.json (SSD, one 6x6
// belly patch on the mannequin, the jump) with and without its elastic layer,
// frame after frame, so the difference is the elastic layer's cost per frame.
// BM_BellyFrameShare: that cost as a share of a whole rendered frame.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "app/demo_data.h"
#include "app/motion_source.h"
#include "deform/pipeline/elastic_layer.h"
#include "app/frame_render.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "mocap/kinematics.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"

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
struct BellyScene {
  app::Rig rig;
  app::Character character;
  std::vector<deform::PatchSetup> patches;
  std::vector<deform::ElasticPatchSpec> specs;
};

std::optional<BellyScene> LoadBelly(benchmark::State& state) {
  auto rig = app::LoadRig(std::string(PATCHSKIN_SAMPLES_DIR) + "/belly_jump.json");
  if (!rig.ok()) {
    state.SkipWithError(rig.error().ToString().c_str());
    return std::nullopt;
  }
  auto src = app::LoadMotionSource(rig->motion, {.y_up = true});
  if (!src.ok()) std::abort();
  auto c = app::MakeCharacter(std::move(*src));
  if (!c.ok()) std::abort();
  auto patches = app::BuildRigPatches(*rig, *c);
  if (!patches.ok()) std::abort();
  auto specs = app::ResolveRigElastic(*rig, *c, *patches);
  if (!specs.ok()) std::abort();
  return BellyScene{std::move(*rig), std::move(*c), std::move(*patches), std::move(*specs)};
}

void BM_EvaluateBelly(benchmark::State& state, bool elastic) {
  std::optional<BellyScene> scene = LoadBelly(state);
  if (!scene) return;
  const app::Character* c = &scene->character;
  auto pipeline = deform::FramePipeline::Create(*c, deform::GlobalMethod::kSsd, 1);
  if (!pipeline.ok()) std::abort();
  if (!pipeline->SetPatches(std::move(scene->patches)).ok()) std::abort();
  if (elastic && !pipeline->SetElastic(std::move(scene->specs)).ok()) std::abort();
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

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The elastic layer's cost per output frame as a share of the whole frame: the
// belly_jump rig at 30 fps, each iteration one frame of (a) the layered
// pipeline with the elastic patch (Evaluate) and (b) its render at 1280 x 720,
// supersample 2, one thread (DrawCharacterFrame, as `patchskin render` draws;
// PNG encoding not included), while a separate ElasticLayer advances a copy of
// the same network to the same time (c). Counters (thread CPU time per frame):
// elastic_us = (c), frame_us = (a) + (b), elastic_share = (c) / ((a) + (b)).
void BM_BellyFrameShare(benchmark::State& state) {
  std::optional<BellyScene> scene = LoadBelly(state);
  if (!scene) return;
  const app::Rig* rig = &scene->rig;
  const app::Character* c = &scene->character;
  auto pipeline = deform::FramePipeline::Create(*c, deform::GlobalMethod::kSsd, 1);
  if (!pipeline.ok()) std::abort();
  auto layer = deform::ElasticLayer::Create(*c, scene->patches, scene->specs);
  if (!layer.ok()) std::abort();
  if (!pipeline->SetPatches(std::move(scene->patches)).ok()) std::abort();
  if (!pipeline->SetElastic(std::move(scene->specs)).ok()) std::abort();
  // Joint matrices of every frame for the separate layer's driving rotation.
  const mocap::Skeleton& skel = c->skeleton;
  const std::size_t nj = static_cast<std::size_t>(skel.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(static_cast<std::size_t>(c->motion.num_frames) * nj);
  if (!mocap::ModelMatricesJob{.skeleton = &skel, .motion = &c->motion, .locals = locals,
                               .model_from_joint = model}
           .Run()) {
    std::abort();
  }
  deform::DeformedFrame frame;
  if (!pipeline->Evaluate(0.0, frame).ok()) std::abort();
  render::RenderSettings settings;  // 1280 x 720
  settings.supersample = 2;
  settings.threads = 1;
  const render::Camera camera =
      render::FrameBounds(frame.bounds, 35.0f, 1280.0f / 720.0f, glm::vec3(0.0f, 0.0f, -1.0f));
  render::Renderer renderer, unused;
  render::Image image, scratch;
  std::vector<std::vector<glm::vec3>> displacements(static_cast<std::size_t>(rig->patches.size()));
  const double dt = 1.0 / 30.0;
  const int frames = static_cast<int>(c->motion.duration_s() / dt);
  const double clip_dt = c->motion.frame_time_s;
  double elastic_s = 0.0, frame_s = 0.0;
  int f = 0;
  for (auto _ : state) {
    const double t = f * dt;
    const double t0 = ThreadCpuSeconds();
    if (!pipeline->Evaluate(t, frame).ok()) std::abort();
    app::FrameDrawOptions options;
    options.frame_number = f;
    if (!app::DrawCharacterFrame(*c, frame, nullptr, camera, settings, options, renderer, unused,
                                 scratch, image)
             .ok()) {
      std::abort();
    }
    const double t1 = ThreadCpuSeconds();
    const std::size_t clip_frame = static_cast<std::size_t>(std::lround(t / clip_dt));
    const std::span<const glm::mat4> joints(&model[std::min(clip_frame, model.size() / nj - 1) * nj], nj);
    if (!(*layer)->Advance(t, joints, displacements).ok()) std::abort();
    const double t2 = ThreadCpuSeconds();
    frame_s += t1 - t0;
    elastic_s += t2 - t1;
    benchmark::DoNotOptimize(image);
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
