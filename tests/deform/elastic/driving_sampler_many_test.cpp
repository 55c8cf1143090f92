// KinematicsDrivingSampler::SampleMany (deform/elastic/internal/driving_sampler.h)
// against Sample on each time in order, and both against
// mocap::SampleJointKinematics: the same bits for RK4 stage-time batches as
// ModalRunner::Steps asks for them, batches that cross frame intervals and the
// clip's ends, frame-exact and nearly frame-exact times, times outside the clip
// or not finite, odd batch lengths, the slerp's three branches (turning,
// nearly equal, the shorter-arc flip) and a zero-length blend; with the AVX
// pairs (where the CPU has AVX) and without.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "support/fast_turns_clip.h"
#include "deform/elastic/internal/driving_sampler.h"
#include "mocap/kinematics.h"
#include "mocap/synthetic.h"

namespace {

using deform::DrivingFrame;
using deform::internal::KinematicsDrivingSampler;

bool SameBits(const DrivingFrame& a, const DrivingFrame& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

DrivingFrame FromKinematics(const mocap::JointKinematics& k) {
  return {k.rotation, k.local_linear_acceleration, k.local_angular_velocity,
          k.local_angular_acceleration};
}

// Batches of times in the order ModalRunner::Steps samples them: for up to 8
// steps from `start` (t = t + h), t + h/2 then t + h.
std::vector<double> StageTimes(double start, double h, int steps) {
  std::vector<double> times;
  double t = start;
  for (int i = 0; i < steps; ++i, t = t + h) {
    times.push_back(t + 0.5 * h);
    times.push_back(t + h);
  }
  return times;
}

// Every batch goes through SampleMany on one sampler and Sample, time by time,
// on another; each result is also checked against SampleJointKinematics.
// `turning`: how many samples were on a turning joint (the slerp branch).
void ExpectManySameAsSample(const std::vector<mocap::JointKinematics>& kin, int nj,
                            double frame_time_s, const std::vector<std::vector<double>>& batches,
                            int& turning) {
  turning = 0;
  for (int j = 0; j < nj; ++j) {
    KinematicsDrivingSampler many(kin, nj, j, frame_time_s);
    KinematicsDrivingSampler many_sse2(kin, nj, j, frame_time_s);
    KinematicsDrivingSampler one(kin, nj, j, frame_time_s);
    for (const std::vector<double>& times : batches) {
      // Garbage in the output: SampleMany must not read it.
      std::vector<DrivingFrame> out(times.size() + 1), out_sse2(times.size() + 1);
      std::memset(static_cast<void*>(out.data()), 0xff, out.size() * sizeof(DrivingFrame));
      std::memset(static_cast<void*>(out_sse2.data()), 0xff, out.size() * sizeof(DrivingFrame));
      const DrivingFrame sentinel = out.back();
      many.SampleMany(times, out.data());  // AVX pairs where the CPU has AVX
      many_sse2.SampleMany(times, out_sse2.data(), /*allow_avx=*/false);
      EXPECT_TRUE(SameBits(out.back(), sentinel)) << "wrote past the batch";
      EXPECT_TRUE(SameBits(out_sse2.back(), sentinel)) << "wrote past the batch";
      for (std::size_t i = 0; i < times.size(); ++i) {
        const DrivingFrame d = one.Sample(times[i]);
        ASSERT_TRUE(SameBits(out[i], d)) << "joint " << j << " t " << times[i] << " #" << i;
        ASSERT_TRUE(SameBits(out_sse2[i], d)) << "joint " << j << " t " << times[i] << " #" << i;
        mocap::JointKinematics k;
        ASSERT_TRUE(mocap::SampleJointKinematics(kin, nj, j, frame_time_s, times[i], &k));
        ASSERT_TRUE(SameBits(out[i], FromKinematics(k))) << "joint " << j << " t " << times[i];
        turning += glm::length(k.angular_velocity) > 1.0f;
      }
    }
  }
}

// Stage-time batches from before the start to past the end of the clip, a
// batch of frame times and of times within a few ulps of them, one of clamped
// and non-finite times, batches of every length up to 17 and one that hops
// between intervals (each hop prepares its interval again).
std::vector<std::vector<double>> Batches(double frame_time_s, double end_s) {
  const double h = 1.0 / 240;
  std::vector<std::vector<double>> batches;
  for (double start = -0.02; start < end_s + 0.02; start = start + 8 * h) {
    batches.push_back(StageTimes(start, h, 8));
  }
  std::vector<double> on_frames, near_frames;
  for (double t = 0.0; t <= end_s; t += frame_time_s) {
    on_frames.push_back(t);
    near_frames.push_back(std::nextafter(t, 0.0));
    near_frames.push_back(std::nextafter(t, end_s + 1.0));
    near_frames.push_back(t + 1e-12);
    near_frames.push_back(t - 1e-9 * frame_time_s);
  }
  batches.push_back(on_frames);
  batches.push_back(near_frames);
  const double inf = std::numeric_limits<double>::infinity();
  batches.push_back({-1.0, 0.0, end_s, end_s + 0.3, std::nan(""), 0.5 * frame_time_s, inf, -inf,
                     1e300, -0.0, 1e-300, end_s - 0.25 * frame_time_s});
  for (std::size_t n = 1; n <= 17; ++n) {
    std::vector<double> times =
        StageTimes(0.37 * end_s + static_cast<double>(n) * frame_time_s, h, 9);
    times.resize(n);
    batches.push_back(times);
  }
  // Weights a few float ulps apart in each interval: sine arguments that
  // differ only in their low bits.
  std::vector<double> close_weights;
  for (double frame = 0.0; frame + 1.0 < end_s / frame_time_s; frame += 1.0) {
    for (int ulps = 0; ulps < 5; ++ulps) {
      close_weights.push_back((frame + 0.3 + 3e-8 * ulps) * frame_time_s);
    }
  }
  batches.push_back(close_weights);
  std::vector<double> hops;
  for (int i = 0; i < 12; ++i) {
    hops.push_back((2.25 + (i % 3) * 1.5) * frame_time_s);
    hops.push_back((5.75 - (i % 2) * 3.0) * frame_time_s);
  }
  batches.push_back(hops);
  return batches;
}

int ExpectSameForMotion(const mocap::Skeleton& skel, const mocap::Motion& motion) {
  const std::vector<mocap::JointKinematics> kin = mocap::ComputeKinematics(skel, motion).value();
  int turning = 0;
  ExpectManySameAsSample(kin, skel.num_joints(), motion.frame_time_s,
                         Batches(motion.frame_time_s, motion.duration_s()), turning);
  return turning;
}

TEST(KinematicsDrivingSampler, SampleManyMatchesSampleOnAWalkAt30Fps) {
  const mocap::Skeleton skel = mocap::MakeHumanoidSkeleton();
  EXPECT_GT(ExpectSameForMotion(skel, mocap::MakeWalkMotion(skel).value()), 500);
}

TEST(KinematicsDrivingSampler, SampleManyMatchesSampleOnAJumpAt120Fps) {
  const mocap::Skeleton skel = mocap::MakeHumanoidSkeleton();
  mocap::JumpOptions options;
  options.frame_time_s = 1.0 / 120;
  EXPECT_GT(ExpectSameForMotion(skel, mocap::MakeJumpMotion(skel, options).value()), 500);
}

// One joint turning 0.9 rad per frame with every other quaternion negated (the
// shorter-arc flip), then a stretch of identical frames (the nearly-equal lerp)
// and two zero quaternions (a glitch: the blend has length 0, glm's identity).
TEST(KinematicsDrivingSampler, SampleManyMatchesSampleOnFastTurnsAndSignFlips) {
  std::vector<mocap::JointKinematics> kin = test_clips::FastTurnsClip();
  kin[36].rotation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
  kin[37].rotation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
  const double frame_time_s = 1.0 / 30;
  int turning = 0;
  ExpectManySameAsSample(kin, 1, frame_time_s, Batches(frame_time_s, 39.0 / 30), turning);
  EXPECT_GT(turning, 500);
}

// A one-frame buffer: every time gives that frame.
TEST(KinematicsDrivingSampler, SampleManyOnOneFrameGivesThatFrame) {
  std::vector<mocap::JointKinematics> kin(1);
  kin[0].rotation = glm::angleAxis(0.3f, glm::vec3(0.0f, 1.0f, 0.0f));
  kin[0].local_angular_velocity = glm::vec3(1.0f, 2.0f, 3.0f);
  KinematicsDrivingSampler sampler(kin, 1, 0, 1.0 / 30);
  const std::vector<double> times = StageTimes(-0.01, 1.0 / 240, 8);
  std::vector<DrivingFrame> out(times.size());
  sampler.SampleMany(times, out.data());
  for (const DrivingFrame& d : out) EXPECT_TRUE(SameBits(d, FromKinematics(kin[0])));
}

}  // namespace
