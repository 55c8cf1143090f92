// The modal solver's SIMD step (deform/internal/mass_spring_modal.h): the AVX
// and SSE2 paths give the same bits, and both give the bits of the scalar
// formulation the header documents (same operations in the same order), for
// mode counts that use every lane grouping (16-lane groups, an 8-lane tail).

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "deform/mass_spring.h"

namespace {

using deform::DrivingFrame;
using deform::MassSpringNetwork;
using deform::MassSpringParams;
using deform::MassSpringState;
using deform::MassSpringStepJob;
using DriveFn = std::function<DrivingFrame(double)>;

MassSpringNetwork Build(int rows, int cols, const MassSpringParams& params) {
  std::vector<glm::vec3> points;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      points.emplace_back(2.0f * static_cast<float>(j), 0.3f * static_cast<float>(i * j),
                          2.0f * static_cast<float>(i));
  auto net = deform::BuildMassSpringNetwork(
      {.rows = rows, .cols = cols, .rest_points = points, .max_angular_speed_rad_s = 3.0f},
      params);
  EXPECT_TRUE(net.ok()) << net.error().ToString();
  return std::move(net).value();
}

// A turning, swaying frame with spikes large enough to hit the displacement
// limit and the acceleration clamp, and a NaN now and then.
DrivingFrame Rough(double t) {
  const float s = static_cast<float>(std::sin(5.0 * t)), c = static_cast<float>(std::cos(3.0 * t));
  DrivingFrame d{glm::angleAxis(0.7f * s, glm::normalize(glm::vec3(0.2f, 1.0f, 0.1f))),
                 glm::vec3(900.0f * s, 400.0f * c, -300.0f * s * c), glm::vec3(0.5f * c, 2.0f * c, 0.3f),
                 glm::vec3(-4.0f * s, -10.0f * s, 2.0f * c)};
  const int k = static_cast<int>(t * 480.0);
  if (k % 97 == 0) d.linear_acceleration = glm::vec3(3e4f, -2e4f, 1e4f);
  if (k % 389 == 0) d.angular_velocity.y = std::nanf("");
  return d;
}

bool SameBits(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

// Grid sizes, their mode counts and lane groups: 4x4: 4 (one 8-lane group),
// 5x5: 9 (one 16-lane group), 6x9: 28 (two 16-lane groups), 8x8: 36 (two 16-lane
// groups and an 8-lane one), 16x16: 196 (twelve and one).
TEST(MassSpringSimd, AvxAndSse2PathsGiveTheSameBits) {
  if (!__builtin_cpu_supports("avx")) GTEST_SKIP() << "this CPU has no AVX: only the SSE2 path runs";
  const DriveFn drive = Rough;
  for (const auto& [rows, cols] : {std::pair{4, 4}, {5, 5}, {6, 9}, {8, 8}, {16, 16}}) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    MassSpringParams p;
    p.max_displacement = 0.6f;  // reached often under Rough
    const MassSpringNetwork net = Build(rows, cols, p);
    MassSpringState avx, sse;
    avx.Resize(net);
    sse.Resize(net);
    const std::size_t points = static_cast<std::size_t>(rows * cols);
    std::vector<glm::vec3> out_avx(points), out_sse(points);
    const int frames = rows == 16 ? 60 : 600;
    for (int f = 0; f < frames; ++f) {
      for (auto [state, out, allow] : {std::tuple{&avx, &out_avx, true}, {&sse, &out_sse, false}}) {
        const MassSpringStepJob job{.network = &net, .state = state, .time_s = f / 30.0,
                                    .driving = &drive, .displacements = *out, .allow_avx = allow};
        ASSERT_TRUE(job.Run());
      }
      ASSERT_TRUE(SameBits(out_avx, out_sse)) << "frame " << f;
    }
    EXPECT_TRUE(SameBits(avx.position, sse.position));
    EXPECT_TRUE(SameBits(avx.velocity, sse.velocity));
    EXPECT_TRUE(SameBits(avx.prev_position, sse.prev_position));
    EXPECT_EQ(avx.counters.steps, sse.counters.steps);
    EXPECT_EQ(avx.counters.displacement_clamps, sse.counters.displacement_clamps);
    EXPECT_GT(avx.counters.displacement_clamps, 0);  // the limit path ran
    EXPECT_GT(avx.counters.acceleration_clamps, 0);
    EXPECT_GT(avx.counters.non_finite_inputs, 0);
  }
}

// The scalar formulation of deform/mass_spring.h, one mode and one component at
// a time, in the order the header's equations are written: with no limit
// reached, the SIMD paths must reproduce it bit for bit.
struct ScalarModes {
  std::vector<glm::vec3> x, v;
};

void ScalarStage(const MassSpringNetwork& net, const DrivingFrame& d, const ScalarModes& in,
                 ScalarModes& acc) {
  const float gain = net.params.gain;
  const glm::vec3 common = -gain * d.linear_acceleration + glm::vec3(0.0f);
  const glm::vec3 w = d.angular_velocity, al = d.angular_acceleration;
  const float ww = glm::dot(w, w);
  const float skew_al[3][3] = {{0, -al.z, al.y}, {al.z, 0, -al.x}, {-al.y, al.x, 0}};
  const float skew_w[3][3] = {{0, -w.z, w.y}, {w.z, 0, -w.x}, {-w.y, w.x, 0}};
  float mx[3][3], mv[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      mx[r][c] = -gain * (skew_al[r][c] + (w[r] * w[c] - (r == c ? ww : 0.0f)));
      mv[r][c] = -2.0f * gain * skew_w[r][c];
    }
  }
  for (std::size_t k = 0; k < in.x.size(); ++k) {
    const glm::vec3 e = net.mode_rest[k] + in.x[k];
    for (int c = 0; c < 3; ++c) {
      acc.x[k][c] = net.mode_sum[k] * common[c] + mx[c][0] * e.x + mx[c][1] * e.y +
                    mx[c][2] * e.z + mv[c][0] * in.v[k].x + mv[c][1] * in.v[k].y +
                    mv[c][2] * in.v[k].z - net.mode_omega2[k] * in.x[k][c] -
                    net.mode_damping[k] * in.v[k][c];
    }
  }
}

void ScalarStep(const MassSpringNetwork& net, const DriveFn& drive, double t, ScalarModes& z) {
  const float h = static_cast<float>(net.time_step_s), hh = 0.5f * h;
  const double hd = net.time_step_s;
  const std::size_t n = z.x.size();
  ScalarModes acc{std::vector<glm::vec3>(n), {}}, s{z.v, {}}, zs{z.x, z.v};
  s.v.resize(n);
  const DrivingFrame f0 = drive(t), fm = drive(t + 0.5 * hd), f1 = drive(t + hd);
  ScalarStage(net, f0, z, acc);
  for (std::size_t k = 0; k < n; ++k) {
    s.v[k] = acc.x[k];
    zs.x[k] = z.x[k] + hh * z.v[k];
    zs.v[k] = z.v[k] + hh * acc.x[k];
  }
  for (const float step : {hh, h}) {
    ScalarStage(net, fm, zs, acc);
    for (std::size_t k = 0; k < n; ++k) {
      s.x[k] = s.x[k] + 2.0f * zs.v[k];
      s.v[k] = s.v[k] + 2.0f * acc.x[k];
      zs.x[k] = z.x[k] + step * zs.v[k];
      zs.v[k] = z.v[k] + step * acc.x[k];
    }
  }
  ScalarStage(net, f1, zs, acc);
  for (std::size_t k = 0; k < n; ++k) {
    z.x[k] = z.x[k] + (h / 6.0f) * (s.x[k] + zs.v[k]);
    z.v[k] = z.v[k] + (h / 6.0f) * (s.v[k] + acc.x[k]);
  }
}

TEST(MassSpringSimd, BothPathsMatchTheScalarFormulation) {
  const DriveFn drive = [](double t) {  // gentle: no limit is reached
    const float s = static_cast<float>(std::sin(6.0 * t));
    return DrivingFrame{glm::quat(1, 0, 0, 0), glm::vec3(80.0f * s, 30.0f, -20.0f * s),
                        glm::vec3(0.3f, 1.2f * s, 0.1f), glm::vec3(0.5f, -7.0f * s, 0.2f)};
  };
  for (const auto& [rows, cols] : {std::pair{5, 5}, {7, 7}, {8, 8}}) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    MassSpringParams p;
    p.gravity = false;
    const MassSpringNetwork net = Build(rows, cols, p);
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    for (const bool allow_avx : {true, false}) {
      MassSpringState state;
      state.Resize(net);
      const int frames = 90;
      for (int f = 0; f < frames; ++f) {
        const MassSpringStepJob job{.network = &net, .state = &state, .time_s = f / 30.0,
                                    .driving = &drive, .allow_avx = allow_avx};
        ASSERT_TRUE(job.Run());
      }
      ASSERT_EQ(state.counters.any_limit(), 0);
      ScalarModes z{std::vector<glm::vec3>(n), std::vector<glm::vec3>(n)};
      double t = 0.0;
      for (std::int64_t step = 0; step < state.counters.steps; ++step) {
        ScalarStep(net, drive, t, z);
        t += net.time_step_s;
      }
      EXPECT_TRUE(SameBits(z.x, state.position)) << "avx allowed: " << allow_avx;
      EXPECT_TRUE(SameBits(z.v, state.velocity)) << "avx allowed: " << allow_avx;
      EXPECT_GT(glm::length(state.position[0]), 0.01f);  // the drive moved it
    }
  }
}

}  // namespace
