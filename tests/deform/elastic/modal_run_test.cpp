// The modal run (deform/elastic/internal/modal_run.h) starts each run from the previous
// run's last stage (MassSpringState::last_stage) instead of sampling that time
// again. These tests run the same frames twice: once as the job does, once with
// the remembered stage thrown away before every run (so every stage time is
// sampled, as before the reuse), and ask for the same bits and counters; and
// check that a change of push or source is not served from the old stage.

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "deform/elastic/mass_spring.h"
#include "mocap/kinematics.h"
#include "mocap/synthetic.h"
#include "support/mass_spring_networks.h"

namespace {

using deform::DrivingFrame;
using deform::MassSpringNetwork;
using deform::MassSpringState;
using deform::MassSpringStepJob;
using DriveFn = std::function<DrivingFrame(double)>;

bool SameBits(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

DrivingFrame Sway(double t) {
  const float s = static_cast<float>(std::sin(4.0 * t)), c = static_cast<float>(std::cos(6.0 * t));
  return DrivingFrame{glm::angleAxis(0.4f * s, glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f))),
                      glm::vec3(120.0f * s, 60.0f * c, -30.0f * s), glm::vec3(0.2f, 1.2f * c, 0.1f),
                      glm::vec3(0.5f * c, -4.0f * s, 0.3f)};
}

// What one run of a sequence uses.
struct RunInput {
  double time_s = 0.0;
  const DriveFn* driving = nullptr;
  glm::vec3 push{0.0f};
};

struct Outcome {
  std::vector<std::vector<glm::vec3>> displacements;  // per run
  MassSpringState state;
};

// Runs `inputs` in order on a fresh state; `forget` drops the remembered stage
// before every run.
Outcome RunAll(const MassSpringNetwork& net, const std::vector<RunInput>& inputs, bool forget) {
  Outcome o;
  o.state.Resize(net);
  for (const RunInput& in : inputs) {
    if (forget) o.state.last_stage.valid = false;
    std::vector<glm::vec3> disp(static_cast<std::size_t>(net.rows * net.cols));
    const MassSpringStepJob job{.network = &net, .state = &o.state, .time_s = in.time_s,
                                .driving = in.driving, .user_acceleration = in.push,
                                .displacements = disp};
    EXPECT_TRUE(job.Run());
    o.displacements.push_back(std::move(disp));
  }
  return o;
}

void ExpectSame(const Outcome& a, const Outcome& b) {
  ASSERT_EQ(a.displacements.size(), b.displacements.size());
  for (std::size_t f = 0; f < a.displacements.size(); ++f) {
    ASSERT_TRUE(SameBits(a.displacements[f], b.displacements[f])) << "run " << f;
  }
  EXPECT_EQ(a.state.modal_newest, b.state.modal_newest);
  EXPECT_TRUE(a.state.modal.size() == b.state.modal.size() &&
              std::memcmp(a.state.modal.data(), b.state.modal.data(),
                          a.state.modal.size() * sizeof(float)) == 0);
  EXPECT_EQ(a.state.counters.steps, b.state.counters.steps);
  EXPECT_EQ(a.state.counters.acceleration_clamps, b.state.counters.acceleration_clamps);
  EXPECT_EQ(a.state.counters.non_finite_inputs, b.state.counters.non_finite_inputs);
  EXPECT_EQ(a.state.counters.displacement_clamps, b.state.counters.displacement_clamps);
}

// 30 fps: after the first run, each run asks the source for 16 stage times (8
// steps, two new times each); the 17th, its first, is the run before's last.
TEST(ModalRun, ReusesTheLastStageOfThePreviousRun) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 6);
  int calls = 0;
  const DriveFn counted = [&calls](double t) {
    ++calls;
    return Sway(t);
  };
  std::vector<RunInput> inputs;
  for (int f = 0; f < 30; ++f) inputs.push_back({f / 30.0, &counted});
  const Outcome forgetting = RunAll(net, inputs, true);
  const int calls_forgetting = calls;
  calls = 0;
  const Outcome reusing = RunAll(net, inputs, false);
  ExpectSame(reusing, forgetting);
  // Run 0 resets and takes no step; run 1 samples its first time; 28 runs reuse it.
  EXPECT_EQ(calls_forgetting - calls, 28);
  EXPECT_EQ(calls, 29 * 16 + 1);
  EXPECT_GT(glm::length(reusing.state.ModalDisplacement(0)), 0.01f);  // the drive moved it
}

// A different push in a run changes the forcing at its first stage time too: the
// remembered coefficients (made with the old push) must not be used.
TEST(ModalRun, NewPushRecomputesTheFirstStage) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 5);
  const DriveFn drive = Sway;
  std::vector<RunInput> inputs;
  for (int f = 0; f < 20; ++f) {
    inputs.push_back({f / 30.0, &drive, glm::vec3(0.0f, 0.0f, static_cast<float>(f % 3) * 40.0f)});
  }
  ExpectSame(RunAll(net, inputs, false), RunAll(net, inputs, true));
}

// Another callback (another source) is sampled, not served from the old one.
TEST(ModalRun, AnotherSourceIsSampledAgain) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 5);
  const DriveFn a = Sway;
  const DriveFn b = [](double t) {
    DrivingFrame d = Sway(t + 0.3);
    d.linear_acceleration.y += 200.0f;
    return d;
  };
  std::vector<RunInput> inputs;
  for (int f = 0; f < 20; ++f) inputs.push_back({f / 30.0, f % 2 == 0 ? &a : &b});
  ExpectSame(RunAll(net, inputs, false), RunAll(net, inputs, true));
}

// The limits' counters read as if every stage time were sampled: with |a| over
// the clamp at every time, 17 clamps per 30 fps run (its first time included),
// and NaN frames counted each time they are used.
TEST(ModalRun, CountersCountTheReusedStage) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const DriveFn wild = [nan](double t) {
    DrivingFrame d = Sway(t);
    d.linear_acceleration = glm::vec3(1e6f, 0.0f, 0.0f);  // far above the 200 m/s^2 clamp
    // NaN at every multiple of 1/30 s from 0.1 s: the end of one run, the start of the next.
    const long tick = std::lround(t * 30.0);
    if (t > 0.09 && std::abs(t * 30.0 - static_cast<double>(tick)) < 1e-6) d.angular_velocity.x = nan;
    return d;
  };
  std::vector<RunInput> inputs;
  for (int f = 0; f < 12; ++f) inputs.push_back({f / 30.0, &wild});
  const Outcome reusing = RunAll(net, inputs, false);
  ExpectSame(reusing, RunAll(net, inputs, true));
  // 11 runs of 8 steps: 17 samples each. The NaN frames (t = 0.1, ..., 11/30 s:
  // 9 of them, each a run's end and the next run's start but the last) are not
  // clamped (taken as at rest); all others are.
  const std::int64_t nan_uses = 9 + 8;
  EXPECT_EQ(reusing.state.counters.non_finite_inputs, nan_uses);
  EXPECT_EQ(reusing.state.counters.acceleration_clamps, 11 * 17 - nan_uses);
}

// The kinematics source: reused between runs over the same table, bit for bit.
TEST(ModalRun, KinematicsSourceReusesTheLastStage) {
  const mocap::Skeleton skel = mocap::MakeHumanoidSkeleton();
  mocap::JumpOptions options;
  options.frame_time_s = 1.0 / 120;
  const mocap::Motion motion = mocap::MakeJumpMotion(skel, options).value();
  const std::vector<mocap::JointKinematics> kin = mocap::ComputeKinematics(skel, motion).value();
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(6, 5);
  std::vector<std::vector<glm::vec3>> out[2];  // pass 0 reuses, pass 1 forgets
  MassSpringState states[2];
  for (int pass = 0; pass < 2; ++pass) {
    MassSpringState& state = states[pass];
    state.Resize(net);
    for (int f = 0; f < 24; ++f) {
      if (pass == 1) state.last_stage.valid = false;
      std::vector<glm::vec3> disp(30);
      const MassSpringStepJob job{.network = &net, .state = &state, .time_s = f / 30.0,
                                  .kinematics = kin, .num_joints = skel.num_joints(),
                                  .joint = skel.FindJoint("Hips"),
                                  .frame_time_s = options.frame_time_s, .displacements = disp};
      ASSERT_TRUE(job.Run());
      out[pass].push_back(std::move(disp));
    }
  }
  for (std::size_t f = 0; f < out[0].size(); ++f) ASSERT_TRUE(SameBits(out[0][f], out[1][f])) << f;
  EXPECT_EQ(states[0].counters.acceleration_clamps, states[1].counters.acceleration_clamps);
  EXPECT_TRUE(states[0].last_stage.valid);
  EXPECT_EQ(states[0].last_stage.time_s, states[0].step_time_s);
}

}  // namespace

namespace {

// A patch pushed and then left alone in the bind pose decays to rest: its modes
// are set to exactly 0 once their squares sum below 1e-24 (modal_run.cpp,
// kRestSum), before any float of the state reaches the subnormal range; until
// then the decay is left alone.
TEST(ModalRun, AStateThatHasDecayedIsSetToExactlyZero) {
  const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 5);
  const DriveFn still = [](double) { return DrivingFrame{glm::quat(1, 0, 0, 0)}; };
  MassSpringState state;
  state.Resize(net);
  std::vector<glm::vec3> disp(25);
  const auto sum_of_squares = [&state](int field) {
    const float* f = state.ModalField(field);
    double s = 0.0;
    for (std::size_t i = 0; i < 3 * state.modal_stride; ++i) s += double(f[i]) * double(f[i]);
    return s;
  };
  bool seen_small = false;  // a frame whose state was small but not yet at rest
  int zero_from = -1;
  for (int frame = 0; frame < 30 * 60; ++frame) {
    const MassSpringStepJob job{
        .network = &net, .state = &state, .time_s = frame / 30.0, .driving = &still,
        .user_acceleration = frame >= 1 && frame <= 3 ? glm::vec3(0, 50.0f, 0) : glm::vec3(0.0f),
        .displacements = disp};
    ASSERT_TRUE(job.Run());
    for (const float f : state.modal) {
      ASSERT_NE(std::fpclassify(f), FP_SUBNORMAL) << "frame " << frame;
    }
    const double x2 = sum_of_squares(2 * state.modal_newest);
    const double v2 = sum_of_squares(2 * state.modal_newest + 1);
    if (frame <= 3) continue;  // at rest before the push
    if (x2 == 0.0 && v2 == 0.0) {
      if (zero_from < 0) zero_from = frame;
      for (const glm::vec3& d : disp) ASSERT_EQ(d, glm::vec3(0.0f)) << "frame " << frame;
    } else {
      ASSERT_LT(zero_from, 0) << "the state left 0 at frame " << frame;
      seen_small = seen_small || (x2 < 1e-20 && x2 > 1e-24);
    }
  }
  EXPECT_GT(zero_from, 3);
  EXPECT_TRUE(seen_small);
  std::printf("at rest (exactly 0) from frame %d\n", zero_from);
  EXPECT_EQ(state.counters.any_limit(), 0) << state.counters.displacement_clamps;
}

}  // namespace

namespace {

// The same rule in the point-space solver (both force models), after each step.
TEST(ModalRun, PointSpaceStateThatHasDecayedIsSetToExactlyZeroToo) {
  for (const auto model : {deform::SpringForceModel::kLinear, deform::SpringForceModel::kLength}) {
    SCOPED_TRACE(model == deform::SpringForceModel::kLinear ? "linear" : "length");
    deform::MassSpringParams p;
    p.solver = deform::MassSpringSolver::kPointSpace;
    p.force_model = model;
    const MassSpringNetwork net = testsupport::CurvedGridNetwork(5, 5, p);
    const DriveFn still = [](double) { return DrivingFrame{glm::quat(1, 0, 0, 0)}; };
    MassSpringState state;
    state.Resize(net);
    ASSERT_EQ(state.position.size(), 9u);
    bool seen_small = false;
    int zero_from = -1;
    for (int frame = 0; frame < 30 * 60; ++frame) {
      const MassSpringStepJob job{
          .network = &net, .state = &state, .time_s = frame / 30.0, .driving = &still,
          .user_acceleration = frame >= 1 && frame <= 3 ? glm::vec3(0, 50.0f, 0) : glm::vec3(0.0f)};
      ASSERT_TRUE(job.Run());
      double x2 = 0.0, v2 = 0.0;
      for (std::size_t a = 0; a < state.position.size(); ++a) {
        for (int c = 0; c < 3; ++c) {
          ASSERT_NE(std::fpclassify(state.position[a][c]), FP_SUBNORMAL) << "frame " << frame;
          ASSERT_NE(std::fpclassify(state.velocity[a][c]), FP_SUBNORMAL) << "frame " << frame;
          x2 += double(state.position[a][c]) * double(state.position[a][c]);
          v2 += double(state.velocity[a][c]) * double(state.velocity[a][c]);
        }
      }
      if (frame <= 3) continue;
      if (x2 == 0.0 && v2 == 0.0) {
        if (zero_from < 0) zero_from = frame;
      } else {
        ASSERT_LT(zero_from, 0) << "the state left 0 at frame " << frame;
        seen_small = seen_small || (x2 < 1e-20 && x2 > 1e-24);
      }
    }
    EXPECT_GT(zero_from, 3);
    EXPECT_TRUE(seen_small);
    EXPECT_EQ(state.counters.any_limit(), 0);
  }
}

}  // namespace
