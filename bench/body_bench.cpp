// The generated body (deform/body/) of a real ~30-joint humanoid capture, CMU cgspeed
// 01_01 (31 joints) at its rest pose, on one core (TBB limited to one thread): the
// shape, the OpenVDB mesh, the bone-heat weights, all three together, and a read back
// from the body cache. Counters: triangles and vertices of the body.
// Budget (issue 25): 20k-60k triangles, shape + mesh + weights under 2 s.

#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "deform/body/body_mesher.h"
#include "deform/body/bone_heat.h"
#include "deform/body/generated_body.h"
#include "deform/body/implicit_body.h"
#include "mocap/bvh_reader.h"
#include "mocap/pose.h"

namespace {

struct Capture {
  mocap::Skeleton skeleton;
  std::vector<glm::mat4> rest;
  bool ok = false;
};

const Capture& Cmu() {
  static const Capture c = [] {
    Capture out;
    auto file = mocap::ReadBvhFile(std::string(PATCHSKIN_DATA_DIR) + "/bvh/cmu_cgspeed/01_01.bvh");
    if (!file.ok()) return out;
    out.skeleton = std::move(file->skeleton);
    std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(out.skeleton.num_joints()));
    mocap::RestPose(out.skeleton, locals);
    out.rest.resize(locals.size());
    out.ok = static_cast<bool>(
        mocap::LocalToModelJob{.parents = out.skeleton.parents, .locals = locals, .model_from_joint = out.rest}.Run());
    return out;
  }();
  return c;
}

bool Ready(benchmark::State& state) {
  if (Cmu().ok) return true;
  state.SkipWithError("../shared/data/bvh/cmu_cgspeed/01_01.bvh is absent (PATCHSKIN_DATA_DIR)");
  return false;
}

void BM_Shape(benchmark::State& state) {
  if (!Ready(state)) return;
  for (auto _ : state) {
    auto body = deform::BuildImplicitBody(Cmu().skeleton, Cmu().rest);
    benchmark::DoNotOptimize(body);
  }
}

void BM_Mesh(benchmark::State& state) {
  if (!Ready(state)) return;
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  auto body = deform::BuildImplicitBody(Cmu().skeleton, Cmu().rest);
  int triangles = 0;
  for (auto _ : state) {
    auto mesh = deform::MeshImplicitBody(*body);
    triangles = mesh->num_triangles();
    benchmark::DoNotOptimize(mesh);
  }
  state.counters["triangles"] = triangles;
}

void BM_Weights(benchmark::State& state) {
  if (!Ready(state)) return;
  auto body = deform::BuildImplicitBody(Cmu().skeleton, Cmu().rest);
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  auto mesh = deform::MeshImplicitBody(*body);
  const deform::ImplicitBody& b = *body;
  for (auto _ : state) {
    auto w = deform::ComputeBoneHeatWeights(*mesh, b.bones(), [&b](const glm::vec3& p) { return b.Distance(p); },
                                            b.size());
    benchmark::DoNotOptimize(w);
  }
  state.counters["vertices"] = mesh->num_vertices();
}

void BM_WholeBody(benchmark::State& state) {
  if (!Ready(state)) return;
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  int triangles = 0, vertices = 0;
  for (auto _ : state) {
    auto m = deform::BuildGeneratedBody(Cmu().skeleton, Cmu().rest);
    triangles = m->bind.num_triangles();
    vertices = m->bind.num_vertices();
    benchmark::DoNotOptimize(m);
  }
  state.counters["triangles"] = triangles;
  state.counters["vertices"] = vertices;
}

void BM_FromCache(benchmark::State& state) {
  if (!Ready(state)) return;
  const std::filesystem::path folder = std::filesystem::path(PATCHSKIN_BENCH_OUTPUT_DIR) / "body_cache";
  std::filesystem::remove_all(folder);
  (void)deform::BuildGeneratedBodyCached(Cmu().skeleton, Cmu().rest, {}, folder);  // fills it
  bool hit = false;
  for (auto _ : state) {
    auto m = deform::BuildGeneratedBodyCached(Cmu().skeleton, Cmu().rest, {}, folder, &hit);
    benchmark::DoNotOptimize(m);
  }
  if (!hit) state.SkipWithError("the cache was not used");
}

BENCHMARK(BM_Shape)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Mesh)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Weights)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WholeBody)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FromCache)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
