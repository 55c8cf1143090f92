// Patch benchmark: the four patch sizes of the paper (elbow+biceps 9x10 with
// ~1150 bound vertices, shoulder 9x6 / ~1350, abdomen 5x5 / ~55, face 7x7 /
// ~250) on generated tube regions. Reports rebuild vertices per second (one
// core), bytes per bound vertex, and the setup times of fitting and binding.
//
//   build/bench/bench/patch_bench --benchmark_min_time=0.5

#include <benchmark/benchmark.h>

#include <vector>

#include "deform/patch/patch_binding.h"
#include "deform/patch/patch_fit.h"
#include "deform/simd.h"
#include "support/patch_meshes.h"

namespace {

struct PatchCase {
  int m, n;                // control grid
  int around, along;       // tube vertices: around x along ~ the paper's vertex count
};

// Indexed by the benchmark argument.
constexpr PatchCase kCases[] = {{9, 10, 46, 25}, {9, 6, 54, 25}, {5, 5, 11, 5}, {7, 7, 25, 10}};

struct Prepared {
  deform::Mesh mesh;
  deform::RegionParametrization param;
  deform::PatchSamples samples;
  deform::BSplineSurface surface;
  deform::PatchBinding binding;
};

deform::Mesh CaseMesh(const PatchCase& c) {
  return testsupport::MakeTube(c.around, c.along, 4.0f, 200.0f, 20.0f);
}

deform::RegionParametrization Param(const deform::Mesh& mesh) {
  return *deform::ParametrizeCylinder(mesh.positions, testsupport::AllVertices(mesh), mesh.triangles,
                                      glm::dvec3(0.0), glm::dvec3(0, 0, 1));
}

deform::PatchSamples Samples(const deform::Mesh& mesh, const deform::RegionParametrization& p,
                             const PatchCase& c) {
  return *deform::SampleRegion(mesh.positions, mesh.triangles, p, deform::UniformParameters(c.m + 4),
                               deform::UniformParameters(c.n + 4));
}

Prepared Prepare(const PatchCase& c) {
  Prepared p;
  p.mesh = CaseMesh(c);
  p.param = Param(p.mesh);
  p.samples = Samples(p.mesh, p.param, c);
  p.surface = deform::FitSurface(p.samples, {.num_u = c.m, .num_v = c.n})->surface;
  deform::OrientNormal(p.surface, p.param);
  p.binding = deform::BindPatch(p.surface, p.mesh.positions, p.param.region, p.param.uv)->binding;
  return p;
}

void SetLabel(benchmark::State& state, const PatchCase& c, size_t bound) {
  state.SetLabel(std::to_string(c.m) + "x" + std::to_string(c.n) + "/" + std::to_string(bound) +
                 " bound verts");
}

void RebuildBench(benchmark::State& state, bool normals, bool simd) {
  const PatchCase& c = kCases[state.range(0)];
  const Prepared p = Prepare(c);
  std::vector<glm::vec3> control = deform::ControlPointsAsFloat(p.surface);
  for (glm::vec3& q : control) q *= 1.01f;  // a deformed frame
  std::vector<glm::vec3> pos(p.binding.size()), nrm(normals ? p.binding.size() : 0);
  const deform::PatchRebuildJob job{
      .control = control, .bindings = p.binding.view(), .positions = pos, .normals = nrm};
  // simd = false: the scalar loop, the process capped to the baseline (deform/simd.h).
  deform::SetSimdCap(simd ? deform::SimdLevel::kAvx : deform::SimdLevel::kBaseline);
  for (auto _ : state) {
    benchmark::DoNotOptimize(job.Run());
    benchmark::ClobberMemory();
  }
  deform::SetSimdCap(deform::SimdLevel::kAvx);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(p.binding.size()));
  state.counters["bytes_per_vertex"] = deform::PatchBinding::kStoredBytesPerVertex;
  state.counters["rebuild_bytes_per_vertex"] = deform::PatchBinding::kRebuildBytesPerVertex;
  state.counters["us_per_rebuild"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * 1e-6,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  SetLabel(state, c, p.binding.size());
}

void BM_Rebuild(benchmark::State& state) { RebuildBench(state, false, true); }
void BM_RebuildWithNormals(benchmark::State& state) { RebuildBench(state, true, true); }
void BM_RebuildScalar(benchmark::State& state) { RebuildBench(state, false, false); }

void BM_Fit(benchmark::State& state) {
  const PatchCase& c = kCases[state.range(0)];
  const deform::Mesh mesh = CaseMesh(c);
  double max_error = 0.0;
  for (auto _ : state) {
    const deform::RegionParametrization param = Param(mesh);
    const deform::PatchSamples samples = Samples(mesh, param, c);
    auto fit = deform::FitSurface(samples, {.num_u = c.m, .num_v = c.n});
    max_error = fit->max_error;
    benchmark::DoNotOptimize(fit);
  }
  state.counters["fit_max_error"] = max_error;
  SetLabel(state, c, mesh.positions.size());
}

void BM_Bind(benchmark::State& state) {
  const PatchCase& c = kCases[state.range(0)];
  const Prepared p = Prepare(c);
  deform::BindingReport report;
  for (auto _ : state) {
    auto bound = deform::BindPatch(p.surface, p.mesh.positions, p.param.region, p.param.uv);
    report = bound->report;
    benchmark::DoNotOptimize(bound);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(p.param.region.size()));
  state.counters["bound"] = report.bound;
  state.counters["border"] = static_cast<double>(report.border_vertices.size());
  state.counters["rest_err_rel"] = report.max_rest_error / report.patch_diagonal;
  SetLabel(state, c, static_cast<size_t>(report.bound));
}

BENCHMARK(BM_Rebuild)->DenseRange(0, 3);
BENCHMARK(BM_RebuildWithNormals)->DenseRange(0, 3);
BENCHMARK(BM_RebuildScalar)->DenseRange(0, 3);
BENCHMARK(BM_Fit)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Bind)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
