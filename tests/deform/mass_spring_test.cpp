// The elastic layer (ALGORITHMS.md 6): topology, the scaled slowest mode and its
// damping, energy decay, static response, RK4 order, frame-rate independence,
// limits under glitches, real captures, resets and preroll.

#include "deform/mass_spring.h"

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "mocap/kinematics.h"
#include "mocap/synthetic.h"
#include "support/data_paths.h"
#include "support/tolerances.h"

namespace {

using deform::BuildMassSpringNetwork;
using deform::DrivingFrame;
using deform::MassSpringNetwork;
using deform::MassSpringParams;
using deform::MassSpringSetup;
using deform::MassSpringState;
using deform::MassSpringStepJob;
using mocap::JobStatus;
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
  for (std::size_t a = 0; a < n; ++a) state.position[a] = glm::vec3(net.modes[a * n], 0, 0);
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
  EXPECT_EQ(state.counters.any_limit(), 0);
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

}  // namespace
