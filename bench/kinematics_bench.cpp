// Pose sampling, resampling and finite-difference kinematics over a realistic
// clip: 30 s at 30 fps of a 60-joint chain (STYLE.md 10) and of the 24-joint
// synthetic humanoid walking. Items are joint-frames (or samples) per second.

#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>

#include "mocap/joint_angles.h"
#include "mocap/kinematics.h"
#include "mocap/sampling.h"
#include "tools/synthetic.h"

namespace {

constexpr double kClipSeconds = 30.0;
constexpr double kFrameTime = 1.0 / 30.0;

struct Clip {
  mocap::Skeleton skeleton;
  mocap::Motion motion;
};

// A 60-joint chain whose joints wave with different phases.
const Clip& ChainClip() {
  static const Clip clip = [] {
    Clip c{*synthetic::MakeChainSkeleton(60, 5.0f), {}};
    c.motion.frame_time_s = kFrameTime;
    c.motion.num_frames = static_cast<int>(kClipSeconds / kFrameTime) + 1;
    c.motion.num_channels = c.skeleton.num_channels;
    for (int f = 0; f < c.motion.num_frames; ++f) {
      const double t = f * kFrameTime;
      for (int ch = 0; ch < c.motion.num_channels; ++ch) {
        c.motion.values.push_back(static_cast<float>(30.0 * std::sin(1.3 * t + 0.37 * ch)));
      }
    }
    return c;
  }();
  return clip;
}

const Clip& WalkClip() {
  static const Clip clip = [] {
    Clip c{synthetic::MakeHumanoidSkeleton(), {}};
    c.motion =
        *synthetic::MakeWalkMotion(c.skeleton, {.frame_time_s = kFrameTime, .num_cycles = 30});
    return c;
  }();
  return clip;
}

const Clip& ClipOf(const benchmark::State& state) {
  return state.range(0) == 0 ? ChainClip() : WalkClip();
}

void BM_ModelMatricesJob(benchmark::State& state) {
  const Clip& c = ClipOf(state);
  const std::size_t nj = static_cast<std::size_t>(c.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(static_cast<std::size_t>(c.motion.num_frames) * nj);
  for (auto _ : state) {
    const base::JobStatus s = mocap::ModelMatricesJob{.skeleton = &c.skeleton,
                                                      .motion = &c.motion,
                                                      .locals = locals,
                                                      .model_from_joint = model}
                                  .Run();
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(model.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(model.size()));
  state.SetLabel(state.range(0) == 0 ? "chain60 30s" : "humanoid24 walk 30s");
}
BENCHMARK(BM_ModelMatricesJob)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_KinematicsJob(benchmark::State& state) {
  const Clip& c = ClipOf(state);
  const std::size_t nj = static_cast<std::size_t>(c.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(static_cast<std::size_t>(c.motion.num_frames) * nj);
  (void)mocap::ModelMatricesJob{
      .skeleton = &c.skeleton, .motion = &c.motion, .locals = locals, .model_from_joint = model}
      .Run();
  std::vector<mocap::JointKinematics> out(model.size());
  for (auto _ : state) {
    const base::JobStatus s = mocap::KinematicsJob{.model_from_joint = model,
                                                   .num_joints = static_cast<int>(nj),
                                                   .frame_time_s = c.motion.frame_time_s,
                                                   .output = out}
                                  .Run();
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(out.size()));
  state.SetLabel(state.range(0) == 0 ? "chain60 30s" : "humanoid24 walk 30s");
}
BENCHMARK(BM_KinematicsJob)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_SmoothTrajectoriesJob(benchmark::State& state) {
  const Clip& c = ClipOf(state);
  const std::size_t nj = static_cast<std::size_t>(c.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(static_cast<std::size_t>(c.motion.num_frames) * nj);
  (void)mocap::ModelMatricesJob{
      .skeleton = &c.skeleton, .motion = &c.motion, .locals = locals, .model_from_joint = model}
      .Run();
  std::vector<glm::mat4> out(model.size());
  for (auto _ : state) {
    // 10 Hz at 30 fps is a 1-tap kernel; use 4 Hz so the window has 3 taps.
    const base::JobStatus s = mocap::SmoothTrajectoriesJob{.model_from_joint = model,
                                                           .num_joints = static_cast<int>(nj),
                                                           .frame_time_s = c.motion.frame_time_s,
                                                           .cutoff_hz = 4.0,
                                                           .output = out}
                                  .Run();
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(out.size()));
  state.SetLabel(state.range(0) == 0 ? "chain60 30s" : "humanoid24 walk 30s");
}
BENCHMARK(BM_SmoothTrajectoriesJob)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_Resample30To120(benchmark::State& state) {
  const Clip& c = ClipOf(state);
  std::int64_t frames = 0;
  for (auto _ : state) {
    auto r = mocap::Resample(c.skeleton, c.motion, 1.0 / 120.0);
    frames = r->num_frames;
    benchmark::DoNotOptimize(r->values.data());
  }
  state.SetItemsProcessed(state.iterations() * frames * c.skeleton.num_joints());
  state.SetLabel(state.range(0) == 0 ? "chain60 30s" : "humanoid24 walk 30s");
}
BENCHMARK(BM_Resample30To120)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_SampleLocalsJob(benchmark::State& state) {
  const Clip& c = WalkClip();
  const std::size_t nj = static_cast<std::size_t>(c.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj), scratch(nj);
  double t = 0.0;
  for (auto _ : state) {
    t += 0.0123;
    if (t > kClipSeconds) t = 0.0;
    const base::JobStatus s = mocap::SampleLocalsJob{.skeleton = &c.skeleton,
                                                     .motion = &c.motion,
                                                     .time_s = t,
                                                     .scratch = scratch,
                                                     .locals = locals}
                                  .Run();
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(locals.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(nj));
}
BENCHMARK(BM_SampleLocalsJob);

void BM_SampleJointKinematics(benchmark::State& state) {
  const Clip& c = WalkClip();
  const auto k = mocap::ComputeKinematics(c.skeleton, c.motion);
  mocap::JointKinematics out;
  double t = 0.0;
  for (auto _ : state) {
    t += 1.0 / 240.0;  // RK4 at the default 1/240 s step
    if (t > kClipSeconds) t = 0.0;
    const base::JobStatus s = mocap::SampleJointKinematics(*k, c.skeleton.num_joints(), 1,
                                                           c.motion.frame_time_s, t, &out);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SampleJointKinematics);

void BM_QuatToEulerNear(benchmark::State& state) {
  const mocap::ChannelType zxy[3] = {mocap::ChannelType::kZRotation, mocap::ChannelType::kXRotation,
                                     mocap::ChannelType::kYRotation};
  float angles[3] = {10.0f, 20.0f, 30.0f};
  float ref[3] = {10.0f, 20.0f, 30.0f};
  for (auto _ : state) {
    angles[0] += 0.1f;
    const glm::quat q = mocap::EulerToQuat(zxy, angles, 3);
    mocap::QuatToEulerNear(q, zxy, 3, ref, ref);
    benchmark::DoNotOptimize(ref);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_QuatToEulerNear);

}  // namespace

BENCHMARK_MAIN();
