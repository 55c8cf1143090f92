// PatchControlRotations' SSD fast path (deform/patch/patch_control_rotations.cpp):
// the 3+-bone blends give the Newton iteration's bits on the dmat3 blend
// summed in slot order, and stay within the definition (the SVD); the slot masks for 4
// and for 8 influences, the moving control points found four at a time,
// joints beyond the palette, and the patches it hands to the general path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/direct_manipulation.h"
#include "deform/shapes/example_shapes.h"
#include "deform/shapes/polar_rotation.h"
#include "support/random_blends.h"
#include "support/rotations.h"
#include "support/tolerances.h"
#include "support/same_bits.h"

namespace {

using testsupport::QuatDistance;
using testsupport::RandomRotation;

// #C control points with `influences` slots over `bones` skin joints; point
// c has 1 + c % 4 weighted slots (1, 2, 3, 4 bones), the others weight 0 and
// a joint index far beyond any palette (never read).
deform::PatchSetup Patch(std::mt19937& rng, int count, int bones, int influences = 4) {
  deform::PatchSetup p;
  p.rest_control.assign(static_cast<std::size_t>(count), glm::vec3(0.0f));
  p.control_weights.influences = influences;
  std::uniform_int_distribution<int> bone(0, bones - 1);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (int c = 0; c < count; ++c) {
    const int used = 1 + c % 4;
    float w[4] = {0, 0, 0, 0}, sum = 0.0f;
    for (int i = 0; i < used; ++i) sum += (w[i] = 0.1f + uni(rng));
    const int first = bone(rng);
    for (int i = 0; i < influences; ++i) {
      const bool real = i < 4 && w[i] != 0.0f;
      p.control_weights.joints.push_back(
          static_cast<std::uint16_t>(real ? (first + 3 * i) % bones : 60000));
      p.control_weights.weights.push_back(real ? w[i] / sum : 0.0f);
    }
  }
  return p;
}

// Rigid palette of `bones` rotations within `spread_rad` of a common one.
std::vector<glm::mat4> Palette(std::mt19937& rng, int bones, double spread_rad) {
  const glm::dquat base = RandomRotation(rng);
  std::vector<glm::mat4> palette(static_cast<std::size_t>(bones));
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (glm::mat4& m : palette) {
    const glm::dvec3 axis = glm::normalize(RandomRotation(rng) * glm::dvec3(0, 1, 0));
    m = glm::mat4(glm::mat3_cast(glm::quat(base * glm::angleAxis(spread_rad * uni(rng), axis))));
    m[3] = glm::vec4(0.5f, -1.0f, 2.0f, 1.0f);
  }
  return palette;
}

// Control point c's blend sum_b w_b R_b (slot order, double) and its number of bones.
glm::dmat3 Blend(const deform::PatchSetup& p, std::span<const glm::mat4> palette, std::size_t c,
                 int* bones) {
  const auto k = static_cast<std::size_t>(p.control_weights.influences);
  glm::dmat3 blend(0.0);
  *bones = 0;
  for (std::size_t i = c * k; i < (c + 1) * k; ++i) {
    const float w = p.control_weights.weights[i];
    if (w == 0.0f) continue;
    ++*bones;
    blend += static_cast<double>(w) * glm::dmat3(glm::mat3(palette[p.control_weights.joints[i]]));
  }
  return blend;
}

using testsupport::SameBits;

// Every 3+-bone rotation the bits of the Newton iteration on its blend (where
// that accepts the blend), and every rotation within kRotationTol of the SVD
// polar factor (the definition, 4.3).
void ExpectTheDefinition(const deform::PatchSetup& p, std::span<const glm::mat4> palette,
                         std::span<const glm::quat> fast, int* three_plus) {
  for (std::size_t c = 0; c < fast.size(); ++c) {
    int bones = 0;
    const glm::dmat3 blend = Blend(p, palette, c, &bones);
    const glm::quat svd(glm::quat_cast(deform::PolarRotationSvd(blend)));
    EXPECT_LT(QuatDistance(fast[c], svd), testsupport::kRotationTol) << c;
    if (bones < 3) continue;
    ++*three_plus;
    glm::dmat3 r;
    if (deform::PolarRotationNewton(blend, r)) {
      const glm::quat newton = glm::normalize(glm::quat(glm::quat_cast(r)));
      EXPECT_TRUE(SameBits<glm::quat>(std::span(&fast[c], 1), std::span(&newton, 1))) << c;
    }
  }
}

TEST(PatchControlRotations, ThreeBoneBlendsMatchTheIterationsForAnyCount) {
  std::mt19937 rng(23);
  for (int count = 1; count <= 70; count += 3) {  // chunks of 64; 3+-bone counts not multiples of 8
    const deform::PatchSetup p = Patch(rng, count, 5);
    const std::vector<glm::mat4> palette = Palette(rng, 5, 1.6);
    std::vector<glm::quat> fast(static_cast<std::size_t>(count));
    ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
    int three_plus = 0;
    ExpectTheDefinition(p, palette, fast, &three_plus);
    EXPECT_EQ(three_plus, count / 4 * 2 + std::max(0, count % 4 - 2)) << count;  // c % 4 = 2, 3
  }
}

TEST(PatchControlRotations, ManyBonesMatchTheIterations) {
  std::mt19937 rng(29);
  const int bones = 20;
  const deform::PatchSetup p = Patch(rng, 90, bones);
  const std::vector<glm::mat4> palette = Palette(rng, bones, 1.2);
  std::vector<glm::quat> fast(90);
  ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
  int three_plus = 0;
  ExpectTheDefinition(p, palette, fast, &three_plus);
  EXPECT_EQ(three_plus, 44);
}

TEST(PatchControlRotations, EightInfluencesGiveTheFourInfluenceBits) {
  std::mt19937 rng(31);
  std::mt19937 same = rng;
  const deform::PatchSetup four = Patch(rng, 50, 6, 4);
  const deform::PatchSetup eight = Patch(same, 50, 6, 8);  // the same weights, 4 empty slots more
  const std::vector<glm::mat4> palette = Palette(rng, 6, 2.0);
  std::vector<glm::vec3> ds(50, glm::vec3(0.0f, 0.0f, 1.0f));
  for (std::size_t c = 0; c < ds.size(); c += 3) ds[c] = glm::vec3(0.0f);  // some stay still
  std::vector<glm::quat> a(50), b(50);
  ASSERT_TRUE(deform::PatchControlRotations(four, {.model_from_bind = palette}, a, ds));
  ASSERT_TRUE(deform::PatchControlRotations(eight, {.model_from_bind = palette}, b, ds));
  EXPECT_TRUE(SameBits(a, b));
  for (std::size_t c = 0; c < ds.size(); c += 3) EXPECT_EQ(a[c], glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
}

TEST(PatchControlRotations, AWeightedJointBeyondThePaletteIsRefused) {
  std::mt19937 rng(37);
  const std::vector<glm::mat4> palette = Palette(rng, 6, 1.0);
  for (int influences : {4, 8}) {
    // 6 is one past the palette; 40000 is past it as a signed 16-bit number too.
    for (std::uint16_t beyond : {std::uint16_t{6}, std::uint16_t{40000}}) {
      deform::PatchSetup p = Patch(rng, 20, 6, influences);
      std::vector<glm::quat> out(20);
      ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, out));
      const auto slot = static_cast<std::size_t>(influences * 14 + 1);  // c = 14: 3 bones
      ASSERT_NE(p.control_weights.weights[slot], 0.0f);
      p.control_weights.joints[slot] = beyond;
      EXPECT_EQ(deform::PatchControlRotations(p, {.model_from_bind = palette}, out).code,
                base::JobStatus::kOutOfRange)
          << influences << " " << beyond;
      // Not looked at where that control point does not move.
      std::vector<glm::vec3> ds(20, glm::vec3(1.0f, 0.0f, 0.0f));
      ds[14] = glm::vec3(0.0f);
      EXPECT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, out, ds));
    }
  }
}

TEST(PatchControlRotations, ANonRigidPaletteTakesTheGeneralPath) {
  std::mt19937 rng(41);
  deform::PatchSetup p = Patch(rng, 30, 4);
  // SsdControlRotations reads every slot's joint, weighted or not.
  for (std::uint16_t& j : p.control_weights.joints) j = j < 4 ? j : 0;
  std::vector<glm::mat4> palette = Palette(rng, 4, 1.0);
  palette[2][1] *= 1.5f;  // stretched
  std::vector<glm::quat> fast(30), general(30);
  ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
  const deform::SkinWeights& w = p.control_weights;
  ASSERT_TRUE(deform::SsdControlRotations(palette, w.influences, w.joints, w.weights, general));
  EXPECT_TRUE(SameBits(fast, general));
}

TEST(PatchControlRotations, DegenerateBlendsKeepTheirFallbacks) {
  // Two bones half a turn apart: at equal weight the blend is singular (the
  // SVD's answer), at 0.1 / 0.9 the closed form's phi = pi case goes to the
  // float lanes; a third bone at a weight of 1e-4 leaves a nearly singular
  // 3-bone blend for the double lanes or the SVD.
  const glm::dmat3 turn = glm::mat3_cast(glm::angleAxis(std::numbers::pi, glm::dvec3(0, 0, 1)));
  const std::vector<glm::mat4> palette = {
      glm::mat4(1.0f), glm::mat4(glm::mat3(turn)),
      glm::mat4(glm::mat3_cast(glm::angleAxis(0.4f, glm::vec3(1, 0, 0))))};
  deform::PatchSetup p;
  p.rest_control.assign(4, glm::vec3(0.0f));
  p.control_weights.influences = 4;
  const float weights[4][3] = {{0.5f, 0.5f, 0.0f}, {0.1f, 0.9f, 0.0f},
                               {0.49995f, 0.49995f, 1e-4f}, {0.3f, 0.3f, 0.4f}};
  for (const auto& row : weights) {
    for (std::uint16_t b = 0; b < 4; ++b) {
      p.control_weights.joints.push_back(b < 3 ? b : 0);
      p.control_weights.weights.push_back(b < 3 ? row[b] : 0.0f);
    }
  }
  std::vector<glm::quat> fast(4), general(4);
  ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, fast));
  const deform::SkinWeights& w = p.control_weights;
  ASSERT_TRUE(deform::SsdControlRotations(palette, 4, w.joints, w.weights, general));
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_LT(QuatDistance(fast[c], general[c]), testsupport::kRotationTol) << c;
  }
  EXPECT_EQ(fast[0], general[0]);  // both the SVD of the same blend
}

// The moving control points are found four at a time: for every count (whole
// groups of 4 and tails) a control point keeps the identity exactly where
// its dS is (+-0, +-0, +-0), and gets the rotation computed without dS
// elsewhere (NaN and tiny components count as nonzero).
TEST(PatchControlRotations, FindsTheMovingControlPointsForAnyCount) {
  std::mt19937 rng(43);
  for (int count = 1; count <= 13; ++count) {
    const deform::PatchSetup p = Patch(rng, count, 5);
    const std::vector<glm::mat4> palette = Palette(rng, 5, 1.0);
    std::vector<glm::vec3> ds(static_cast<std::size_t>(count));
    for (std::size_t c = 0; c < ds.size(); ++c) {
      switch ((c + static_cast<std::size_t>(count)) % 6) {
        case 0: ds[c] = glm::vec3(0.0f); break;
        case 1: ds[c] = glm::vec3(-0.0f, 0.0f, -0.0f); break;
        case 2: ds[c] = glm::vec3(0.0f, 0.0f, 1e-38f); break;
        case 3: ds[c] = glm::vec3(0.0f, NAN, 0.0f); break;
        case 4: ds[c] = glm::vec3(-2.0f, 0.0f, 0.0f); break;
        default: ds[c] = glm::vec3(0.3f, 0.1f, -0.2f); break;
      }
    }
    std::vector<glm::quat> all(ds.size()), masked(ds.size());
    ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, all));
    ASSERT_TRUE(deform::PatchControlRotations(p, {.model_from_bind = palette}, masked, ds));
    for (std::size_t c = 0; c < ds.size(); ++c) {
      const bool still = ds[c].x == 0.0f && ds[c].y == 0.0f && ds[c].z == 0.0f;
      const glm::quat expected = still ? glm::quat(1.0f, 0.0f, 0.0f, 0.0f) : all[c];
      EXPECT_TRUE(SameBits<glm::quat>(std::span(&masked[c], 1), std::span(&expected, 1)))
          << count << " " << c;
    }
  }
}

}  // namespace
