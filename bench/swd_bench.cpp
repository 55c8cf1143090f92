// SWD throughput on a ~20k-vertex arm: a tube of 417 rings x 48 vertices around a
// 3-bone chain (upper arm 30, forearm 25, hand 10 units), elbow bent 100 degrees and
// the hand pronated 60 degrees. Reports vertices per second for the per-frame job
// (with normals; plain, volume keeping, volume keeping + elliptic bulge) and for the
// one-off binding.

#include <array>
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/global/swd_job.h"
#include "deform/global/sweep.h"

namespace {

struct BenchArm {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  deform::SweepChain chain;
};

BenchArm MakeBenchArm() {
  constexpr int kRings = 417;
  constexpr int kSegments = 48;
  BenchArm arm;
  for (int r = 0; r < kRings; ++r) {
    const float x = 65.0f * static_cast<float>(r) / static_cast<float>(kRings - 1);
    for (int i = 0; i < kSegments; ++i) {
      const float angle = 6.2831853f * static_cast<float>(i) / kSegments;
      const glm::vec3 radial(0.0f, std::cos(angle), std::sin(angle));
      arm.positions.push_back(glm::vec3(x, 0, 0) + (4.0f - 0.03f * x) * radial);
      arm.normals.push_back(radial);
    }
  }
  deform::SweepChainSpec spec;
  spec.joints = {0, 1, 2};
  spec.rest_points = {glm::vec3(0), glm::vec3(30, 0, 0), glm::vec3(55, 0, 0),
                      glm::vec3(65, 0, 0)};
  spec.skin_radii = {0.0f, 3.1f, 2.35f, 0.0f};
  spec.twist_spread = {deform::TwistSpread::kDownstream, deform::TwistSpread::kDownstream,
                       deform::TwistSpread::kUpstream, deform::TwistSpread::kDownstream};
  arm.chain = *deform::BuildSweepChain(spec);
  return arm;
}

void BM_SwdJob(benchmark::State& state) {
  const BenchArm arm = MakeBenchArm();
  const std::vector<deform::SweepChain> chains = {arm.chain};
  const auto bindings = deform::BindToSweeps(chains, {}, arm.positions);
  if (!bindings.ok()) {
    state.SkipWithError("binding failed");
    return;
  }
  const glm::quat bend = glm::angleAxis(glm::radians(100.0f), glm::vec3(0, 0, 1));
  const glm::quat hand = bend * glm::angleAxis(glm::radians(60.0f), glm::vec3(1, 0, 0));
  const std::array<glm::quat, 3> rotations = {glm::quat(1, 0, 0, 0), bend, hand};
  const glm::vec3 elbow(30, 0, 0);
  const std::array<glm::vec3, 3> joints = {glm::vec3(0), elbow,
                                           elbow + bend * glm::vec3(25, 0, 0)};
  std::vector<glm::vec3> positions(arm.positions.size()), normals(arm.positions.size());
  // Mode 2 adds a biceps-like elliptic bulge in the elbow region.
  const std::array<deform::SectionScale, 1> bulge = {
      deform::SectionScale{.chain = 0, .joint = 1, .scale_a = 1.3f, .scale_b = 0.9f}};
  const deform::SwdJob job{.chains = chains,
                           .joint_rotations = rotations,
                           .joint_positions = joints,
                           .bindings = *bindings,
                           .rest_normals = arm.normals,
                           .keep_volume = state.range(0) != 0,
                           .section_scales = state.range(0) == 2
                                                 ? std::span<const deform::SectionScale>(bulge)
                                                 : std::span<const deform::SectionScale>(),
                           .positions = positions,
                           .normals = normals};
  for (auto _ : state) {
    const bool ok = job.Run().ok();
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(positions.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(positions.size()));
  state.counters["vertices"] = static_cast<double>(positions.size());
}
// mode 0: plain; 1: keep_volume; 2: keep_volume + elliptic bulge at the elbow.
BENCHMARK(BM_SwdJob)->ArgName("mode")->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_SwdBind(benchmark::State& state) {
  const BenchArm arm = MakeBenchArm();
  const std::vector<deform::SweepChain> chains = {arm.chain};
  for (auto _ : state) {
    auto bindings = deform::BindToSweeps(chains, {}, arm.positions);
    benchmark::DoNotOptimize(bindings);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(arm.positions.size()));
}
BENCHMARK(BM_SwdBind)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
