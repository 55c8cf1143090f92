// Elastic layer speed: simulated output frames per second of one patch at
// h = 1/240 s and 30 fps output (8 RK4 steps, 4 force evaluations each, per frame).
// The paper (Lee, Kim, Yoon 2009) reports 1122 updates/s for a 5x5 network and
// 400 for a 7x7 one; the goal is 1000x that per core: 1.122 M and 400 k frames/s.

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "deform/elastic/mass_spring.h"
#include "mocap/kinematics.h"
#include "tools/synthetic.h"

namespace {

// max_displacement: e_max (0: the default, half the spacing).
deform::MassSpringNetwork MakeNetwork(int size, deform::MassSpringSolver solver,
                                      float max_displacement = 0.0f) {
  std::vector<glm::vec3> pts;
  for (int i = 0; i < size; ++i)
    for (int j = 0; j < size; ++j)
      pts.emplace_back(6.0f * static_cast<float>(j), 0.0f, 6.0f * static_cast<float>(i));
  deform::MassSpringParams p;  // defaults: belly, f0 = 3 Hz, h = 1/240 s
  p.solver = solver;
  p.max_displacement = max_displacement;
  auto net = deform::BuildMassSpringNetwork(
      {.rows = size, .cols = size, .rest_points = pts, .max_angular_speed_rad_s = 2.0f}, p);
  return std::move(net).value();
}

// Driving frame from a callback: a swaying, turning frame (no table look-up).
void BM_MassSpringCallback(benchmark::State& bench, int size, deform::MassSpringSolver solver) {
  const deform::MassSpringNetwork net = MakeNetwork(size, solver);
  deform::MassSpringState state;
  state.Resize(net);
  const std::function<deform::DrivingFrame(double)> drive = [](double t) {
    const float s = static_cast<float>(std::sin(7.0 * t)), c = static_cast<float>(std::cos(7.0 * t));
    return deform::DrivingFrame{glm::angleAxis(0.2f * s, glm::vec3(0, 1, 0)),
                                glm::vec3(300.0f * s, 100.0f * c, 0), glm::vec3(0, 1.4f * c, 0),
                                glm::vec3(0, -9.8f * s, 0)};
  };
  std::vector<glm::vec3> disp(static_cast<std::size_t>(size * size));
  int frame = 0;
  for (auto _ : bench) {
    const deform::MassSpringStepJob job{.network = &net, .state = &state,
                                        .time_s = frame++ / 30.0, .driving = &drive,
                                        .displacements = disp};
    benchmark::DoNotOptimize(job.Run());
    benchmark::DoNotOptimize(disp.data());
  }
  bench.SetItemsProcessed(bench.iterations());
  bench.counters["steps_per_frame"] =
      static_cast<double>(state.counters().steps) / static_cast<double>(bench.iterations());
  bench.counters["paper_updates_per_s"] = size == 5 ? 1122.0 : 400.0;
}

// A driving callback that reads `table` (frames every `half_step` seconds from
// t = 0) at the entry nearest t, clamped to its ends; `table` must outlive it.
std::function<deform::DrivingFrame(double)> TableDriving(const std::vector<deform::DrivingFrame>& table,
                                                         double half_step) {
  return [&table, half_step](double t) {
    const long i = std::lround(t / half_step);
    return table[static_cast<std::size_t>(std::clamp(i, 0L, static_cast<long>(table.size()) - 1))];
  };
}

// The Callback row's motion read from a table made before timing (every h/2 over
// 10 s, the clip looped): the same job with the bench's own sin/cos and most of
// its callback cost taken out, to show the elastic layer's share alone. Labelled
// as such; the Callback row stays the reference.
void BM_MassSpringTable(benchmark::State& bench, int size) {
  const deform::MassSpringNetwork net = MakeNetwork(size, deform::MassSpringSolver::kModal);
  deform::MassSpringState state;
  state.Resize(net);
  const double half_step = 0.5 * net.time_step_s;
  const int frames30 = 300;  // 10 s at 30 fps
  std::vector<deform::DrivingFrame> table(static_cast<std::size_t>(10.0 / half_step) + 2);
  for (std::size_t i = 0; i < table.size(); ++i) {
    const double t = static_cast<double>(i) * half_step;
    const float s = static_cast<float>(std::sin(7.0 * t)), c = static_cast<float>(std::cos(7.0 * t));
    table[i] = deform::DrivingFrame{glm::angleAxis(0.2f * s, glm::vec3(0, 1, 0)),
                                    glm::vec3(300.0f * s, 100.0f * c, 0), glm::vec3(0, 1.4f * c, 0),
                                    glm::vec3(0, -9.8f * s, 0)};
  }
  const std::function<deform::DrivingFrame(double)> drive = TableDriving(table, half_step);
  std::vector<glm::vec3> disp(static_cast<std::size_t>(size * size));
  int frame = 0;
  for (auto _ : bench) {
    const deform::MassSpringStepJob job{.network = &net, .state = &state,
                                        .time_s = (frame++ % frames30) / 30.0, .driving = &drive,
                                        .displacements = disp};
    benchmark::DoNotOptimize(job.Run());
    benchmark::DoNotOptimize(disp.data());
  }
  bench.SetItemsProcessed(bench.iterations());
  bench.counters["paper_updates_per_s"] = size == 5 ? 1122.0 : 400.0;
}

// Floats of displacements in the subnormal range, where each float operation
// on this machine costs a microcode assist.
int SubnormalFloats(const std::vector<glm::vec3>& e) {
  int count = 0;
  for (const glm::vec3& p : e)
    for (int c = 0; c < 3; ++c) count += std::fpclassify(p[c]) == FP_SUBNORMAL ? 1 : 0;
  return count;
}

// A character standing still after a push: the driving frame at rest in the
// bind orientation, the patch pushed for the first three frames and then left
// to settle, as a patch at rest costs per frame. The modes once ended in the
// subnormal floats (25 of a 7x7's 150 state floats) and the row measured
// microcode assists (1347 ns for 5x5 against 873 for a driven table frame);
// the job now sets a decayed state to exactly 0 first, and subnormal_floats
// (the newest step's displacements at the end) stays 0.
void BM_MassSpringAtRest(benchmark::State& bench, int size) {
  const deform::MassSpringNetwork net = MakeNetwork(size, deform::MassSpringSolver::kModal);
  deform::MassSpringState state;
  state.Resize(net);
  const std::function<deform::DrivingFrame(double)> still = [](double) {
    return deform::DrivingFrame{glm::quat(1, 0, 0, 0)};
  };
  std::vector<glm::vec3> disp(static_cast<std::size_t>(size * size));
  int frame = 0;
  for (auto _ : bench) {
    const deform::MassSpringStepJob job{
        .network = &net, .state = &state, .time_s = frame / 30.0, .driving = &still,
        .user_acceleration = frame >= 1 && frame <= 3 ? glm::vec3(0, 500.0f, 0) : glm::vec3(0.0f),
        .displacements = disp};
    ++frame;
    benchmark::DoNotOptimize(job.Run());
    benchmark::DoNotOptimize(disp.data());
  }
  bench.SetItemsProcessed(bench.iterations());
  std::vector<glm::vec3> newest(static_cast<std::size_t>(net.num_free));
  deform::MassSpringPointDisplacements(net, state, newest);
  bench.counters["subnormal_floats"] = SubnormalFloats(newest);
}

// The generated jump at 120 fps and its per-frame kinematics.
struct JumpClip {
  mocap::Skeleton skel = synthetic::MakeHumanoidSkeleton();
  int hips = skel.FindJoint("Hips");  // the rows' driving joint
  double frame_time_s = 1.0 / 120;
  std::vector<mocap::JointKinematics> kin;
  int frames30 = 0;  // whole 30 fps frames in the clip

  JumpClip() {
    synthetic::JumpOptions options;
    options.frame_time_s = frame_time_s;
    const mocap::Motion motion = synthetic::MakeJumpMotion(skel, options).value();
    kin = mocap::ComputeKinematics(skel, motion).value();
    frames30 = static_cast<int>(motion.duration_s() * 30.0);
  }
};

// Where a jump row's driving frames come from: mocap::SampleJointKinematics at
// every RK4 stage time, as the job does with MassSpringStepJob::kinematics; or a
// table of the same samples (mocap::SampleJointKinematics every h/2, made
// before timing) read through the callback, which takes the sampler's cost out.
enum class JumpDriving { kSampler, kTable };

// The sampled frames of a clip every `half_step` seconds, for JumpDriving::kTable.
std::vector<deform::DrivingFrame> JumpTable(const JumpClip& clip, double half_step) {
  std::vector<deform::DrivingFrame> table(
      static_cast<std::size_t>(clip.frames30 / 30.0 / half_step) + 3);
  for (std::size_t i = 0; i < table.size(); ++i) {
    mocap::JointKinematics k;
    if (!mocap::SampleJointKinematics(clip.kin, clip.skel.num_joints(), clip.hips, clip.frame_time_s,
                                      static_cast<double>(i) * half_step, &k)) {
      return {};
    }
    table[i] = deform::DrivingFrame{k.rotation, k.local_linear_acceleration,
                                    k.local_angular_velocity, k.local_angular_acceleration};
  }
  return table;
}

// Driving frame sampled from the jump's per-frame kinematics (hips, 120 fps) at
// every RK4 stage time (mocap::SampleJointKinematics); loops over the clip.
// The parts of a frame's time: `driving` kTable takes the sampler out; with
// limit false, e_max is 1e6 cm, so the displacement limit never acts (its
// cheap exits still run) and clamps_per_frame is 0.
void BM_MassSpringSampled(benchmark::State& bench, int size,
                          JumpDriving driving = JumpDriving::kSampler, bool limit = true) {
  const deform::MassSpringNetwork net =
      MakeNetwork(size, deform::MassSpringSolver::kModal, limit ? 0.0f : 1e6f);
  deform::MassSpringState state;
  state.Resize(net);
  const JumpClip clip;
  const double half_step = 0.5 * net.time_step_s;
  const std::vector<deform::DrivingFrame> table =
      driving == JumpDriving::kTable ? JumpTable(clip, half_step) : std::vector<deform::DrivingFrame>{};
  if (driving == JumpDriving::kTable && table.empty()) {
    bench.SkipWithError("sampling the jump failed");
    return;
  }
  const std::function<deform::DrivingFrame(double)> from_table = TableDriving(table, half_step);
  std::vector<glm::vec3> disp(static_cast<std::size_t>(size * size));
  int frame = 0;
  for (auto _ : bench) {
    deform::MassSpringStepJob job{.network = &net, .state = &state,
                                  .time_s = (frame++ % clip.frames30) / 30.0,
                                  .displacements = disp};
    if (driving == JumpDriving::kTable) {
      job.driving = &from_table;
    } else {
      job.kinematics = clip.kin;
      job.num_joints = clip.skel.num_joints();
      job.joint = clip.hips;
      job.frame_time_s = clip.frame_time_s;
    }
    benchmark::DoNotOptimize(job.Run());
    benchmark::DoNotOptimize(disp.data());
  }
  bench.SetItemsProcessed(bench.iterations());
  bench.counters["paper_updates_per_s"] = size == 5 ? 1122.0 : 400.0;
  bench.counters["clamps_per_frame"] = static_cast<double>(state.counters().displacement_clamps) /
                                       static_cast<double>(bench.iterations());
}

}  // namespace

BENCHMARK_CAPTURE(BM_MassSpringCallback, modal_5x5, 5, deform::MassSpringSolver::kModal);
BENCHMARK_CAPTURE(BM_MassSpringCallback, modal_7x7, 7, deform::MassSpringSolver::kModal);
BENCHMARK_CAPTURE(BM_MassSpringCallback, point_5x5, 5, deform::MassSpringSolver::kPointSpace);
BENCHMARK_CAPTURE(BM_MassSpringCallback, point_7x7, 7, deform::MassSpringSolver::kPointSpace);
BENCHMARK_CAPTURE(BM_MassSpringTable, modal_5x5, 5);
BENCHMARK_CAPTURE(BM_MassSpringTable, modal_7x7, 7);
BENCHMARK_CAPTURE(BM_MassSpringAtRest, modal_5x5, 5);
BENCHMARK_CAPTURE(BM_MassSpringAtRest, modal_7x7, 7);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_5x5, 5);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_7x7, 7);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_5x5_from_table, 5, JumpDriving::kTable);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_7x7_from_table, 7, JumpDriving::kTable);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_5x5_no_limit, 5, JumpDriving::kSampler, false);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_7x7_no_limit, 7, JumpDriving::kSampler, false);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_5x5_from_table_no_limit, 5, JumpDriving::kTable,
                  false);
BENCHMARK_CAPTURE(BM_MassSpringSampled, modal_7x7_from_table_no_limit, 7, JumpDriving::kTable,
                  false);

BENCHMARK_MAIN();
