// PolarRotationsNewton (deform/shapes/polar_rotation_lanes.h): every lane path gives
// the scalar PolarRotationNewton's bits (rotation, quaternion and refusal) on
// random, stretched, nearly singular and reflecting blends, for any count, and
// stays within the SVD's polar factor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/direct_manipulation.h"
#include "deform/shapes/polar_rotation.h"
#include "deform/shapes/polar_rotation_lanes.h"
#include "support/random_blends.h"
#include "support/tolerances.h"

namespace {

using testsupport::RandomBlend;
using testsupport::RandomRotation;

using deform::PolarLanesPath;

// R P with P symmetric positive definite, singular values 1, s1, s2: det far
// below 1/8, so Higham's scaling runs in the first iterations.
glm::dmat3 StretchedRotation(std::mt19937& rng, double s1, double s2) {
  const glm::dmat3 r = glm::mat3_cast(RandomRotation(rng));
  const glm::dmat3 v = glm::mat3_cast(RandomRotation(rng));
  return r * v * glm::dmat3(1.0, 0, 0, 0, s1, 0, 0, 0, s2) * glm::transpose(v);
}

// A mix of every kind of input, in an order that puts refused, scaled and
// ordinary blends side by side in the same groups.
std::vector<glm::dmat3> MixedBlends(std::mt19937& rng, int count) {
  std::vector<glm::dmat3> out;
  const glm::dmat3 half_turn = glm::mat3_cast(glm::angleAxis(std::numbers::pi, glm::dvec3(0, 0, 1)));
  const glm::dmat3 tilt = glm::mat3_cast(glm::angleAxis(0.4, glm::dvec3(1, 0, 0)));
  for (int t = 0; t < count; ++t) {
    switch (t % 7) {
      case 0: out.push_back(StretchedRotation(rng, 0.3 + 0.001 * t, 0.01 + 0.0005 * (t % 50))); break;
      case 1: {  // two bones half a turn apart plus eps of a third: det ~ eps^2
        const double eps = std::pow(0.5, t % 20);
        out.push_back(0.5 * (1.0 - eps) * (glm::dmat3(1.0) + half_turn) + eps * tilt);
        break;
      }
      case 2: out.push_back(-RandomBlend(rng, 3, 1.0)); break;            // reflects: det < 0
      default: out.push_back(RandomBlend(rng, 3 + t % 2, t % 3 == 0 ? 2.8 : 1.5)); break;
    }
  }
  out[static_cast<std::size_t>(count / 2)][1][2] = std::numeric_limits<double>::quiet_NaN();
  return out;
}

std::vector<PolarLanesPath> Paths() {
  std::vector<PolarLanesPath> paths = {PolarLanesPath::kScalar, PolarLanesPath::kSse2,
                                       PolarLanesPath::kAuto};
  if (deform::PolarLanesAvxAvailable()) paths.push_back(PolarLanesPath::kAvx);
  return paths;
}

bool SameBits(const glm::dmat3& a, const glm::dmat3& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }
bool SameBits(const glm::quat& a, const glm::quat& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

double MaxEntryDiff(const glm::dmat3& a, const glm::dmat3& b) {
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(a[c][r] - b[c][r]));
  }
  return worst;
}

TEST(PolarRotationsNewton, EveryPathGivesTheScalarIterationsBits) {
  std::mt19937 rng(19);
  const std::vector<glm::dmat3> blends = MixedBlends(rng, 2003);  // not a multiple of 4 or 8
  const std::size_t n = blends.size();
  for (PolarLanesPath path : Paths()) {
    std::vector<glm::dmat3> rot(n, glm::dmat3(7.0));
    std::vector<glm::quat> quat(n, glm::quat(7.0f, 7.0f, 7.0f, 7.0f));
    std::vector<std::uint8_t> ok(n, 9);
    ASSERT_TRUE(deform::PolarRotationsNewton(blends, rot, ok, path, quat));
    int refused = 0;
    for (std::size_t i = 0; i < n; ++i) {
      glm::dmat3 scalar;
      const bool scalar_ok = deform::PolarRotationNewton(blends[i], scalar);
      ASSERT_EQ(ok[i], scalar_ok ? 1 : 0) << "path " << int(path) << " blend " << i;
      if (!scalar_ok) {
        ++refused;
        EXPECT_TRUE(SameBits(rot[i], glm::dmat3(7.0))) << "a refused lane's output is left alone";
        EXPECT_TRUE(SameBits(quat[i], glm::quat(7.0f, 7.0f, 7.0f, 7.0f)));
        continue;
      }
      EXPECT_TRUE(SameBits(rot[i], scalar)) << "path " << int(path) << " blend " << i;
      EXPECT_TRUE(SameBits(quat[i], glm::normalize(glm::quat(glm::quat_cast(scalar)))))
          << "path " << int(path) << " blend " << i;
    }
    // Every reflection (t % 7 == 2) and the NaN are refused, and so are the
    // nearly singular blends (t % 7 == 1, det ~ eps^2 <= 1e-6 for the
    // smaller half of the eps); everything else is accepted.
    for (std::size_t i = 2; i < n; i += 7) EXPECT_EQ(ok[i], 0) << i;
    EXPECT_EQ(ok[n / 2], 0);
    EXPECT_GT(refused, static_cast<int>(n) / 7 + static_cast<int>(n) / 28);
    EXPECT_LT(refused, static_cast<int>(n) / 7 + static_cast<int>(n) / 10);
  }
}

TEST(PolarRotationsNewton, AcceptedBlendsMatchTheSvdPolarFactor) {
  std::mt19937 rng(23);
  const std::vector<glm::dmat3> blends = MixedBlends(rng, 1001);
  std::vector<glm::dmat3> rot(blends.size());
  std::vector<std::uint8_t> ok(blends.size());
  ASSERT_TRUE(deform::PolarRotationsNewton(blends, rot, ok));
  int accepted = 0;
  for (std::size_t i = 0; i < blends.size(); ++i) {
    if (!ok[i]) {
      // Refused only where the scalar refuses: det at or below the threshold
      // (reflections included), or not finite.
      EXPECT_FALSE(glm::determinant(blends[i]) > deform::kPolarNewtonMinDet) << i;
      continue;
    }
    ++accepted;
    EXPECT_LT(MaxEntryDiff(rot[i], deform::PolarRotationSvd(blends[i])),
              testsupport::kPolarFactorTol) << i;
    EXPECT_NEAR(glm::determinant(rot[i]), 1.0, testsupport::kPolarFactorTol) << i;
  }
  EXPECT_GT(accepted, 700);
}

TEST(PolarRotationsNewton, AnyCountAndAnyGroupingGiveTheSameResults) {
  std::mt19937 rng(29);
  const std::vector<glm::dmat3> blends = MixedBlends(rng, 40);
  std::vector<glm::quat> whole(blends.size());
  std::vector<std::uint8_t> whole_ok(blends.size());
  ASSERT_TRUE(deform::PolarRotationsNewton(blends, {}, whole_ok, PolarLanesPath::kAuto, whole));
  for (PolarLanesPath path : Paths()) {
    for (std::size_t first = 0; first < 3; ++first) {
      for (std::size_t count = 0; count <= 17; ++count) {
        // One sentinel past the end must stay untouched.
        std::vector<glm::quat> q(count + 1, glm::quat(5.0f, 5.0f, 5.0f, 5.0f));
        std::vector<std::uint8_t> ok(count + 1, 9);
        ASSERT_TRUE(deform::PolarRotationsNewton(std::span(blends).subspan(first, count), {},
                                                 std::span(ok).first(count), path,
                                                 std::span(q).first(count)));
        for (std::size_t i = 0; i < count; ++i) {
          ASSERT_EQ(ok[i], whole_ok[first + i]) << first << " " << count << " " << i;
          if (ok[i]) {
            EXPECT_TRUE(SameBits(q[i], whole[first + i])) << first << " " << count << " " << i;
          }
        }
        EXPECT_EQ(ok[count], 9);
        EXPECT_TRUE(SameBits(q[count], glm::quat(5.0f, 5.0f, 5.0f, 5.0f)));
      }
    }
  }
}

TEST(PolarRotationsNewton, RejectsMismatchedSpansAndAnUnavailablePath) {
  const std::vector<glm::dmat3> blends(5, glm::dmat3(1.0));
  std::vector<glm::dmat3> rot(4);
  std::vector<glm::quat> quat(6);
  std::vector<std::uint8_t> ok(5), short_ok(4);
  EXPECT_EQ(deform::PolarRotationsNewton(blends, rot, ok).code, mocap::JobStatus::kSizeMismatch);
  EXPECT_EQ(deform::PolarRotationsNewton(blends, {}, short_ok).code, mocap::JobStatus::kSizeMismatch);
  EXPECT_EQ(deform::PolarRotationsNewton(blends, {}, ok, PolarLanesPath::kAuto, quat).code,
            mocap::JobStatus::kSizeMismatch);
  EXPECT_TRUE(deform::PolarRotationsNewton(blends, {}, ok));  // no output but the flags: fine
  for (std::uint8_t f : ok) EXPECT_EQ(f, 1);
  const mocap::JobStatus avx = deform::PolarRotationsNewton(blends, {}, ok, PolarLanesPath::kAvx);
  EXPECT_EQ(avx.ok(), deform::PolarLanesAvxAvailable());
  if (!avx.ok()) {
    EXPECT_EQ(avx.code, mocap::JobStatus::kOutOfRange);
  }
}

}  // namespace

namespace {

float QuatDistance(const glm::quat& a, const glm::quat& b) {
  const glm::quat s = glm::dot(a, b) < 0.0f ? -b : b;
  return glm::length(glm::vec4(a.x - s.x, a.y - s.y, a.z - s.z, a.w - s.w));
}

TEST(PolarRotationsNewtonFloat, TakesWellConditionedBlendsWithinTheFloatTolerance) {
  std::mt19937 rng(31);
  const std::vector<glm::dmat3> blends = MixedBlends(rng, 3001);
  const std::size_t n = blends.size();
  std::vector<glm::quat> reference(n);
  std::vector<std::uint8_t> reference_ok(n);
  ASSERT_TRUE(deform::PolarRotationsNewton(blends, {}, reference_ok, PolarLanesPath::kScalar, reference));
  std::vector<glm::quat> first;
  std::vector<std::uint8_t> first_ok;
  for (PolarLanesPath path : Paths()) {
    if (path == PolarLanesPath::kScalar) {
      std::vector<glm::quat> q(n);
      std::vector<std::uint8_t> ok(n);
      EXPECT_EQ(deform::PolarRotationsNewtonFloat(blends, q, ok, path).code,
                mocap::JobStatus::kOutOfRange);
      continue;
    }
    std::vector<glm::quat> q(n, glm::quat(3.0f, 3.0f, 3.0f, 3.0f));
    std::vector<std::uint8_t> ok(n, 9);
    ASSERT_TRUE(deform::PolarRotationsNewtonFloat(blends, q, ok, path));
    int taken = 0;
    float worst = 0.0f;
    for (std::size_t i = 0; i < n; ++i) {
      const double det = glm::determinant(blends[i]);
      if (!ok[i]) {
        EXPECT_EQ(ok[i], 0);
        EXPECT_TRUE(SameBits(q[i], glm::quat(3.0f, 3.0f, 3.0f, 3.0f))) << i;
        // Refused: outside the float range at the start (or, rarely, later).
        continue;
      }
      ++taken;
      // Taken only where the double iteration converges too, det in range.
      ASSERT_EQ(reference_ok[i], 1) << i;
      EXPECT_GT(det, deform::kPolarFloatMinDet * (1.0 - 1e-6)) << i;
      EXPECT_LE(det, deform::kPolarFloatMaxDet) << i;
      const float d = QuatDistance(q[i], reference[i]);
      worst = std::max(worst, d);
      EXPECT_LT(d, testsupport::kPolarFloatTol) << i << " det " << det;
      EXPECT_NEAR(glm::length(glm::vec4(q[i].x, q[i].y, q[i].z, q[i].w)), 1.0f, 1e-6f);
    }
    // Every well-conditioned random blend is taken (4 of 7 kinds, minus the
    // wide 3- and 4-bone blends with det <= 1/8).
    EXPECT_GT(taken, static_cast<int>(n) * 4 / 7 - static_cast<int>(n) / 10) << int(path);
    std::printf("float lanes, path %d: %d of %zu taken, worst %.3g\n", int(path), taken, n,
                static_cast<double>(worst));
    // The same bits whatever the path (AVX 8 lanes, SSE 4 lanes).
    if (first.empty()) {
      first = q, first_ok = ok;
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(ok[i], first_ok[i]) << i;
        if (ok[i]) {
          EXPECT_TRUE(SameBits(q[i], first[i])) << i;
        }
      }
    }
  }
}

TEST(PolarRotationsNewtonFloat, AnyCountGivesTheSameResults) {
  std::mt19937 rng(37);
  const std::vector<glm::dmat3> blends = MixedBlends(rng, 40);
  std::vector<glm::quat> whole(blends.size());
  std::vector<std::uint8_t> whole_ok(blends.size());
  ASSERT_TRUE(deform::PolarRotationsNewtonFloat(blends, whole, whole_ok));
  for (std::size_t first = 0; first < 3; ++first) {
    for (std::size_t count = 0; count <= 17; ++count) {
      std::vector<glm::quat> q(count + 1, glm::quat(5.0f, 5.0f, 5.0f, 5.0f));
      std::vector<std::uint8_t> ok(count + 1, 9);
      ASSERT_TRUE(deform::PolarRotationsNewtonFloat(std::span(blends).subspan(first, count),
                                                    std::span(q).first(count),
                                                    std::span(ok).first(count)));
      for (std::size_t i = 0; i < count; ++i) {
        ASSERT_EQ(ok[i], whole_ok[first + i]) << first << " " << count << " " << i;
        if (ok[i]) {
          EXPECT_TRUE(SameBits(q[i], whole[first + i])) << first << " " << count << " " << i;
        }
      }
      EXPECT_EQ(ok[count], 9);
      EXPECT_TRUE(SameBits(q[count], glm::quat(5.0f, 5.0f, 5.0f, 5.0f)));
    }
  }
  std::vector<glm::quat> q(3);
  std::vector<std::uint8_t> ok(4);
  EXPECT_EQ(deform::PolarRotationsNewtonFloat(std::span(blends).first(4), q, ok).code,
            mocap::JobStatus::kSizeMismatch);
}

// The blends as PolarRotationsNewtonFloatRows takes them: entry e of blend i
// at rows[e * stride + i], rounded to float; the rest NaN (never read).
std::vector<float> Rows(std::span<const glm::dmat3> blends, std::size_t stride) {
  std::vector<float> rows(9 * stride, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < blends.size(); ++i) {
    for (int e = 0; e < 9; ++e) {
      rows[static_cast<std::size_t>(e) * stride + i] = static_cast<float>(blends[i][e / 3][e % 3]);
    }
  }
  return rows;
}

TEST(PolarRotationsNewtonFloatRows, GivesTheFloatIterationsBitsForAnyCountAndStride) {
  std::mt19937 rng(41);
  const std::vector<glm::dmat3> blends = MixedBlends(rng, 60);
  std::vector<PolarLanesPath> paths = {PolarLanesPath::kSse2, PolarLanesPath::kAuto};
  if (deform::PolarLanesAvxAvailable()) paths.push_back(PolarLanesPath::kAvx);
  for (PolarLanesPath path : paths) {
    std::vector<glm::quat> whole(blends.size());
    std::vector<std::uint8_t> whole_ok(blends.size());
    ASSERT_TRUE(deform::PolarRotationsNewtonFloat(blends, whole, whole_ok, path));
    int taken = 0;
    for (std::size_t first = 0; first < 40; first += 13) {
      // Counts below, at and past the lane widths (4 and 8), and strides
      // equal to the count or longer.
      for (std::size_t count = 0; count <= 20; ++count) {
        for (std::size_t stride : {count, count + 3}) {
          const std::vector<float> rows = Rows(std::span(blends).subspan(first, count), stride);
          std::vector<glm::quat> q(count + 1, glm::quat(5.0f, 5.0f, 5.0f, 5.0f));
          std::vector<std::uint8_t> ok(count + 1, 9);
          ASSERT_TRUE(deform::PolarRotationsNewtonFloatRows(rows, std::span(q).first(count),
                                                            std::span(ok).first(count), path));
          for (std::size_t i = 0; i < count; ++i) {
            ASSERT_EQ(ok[i], whole_ok[first + i]) << first << " " << count << " " << i;
            if (ok[i]) {
              ++taken;
              EXPECT_TRUE(SameBits(q[i], whole[first + i])) << first << " " << count << " " << i;
            } else {
              EXPECT_TRUE(SameBits(q[i], glm::quat(5.0f, 5.0f, 5.0f, 5.0f))) << "left alone";
            }
          }
          EXPECT_EQ(ok[count], 9);  // past #N: untouched
          EXPECT_TRUE(SameBits(q[count], glm::quat(5.0f, 5.0f, 5.0f, 5.0f)));
        }
      }
    }
    EXPECT_GT(taken, 400) << int(path);
  }
}

TEST(PolarRotationsNewtonFloatRows, RejectsBadSizesAndTheScalarPath) {
  const std::vector<glm::dmat3> blends(5, glm::dmat3(1.0));
  const std::vector<float> rows = Rows(blends, 5);
  std::vector<glm::quat> q(5);
  std::vector<std::uint8_t> ok(5);
  ASSERT_TRUE(deform::PolarRotationsNewtonFloatRows(rows, q, ok));
  for (const glm::quat& r : q) EXPECT_TRUE(SameBits(r, glm::quat(1.0f, 0.0f, 0.0f, 0.0f)));
  std::vector<glm::quat> six(6);
  std::vector<std::uint8_t> six_ok(6);
  EXPECT_EQ(deform::PolarRotationsNewtonFloatRows(rows, six, six_ok).code,
            mocap::JobStatus::kSizeMismatch);  // stride 5 < 6
  EXPECT_EQ(deform::PolarRotationsNewtonFloatRows(std::span(rows).first(44), q, ok).code,
            mocap::JobStatus::kSizeMismatch);  // not 9 rows
  EXPECT_EQ(deform::PolarRotationsNewtonFloatRows(rows, q, std::span(ok).first(4)).code,
            mocap::JobStatus::kSizeMismatch);
  EXPECT_EQ(deform::PolarRotationsNewtonFloatRows(rows, q, ok, PolarLanesPath::kScalar).code,
            mocap::JobStatus::kOutOfRange);
}

}  // namespace
