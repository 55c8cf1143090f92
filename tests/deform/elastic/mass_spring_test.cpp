// The elastic layer (ALGORITHMS.md 6): topology, the scaled slowest mode and its
// damping, energy decay, static response, RK4 order, frame-rate independence,
// limits under glitches (input checks, the displacement limit in both solvers),
// decay to exactly 0, real captures, resets and preroll.

#include "deform/elastic/mass_spring.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "mocap/kinematics.h"
#include "tools/synthetic.h"
#include "support/data_paths.h"
#include "support/tolerances.h"
#include "support/same_bits.h"

namespace {

using base::JobStatus;
using deform::BuildMassSpringNetwork;
using deform::DrivingFrame;
using deform::MassSpringNetwork;
using deform::MassSpringParams;
using deform::MassSpringSetup;
using deform::MassSpringState;
using deform::MassSpringStepJob;
using namespace testsupport;

using DriveFn = std::function<DrivingFrame(double)>;

// A flat M x N grid centred 2 cm above the frame's origin, parallel to XZ, spacing 2 cm.
std::vector<glm::vec3> FlatGrid(int rows, int cols, float spacing = 2.0f) {
  std::vector<glm::vec3> points;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      points.emplace_back((static_cast<float>(j) - 0.5f * static_cast<float>(cols - 1)) * spacing, 2.0f,
                          (static_cast<float>(i) - 0.5f * static_cast<float>(rows - 1)) * spacing);
  return points;
}

MassSpringNetwork Build(int rows, int cols, const MassSpringParams& params,
                        float max_w = 0.0f) {
  const std::vector<glm::vec3> pts = FlatGrid(rows, cols);
  auto net = BuildMassSpringNetwork(
      MassSpringSetup{.rows = rows, .cols = cols, .rest_points = pts,
                      .max_angular_speed_rad_s = max_w},
      params);
  EXPECT_TRUE(net.ok()) << net.error().ToString();
  return std::move(net).value();
}

MassSpringParams QuietParams() {  // no gravity: only the callback drives
  MassSpringParams p;
  p.gravity = false;
  return p;
}

int CentrePoint(const MassSpringNetwork& net) { return (net.rows / 2) * net.cols + net.cols / 2; }

// Runs the job at times t0 + k dt, k = 0..count-1; returns the centre point's displacement.
std::vector<glm::vec3> RunCentre(const MassSpringNetwork& net, MassSpringState& state,
                                 const DriveFn& drive, double t0, double dt, int count) {
  std::vector<glm::vec3> disp(static_cast<std::size_t>(net.rows * net.cols));
  std::vector<glm::vec3> out;
  for (int k = 0; k < count; ++k) {
    const MassSpringStepJob job{.network = &net, .state = &state, .time_s = t0 + k * dt,
                                .driving = &drive, .displacements = disp};
    EXPECT_TRUE(job.Run()) << job.Run().what;
    out.push_back(disp[static_cast<std::size_t>(CentrePoint(net))]);
  }
  return out;
}

DrivingFrame Still(double) { return {}; }

TEST(MassSpringNetwork, TopologyCounts) {
  const MassSpringNetwork n3 = Build(3, 3, {});
  EXPECT_EQ(n3.num_free, 1);
  EXPECT_EQ(n3.num_springs[deform::kStructural], 4);
  EXPECT_EQ(n3.num_springs[deform::kShear], 4);
  EXPECT_EQ(n3.num_springs[deform::kBending], 0);  // +-2 leaves a 3 x 3 grid
  // 5 x 5: 40 structural edges less the 16 of the boundary ring; 32 diagonals less
  // the 4 joining two boundary points beside the corners; 30 bending pairs less
  // the 12 along the boundary rows and columns.
  const MassSpringNetwork n5 = Build(5, 5, {});
  EXPECT_EQ(n5.num_free, 9);
  EXPECT_EQ(n5.num_springs[deform::kStructural], 24);
  EXPECT_EQ(n5.num_springs[deform::kShear], 28);
  EXPECT_EQ(n5.num_springs[deform::kBending], 18);
  const MassSpringNetwork n7 = Build(7, 9, {});
  EXPECT_EQ(n7.num_free, 5 * 7);
  for (int p = 0; p < 7 * 9; ++p) {
    const int i = p / 9, j = p % 9;
    const bool boundary = i == 0 || i == 6 || j == 0 || j == 8;
    EXPECT_EQ(n7.free_of_point[static_cast<std::size_t>(p)] < 0, boundary) << p;
  }
  // Default e_max: half the 2 cm spacing.
  EXPECT_FLOAT_EQ(n5.params.max_displacement, 1.0f);
}

TEST(MassSpringNetwork, RejectsBadInput) {
  const std::vector<glm::vec3> pts = FlatGrid(5, 5);
  EXPECT_FALSE(BuildMassSpringNetwork({.rows = 2, .cols = 5, .rest_points = pts}).ok());
  EXPECT_FALSE(BuildMassSpringNetwork({.rows = 5, .cols = 4, .rest_points = pts}).ok());
  MassSpringParams bad;
  bad.frequency_hz = -1.0f;
  EXPECT_FALSE(BuildMassSpringNetwork({.rows = 5, .cols = 5, .rest_points = pts}, bad).ok());
  bad = {};
  bad.mass = std::nanf("");
  EXPECT_FALSE(BuildMassSpringNetwork({.rows = 5, .cols = 5, .rest_points = pts}, bad).ok());
}

TEST(MassSpringNetwork, StepRuleHalvesAndLimits) {
  MassSpringParams p;
  p.time_step_s = 1.0 / 30.0;  // too long for a 5 Hz face patch
  p.frequency_hz = 5.0f;
  const MassSpringNetwork net = Build(7, 7, p);
  EXPECT_LT(net.time_step_s, p.time_step_s);
  ASSERT_FALSE(net.messages.empty());
  EXPECT_LE(net.time_step_s * net.gershgorin_rate, 0.5 + kDoubleTol);
  p.frequency_hz = 500.0f;  // no 6 halvings can bring this under 2.5
  const std::vector<glm::vec3> pts = FlatGrid(7, 7);
  EXPECT_FALSE(BuildMassSpringNetwork({.rows = 7, .cols = 7, .rest_points = pts}, p).ok());
}

TEST(MassSpringStepJob, Validate) {
  const MassSpringNetwork net = Build(5, 5, {});
  MassSpringState state;
  const DriveFn drive = Still;
  std::vector<glm::vec3> disp(25);
  EXPECT_EQ((MassSpringStepJob{.network = &net, .state = &state, .driving = &drive}).Validate().code,
            JobStatus::kSizeMismatch);
  state.Resize(net);
  EXPECT_TRUE((MassSpringStepJob{.network = &net, .state = &state, .driving = &drive}).Validate());
  EXPECT_EQ((MassSpringStepJob{.network = &net, .state = &state}).Validate().code,
            JobStatus::kMissingInput);
  EXPECT_EQ((MassSpringStepJob{.state = &state, .driving = &drive}).Validate().code,
            JobStatus::kMissingInput);
  std::vector<glm::vec3> short_disp(24);
  EXPECT_EQ((MassSpringStepJob{.network = &net, .state = &state, .driving = &drive,
                               .displacements = short_disp})
                .Validate()
                .code,
            JobStatus::kSizeMismatch);
  std::vector<mocap::JointKinematics> kin(10);
  EXPECT_EQ((MassSpringStepJob{.network = &net, .state = &state, .kinematics = kin,
                               .num_joints = 2, .joint = 2, .frame_time_s = 0.1})
                .Validate()
                .code,
            JobStatus::kOutOfRange);
  EXPECT_EQ((MassSpringStepJob{.network = &net, .state = &state, .time_s = std::nan(""),
                               .driving = &drive})
                .Validate()
                .code,
            JobStatus::kOutOfRange);
}

// Free response of the slowest mode, integrated in point space (independent of
// the modal solver): its period must be 1 / f0 and its decay z0.
struct FreeResponse {
  std::vector<double> t, x;
};
FreeResponse SlowestModeResponse(float z0, double duration_s) {
  MassSpringParams p = QuietParams();
  p.damping_ratio = z0;
  p.spring_damping_s = 0.0f;  // every mode then has damping ratio z0 * f0 / f_k
  p.solver = deform::MassSpringSolver::kPointSpace;
  const MassSpringNetwork net = Build(7, 7, p);
  MassSpringState state;
  state.Resize(net);
  const DriveFn drive = Still;
  RunCentre(net, state, drive, 0.0, 0.0, 1);  // start the clock at 0
  const std::size_t n = static_cast<std::size_t>(net.num_free);
  std::vector<glm::vec3> mode(n);
  for (std::size_t a = 0; a < n; ++a) mode[a] = glm::vec3(net.modes[a * n], 0, 0);
  EXPECT_TRUE(state.SetDisplacement(net, mode));
  const double dt = net.time_step_s;
  const int count = static_cast<int>(duration_s / dt);
  FreeResponse r;
  const std::vector<glm::vec3> c = RunCentre(net, state, drive, dt, dt, count);
  for (int k = 0; k < count; ++k) {
    r.t.push_back((k + 1) * dt);
    r.x.push_back(c[static_cast<std::size_t>(k)].x);
  }
  return r;
}

TEST(MassSpringStepJob, SlowestModeRingsAtF0) {
  const FreeResponse r = SlowestModeResponse(0.0f, 3.0);
  std::vector<double> crossings;  // downward zero crossings, linearly interpolated
  for (std::size_t k = 1; k < r.x.size(); ++k) {
    if (r.x[k - 1] > 0 && r.x[k] <= 0) {
      crossings.push_back(r.t[k - 1] + (r.t[k] - r.t[k - 1]) * r.x[k - 1] / (r.x[k - 1] - r.x[k]));
    }
  }
  ASSERT_GE(crossings.size(), 5u);
  const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  EXPECT_NEAR(period, 1.0 / 3.0, kModePeriodRelTol / 3.0);
}

TEST(MassSpringStepJob, DampingRatioFromSuccessivePeaks) {
  const float z0 = 0.15f;
  const FreeResponse r = SlowestModeResponse(z0, 2.0);
  std::vector<double> peaks;  // parabola through each local maximum and its neighbours
  for (std::size_t k = 1; k + 1 < r.x.size(); ++k) {
    if (r.x[k] > r.x[k - 1] && r.x[k] >= r.x[k + 1] && r.x[k] > 0) {
      const double a = r.x[k - 1], b = r.x[k], c = r.x[k + 1];
      const double off = 0.5 * (a - c) / (a - 2 * b + c);
      peaks.push_back(b - 0.25 * (a - c) * off);
    }
  }
  ASSERT_GE(peaks.size(), 3u);
  const double delta = std::log(peaks[0] / peaks[1]);
  const double zeta = delta / std::sqrt(4 * std::numbers::pi * std::numbers::pi + delta * delta);
  EXPECT_NEAR(zeta, z0, kDampingRatioTol);
  const double delta2 = std::log(peaks[1] / peaks[2]);
  EXPECT_NEAR(delta2, delta, kDampingRatioTol);
}

// A shaking, turning frame for t < stop_s, then still.
DriveFn Shake(double stop_s, float accel = 150.0f) {
  return [stop_s, accel](double t) {
    DrivingFrame d;
    if (t < stop_s) {
      const float s = static_cast<float>(std::sin(2 * std::numbers::pi * 1.0 * t));
      d.linear_acceleration = glm::vec3(accel * s, 0.3f * accel * s, 0);
      d.angular_velocity = glm::vec3(0, 0.5f * s, 0);
      d.angular_acceleration = glm::vec3(0, 1.0f * std::numbers::pi * 1.0 *
                                                  std::cos(2 * std::numbers::pi * 1.0 * t), 0);
    }
    return d;
  };
}

TEST(MassSpringStepJob, EnergyDecaysAfterTheMotionStops) {
  const MassSpringNetwork net = Build(7, 7, QuietParams(), 0.5f);
  MassSpringState state;
  state.Resize(net);
  const DriveFn drive = Shake(1.0);
  std::vector<glm::vec3> disp(49);
  double previous = 0.0, at_stop = 0.0;
  for (int k = 0; k <= 240 * 5; ++k) {
    const double t = k / 240.0;
    const MassSpringStepJob job{.network = &net, .state = &state, .time_s = t,
                                .driving = &drive, .displacements = disp};
    ASSERT_TRUE(job.Run());
    const double energy = deform::MassSpringEnergy(net, state);
    if (t > 1.0 + net.time_step_s) {
      EXPECT_LE(energy, previous * (1.0 + kEnergyMonotoneRelTol)) << "t = " << t;
    } else {
      at_stop = energy;
    }
    previous = energy;
  }
  ASSERT_GT(at_stop, 0.0);
  // 4 s after the stop, exp(-2 z0 w0 t) = exp(-22.6): rest up to round-off.
  EXPECT_LT(previous, at_stop * kRestEnergyFraction);
  for (const glm::vec3& e : disp) EXPECT_LT(glm::length(e), kRestDisplacementCm);
  EXPECT_EQ(state.counters().any_limit(), 0);
}

TEST(MassSpringStepJob, SustainedAccelerationGivesStaticDisplacement) {
  const float a = 1000.0f;  // 10 m/s^2 in cm/s^2
  for (float gain : {1.0f, 2.0f}) {
    MassSpringParams p = QuietParams();
    p.gain = gain;
    p.max_displacement = 100.0f;  // no clamp
    const MassSpringNetwork net = Build(7, 7, p);
    MassSpringState state;
    state.Resize(net);
    const DriveFn drive = [a](double) {
      DrivingFrame d;
      d.linear_acceleration = glm::vec3(a, 0, 0);
      return d;
    };
    // Steps of 0.25 s (under max_time_gap_s) up to 5 s: settled.
    const std::vector<glm::vec3> c = RunCentre(net, state, drive, 0.0, 0.25, 21);
    // Independent static solution: K e = -gam m a 1, by Gauss-Seidel on the springs.
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    std::vector<double> diag(n, net.anchor_stiffness), e(n, 0.0);
    for (const deform::Spring& s : net.springs) {
      if (s.free_a >= 0) diag[static_cast<std::size_t>(s.free_a)] += s.stiffness;
      if (s.free_b >= 0) diag[static_cast<std::size_t>(s.free_b)] += s.stiffness;
    }
    for (int it = 0; it < 2000; ++it) {
      std::vector<double> rhs(n, -gain * net.params.mass * a);
      for (const deform::Spring& s : net.springs) {
        if (s.free_a >= 0 && s.free_b >= 0) {
          rhs[static_cast<std::size_t>(s.free_a)] += s.stiffness * e[static_cast<std::size_t>(s.free_b)];
          rhs[static_cast<std::size_t>(s.free_b)] += s.stiffness * e[static_cast<std::size_t>(s.free_a)];
        }
      }
      for (std::size_t i = 0; i < n; ++i) e[i] = rhs[i] / diag[i];
    }
    const double expected = e[n / 2];  // the centre point is the middle free point
    EXPECT_NEAR(c.back().x, expected, kStaticResponseRelTol * std::abs(expected));
    // ALGORITHMS.md 6: "about gam a / (2 pi f0)^2" (exact for the slowest mode alone).
    const double rule = gain * a / std::pow(2 * std::numbers::pi * 3.0, 2);
    EXPECT_NEAR(-c.back().x, rule, 0.3 * rule);
  }
}

TEST(MassSpringStepJob, ModalAndPointSpaceAgree) {
  MassSpringParams p = QuietParams();
  p.gravity = true;  // the bind rotation below differs from the frame's
  const std::vector<glm::vec3> pts = FlatGrid(7, 7);
  float largest = 0.0f, worst = 0.0f;
  std::vector<std::vector<glm::vec3>> runs;
  for (auto solver : {deform::MassSpringSolver::kModal, deform::MassSpringSolver::kPointSpace}) {
    p.solver = solver;
    auto net = BuildMassSpringNetwork(
        {.rows = 7, .cols = 7, .rest_points = pts,
         .bind_rotation = glm::angleAxis(0.3f, glm::vec3(1, 0, 0)), .max_angular_speed_rad_s = 1},
        p);
    ASSERT_TRUE(net.ok());
    MassSpringState state;
    state.Resize(*net);
    runs.push_back(RunCentre(*net, state, Shake(1.5), 0.0, 1.0 / 30, 60));
  }
  for (std::size_t k = 0; k < runs[0].size(); ++k) {
    largest = std::max(largest, glm::length(runs[1][k]));
    worst = std::max(worst, glm::length(runs[0][k] - runs[1][k]));
  }
  ASSERT_GT(largest, 0.1f);
  EXPECT_LT(worst, kSolverAgreementRelTol * largest);
}

// Global error at t = 1.5 s of a smoothly driven 1 Hz network against a run at
// h / 16: halving h must divide it by ~16.
TEST(MassSpringStepJob, RungeKuttaIsFourthOrder) {
  const DriveFn drive = [](double t) {
    DrivingFrame d;
    d.linear_acceleration = glm::vec3(300.0f * static_cast<float>(std::sin(4.0 * t)), 0, 0);
    return d;
  };
  const auto run = [&](double h) {
    MassSpringParams p = QuietParams();
    p.frequency_hz = 1.0f;
    p.time_step_s = h;
    p.max_displacement = 100.0f;
    const MassSpringNetwork net = Build(3, 3, p);
    EXPECT_EQ(net.time_step_s, h);
    MassSpringState state;
    state.Resize(net);
    return RunCentre(net, state, drive, 0.0, 0.1, 16).back().x;
  };
  const double h = 1.0 / 20;
  const double ref = run(h / 16);
  const double e1 = std::abs(run(h) - ref), e2 = std::abs(run(h / 2) - ref);
  ASSERT_GT(e2, 0.0);
  EXPECT_GT(e1 / e2, kFourthOrderMinRatio) << e1 << " " << e2;
  EXPECT_LT(e1 / e2, kFourthOrderMaxRatio) << e1 << " " << e2;
}

// Kinematics of a capture after the optional 10 Hz zero-phase low-pass
// (ALGORITHMS.md 6: differentiating mocap twice amplifies noise).
std::vector<mocap::JointKinematics> SmoothedKinematics(const mocap::Skeleton& skel,
                                                       const mocap::Motion& motion) {
  const std::size_t nj = static_cast<std::size_t>(skel.num_joints());
  const std::size_t nf = static_cast<std::size_t>(motion.num_frames);
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> raw(nj * nf), smooth(nj * nf);
  EXPECT_TRUE((mocap::ModelMatricesJob{.skeleton = &skel, .motion = &motion, .locals = locals,
                                       .model_from_joint = raw})
                  .Run());
  EXPECT_TRUE((mocap::SmoothTrajectoriesJob{.model_from_joint = raw,
                                            .num_joints = skel.num_joints(),
                                            .frame_time_s = motion.frame_time_s,
                                            .output = smooth})
                  .Run());
  std::vector<mocap::JointKinematics> kin(nj * nf);
  EXPECT_TRUE((mocap::KinematicsJob{.model_from_joint = smooth, .num_joints = skel.num_joints(),
                                    .frame_time_s = motion.frame_time_s, .output = kin})
                  .Run());
  return kin;
}

// Hips-driven 5x5 patch over the synthetic jump sampled at `fps` (10 Hz low-pass); the centre
// point's displacement at every 1/30 s.
std::vector<glm::vec3> JumpResponse(double fps) {
  const mocap::Skeleton skel = synthetic::MakeHumanoidSkeleton();
  synthetic::JumpOptions options;
  options.frame_time_s = 1.0 / fps;
  auto motion = synthetic::MakeJumpMotion(skel, options);
  EXPECT_TRUE(motion.ok());
  const std::vector<mocap::JointKinematics> kin = SmoothedKinematics(skel, *motion);
  const int hips = skel.FindJoint("Hips");
  MassSpringParams p;  // a 24 x 24 cm belly patch, stiff enough to stay under e_max
  p.frequency_hz = 6.0f;
  p.damping_ratio = 0.25f;
  const std::vector<glm::vec3> pts = FlatGrid(5, 5, 6.0f);
  const MassSpringNetwork net =
      *BuildMassSpringNetwork({.rows = 5, .cols = 5, .rest_points = pts}, p);
  MassSpringState state;
  state.Resize(net);
  std::vector<glm::vec3> disp(25), out;
  const int num_joints = skel.num_joints();
  const int per_output = static_cast<int>(std::lround(fps / 30.0));
  for (int f = 0; f < motion->num_frames; ++f) {
    const MassSpringStepJob job{.network = &net, .state = &state, .time_s = f / fps,
                                .kinematics = kin, .num_joints = num_joints, .joint = hips,
                                .frame_time_s = 1.0 / fps, .displacements = disp};
    EXPECT_TRUE(job.Run());
    if (f % per_output == 0) out.push_back(disp[12]);
  }
  EXPECT_EQ(state.counters().any_limit(), 0);
  return out;
}

TEST(MassSpringStepJob, FrameRateIndependence) {
  const std::vector<glm::vec3> r30 = JumpResponse(30), r60 = JumpResponse(60),
                               r120 = JumpResponse(120);
  const std::size_t n = std::min({r30.size(), r60.size(), r120.size()});
  ASSERT_GT(n, 30u);
  float peak = 0.0f, d30 = 0.0f, d60 = 0.0f;
  for (std::size_t k = 0; k < n; ++k) {
    peak = std::max(peak, glm::length(r120[k]));
    d30 = std::max(d30, glm::length(r30[k] - r120[k]));
    d60 = std::max(d60, glm::length(r60[k] - r120[k]));
  }
  ASSERT_GT(peak, 0.2f);  // the jump visibly moves the patch
  EXPECT_LT(d60, kFrameRateAgreement60 * peak);
  EXPECT_LT(d30, kFrameRateAgreement30 * peak);
  std::printf("jump: peak %.3f cm, max difference 30 vs 120 fps %.4f cm, 60 vs 120 fps %.4f cm\n",
              double(peak), double(d30), double(d60));
}

// A glitchy capture: 1000 m/s^2 spikes, wild rotation and NaN samples.
TEST(MassSpringStepJob, SpikesAndNanStayBounded) {
  for (auto model : {deform::SpringForceModel::kLinear, deform::SpringForceModel::kLength}) {
    MassSpringParams p;
    p.force_model = model;
    const MassSpringNetwork net = Build(7, 7, p, 10.0f);
    MassSpringState state;
    state.Resize(net);
    const DriveFn drive = [](double t) {
      DrivingFrame d;
      const int k = static_cast<int>(t * 240.0);
      if (k % 7 == 0) d.linear_acceleration = glm::vec3(1e5f, -1e5f, 3e4f);  // 1000+ m/s^2
      if (k % 11 == 0) d.angular_velocity = glm::vec3(0, 40.0f, 0);
      if (k % 13 == 0) d.angular_acceleration = glm::vec3(5e3f, 0, 0);
      if (k % 29 == 0) d.linear_acceleration.x = std::nanf("");
      if (k % 31 == 0) d.rotation = glm::quat(0, 0, 0, 0);
      return d;
    };
    std::vector<glm::vec3> disp(49);
    for (int f = 0; f < 600; ++f) {
      const MassSpringStepJob job{.network = &net, .state = &state, .time_s = f / 30.0,
                                  .driving = &drive, .displacements = disp};
      ASSERT_TRUE(job.Run());
      for (const glm::vec3& e : disp) {
        ASSERT_TRUE(std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z));
        ASSERT_LE(glm::length(e), net.params.max_displacement * (1.0f + kFloatTol));
      }
    }
    EXPECT_GT(state.counters().acceleration_clamps, 0);
    EXPECT_GT(state.counters().non_finite_inputs, 0);
    EXPECT_GT(state.counters().displacement_clamps, 0);
  }
}

TEST(MassSpringStepJob, ResetsWhenTimeJumps) {
  const MassSpringNetwork net = Build(5, 5, QuietParams());
  MassSpringState state;
  state.Resize(net);
  const DriveFn drive = Shake(100.0);
  const std::vector<glm::vec3> a = RunCentre(net, state, drive, 0.0, 1.0 / 30, 30);
  EXPECT_EQ(state.counters().time_resets, 1);
  EXPECT_GT(glm::length(a.back()), 0.0f);
  // Forward jump beyond max_time_gap_s, then backwards: each starts from rest.
  for (double t : {10.0, 2.0}) {
    const std::vector<glm::vec3> b = RunCentre(net, state, drive, t, 1.0 / 30, 1);
    EXPECT_EQ(glm::length(b[0]), 0.0f);
  }
  EXPECT_EQ(state.counters().time_resets, 3);
  // The same frame twice is no jump.
  RunCentre(net, state, drive, 2.0, 0.0, 2);
  EXPECT_EQ(state.counters().time_resets, 3);
}

TEST(MassSpringStepJob, PrerollStartsSettled) {
  // Gravity with the frame tilted 30 degrees from bind: a constant load the
  // patch sags under. Without preroll the first frame is at rest (e = 0); with
  // 3 s of preroll it is already at the settled sag.
  const glm::quat tilted = glm::angleAxis(0.5f, glm::vec3(0, 0, 1));
  const DriveFn drive = [tilted](double) { return DrivingFrame{tilted}; };
  const auto first = [&](double preroll) {
    MassSpringParams p;
    p.preroll_s = preroll;
    const MassSpringNetwork net = Build(5, 5, p);
    MassSpringState state;
    state.Resize(net);
    return RunCentre(net, state, drive, 7.0, 0.25, 20);
  };
  const std::vector<glm::vec3> cold = first(0.0), warm = first(3.0);
  EXPECT_EQ(glm::length(cold[0]), 0.0f);
  const glm::vec3 settled = cold.back();
  ASSERT_GT(glm::length(settled), 0.1f);
  EXPECT_LT(glm::length(warm[0] - settled), kPrerollSettledRel * glm::length(settled));
}

// 10,000 frames of real captures (CMU, 120 fps, hips-driven), with the default
// belly and face parameters: no NaN, displacement within e_max.
TEST(MassSpringStepJob, RealCapturesStayFinite) {
  constexpr float kCmuUnitsPerMetre = 18.7f;
  const auto path1 = SharedDataPath("bvh/cmu_cgspeed/01_01.bvh");
  const auto path3 = SharedDataPath("bvh/cmu_cgspeed/01_03.bvh");
  PATCHSKIN_REQUIRE_SHARED_FILE(path1);
  PATCHSKIN_REQUIRE_SHARED_FILE(path3);
  int frames = 0;
  std::int64_t limits = 0;
  for (int pass = 0; frames < 10000; ++pass) {
    mocap::BvhReadOptions options;
    auto file = mocap::ReadBvhFile((pass % 2 == 0 ? path3 : path1).string(), options);
    ASSERT_TRUE(file.ok()) << file.error().ToString();
    const std::vector<mocap::JointKinematics> kin = SmoothedKinematics(file->skeleton, file->motion);
    const int joint = file->skeleton.FindJoint(pass % 2 == 0 ? "Hips" : "Spine");
    ASSERT_GE(joint, 0);
    MassSpringParams p;
    // cgspeed's CMU units: the hips stand ~17.8 units high, ~0.95 m.
    p.units_per_metre = kCmuUnitsPerMetre;
    if (pass % 2 == 1) {
      p.frequency_hz = 5.0f;
      p.damping_ratio = 0.25f;
    }
    const std::vector<glm::vec3> pts = FlatGrid(7, 7, 0.06f * kCmuUnitsPerMetre);  // 36 cm wide
    auto net = BuildMassSpringNetwork(
        {.rows = 7, .cols = 7, .rest_points = pts, .max_angular_speed_rad_s = 20}, p);
    ASSERT_TRUE(net.ok());
    MassSpringState state;
    state.Resize(*net);
    std::vector<glm::vec3> disp(49);
    const double h = file->motion.frame_time_s;
    for (int f = 0; f < file->motion.num_frames && frames < 10000; ++f, ++frames) {
      const MassSpringStepJob job{.network = &*net, .state = &state, .time_s = f * h,
                                  .kinematics = kin, .num_joints = file->skeleton.num_joints(),
                                  .joint = joint, .frame_time_s = h, .displacements = disp};
      ASSERT_TRUE(job.Run());
      for (const glm::vec3& e : disp) {
        ASSERT_TRUE(std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z));
        ASSERT_LE(glm::length(e), net->params.max_displacement * (1.0f + kFloatTol));
      }
    }
    limits += state.counters().any_limit();
    std::printf("pass %d: %lld acceleration clamps, %lld displacement clamps\n", pass,
                static_cast<long long>(state.counters().acceleration_clamps),
                static_cast<long long>(state.counters().displacement_clamps));
  }
  std::printf("10000 real frames: %lld limit events\n", static_cast<long long>(limits));
}

// Runs `drive` on a fresh state of `net` at 30 fps for `frames` frames; all
// displacements, frame after frame.
std::vector<glm::vec3> RunAll(const MassSpringNetwork& net, const DriveFn& drive, int frames,
                              MassSpringState& state) {
  state.Resize(net);
  const std::size_t points = static_cast<std::size_t>(net.rows * net.cols);
  std::vector<glm::vec3> all(points * static_cast<std::size_t>(frames));
  for (int f = 0; f < frames; ++f) {
    const MassSpringStepJob job{
        .network = &net, .state = &state, .time_s = f / 30.0, .driving = &drive,
        .displacements = std::span(all).subspan(static_cast<std::size_t>(f) * points, points)};
    EXPECT_TRUE(job.Run()) << job.Run().what;
  }
  return all;
}

using testsupport::SameBits;

// A sample with a NaN or Inf in any of its 13 floats, or a zero rotation, is
// the bind frame at rest (the same bits as a source that gives it), counted
// once per sample; |a| above the clamp is scaled back to it (the same bits
// as a source that gives the clamped vector), counted; large finite values
// of everything else pass unchanged.
TEST(MassSpringStepJob, InputChecksReplaceGlitchesAndClampTheAcceleration) {
  MassSpringParams p;  // gravity on: the bind frame is not the identity below
  p.max_displacement = 100.0f;
  const glm::quat bind = glm::angleAxis(0.4f, glm::vec3(1, 0, 0));
  const std::vector<glm::vec3> pts = FlatGrid(5, 5);
  const MassSpringNetwork net = *BuildMassSpringNetwork(
      {.rows = 5, .cols = 5, .rest_points = pts, .bind_rotation = bind, .max_angular_speed_rad_s = 1},
      p);
  const auto sway = [](double t) {
    const float s = static_cast<float>(std::sin(3.0 * t));
    return DrivingFrame{glm::angleAxis(0.3f * s, glm::vec3(0, 0, 1)), glm::vec3(200.0f * s, 0, 50.0f),
                        glm::vec3(0, 0.8f * s, 0), glm::vec3(0.5f * s, 0, 0)};
  };
  // Glitches in field `field` (0..12) at every sample in [0.5, 0.6) s.
  const auto glitchy = [&](int field, float bad) {
    return DriveFn([=](double t) {
      DrivingFrame d = sway(t);
      if (t >= 0.5 && t < 0.6) (&d.rotation.x)[field] = bad;
      return d;
    });
  };
  const DriveFn at_rest = [&](double t) {
    return t >= 0.5 && t < 0.6 ? DrivingFrame{bind} : sway(t);
  };
  MassSpringState reference_state;
  const std::vector<glm::vec3> reference = RunAll(net, at_rest, 30, reference_state);
  EXPECT_EQ(reference_state.counters().non_finite_inputs, 0);
  // Stage times h/2 apart in [0.5, 0.6): 48; the run boundaries 0.5, 0.533 and
  // 0.567 are sampled twice (one run's last stage, the next run's first).
  const int samples = 48 + 3;
  for (int field = 0; field < 13; ++field) {
    for (float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
      SCOPED_TRACE(testing::Message() << "field " << field << " value " << bad);
      MassSpringState state;
      EXPECT_TRUE(SameBits(RunAll(net, glitchy(field, bad), 30, state), reference));
      EXPECT_EQ(state.counters().non_finite_inputs, samples);
    }
  }
  const DriveFn zero_rotation = [&](double t) {
    DrivingFrame d = sway(t);
    if (t >= 0.5 && t < 0.6) d.rotation = glm::quat(0, 0, 0, 0);
    return d;
  };
  MassSpringState zero_state;
  EXPECT_TRUE(SameBits(RunAll(net, zero_rotation, 30, zero_state), reference));
  EXPECT_GT(zero_state.counters().non_finite_inputs, 0);

  // |a| = 10x the clamp along (3, 4, 0) against a source giving the clamp itself.
  const float clamp = p.max_acceleration_mps2 * p.units_per_metre;
  const auto pushed = [&](float length) {
    return DriveFn([=](double t) {
      DrivingFrame d = sway(t);
      d.angular_velocity.y += 5.0f;  // large, finite: passes unchanged
      if (t >= 0.5 && t < 0.6) d.linear_acceleration = glm::vec3(0.6f, 0.8f, 0.0f) * length;
      return d;
    });
  };
  MassSpringState clamped, exact;
  const std::vector<glm::vec3> a = RunAll(net, pushed(10.0f * clamp), 30, clamped);
  const std::vector<glm::vec3> b = RunAll(net, pushed(clamp * (1.0f - 1e-6f)), 30, exact);
  EXPECT_GT(clamped.counters().acceleration_clamps, 0);
  EXPECT_EQ(exact.counters().acceleration_clamps, 0);
  EXPECT_EQ(clamped.counters().non_finite_inputs, 0);
  float worst = 0.0f, largest = 0.0f;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, glm::length(a[i] - b[i]));
    largest = std::max(largest, glm::length(b[i]));
  }
  ASSERT_GT(largest, 0.1f);
  EXPECT_LT(worst, 1e-4f * largest);  // the clamp's 1e-6 of |a|, integrated
}

// The displacement limit in the modal solver (points found from the modes,
// their clamps taken back to the modes) against the point-space solver's
// clamp per point: under a drive that keeps pushing the patch past e_max,
// both clamp, stay within e_max and follow the same trajectory (float
// round-off apart: the clamp is continuous).
TEST(MassSpringStepJob, ModalLimitFollowsThePointSpaceLimit) {
  const DriveFn shove = [](double t) {
    DrivingFrame d;
    const float s = static_cast<float>(std::sin(2 * std::numbers::pi * 2.0 * t));
    d.linear_acceleration = glm::vec3(3000.0f * s, 1500.0f, 800.0f * s);
    d.angular_velocity = glm::vec3(0, 2.0f * s, 0);
    return d;
  };
  std::vector<glm::vec3> runs[2];
  std::int64_t clamps[2] = {};
  for (int solver = 0; solver < 2; ++solver) {
    MassSpringParams p = QuietParams();
    p.solver = solver == 0 ? deform::MassSpringSolver::kModal : deform::MassSpringSolver::kPointSpace;
    const MassSpringNetwork net = Build(7, 7, p, 2.0f);
    MassSpringState state;
    runs[solver] = RunAll(net, shove, 60, state);
    clamps[solver] = state.counters().displacement_clamps;
    for (const glm::vec3& e : runs[solver]) {
      ASSERT_LE(glm::length(e), net.params.max_displacement * (1.0f + kFloatTol));
    }
  }
  EXPECT_GT(clamps[0], 100);
  EXPECT_NEAR(static_cast<double>(clamps[0]), static_cast<double>(clamps[1]),
              0.02 * static_cast<double>(clamps[1]));
  float worst = 0.0f;
  for (std::size_t i = 0; i < runs[0].size(); ++i) {
    worst = std::max(worst, glm::length(runs[0][i] - runs[1][i]));
  }
  EXPECT_LT(worst, 1e-3f);  // cm, against e_max = 1 cm
}

// A patch pushed and then left alone in the bind pose decays to rest: once
// its displacements' and velocities' squares each sum below 1e-24 it is set
// to exactly 0 (before any float of it reaches the subnormal range, where
// every operation is slow), and stays 0; until then the decay is left alone.
// Both solvers, both force models.
TEST(MassSpringStepJob, AStateThatHasDecayedIsSetToExactlyZero) {
  struct Case {
    deform::MassSpringSolver solver;
    deform::SpringForceModel model;
  };
  for (const Case c : {Case{deform::MassSpringSolver::kModal, deform::SpringForceModel::kLinear},
                       Case{deform::MassSpringSolver::kPointSpace, deform::SpringForceModel::kLinear},
                       Case{deform::MassSpringSolver::kPointSpace, deform::SpringForceModel::kLength}}) {
    SCOPED_TRACE(testing::Message() << "solver " << static_cast<int>(c.solver) << " model "
                                    << static_cast<int>(c.model));
    MassSpringParams p;
    p.solver = c.solver;
    p.force_model = c.model;
    const MassSpringNetwork net = Build(5, 5, p);
    const DriveFn still = [](double) { return DrivingFrame{glm::quat(1, 0, 0, 0)}; };
    MassSpringState state;
    state.Resize(net);
    std::vector<glm::vec3> disp(25), newest(9);
    bool seen_small = false;  // a frame whose state was small but not yet at rest
    int zero_from = -1;
    for (int frame = 0; frame < 30 * 60; ++frame) {
      const MassSpringStepJob job{
          .network = &net, .state = &state, .time_s = frame / 30.0, .driving = &still,
          .user_acceleration = frame >= 1 && frame <= 3 ? glm::vec3(0, 50.0f, 0) : glm::vec3(0.0f),
          .displacements = disp};
      ASSERT_TRUE(job.Run());
      deform::MassSpringPointDisplacements(net, state, newest);
      double x2 = 0.0;
      for (const glm::vec3& e : newest) {
        for (int k = 0; k < 3; ++k) {
          ASSERT_NE(std::fpclassify(e[k]), FP_SUBNORMAL) << "frame " << frame;
          x2 += double(e[k]) * double(e[k]);
        }
      }
      if (frame <= 3) continue;  // at rest before the push
      if (deform::MassSpringEnergy(net, state) == 0.0) {
        if (zero_from < 0) zero_from = frame;
        for (const glm::vec3& d : disp) ASSERT_EQ(d, glm::vec3(0.0f)) << "frame " << frame;
      } else {
        ASSERT_LT(zero_from, 0) << "the state left 0 at frame " << frame;
        seen_small = seen_small || (x2 < 1e-20 && x2 > 1e-24);
      }
    }
    EXPECT_GT(zero_from, 3);
    EXPECT_TRUE(seen_small);
    EXPECT_EQ(state.counters().any_limit(), 0);
  }
}

TEST(MassSpringState, SetDisplacementChecksItsSizes) {
  const MassSpringNetwork net = Build(5, 5, {});
  MassSpringState state;
  const std::vector<glm::vec3> e(9, glm::vec3(0.1f, 0, 0));
  EXPECT_FALSE(state.SetDisplacement(net, e));  // not sized
  state.Resize(net);
  EXPECT_FALSE(state.SetDisplacement(net, std::span(e).first(8)));
  ASSERT_TRUE(state.SetDisplacement(net, e));
  std::vector<glm::vec3> back(9);
  deform::MassSpringPointDisplacements(net, state, back);  // through the modes and back
  for (const glm::vec3& b : back) EXPECT_NEAR(b.x, 0.1f, 1e-6f);
}

}  // namespace
