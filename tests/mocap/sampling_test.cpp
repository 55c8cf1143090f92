#include "mocap/sampling.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/joint_angles.h"
#include "support/tolerances.h"

namespace {

using mocap::ChannelType;

// Root with 6 channels (ZXY), one child with ZXY rotation, one child with quaternion channels.
mocap::Skeleton ThreeJoints(
    mocap::PositionChannelMode mode = mocap::PositionChannelMode::kReplaceOffset) {
  mocap::Skeleton s;
  s.names = {"root", "elbow", "quat"};
  s.parents = {mocap::kNoParent, 0, 1};
  s.rest_translations = {glm::vec3(0, 90, 0), glm::vec3(0, 20, 0), glm::vec3(10, 0, 0)};
  s.rest_rotations = {glm::quat(1, 0, 0, 0), glm::angleAxis(0.3f, glm::vec3(0, 1, 0)),
                      glm::quat(1, 0, 0, 0)};
  s.rest_scales.assign(3, glm::vec3(1));
  s.channels.resize(3);
  s.channels[0] = {0,
                   6,
                   {ChannelType::kXPosition, ChannelType::kYPosition, ChannelType::kZPosition,
                    ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}};
  s.channels[1] = {
      6, 3, {ChannelType::kZRotation, ChannelType::kXRotation, ChannelType::kYRotation}};
  s.channels[2] = {
      9, 4, {ChannelType::kQuatX, ChannelType::kQuatY, ChannelType::kQuatZ, ChannelType::kQuatW}};
  s.num_channels = 13;
  s.position_mode = mode;
  return s;
}

// A smooth deterministic motion; angles wander past +-180 so continuity matters.
mocap::Motion Wander(int num_frames, double frame_time_s) {
  mocap::Motion m;
  m.num_frames = num_frames;
  m.num_channels = 13;
  m.frame_time_s = frame_time_s;
  for (int f = 0; f < num_frames; ++f) {
    const float t = static_cast<float>(f * frame_time_s);
    const glm::quat q = glm::angleAxis(1.5f * t, glm::normalize(glm::vec3(1, std::sin(t), 0.5f)));
    const float sign = (f % 3 == 0) ? -1.0f : 1.0f;  // stored signs flip: sampling must not care
    const float row[13] = {10 * t,
                           90 + 3 * std::sin(4 * t),
                           -5 * t,
                           170 + 40 * t,
                           20 * std::sin(2 * t),
                           160 + 30 * std::cos(t),
                           -30 + 120 * t,
                           35 * std::sin(3 * t),
                           10,
                           sign * q.x,
                           sign * q.y,
                           sign * q.z,
                           sign * q.w};
    m.values.insert(m.values.end(), row, row + 13);
  }
  return m;
}

std::vector<mocap::JointTransform> PoseAt(const mocap::Skeleton& s, const mocap::Motion& m,
                                          double t) {
  std::vector<mocap::JointTransform> locals(3), scratch(3);
  EXPECT_TRUE((mocap::SampleLocalsJob{
                   .skeleton = &s, .motion = &m, .time_s = t, .scratch = scratch, .locals = locals})
                  .Run()
                  .ok());
  return locals;
}

float RotationDistance(const glm::quat& a, const glm::quat& b) {
  return 2.0f * std::acos(std::min(1.0f, std::abs(glm::dot(a, b))));
}

TEST(FindFrameBlend, ExactAtFramesClampedOutside) {
  const double dt = 1.0 / 30.0;
  for (int f = 0; f < 10; ++f) {
    const mocap::FrameBlend b = mocap::FindFrameBlend(10, dt, f * dt);
    EXPECT_EQ(b.frame0, f);
    EXPECT_EQ(b.frame1, f);
    EXPECT_EQ(b.weight, 0.0f);
  }
  const mocap::FrameBlend mid = mocap::FindFrameBlend(10, dt, 2.25 * dt);
  EXPECT_EQ(mid.frame0, 2);
  EXPECT_EQ(mid.frame1, 3);
  EXPECT_NEAR(mid.weight, 0.25f, testsupport::kFloatTol);
  EXPECT_EQ(mocap::FindFrameBlend(10, dt, -1.0).frame0, 0);
  EXPECT_EQ(mocap::FindFrameBlend(10, dt, 100.0).frame0, 9);
  EXPECT_EQ(mocap::FindFrameBlend(10, dt, std::nan("")).frame0, 0);
}

TEST(SampleLocalsJob, Validity) {
  const mocap::Skeleton s = ThreeJoints();
  mocap::Motion m = Wander(4, 0.1);
  std::vector<mocap::JointTransform> locals(3), scratch(3), small(2);
  EXPECT_EQ((mocap::SampleLocalsJob{
                 .skeleton = nullptr, .motion = &m, .scratch = scratch, .locals = locals})
                .Validate()
                .code,
            base::JobStatus::kMissingInput);
  EXPECT_EQ(
      (mocap::SampleLocalsJob{.skeleton = &s, .motion = &m, .scratch = small, .locals = locals})
          .Validate()
          .code,
      base::JobStatus::kSizeMismatch);
  EXPECT_EQ(
      (mocap::SampleLocalsJob{.skeleton = &s, .motion = &m, .scratch = scratch, .locals = small})
          .Validate()
          .code,
      base::JobStatus::kSizeMismatch);
  mocap::Motion bad_time = m;
  bad_time.frame_time_s = 0.0;
  EXPECT_EQ((mocap::SampleLocalsJob{
                 .skeleton = &s, .motion = &bad_time, .scratch = scratch, .locals = locals})
                .Validate()
                .code,
            base::JobStatus::kOutOfRange);
  mocap::Motion empty = m;
  empty.num_frames = 0;
  EXPECT_EQ((mocap::SampleLocalsJob{
                 .skeleton = &s, .motion = &empty, .scratch = scratch, .locals = locals})
                .Run()
                .code,
            base::JobStatus::kMissingInput);
  EXPECT_TRUE(
      (mocap::SampleLocalsJob{.skeleton = &s, .motion = &m, .scratch = scratch, .locals = locals})
          .Run()
          .ok());
}

TEST(SampleLocalsJob, ExactAtFrameTimes) {
  const mocap::Skeleton s = ThreeJoints();
  const mocap::Motion m = Wander(12, 1.0 / 30.0);
  std::vector<mocap::JointTransform> expected(3);
  for (int f = 0; f < m.num_frames; ++f) {
    ASSERT_TRUE((mocap::LocalPoseJob{&s, m.frame(f), expected}).Run().ok());
    const auto got = PoseAt(s, m, f * m.frame_time_s);
    for (int j = 0; j < 3; ++j) {
      EXPECT_EQ(got[j].translation, expected[j].translation);
      EXPECT_EQ(got[j].rotation, expected[j].rotation);
    }
  }
}

TEST(SampleLocalsJob, SlerpMidpointAndLerp) {
  mocap::Skeleton s = ThreeJoints();
  mocap::Motion m;
  m.num_frames = 2;
  m.num_channels = 13;
  m.frame_time_s = 0.5;
  // Elbow Z 0 -> 90; quat joint 0 -> 120 degrees about X stored with a negative w
  // (the long way round if taken literally); root x 0 -> 8.
  const glm::quat q1 = glm::angleAxis(glm::radians(120.0f), glm::vec3(1, 0, 0));
  m.values = {0, 90, 0, 0, 0, 0, 0,  0, 0, 0,     0,     0,     1,
              8, 90, 0, 0, 0, 0, 90, 0, 0, -q1.x, -q1.y, -q1.z, -q1.w};
  const auto mid = PoseAt(s, m, 0.25);
  const glm::quat expected_elbow =
      s.rest_rotations[1] * glm::angleAxis(glm::radians(45.0f), glm::vec3(0, 0, 1));
  EXPECT_LT(RotationDistance(mid[1].rotation, expected_elbow), testsupport::kRotationTolRad);
  EXPECT_LT(
      RotationDistance(mid[2].rotation, glm::angleAxis(glm::radians(60.0f), glm::vec3(1, 0, 0))),
      testsupport::kRotationTolRad);
  EXPECT_NEAR(mid[0].translation.x, 4.0f, testsupport::kFloatTol);
  const auto quarter = PoseAt(s, m, 0.125);
  EXPECT_NEAR(quarter[0].translation.x, 2.0f, testsupport::kFloatTol);
  EXPECT_LT(RotationDistance(quarter[2].rotation,
                             glm::angleAxis(glm::radians(30.0f), glm::vec3(1, 0, 0))),
            testsupport::kRotationTolRad);
  // Clamped outside the clip.
  EXPECT_EQ(PoseAt(s, m, 7.0)[0].translation.x, 8.0f);
  EXPECT_EQ(PoseAt(s, m, -7.0)[0].translation.x, 0.0f);
}

void ExpectChannelsNear(const mocap::Motion& a, int fa, const mocap::Motion& b, int fb) {
  for (int c = 0; c < a.num_channels; ++c) {
    const float tol = c >= 9 ? testsupport::kFloatTol * 10 : testsupport::kResampleChannelTol;
    EXPECT_NEAR(a.frame(fa)[c], b.frame(fb)[c], tol) << "channel " << c << " frame " << fa;
  }
}

TEST(Resample, RoundTrip30To120To30) {
  for (auto mode :
       {mocap::PositionChannelMode::kReplaceOffset, mocap::PositionChannelMode::kAddToOffset}) {
    const mocap::Skeleton s = ThreeJoints(mode);
    mocap::Motion m = Wander(31, 1.0 / 30.0);
    // Canonical quaternion signs (w >= 0 at frame 0, then continuous) so the values compare.
    for (int f = 0; f < m.num_frames; ++f) {
      auto row = m.frame(f);
      const float prev_dot = f == 0
                                 ? row[12]
                                 : row[9] * m.frame(f - 1)[9] + row[10] * m.frame(f - 1)[10] +
                                       row[11] * m.frame(f - 1)[11] + row[12] * m.frame(f - 1)[12];
      if (prev_dot < 0)
        for (int c = 9; c < 13; ++c) row[c] = -row[c];
    }
    auto up = mocap::Resample(s, m, 1.0 / 120.0);
    ASSERT_TRUE(up.ok()) << up.error().ToString();
    EXPECT_EQ(up->num_frames, 121);
    EXPECT_EQ(up->num_channels, 13);
    for (int f = 0; f < m.num_frames; ++f) ExpectChannelsNear(m, f, *up, 4 * f);
    auto down = mocap::Resample(s, *up, 1.0 / 30.0);
    ASSERT_TRUE(down.ok());
    ASSERT_EQ(down->num_frames, m.num_frames);
    for (int f = 0; f < m.num_frames; ++f) ExpectChannelsNear(m, f, *down, f);
  }
}

TEST(Resample, EulerChannelsStayContinuous) {
  const mocap::Skeleton s = ThreeJoints();
  mocap::Motion m = Wander(20, 0.1);
  // The elbow spins about Z by 700 degrees over the clip.
  for (int f = 0; f < m.num_frames; ++f) m.frame(f)[6] = 700.0f * static_cast<float>(f) / 19.0f;
  auto up = mocap::Resample(s, m, 0.025);
  ASSERT_TRUE(up.ok());
  for (int f = 1; f < up->num_frames; ++f) {
    for (int c = 3; c < 9; ++c) {
      EXPECT_LT(std::abs(up->frame(f)[c] - up->frame(f - 1)[c]), testsupport::kMaxAngleStepDeg)
          << "channel " << c << " frame " << f;
    }
  }
  EXPECT_NEAR(up->frame(up->num_frames - 1)[6], 700.0f, testsupport::kResampleChannelTol);
}

TEST(Resample, RejectsBadInput) {
  const mocap::Skeleton s = ThreeJoints();
  const mocap::Motion m = Wander(5, 0.1);
  EXPECT_EQ(mocap::Resample(s, m, 0.0).error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(mocap::Resample(s, m, std::nan("")).error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(mocap::Resample(s, m, 1e-12).error().code, base::ErrorCode::kLimitExceeded);
  mocap::Motion short_rows = m;
  short_rows.values.pop_back();
  EXPECT_EQ(mocap::Resample(s, short_rows, 0.05).error().code, base::ErrorCode::kInvalidArgument);
  mocap::Skeleton other = s;
  other.num_channels = 12;
  EXPECT_EQ(mocap::Resample(other, m, 0.05).error().code, base::ErrorCode::kInvalidArgument);
}

// FindFrameBlend (truncation instead of floor and round) against its definition
// with std::floor and std::round: frames, weights and the on-a-frame snapping
// (within 1e-9 frames) the same at stage times, near frame times on either side
// of the snapping threshold, at half frames (round's ties), at and past both
// ends, and for degenerate inputs.
mocap::FrameBlend FloorRoundFrameBlend(int num_frames, double frame_time_s, double time_s) {
  if (num_frames <= 1 || !(frame_time_s > 0.0) || !std::isfinite(time_s) || time_s <= 0.0) {
    return {};
  }
  const double f = time_s / frame_time_s;
  if (f >= num_frames - 1) return {num_frames - 1, num_frames - 1, 0.0f};
  const double nearest = std::round(f);
  if (std::abs(f - nearest) <= 1e-9 * std::max(1.0, nearest)) {
    const int k = static_cast<int>(nearest);
    return {k, k, 0.0f};
  }
  const double base = std::floor(f);
  const int k = static_cast<int>(base);
  return {k, k + 1, static_cast<float>(f - base)};
}

TEST(FindFrameBlend, MatchesTheFloorAndRoundDefinitionBitForBit) {
  std::vector<double> times = {0.0, -0.0, -1.0, 1e-300, std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 80.0);
  for (int i = 0; i < 20000; ++i) times.push_back(u(rng));
  int snapped = 0, blended = 0;
  for (const int num_frames : {0, 1, 2, 3, 121, 9000}) {
    for (const double h : {1.0 / 120, 1.0 / 30, 0.01, 1.0 / 7, 0.0, -1.0}) {
      std::vector<double> all = times;
      for (int k = 0; k <= 200 && k < num_frames + 2; ++k) {
        const double at = k * h;
        for (const double d : {0.0, 1e-12, -1e-12, 0.99e-9, -0.99e-9, 1.01e-9, -1.01e-9, 1e-7}) {
          all.push_back(at + d * h * std::max(1, k));
        }
        all.push_back((k + 0.5) * h);                    // a tie for round
        all.push_back(std::nextafter((k + 0.5) * h, 0.0));
        for (int s = 0; s < 4; ++s) all.push_back(k * h + s * h / 4.0);  // stage times
      }
      for (const double t : all) {
        const mocap::FrameBlend a = FloorRoundFrameBlend(num_frames, h, t);
        const mocap::FrameBlend b = mocap::FindFrameBlend(num_frames, h, t);
        ASSERT_EQ(a.frame0, b.frame0) << num_frames << " frames, h " << h << ", t " << t;
        ASSERT_EQ(a.frame1, b.frame1) << num_frames << " frames, h " << h << ", t " << t;
        ASSERT_EQ(std::memcmp(&a.weight, &b.weight, sizeof a.weight), 0) << "t " << t;
        snapped += a.frame0 == a.frame1 && a.frame0 > 0 && a.frame0 < num_frames - 1;
        blended += a.frame0 != a.frame1;
      }
    }
  }
  EXPECT_GT(snapped, 1000);  // the on-a-frame branch ran inside the clip
  EXPECT_GT(blended, 10000);
}

}  // namespace
