// Per-patch example-shape update on the shipped demo rigs (issue 6; the
// paper's Table 1): samples/data/biceps.json (the 9x10 elbow + biceps patch,
// 5 examples) and samples/data/shoulder.json (9x6, 5 examples), on the
// mannequin, at a pose between examples.
//
//   BM_DemoPoseUpdate        theta (features from the local pose) -> dS(theta)
//                            -> A (control-point rotations) -> Q = G + A dS:
//                            the paper's "RBF" column (3195 and 5348 per second)
//   BM_DemoRotations, BM_DemoDisplacementAndApply
//                            the update's two parts alone: A (given dS), and
//                            features -> dS -> Q = G + A dS (given A)
//   BM_DemoUpdateAndRebuild  carry G by SSD + the update above + rebuild of the
//                            bound vertices: one patch's whole per-frame work,
//                            beside the paper's "Total (FPS)" (581 and 532)
//
//   build/bench/bench/example_demos_bench --benchmark_min_time=0.5

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/bench_scenes.h"
#include "app/character.h"
#include "app/rig_examples.h"
#include "deform/shapes/example_shapes.h"
#include "deform/global/skinning_job.h"
#include "mocap/pose.h"

namespace {

struct DemoScene {
  app::Rig rig;
  app::Character character;
  std::vector<deform::PatchSetup> patches;
  app::RigPoseSpaces spaces;
  std::vector<mocap::JointTransform> locals;  // the pose benchmarked
  std::vector<glm::mat4> palette;
  std::string error;
};

// Loads samples/data/<name>.json and poses it at `frame` of its motion.
std::unique_ptr<DemoScene> LoadScene(const std::string& name, int frame) {
  auto s = std::make_unique<DemoScene>();
  auto scene = app::bench::LoadSampleRig(std::string(PATCHSKIN_SAMPLES_DIR) + "/" + name + ".json");
  if (!scene.ok()) return s->error = scene.error().ToString(), std::move(s);
  s->rig = std::move(scene->rig);
  s->character = std::move(scene->character);
  s->patches = std::move(scene->layers.patches);
  auto spaces =
      app::BuildRigPoseSpaces(s->rig, s->character, s->patches, deform::GlobalMethod::kSsd);
  if (!spaces.ok()) return s->error = spaces.error().ToString(), std::move(s);
  s->spaces = std::move(*spaces);
  const mocap::Skeleton& sk = s->character.skeleton;
  const auto nj = static_cast<std::size_t>(sk.num_joints());
  s->locals.resize(nj);
  std::vector<glm::mat4> model(nj);
  s->palette.resize(s->character.mesh.skin_joints.size());
  (void)mocap::LocalPoseJob{&sk, s->character.motion.frame(frame), s->locals}.Run();
  (void)mocap::LocalToModelJob{.parents = sk.parents, .locals = s->locals, .model_from_joint = model}
      .Run();
  (void)deform::BuildSkinningPalette(model, s->character.mesh, s->palette);
  return s;
}

// Frames between examples: the biceps rig's examples are at frames 12, 24, 36,
// 48, 60 of bend.bvh, the shoulder's at 15, 45, 75, 105, 135 of shoulder.bvh
// (frame 52: the arm halfway down from raised).
const DemoScene& Scene(int which) {
  static const std::unique_ptr<DemoScene> biceps = LoadScene("biceps", 42);
  static const std::unique_ptr<DemoScene> shoulder = LoadScene("shoulder", 52);
  return which == 0 ? *biceps : *shoulder;
}

void Update(benchmark::State& state, bool rebuild) {
  const DemoScene& s = Scene(static_cast<int>(state.range(0)));
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  const deform::PatchSetup& p = s.patches[0];
  const deform::PatchPoseSpace& space = s.spaces.patches[0];
  const auto nc = static_cast<std::size_t>(p.num_control());
  std::vector<glm::vec3> carried(nc), ds(nc), rebuilt(p.bound.binding.size());
  std::vector<glm::quat> rotations(nc);
  std::vector<float> features(static_cast<std::size_t>(space.model.dimension));
  (void)deform::CarryControlPointsJob{
      .patch = &p, .pose = {.model_from_bind = s.palette}, .control = carried}
      .Run();
  const deform::SkinningPose pose{.model_from_bind = s.palette};
  // How many control points need A at this pose (dS != 0), and how many of
  // those blend three or more bones (Newton's polar iteration).
  (void)deform::ComputePoseFeatures(s.character.skeleton, space.features, s.locals, features);
  (void)deform::PoseSpaceJob{.model = &space.model, .features = features, .displacement = ds}.Run();
  // And how many distinct bones those control points blend (each is
  // converted once per update).
  int moving = 0, three_plus = 0;
  std::vector<std::uint8_t> bone_used(s.palette.size(), 0);
  for (std::size_t c = 0; c < nc; ++c) {
    if (ds[c] == glm::vec3(0.0f)) continue;
    ++moving;
    int bones = 0;
    for (int i = 0; i < p.control_weights.influences; ++i) {
      const std::size_t slot = c * static_cast<std::size_t>(p.control_weights.influences) +
                               static_cast<std::size_t>(i);
      if (p.control_weights.weights[slot] == 0.0f) continue;
      ++bones;
      bone_used[p.control_weights.joints[slot]] = 1;
    }
    three_plus += bones >= 3;
  }
  state.counters["moving"] = moving;
  state.counters["moving_3plus_bones"] = three_plus;
  state.counters["bones"] = static_cast<double>(std::count(bone_used.begin(), bone_used.end(), 1));
  for (auto _ : state) {
    if (rebuild) {
      (void)deform::CarryControlPointsJob{
          .patch = &p, .pose = {.model_from_bind = s.palette}, .control = carried}
          .Run();
    }
    (void)deform::ComputePoseFeatures(s.character.skeleton, space.features, s.locals, features);
    (void)deform::PoseSpaceJob{.model = &space.model, .features = features, .displacement = ds}
        .Run();
    (void)deform::PatchControlRotations(p, pose, rotations, ds);
    (void)deform::PoseSpaceApplyJob{.global = carried, .rotations = rotations, .displacement = ds,
                                    .control = carried}
        .Run();
    if (rebuild) {
      (void)deform::PatchRebuildJob{.control = carried, .bindings = p.bound.binding.view(),
                                    .positions = rebuilt}
          .Run();
    }
    benchmark::DoNotOptimize(carried.data());
    benchmark::DoNotOptimize(rebuilt.data());
  }
  state.SetItemsProcessed(state.iterations());
  const bool elbow = state.range(0) == 0;
  state.counters["paper_per_s"] = rebuild ? (elbow ? 581 : 532) : (elbow ? 3195 : 5348);
  state.SetLabel(std::string(elbow ? "biceps " : "shoulder ") + std::to_string(p.fit.surface.num_u()) +
                 "x" + std::to_string(p.fit.surface.num_v()) + ", " +
                 std::to_string(space.model.num_centres - 1) + " examples, " +
                 std::to_string(rebuilt.size()) + " bound vertices");
}

// The update's parts on their own, for where the time goes: the rotations A
// (PatchControlRotations, given dS) and the rest (features, dS, Q = G + A dS
// with given A).
void Part(benchmark::State& state, bool rotations_only) {
  const DemoScene& s = Scene(static_cast<int>(state.range(0)));
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  const deform::PatchSetup& p = s.patches[0];
  const deform::PatchPoseSpace& space = s.spaces.patches[0];
  const auto nc = static_cast<std::size_t>(p.num_control());
  std::vector<glm::vec3> carried(nc), ds(nc), control(nc);
  std::vector<glm::quat> rotations(nc);
  std::vector<float> features(static_cast<std::size_t>(space.model.dimension));
  (void)deform::CarryControlPointsJob{
      .patch = &p, .pose = {.model_from_bind = s.palette}, .control = carried}
      .Run();
  const deform::SkinningPose pose{.model_from_bind = s.palette};
  (void)deform::ComputePoseFeatures(s.character.skeleton, space.features, s.locals, features);
  (void)deform::PoseSpaceJob{.model = &space.model, .features = features, .displacement = ds}.Run();
  (void)deform::PatchControlRotations(p, pose, rotations, ds);
  for (auto _ : state) {
    if (rotations_only) {
      (void)deform::PatchControlRotations(p, pose, rotations, ds);
      benchmark::DoNotOptimize(rotations.data());
    } else {
      (void)deform::ComputePoseFeatures(s.character.skeleton, space.features, s.locals, features);
      (void)deform::PoseSpaceJob{.model = &space.model, .features = features, .displacement = ds}
          .Run();
      (void)deform::PoseSpaceApplyJob{.global = carried, .rotations = rotations,
                                      .displacement = ds, .control = control}
          .Run();
      benchmark::DoNotOptimize(control.data());
    }
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_DemoPoseUpdate(benchmark::State& state) { Update(state, false); }
void BM_DemoRotations(benchmark::State& state) { Part(state, true); }
void BM_DemoDisplacementAndApply(benchmark::State& state) { Part(state, false); }
void BM_DemoUpdateAndRebuild(benchmark::State& state) { Update(state, true); }
BENCHMARK(BM_DemoPoseUpdate)->Arg(0)->Arg(1);
BENCHMARK(BM_DemoRotations)->Arg(0)->Arg(1);
BENCHMARK(BM_DemoDisplacementAndApply)->Arg(0)->Arg(1);
BENCHMARK(BM_DemoUpdateAndRebuild)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
