// The elastic layer's stage coefficients four frames at a time
// (deform/elastic/internal/stage_forcing.h) against the scalar formulation, bit for bit,
// and the modal job (which samples a batch of stage times before stepping)
// against a step-by-step loop that samples each stage time as it reaches it.

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "deform/elastic/internal/mass_spring_modal.h"
#include "deform/elastic/internal/stage_forcing.h"
#include "deform/elastic/mass_spring.h"

namespace {

using deform::DrivingFrame;
using deform::internal::ForcingConstants;
using deform::internal::StageCoefficients;

bool SameBits(const StageCoefficients& a, const StageCoefficients& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

std::vector<DrivingFrame> RandomFrames(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<DrivingFrame> frames(count);
  for (DrivingFrame& f : frames) {
    // Unnormalized rotations (the sampler's are only nearly unit), large and
    // small accelerations, angular rates of a few rad/s.
    f.rotation = glm::quat(u(rng), u(rng), u(rng), u(rng));
    f.linear_acceleration = 3000.0f * glm::vec3(u(rng), u(rng), u(rng));
    f.angular_velocity = 6.0f * glm::vec3(u(rng), u(rng), u(rng));
    f.angular_acceleration = 80.0f * glm::vec3(u(rng), u(rng), u(rng));
  }
  // Values where rounding and signed zeros show: exact zeros of both signs, a
  // zero rotation (glm::normalize's identity branch), tiny and huge entries.
  frames[0] = DrivingFrame{};
  frames[1].angular_velocity = glm::vec3(-0.0f, 0.0f, -0.0f);
  frames[1].angular_acceleration = glm::vec3(0.0f, -0.0f, -0.0f);
  frames[1].linear_acceleration = glm::vec3(-0.0f);
  frames[2].rotation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
  frames[3].angular_velocity = glm::vec3(1e-20f, -3e18f, 7.0f);
  frames[3].rotation = glm::quat(1e-3f, -2e-4f, 0.0f, 5e-4f);
  return frames;
}

ForcingConstants Constants(bool gravity, float gain) {
  ForcingConstants k;
  k.gain = gain;
  k.user_acceleration = glm::vec3(3.5f, -0.25f, 12.0f);
  k.gravity = gravity;
  k.gravity_model = glm::vec3(0.0f, -981.0f, 0.0f);
  k.gravity_bind = glm::conjugate(glm::normalize(glm::quat(0.9f, 0.1f, -0.3f, 0.2f))) *
                   k.gravity_model;
  return k;
}

// allow_avx: groups of eight in AVX lanes (on a CPU with AVX), the rest in
// groups of four; without it, all in groups of four.
TEST(StageForcing, FourAndEightAtATimeGiveTheScalarBits) {
  const std::vector<DrivingFrame> frames = RandomFrames(203, 7);
  for (const bool gravity : {true, false}) {
    for (const float gain : {1.0f, 0.37f, 0.0f, 2.5f}) {
      for (const bool avx : {true, false}) {
        SCOPED_TRACE(testing::Message() << "gravity " << gravity << ", gain " << gain
                                        << ", avx " << avx);
        const ForcingConstants k = Constants(gravity, gain);
        std::vector<StageCoefficients> batched(frames.size());
        deform::internal::StageCoefficientsOfEach(frames, k, batched, avx);
        int compared = 0;
        for (std::size_t i = 0; i < frames.size(); ++i) {
          const StageCoefficients scalar = deform::internal::StageCoefficientsOf(frames[i], k);
          ASSERT_TRUE(SameBits(scalar, batched[i])) << "frame " << i;
          ++compared;
        }
        EXPECT_EQ(compared, 203);
      }
    }
  }
}

// Every count from 1 to 19 (whole groups of eight and four and partial ones)
// fills exactly its own entries and leaves the rest of the output alone.
TEST(StageForcing, PartialGroupsWriteOnlyTheirEntries) {
  const std::vector<DrivingFrame> frames = RandomFrames(19, 11);
  const ForcingConstants k = Constants(true, 1.0f);
  StageCoefficients marker;
  marker.common[0] = 12345.0f;
  marker.Mx(0, 0) = -7.0f;
  for (std::size_t count = 1; count <= 19; ++count) {
    std::vector<StageCoefficients> out(20, marker);
    deform::internal::StageCoefficientsOfEach(std::span(frames).first(count), k,
                                              std::span(out).first(count));
    for (std::size_t i = 0; i < count; ++i) {
      EXPECT_TRUE(SameBits(out[i], deform::internal::StageCoefficientsOf(frames[i], k)))
          << count << " frames, entry " << i;
    }
    for (std::size_t i = count; i < out.size(); ++i) EXPECT_TRUE(SameBits(out[i], marker));
  }
}

// The job computes the coefficients of up to 8 steps before taking them. A loop
// that samples and steps one step at a time (the stage times t, t + h/2, t + h
// accumulated the same way) must give the same bits, across runs of 1 to many
// steps (30, 60 and 17 fps outputs and a long first run with preroll).
TEST(StageForcing, BatchedJobMatchesStepByStepSampling) {
  const std::function<DrivingFrame(double)> drive = [](double t) {
    const float s = static_cast<float>(std::sin(5.0 * t)), c = static_cast<float>(std::cos(3.0 * t));
    return DrivingFrame{glm::angleAxis(0.5f * s, glm::normalize(glm::vec3(0.2f, 1.0f, 0.1f))),
                        glm::vec3(90.0f * s, 40.0f * c, -25.0f * s), glm::vec3(0.3f, 1.1f * c, -0.2f),
                        glm::vec3(0.4f * c, -5.0f * s, 0.6f)};
  };
  std::vector<glm::vec3> points;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 5; ++j)
      points.emplace_back(3.0f * static_cast<float>(j), 0.2f * static_cast<float>(i), 3.0f * static_cast<float>(i));
  deform::MassSpringParams params;
  params.preroll_s = 0.3;
  params.units_per_metre = 10.0f;  // gravity 98 units/s^2: well inside the displacement limit
  params.down = glm::normalize(glm::vec3(0.1f, -1.0f, 0.2f));
  auto built = deform::BuildMassSpringNetwork(
      {.rows = 6, .cols = 5, .rest_points = points, .bind_rotation = glm::quat(0.9f, 0.1f, -0.3f, 0.2f),
       .max_angular_speed_rad_s = 3.0f},
      params);
  ASSERT_TRUE(built.ok()) << built.error().ToString();
  const deform::MassSpringNetwork& net = built.value();
  const glm::vec3 push(0.0f, 0.0f, 15.0f);
  const double g = 9.81 * params.units_per_metre;
  ForcingConstants k;
  k.gain = params.gain;
  k.user_acceleration = push;
  k.gravity = true;
  k.gravity_model = glm::vec3(glm::dvec3(glm::normalize(params.down)) * g);
  k.gravity_bind = glm::conjugate(net.bind_rotation) * k.gravity_model;

  for (const double fps : {30.0, 60.0, 17.0}) {
    SCOPED_TRACE(testing::Message() << fps << " fps");
    deform::MassSpringState state;
    state.Resize(net);
    // Reference: the modes in SoA buffers, stepped one step at a time.
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    const std::size_t stride = static_cast<std::size_t>(net.mode_stride);
    std::vector<float> x(3 * stride, 0.0f), v(3 * stride, 0.0f), x1(3 * stride), v1(3 * stride);
    const auto step = deform::internal::SelectModalStep(true, false);
    const double h = net.time_step_s;
    double t = -params.preroll_s;  // the first run's reset puts the step grid there
    for (int f = 0; f < 40; ++f) {
      const double time = f / fps;
      const deform::MassSpringStepJob job{.network = &net, .state = &state, .time_s = time,
                                          .driving = &drive, .user_acceleration = push};
      ASSERT_TRUE(job.Run());
      while (t < time - 1e-9) {
        const StageCoefficients c0 = deform::internal::StageCoefficientsOf(drive(t), k);
        const StageCoefficients cm = deform::internal::StageCoefficientsOf(drive(t + 0.5 * h), k);
        const StageCoefficients c1 = deform::internal::StageCoefficientsOf(drive(t + h), k);
        step(net, c0, cm, c1, static_cast<float>(h), x.data(), v.data(), x1.data(), v1.data());
        std::swap(x, x1);
        std::swap(v, v1);
        t = t + h;
      }
      ASSERT_EQ(state.step_time_s, t) << "frame " << f;
    }
    ASSERT_EQ(state.counters.any_limit(), 0);
    ASSERT_EQ(state.counters.time_resets, 1);
    for (std::size_t m = 0; m < n; ++m) {
      for (int c = 0; c < 3; ++c) {
        const std::size_t at = static_cast<std::size_t>(c) * stride + m;
        const float got_x = state.ModalDisplacement(m)[c], got_v = state.ModalVelocity(m)[c];
        ASSERT_EQ(std::memcmp(&got_x, &x[at], sizeof(float)), 0) << "mode " << m;
        ASSERT_EQ(std::memcmp(&got_v, &v[at], sizeof(float)), 0) << "mode " << m;
      }
    }
    EXPECT_GT(glm::length(state.ModalDisplacement(0)), 0.01f);  // the drive moved it
  }
}

}  // namespace
