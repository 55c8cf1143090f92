// The modal solver's SIMD step (deform/elastic/internal/mass_spring_modal.h): the exact
// AVX and SSE2 kernels give the same bits, the portable one the bits of the
// scalar formulation the header documents (same operations in the same order),
// and the fastest (AVX2 + FMA) follows them within float round-off, for mode
// counts that use every lane grouping (8-lane groups, a padded group, a lone
// mode in column form).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <functional>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "deform/elastic/mass_spring.h"
#include "deform/internal/cpu_features.h"
#include "deform/elastic/internal/mass_spring_modal.h"
#include "support/mass_spring_networks.h"
#include "support/tolerances.h"

namespace {

using deform::DrivingFrame;
using deform::MassSpringNetwork;
using deform::MassSpringParams;
using deform::MassSpringState;
using deform::MassSpringStepJob;
using DriveFn = std::function<DrivingFrame(double)>;
using namespace testsupport;

bool SameBits(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

// The exact kernels (SSE2 and AVX) step by step from the same states and
// coefficients: the same bits, sums included.
TEST(MassSpringSimd, ExactAvxAndSse2KernelsGiveTheSameBits) {
  if (!__builtin_cpu_supports("avx")) GTEST_SKIP() << "this CPU has no AVX: only the SSE2 path runs";
  using deform::internal::ModalKernel;
  const auto avx = deform::internal::SelectModalStep(ModalKernel::kExactAvx);
  const auto sse = deform::internal::SelectModalStep(ModalKernel::kPortable);
  ASSERT_NE(avx, sse);
  for (const auto& [rows, cols] : testsupport::kModalGrids) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    const MassSpringNetwork net = CurvedGridNetwork(rows, cols);
    const std::size_t size = 3 * static_cast<std::size_t>(net.mode_stride);
    std::vector<float> x(size, 0.0f), v(size, 0.0f);
    for (std::size_t c = 0; c < 3; ++c) {
      for (int k = 0; k < net.num_free; ++k) {  // padding lanes stay 0
        x[c * size / 3 + static_cast<std::size_t>(k)] = std::sin(0.7f * static_cast<float>(k) + static_cast<float>(c));
        v[c * size / 3 + static_cast<std::size_t>(k)] = 3.0f * std::cos(1.3f * static_cast<float>(k * (c + 1)));
      }
    }
    std::vector<float> xa(size), va(size), xb(size), vb(size);
    deform::internal::StageCoefficients s[3];
    for (int step = 0; step < 200; ++step) {
      for (int i = 0; i < 3; ++i) {
        const float t = 0.01f * static_cast<float>(step * 3 + i);
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) {
            s[i].Mx(r, c) = 2.0f * std::sin(t + static_cast<float>(r * 3 + c));
            if (r != c) s[i].Mv(r, c) = std::cos(2.0f * t + static_cast<float>(r - c));
          }
          s[i].common[r] = 400.0f * std::sin(3.0f * t + static_cast<float>(r));
        }
      }
      const float h = static_cast<float>(net.time_step_s);
      const auto sa = avx(net, s[0], s[1], s[2], h, x.data(), v.data(), xa.data(), va.data());
      const auto sb = sse(net, s[0], s[1], s[2], h, x.data(), v.data(), xb.data(), vb.data());
      ASSERT_EQ(std::memcmp(xa.data(), xb.data(), size * sizeof(float)), 0) << "step " << step;
      ASSERT_EQ(std::memcmp(va.data(), vb.data(), size * sizeof(float)), 0) << "step " << step;
      ASSERT_EQ(std::memcmp(&sa, &sb, sizeof sa), 0) << "step " << step;
      x = xa;
      v = va;
    }
    EXPECT_GT(std::abs(x[0]), 0.0f);
  }
}

// Coefficients with no symmetry between their entries, different at each of
// the 2 count + 1 stage times.
std::vector<deform::internal::StageCoefficients> VaryingCoefficients(int count) {
  std::vector<deform::internal::StageCoefficients> s(static_cast<std::size_t>(2 * count + 1));
  for (std::size_t i = 0; i < s.size(); ++i) {
    const float t = 0.013f * static_cast<float>(i);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        s[i].Mx(r, c) = 2.0f * std::sin(t + static_cast<float>(r * 3 + c));
        if (r != c) s[i].Mv(r, c) = std::cos(2.0f * t + static_cast<float>(r - c));
      }
      s[i].common[r] = 900.0f * std::sin(3.0f * t + static_cast<float>(r));
    }
  }
  return s;
}

// The several-step kernels (ModalStepsFn) against the one-step ones of the same
// instruction set called once per step: the same bits in all four buffers and
// in the sums; and with an e_max that the growing state passes, a stop right
// after the first step the limit could change (sum_x above e_max^2 and, in the
// exact kernels, the mode bound above e_max), never after one it could not.
TEST(MassSpringSimd, SeveralStepsGiveTheBitsOfOneStepAtATime) {
  using deform::internal::ModalKernel;
  int bound_decided = 0;  // steps past e_max^2 that the exact kernels ran on past
  int stops = 0;          // early returns
  for (const ModalKernel kernel : {ModalKernel::kPortable, ModalKernel::kExactAvx, ModalKernel::kFastest}) {
    const auto one = deform::internal::SelectModalStep(kernel);
    const auto several = deform::internal::SelectModalSteps(kernel);
    const bool bound_tested = kernel != ModalKernel::kFastest || !deform::internal::CpuHasAvx2Fma();
    for (const auto& [rows, cols] : testsupport::kModalGrids) {
      SCOPED_TRACE(testing::Message() << rows << "x" << cols << " kernel " << static_cast<int>(kernel));
      const MassSpringNetwork net = CurvedGridNetwork(rows, cols);
      const std::size_t size = 3 * static_cast<std::size_t>(net.mode_stride);
      constexpr int kSteps = 8;
      const std::vector<deform::internal::StageCoefficients> s = VaryingCoefficients(kSteps);
      const float h = static_cast<float>(net.time_step_s);
      // From rest, one step at a time; the previous step's buffers start as garbage
      // (their padding lanes included), as the runner's do.
      std::vector<float> ref[4];
      for (auto& a : ref) a.assign(size, 0.0f);
      std::vector<deform::internal::ModalStepSums> ref_sums;
      std::vector<float> ref_bound;  // ModeBound of each step's displacement
      for (int i = 0; i < kSteps; ++i) {
        ref_sums.push_back(one(net, s[2 * i], s[2 * i + 1], s[2 * i + 2], h, ref[0].data(),
                               ref[1].data(), ref[2].data(), ref[3].data()));
        std::swap(ref[0], ref[2]);
        std::swap(ref[1], ref[3]);
        ref_bound.push_back(deform::internal::ModeBound(net, ref[0].data(), true));
      }
      ASSERT_GT(ref_sums.back().sum_x, ref_sums[2].sum_x);
      // e_max: never reached; reached by sum_x from step 4 on; and between the
      // bound and sqrt(sum_x) of the step where they are furthest apart, so that
      // the bound alone decides there.
      std::size_t apart = 0;
      for (std::size_t i = 1; i < ref_bound.size(); ++i) {
        if (ref_bound[i] / std::sqrt(ref_sums[i].sum_x) <
            ref_bound[apart] / std::sqrt(ref_sums[apart].sum_x)) {
          apart = i;
        }
      }
      for (const float e_max : {1e15f, std::sqrt(ref_sums[2].sum_x) * (1.0f + 1e-6f),
                                0.5f * (ref_bound[apart] + std::sqrt(ref_sums[apart].sum_x))}) {
        MassSpringNetwork limited = net;
        limited.params.max_displacement = e_max;
        const auto needs = [&](int step) {  // step >= 1
          const std::size_t i = static_cast<std::size_t>(step - 1);
          return ref_sums[i].sum_x > e_max * e_max && (!bound_tested || ref_bound[i] > e_max);
        };
        alignas(32) float buffers[4][3 * deform::internal::kMaxModeStride];
        std::fill_n(buffers[0], size, 0.0f);
        std::fill_n(buffers[1], size, 0.0f);
        std::fill_n(buffers[2], size, std::nanf(""));
        std::fill_n(buffers[3], size, -7.0f);
        deform::internal::ModalBuffers b{buffers[0], buffers[1], buffers[2], buffers[3]};
        deform::internal::ModalStepSums sums;
        int taken = 0;
        while (taken < kSteps) {
          const int done = several(limited, s.data() + 2 * taken, kSteps - taken, h, b, sums);
          ASSERT_GE(done, 1);
          taken += done;
          ASSERT_LE(taken, kSteps);
          const auto& want = ref_sums[static_cast<std::size_t>(taken - 1)];
          ASSERT_EQ(std::memcmp(&sums, &want, sizeof sums), 0) << "after step " << taken;
          if (taken < kSteps) {
            ASSERT_TRUE(needs(taken)) << "stopped after step " << taken;
            ++stops;
          }
          for (int i = taken - done + 1; i < taken; ++i) {
            ASSERT_FALSE(needs(i)) << "ran past step " << i;
            if (ref_sums[static_cast<std::size_t>(i - 1)].sum_x > e_max * e_max) ++bound_decided;
          }
        }
        const float* got[4] = {b.x, b.v, b.prev_x, b.prev_v};
        for (int a = 0; a < 4; ++a) {
          ASSERT_EQ(std::memcmp(got[a], ref[a].data(), size * sizeof(float)), 0) << "buffer " << a;
        }
      }
    }
  }
  EXPECT_GT(bound_decided, 0);
  EXPECT_GT(stops, 0);
}

// The job with the fastest kernel (AVX2 + FMA where the CPU has it) against the
// portable one over 100 s of a gentle drive (no limit reached): FMA rounds once
// where the exact kernels round twice, and the damped linear system keeps the
// difference at round-off level.
TEST(MassSpringSimd, FastestKernelFollowsThePortableOne) {
  const DriveFn drive = [](double t) {
    const float s = static_cast<float>(std::sin(4.0 * t)), c = static_cast<float>(std::cos(2.5 * t));
    return DrivingFrame{glm::angleAxis(0.4f * s, glm::vec3(0, 1, 0)),
                        glm::vec3(150.0f * s, 60.0f * c, -40.0f * s * c), glm::vec3(0.2f, 0.8f * c, 0.1f),
                        glm::vec3(0.5f, -2.0f * s, 0.3f * c)};
  };
  for (const auto& [rows, cols] : testsupport::kModalGrids) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    const MassSpringNetwork net = CurvedGridNetwork(rows, cols);
    MassSpringState fast, portable;
    fast.Resize(net);
    portable.Resize(net);
    const std::size_t points = static_cast<std::size_t>(rows * cols);
    std::vector<glm::vec3> out_fast(points), out_portable(points);
    float peak = 0.0f, worst = 0.0f;
    const int frames = rows == 16 ? 300 : 3000;
    for (int f = 0; f < frames; ++f) {
      for (auto [state, out, allow] :
           {std::tuple{&fast, &out_fast, true}, {&portable, &out_portable, false}}) {
        const MassSpringStepJob job{.network = &net, .state = state, .time_s = f / 30.0,
                                    .driving = &drive, .displacements = *out, .allow_avx = allow,
                                    .allow_fma = allow};
        ASSERT_TRUE(job.Run());
      }
      for (std::size_t a = 0; a < points; ++a) {
        peak = std::max(peak, glm::length(out_portable[a]));
        worst = std::max(worst, glm::length(out_fast[a] - out_portable[a]));
      }
    }
    ASSERT_EQ(fast.counters.any_limit(), 0);
    EXPECT_GT(peak, 0.1f);
    EXPECT_LE(worst, kFusedKernelRelTol * peak);
    std::printf("%dx%d: peak %.4f, largest fastest - portable difference %.3g\n", rows, cols,
                double(peak), double(worst));
  }
}

// The scalar formulation of deform/elastic/mass_spring.h, one mode and one component at
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
    const glm::vec3 x = in.x[k], v = in.v[k];
    const float sum = net.mode_sum[k], omega2 = net.mode_omega2[k], damping = net.mode_damping[k];
    for (int c = 0; c < 3; ++c) {
      const int a = c == 0 ? 1 : 0, b = c == 2 ? 1 : 2;  // the other two axes
      acc.x[k][c] = ((sum * common[c] + mx[c][0] * e.x) + (mx[c][1] * e.y + mx[c][2] * e.z)) +
                    ((mv[c][a] * v[a] + mv[c][b] * v[b]) - (omega2 * x[c] + damping * v[c]));
    }
  }
}

void ScalarStep(const MassSpringNetwork& net, const DriveFn& drive, double t, ScalarModes& z) {
  const float h = static_cast<float>(net.time_step_s), hh = 0.5f * h, h6 = h / 6.0f;
  const double hd = net.time_step_s;
  const std::size_t n = z.x.size();
  const auto state = [n] { return ScalarModes{std::vector<glm::vec3>(n), std::vector<glm::vec3>(n)}; };
  ScalarModes k1 = state(), k2 = state(), k3 = state(), k4 = state(), z2 = state(), z3 = state(),
              z4 = state();
  const DrivingFrame f0 = drive(t), fm = drive(t + 0.5 * hd), f1 = drive(t + hd);
  ScalarStage(net, f0, z, k1);
  for (std::size_t k = 0; k < n; ++k) {
    z2.x[k] = z.x[k] + hh * z.v[k];
    z2.v[k] = z.v[k] + hh * k1.x[k];
  }
  ScalarStage(net, fm, z2, k2);
  for (std::size_t k = 0; k < n; ++k) {
    z3.x[k] = z.x[k] + hh * z2.v[k];
    z3.v[k] = z.v[k] + hh * k2.x[k];
  }
  ScalarStage(net, fm, z3, k3);
  for (std::size_t k = 0; k < n; ++k) {
    z4.x[k] = z.x[k] + h * z3.v[k];
    z4.v[k] = z.v[k] + h * k3.x[k];
  }
  ScalarStage(net, f1, z4, k4);
  for (std::size_t k = 0; k < n; ++k) {
    z.x[k] = z.x[k] + h6 * ((z.v[k] + z4.v[k]) + 2.0f * (z2.v[k] + z3.v[k]));
    z.v[k] = z.v[k] + h6 * ((k1.x[k] + 2.0f * (k2.x[k] + k3.x[k])) + k4.x[k]);
  }
}

TEST(MassSpringSimd, BothPathsMatchTheScalarFormulation) {
  const DriveFn drive = [](double t) {  // gentle: no limit is reached
    const float s = static_cast<float>(std::sin(6.0 * t));
    return DrivingFrame{glm::quat(1, 0, 0, 0), glm::vec3(80.0f * s, 30.0f, -20.0f * s),
                        glm::vec3(0.3f, 1.2f * s, 0.1f), glm::vec3(0.5f, -7.0f * s, 0.2f)};
  };
  for (const auto& [rows, cols] : {std::pair{5, 5}, {5, 8}, {7, 7}, {8, 8}}) {
    SCOPED_TRACE(testing::Message() << rows << "x" << cols);
    MassSpringParams p;
    p.gravity = false;
    const MassSpringNetwork net = CurvedGridNetwork(rows, cols, p);
    const std::size_t n = static_cast<std::size_t>(net.num_free);
    // (AVX, FMA): the default (exact AVX), the fastest (FMA where the CPU has it), SSE2.
    for (const auto& [allow_avx, allow_fma] : {std::pair{true, false}, {true, true}, {false, false}}) {
      MassSpringState state;
      state.Resize(net);
      const int frames = 90;
      for (int f = 0; f < frames; ++f) {
        const MassSpringStepJob job{.network = &net, .state = &state, .time_s = f / 30.0,
                                    .driving = &drive, .allow_avx = allow_avx,
                                    .allow_fma = allow_fma};
        ASSERT_TRUE(job.Run());
      }
      ASSERT_EQ(state.counters.any_limit(), 0);
      ScalarModes z{std::vector<glm::vec3>(n), std::vector<glm::vec3>(n)};
      double t = 0.0;
      for (std::int64_t step = 0; step < state.counters.steps; ++step) {
        ScalarStep(net, drive, t, z);
        t += net.time_step_s;
      }
      std::vector<glm::vec3> modes_x(n), modes_v(n);
      for (std::size_t k = 0; k < n; ++k) {
        modes_x[k] = state.ModalDisplacement(k);
        modes_v[k] = state.ModalVelocity(k);
      }
      if (!allow_fma) {  // the exact kernels (SSE2, AVX): bit for bit
        EXPECT_TRUE(SameBits(z.x, modes_x));
        EXPECT_TRUE(SameBits(z.v, modes_v));
      } else {  // the fastest: FMA where the CPU has it
        for (std::size_t k = 0; k < n; ++k) {
          EXPECT_LE(glm::length(z.x[k] - modes_x[k]),
                    kFusedKernelRelTol * glm::length(z.x[k]) + kFusedKernelAbsTol);
        }
      }
      EXPECT_GT(glm::length(modes_x[0]), 0.01f);  // the drive moved it
    }
  }
}

}  // namespace
