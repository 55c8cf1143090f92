// Patch layer benchmark on the mannequin (tests/support/patch_layer_fixture.h):
// the left elbow and knee patches at the 120 degree bend. Reports, one core:
//  - CarryAndRebuild/<patch>: one patch's per-frame work (carry its control
//    points by SSD, rebuild its bound vertices), bound vertices per second;
//  - LayeredFrame: a whole frame, SSD of every vertex + both patches + border
//    blend + vertex normals from the mesh, against GlobalFrame (SSD + normals).
//
//   build/bench/bench/patch_layer_bench --benchmark_min_time=0.5

#include <benchmark/benchmark.h>

#include <vector>

#include "support/patch_layer_fixture.h"

namespace {

struct Scene {
  testfixture::LayeredBody body = testfixture::MakeLayeredBody();
  std::vector<deform::PatchSetup> patches;
  std::vector<glm::mat4> palette;
  Scene() {
    patches.push_back(*testfixture::MakePatch(body, testfixture::ElbowSpec(body)));
    patches.push_back(*testfixture::MakePatch(body, testfixture::KneeSpec(body)));
    palette.resize(body.mesh.skin_joints.size());
    (void)deform::BuildSkinningPalette(testfixture::BendPose(body, 120.0f), body.mesh, palette);
  }
};

const Scene& GetScene() {
  static const Scene scene;
  return scene;
}

void CarryAndRebuild(benchmark::State& state) {
  const Scene& s = GetScene();
  const deform::PatchSetup& p = s.patches[static_cast<std::size_t>(state.range(0))];
  std::vector<glm::vec3> control(p.rest_control.size()), rebuilt(p.bound.binding.size());
  for (auto _ : state) {
    (void)deform::CarryControlPointsJob{
        .patch = &p, .pose = {.model_from_bind = s.palette}, .control = control}
        .Run();
    (void)deform::PatchRebuildJob{.control = control, .bindings = p.bound.binding.view(),
                                  .positions = rebuilt}
        .Run();
    benchmark::DoNotOptimize(rebuilt.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(rebuilt.size()));
  state.SetLabel(std::string(state.range(0) == 0 ? "elbow " : "knee ") +
                 std::to_string(p.fit.surface.num_u()) + "x" +
                 std::to_string(p.fit.surface.num_v()) + ", " + std::to_string(rebuilt.size()) +
                 " bound vertices");
}
BENCHMARK(CarryAndRebuild)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void Frame(benchmark::State& state, bool layered) {
  const Scene& s = GetScene();
  const deform::SkinnedMesh& m = s.body.mesh;
  std::vector<glm::vec3> positions(m.bind.positions.size()), normals(positions.size());
  std::vector<std::vector<glm::vec3>> carried(s.patches.size());
  std::vector<std::span<const glm::vec3>> views;
  for (std::size_t k = 0; k < s.patches.size(); ++k) {
    carried[k].resize(s.patches[k].rest_control.size());
    views.emplace_back(carried[k]);
  }
  deform::PatchLayerScratch scratch;
  scratch.Prepare(s.patches, m.bind.num_vertices());
  for (auto _ : state) {
    (void)deform::SkinningJob{.model_from_bind = s.palette, .influences = m.weights.influences,
                              .joint_indices = m.weights.joints, .joint_weights = m.weights.weights,
                              .rest_positions = m.bind.positions, .rest_normals = {},
                              .positions = positions, .normals = {}}
        .Run();
    if (layered) {
      for (std::size_t k = 0; k < s.patches.size(); ++k) {
        (void)deform::CarryControlPointsJob{
            .patch = &s.patches[k], .pose = {.model_from_bind = s.palette}, .control = carried[k]}
            .Run();
      }
      (void)deform::ApplyPatchLayer(s.patches, views, {}, scratch, positions);
    }
    deform::ComputeVertexNormals(positions, m.bind.triangles, normals);
    benchmark::DoNotOptimize(normals.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(positions.size()));
  state.SetLabel(std::to_string(positions.size()) + " vertices");
}
void GlobalFrame(benchmark::State& state) { Frame(state, false); }
void LayeredFrame(benchmark::State& state) { Frame(state, true); }
BENCHMARK(GlobalFrame)->Unit(benchmark::kMicrosecond);
BENCHMARK(LayeredFrame)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
