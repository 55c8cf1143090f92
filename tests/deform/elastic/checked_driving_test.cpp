// The elastic layer's input checks (deform/elastic/internal/checked_driving.h): a NaN or
// Inf in any of a driving frame's 13 floats, or a zero or overflowing rotation,
// gives the bind frame at rest and one count; finite values pass unchanged
// (however large, but for the |a| clamp), and each check is counted once per sample.

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "deform/elastic/internal/checked_driving.h"
#include "deform/elastic/internal/stage_forcing.h"
#include "deform/elastic/mass_spring.h"
#include "support/mass_spring_networks.h"

namespace {

using deform::DrivingFrame;
using deform::internal::CheckedDriving;
using deform::internal::SampleChecks;

DrivingFrame Ordinary() {
  return DrivingFrame{glm::normalize(glm::quat(0.9f, 0.2f, -0.3f, 0.1f)), glm::vec3(50.0f, -20.0f, 5.0f),
                      glm::vec3(0.5f, 1.0f, -0.25f), glm::vec3(3.0f, -2.0f, 1.0f)};
}

bool SameBits(const DrivingFrame& a, const DrivingFrame& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

struct Fixture {
  deform::MassSpringNetwork net;
  deform::MassSpringState state;
  DrivingFrame next;  // what the callback returns
  std::function<DrivingFrame(double)> drive;
  deform::MassSpringStepJob job;
  Fixture() : net(testsupport::CurvedGridNetwork(4, 4)) {
    net.bind_rotation = glm::normalize(glm::quat(0.8f, 0.0f, 0.6f, 0.0f));
    state.Resize(net);
    drive = [this](double) { return next; };
    job = {.network = &net, .state = &state, .driving = &drive};
  }
};

TEST(CheckedDriving, EveryNonFiniteFieldGivesTheBindFrame) {
  const float values[] = {std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity()};
  Fixture f;
  CheckedDriving driving(f.job);
  int expected = 0;
  for (int field = 0; field < 13; ++field) {
    for (const float bad : values) {
      SCOPED_TRACE(testing::Message() << "float " << field << " = " << bad);
      f.next = Ordinary();
      std::memcpy(reinterpret_cast<float*>(&f.next) + field, &bad, sizeof bad);
      DrivingFrame out;
      SampleChecks checks;
      driving.Sample(0.1, out, checks);
      ++expected;
      EXPECT_TRUE(checks.non_finite);
      EXPECT_FALSE(checks.clamped);
      EXPECT_TRUE(SameBits(out, DrivingFrame{f.net.bind_rotation}));
      EXPECT_EQ(f.state.counters.non_finite_inputs, expected);
    }
  }
  EXPECT_EQ(f.state.counters.acceleration_clamps, 0);
}

TEST(CheckedDriving, LargeFiniteValuesPassAndOnlyTheAccelerationIsClamped) {
  Fixture f;
  CheckedDriving driving(f.job);
  const float max_accel = f.net.params.max_acceleration_mps2 * f.net.params.units_per_metre;
  for (int field = 4; field < 13; ++field) {  // the three vectors (the rotation: below)
    SCOPED_TRACE(testing::Message() << "float " << field);
    f.next = Ordinary();
    const float big = 1e18f;  // |a|^2 stays finite (with FLT_MAX it is Inf and a becomes 0)
    std::memcpy(reinterpret_cast<float*>(&f.next) + field, &big, sizeof big);
    DrivingFrame out;
    SampleChecks checks;
    driving.Sample(0.1, out, checks);
    EXPECT_FALSE(checks.non_finite);
    const bool acceleration = field < 7;
    EXPECT_EQ(checks.clamped, acceleration);
    if (acceleration) {
      EXPECT_NEAR(glm::length(out.linear_acceleration), max_accel, 1e-3f * max_accel);
      EXPECT_TRUE(SameBits(DrivingFrame{out.rotation, f.next.linear_acceleration,
                                        out.angular_velocity, out.angular_acceleration},
                           f.next));
    } else {
      EXPECT_TRUE(SameBits(out, f.next));
    }
  }
  // A rotation whose |q|^2 overflows, and a zero one: taken as non-finite.
  for (const glm::quat q : {glm::quat(3e19f, 0.0f, 0.0f, 0.0f), glm::quat(0.0f, 0.0f, 0.0f, 0.0f)}) {
    f.next = Ordinary();
    f.next.rotation = q;
    DrivingFrame out;
    SampleChecks checks;
    driving.Sample(0.1, out, checks);
    EXPECT_TRUE(checks.non_finite);
    EXPECT_TRUE(SameBits(out, DrivingFrame{f.net.bind_rotation}));
  }
  EXPECT_EQ(f.state.counters.non_finite_inputs, 2);
  EXPECT_EQ(f.state.counters.acceleration_clamps, 3);
}

// The batch form (SampleRaw on every time, then CheckAll) gives the frames,
// counts and last-frame checks of Sample on each time, with glitches and large
// accelerations scattered over the batch (the last frame included or not).
TEST(CheckedDriving, CheckAllMatchesSamplingOneAtATime) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const int last_kind : {0, 1, 2}) {  // the last frame: ordinary, NaN, clamped
    SCOPED_TRACE(testing::Message() << "last frame kind " << last_kind);
    const auto make = [nan, last_kind](double t) {
      DrivingFrame d = Ordinary();
      const int i = static_cast<int>(std::lround(t * 100.0));
      d.angular_velocity.y += 0.01f * static_cast<float>(i);
      if (i == 3 || (i == 15 && last_kind == 1)) d.angular_acceleration.z = nan;
      if (i == 5 || (i == 15 && last_kind == 2)) d.linear_acceleration = glm::vec3(0.0f, 3e5f, 0.0f);
      if (i == 9) d.rotation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
      if (i == 11) d.linear_acceleration = glm::vec3(19900.0f, 0.0f, 0.0f);  // just below the clamp
      return d;
    };
    Fixture one, batch;
    one.drive = make;
    batch.drive = make;
    CheckedDriving by_one(one.job), by_batch(batch.job);
    DrivingFrame a[16], b[16];
    SampleChecks checks_one, checks_batch;
    for (int i = 0; i < 16; ++i) {
      by_one.Sample(i / 100.0, a[i], checks_one);
      by_batch.SampleRaw(i / 100.0, b[i]);
    }
    by_batch.CheckAll(b, checks_batch);
    for (int i = 0; i < 16; ++i) EXPECT_TRUE(SameBits(a[i], b[i])) << "frame " << i;
    EXPECT_EQ(one.state.counters.non_finite_inputs, batch.state.counters.non_finite_inputs);
    EXPECT_EQ(one.state.counters.acceleration_clamps, batch.state.counters.acceleration_clamps);
    EXPECT_EQ(batch.state.counters.non_finite_inputs, last_kind == 1 ? 3 : 2);
    EXPECT_EQ(batch.state.counters.acceleration_clamps, last_kind == 2 ? 2 : 1);
    EXPECT_EQ(checks_batch.non_finite, checks_one.non_finite);
    EXPECT_EQ(checks_batch.clamped, checks_one.clamped);
    EXPECT_EQ(checks_batch.non_finite, last_kind == 1);
    EXPECT_EQ(checks_batch.clamped, last_kind == 2);
  }
}

// CheckAll's quick test lets a frame skip the exact checks only when they would
// change nothing: frames at the edges of its bounds (rotations whose |q|^2 is
// near 1e-12 or overflows, accelerations near the clamp along an axis and along
// the diagonal, where each component is smallest for the length, and every
// single field NaN or Inf) give the frames and counts of Sample on each.
std::vector<DrivingFrame> EdgeFrames() {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<DrivingFrame> frames;
  for (float scale = 1e-7f; scale < 1e-5f; scale *= 1.07f) {  // |q| around 1e-6
    DrivingFrame d = Ordinary();
    d.rotation = glm::quat(scale * 0.5f, scale * 0.5f, -scale * 0.5f, scale * 0.5f);
    frames.push_back(d);
    d.rotation = glm::quat(scale, 0.0f, 0.0f, 0.0f);
    frames.push_back(d);
  }
  for (const float big : {1e18f, 1.8e19f, 2e19f, 1e20f, 3e38f}) {  // |q|^2 near overflow
    DrivingFrame d = Ordinary();
    d.rotation = glm::quat(0.5f, big, 0.0f, 0.0f);
    frames.push_back(d);
    d.rotation = glm::quat(big, big, big, big);
    frames.push_back(d);
  }
  const float max_accel = 20000.0f;  // 200 m/s^2 at 100 units per metre
  for (float r = 0.97f; r < 1.03f; r += 0.0005f) {
    for (const glm::vec3 dir : {glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, 1),
                                glm::normalize(glm::vec3(1, -1, 1)),
                                glm::normalize(glm::vec3(1, 1, 0))}) {
      DrivingFrame d = Ordinary();
      d.linear_acceleration = r * max_accel * dir;
      frames.push_back(d);
    }
  }
  for (int field = 0; field < 13; ++field) {
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), inf, -inf}) {
      DrivingFrame d = Ordinary();
      float raw[13];  // the frame's floats in memory order
      static_assert(sizeof raw == sizeof d);
      std::memcpy(raw, &d, sizeof raw);
      raw[field] = bad;
      std::memcpy(&d, raw, sizeof raw);
      frames.push_back(d);
    }
  }
  return frames;
}

TEST(CheckedDriving, CheckAllQuickTestKeepsEveryFrameTheChecksWouldChange) {
  const std::vector<DrivingFrame> frames = EdgeFrames();
  Fixture one, batch;
  const auto replay = [&frames](double t) {
    return frames[static_cast<std::size_t>(std::lround(t * 1000.0))];
  };
  one.drive = replay;
  batch.drive = replay;
  CheckedDriving by_one(one.job), by_batch(batch.job);
  std::vector<DrivingFrame> a(frames.size()), b(frames.size());
  SampleChecks checks_one, checks_batch;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    by_one.Sample(static_cast<double>(i) / 1000.0, a[i], checks_one);
    by_batch.SampleRaw(static_cast<double>(i) / 1000.0, b[i]);
  }
  by_batch.CheckAll(b, checks_batch);
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_TRUE(SameBits(a[i], b[i])) << "frame " << i;
  EXPECT_EQ(one.state.counters.non_finite_inputs, batch.state.counters.non_finite_inputs);
  EXPECT_EQ(one.state.counters.acceleration_clamps, batch.state.counters.acceleration_clamps);
  // The sweeps reach both sides of each bound.
  EXPECT_GT(batch.state.counters.non_finite_inputs, 39 + 10);
  EXPECT_GT(batch.state.counters.acceleration_clamps, 100);
  EXPECT_LT(batch.state.counters.acceleration_clamps, 5 * 120 - 100);
}

// CheckAndCoefficients (the quick test in the AVX coefficients' pass, eight
// frames at a time) against CheckAll then StageCoefficientsOfEach: the same
// frames, counts, last-frame checks and coefficient bits. The edge frames
// above, shifted by 0..7 ordinary frames so that each falls in every lane, and
// ending with an ordinary, a NaN or a clamped frame, at lengths that are and are
// not whole blocks of eight; with AVX allowed and not.
TEST(CheckedDriving, CheckAndCoefficientsMatchesCheckAllThenCoefficients) {
  const std::vector<DrivingFrame> edges = EdgeFrames();
  for (int shift = 0; shift < 8; ++shift) {
    for (const int last_kind : {0, 1, 2}) {  // the last frame: ordinary, NaN, clamped
      for (const std::size_t tail : {std::size_t{0}, std::size_t{3}}) {
        SCOPED_TRACE(testing::Message() << "shift " << shift << " last kind " << last_kind
                                        << " tail " << tail);
        std::vector<DrivingFrame> frames(static_cast<std::size_t>(shift), Ordinary());
        frames.insert(frames.end(), edges.begin(), edges.end());
        while ((frames.size() + 1) % 8 != 0) frames.push_back(Ordinary());
        frames.insert(frames.end(), tail, Ordinary());
        DrivingFrame last = Ordinary();
        if (last_kind == 1) last.angular_velocity.y = std::numeric_limits<float>::quiet_NaN();
        if (last_kind == 2) last.linear_acceleration = glm::vec3(0.0f, 0.0f, -3e5f);
        frames.push_back(last);
        for (const bool avx : {true, false}) {
          Fixture ref, merged;
          CheckedDriving by_ref(ref.job), by_merged(merged.job);
          std::vector<DrivingFrame> a = frames, b = frames;
          std::vector<deform::internal::StageCoefficients> ca(frames.size()), cb(frames.size());
          SampleChecks checks_ref, checks_merged;
          by_ref.CheckAll(a, checks_ref);
          deform::internal::StageCoefficientsOfEach(a, by_ref.forcing(), ca, avx);
          by_merged.CheckAndCoefficients(b, cb, checks_merged, avx);
          ASSERT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(DrivingFrame)), 0);
          ASSERT_EQ(std::memcmp(ca.data(), cb.data(), ca.size() * sizeof(ca[0])), 0);
          EXPECT_EQ(ref.state.counters.non_finite_inputs, merged.state.counters.non_finite_inputs);
          EXPECT_EQ(ref.state.counters.acceleration_clamps, merged.state.counters.acceleration_clamps);
          EXPECT_GT(merged.state.counters.non_finite_inputs, 39 + 10);
          EXPECT_EQ(checks_merged.non_finite, last_kind == 1);
          EXPECT_EQ(checks_merged.clamped, last_kind == 2);
          EXPECT_EQ(checks_merged.non_finite, checks_ref.non_finite);
          EXPECT_EQ(checks_merged.clamped, checks_ref.clamped);
        }
      }
    }
  }
}

}  // namespace
