// PatchControlRotations (example_shapes.h): the rotation A_c each control
// point of a patch moves with, per frame (ALGORITHMS.md 4.3).
//
// The SSD path is shaped for the per-frame budget of issue 6 (the shoulder
// patch: 54 control points, 28 with dS != 0, 21 of them blending three
// bones). Per chunk of control points: the moving ones are listed, each with
// its weighted slots as a bit mask (4 influences: one SSE compare) and its
// kind, 1, 2 or 3+ bones, without a branch per point or slot. Bones are
// converted on first use (once per call). One and two bones take closed
// forms. The blends of three or more bones are summed in slot order in
// double and take Newton's polar iteration (PolarRotationNewton); what it
// refuses takes the SVD. (A table of the
// bones in use, summed per bone for two blends at a time, took fewer
// instructions but made a blend's last bit depend on which other control
// points move: dropped.)
// Measured and dropped: sorting all control points into per-kind lists
// (more instructions for no gain); marking the bones needed with a store per
// slot (a chain of read-modify-writes of the same few bytes).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <emmintrin.h>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/example_shapes.h"
#include "deform/shapes/polar_rotation.h"

namespace deform {
namespace {

// Most skin joints the fast SSD rotation path keeps on the stack.
constexpr std::size_t kMaxFastBones = 256;
// Largest |R^T R - I| entry for a palette matrix to count as a rotation.
constexpr double kRigidTol = 1e-4;
// Control points handled at once (stack arrays of this size; even).
constexpr std::size_t kChunk = 64;

// Set bits of a 4-bit mask (the x86-64 baseline has no popcnt instruction:
// __builtin_popcount is a library call there).
constexpr std::array<std::uint32_t, 16> kBits4 = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
inline std::uint32_t PopCount(std::uint32_t m) {
  std::uint32_t n = 0;
  for (; m != 0; m &= m - 1) ++n;
  return n;
}

constexpr glm::quat kIdentity(1.0f, 0.0f, 0.0f, 0.0f);

}  // namespace

base::JobStatus PatchControlRotations(const PatchSetup& patch, const SkinningPose& pose,
                                      std::span<glm::quat> rotations,
                                      std::span<const glm::vec3> displacement) {
  if (!displacement.empty() && displacement.size() != rotations.size()) {
    return {base::JobStatus::kSizeMismatch, "displacement must be empty or #C"};
  }
  // Q = G + A dS is G whatever A is where dS is exactly zero (A 0 = 0): the
  // identity stands in for A there.
  const auto skip = [&](std::size_t c) {
    return !displacement.empty() && displacement[c] == glm::vec3(0.0f);
  };
  const auto identity_where_skipped = [&](base::JobStatus st) {
    if (!st) return st;
    for (std::size_t c = 0; c < rotations.size(); ++c) {
      if (skip(c)) rotations[c] = kIdentity;
    }
    return st;
  };
  const SkinWeights& w = patch.control_weights;
  if (!pose.dual_quats.empty()) {
    return identity_where_skipped(
        DqsControlRotations(pose.dual_quats, w.influences, w.joints, w.weights, rotations));
  }
  const std::size_t num_skin = pose.model_from_bind.size();
  const int k = w.influences;
  if (k < 1 || k > kMaxInfluences || num_skin < 1 || num_skin > kMaxFastBones ||
      w.joints.size() != rotations.size() * static_cast<std::size_t>(k) ||
      w.weights.size() != w.joints.size()) {
    return identity_where_skipped(
        SsdControlRotations(pose.model_from_bind, k, w.joints, w.weights, rotations));
  }
  // Raw pointers and no byte-sized stores below: a store through an
  // unsigned char may alias anything, which made GCC reload every span and
  // vector pointer inside these loops.
  const float* const weight = w.weights.data();
  const std::uint16_t* const joint = w.joints.data();
  const glm::vec3* const ds = displacement.empty() ? nullptr : displacement.data();
  const auto moves = [ds](std::size_t c) {  // dS_c != 0 (branch-free test)
    if (ds == nullptr) return true;
    const glm::vec3 d = ds[c];
    return !((d.x == 0.0f) & (d.y == 0.0f) & (d.z == 0.0f));
  };
  const auto kk = static_cast<std::size_t>(k);
  // Bone rotations as matrices and quaternions, converted on first use, so
  // once per call and only for the bones the moving control points use.
  std::array<glm::dmat3, kMaxFastBones> bone_matrix;
  std::array<glm::dquat, kMaxFastBones> bone;
  std::array<bool, kMaxFastBones> have;
  std::fill_n(have.begin(), num_skin, false);
  // Converts bone b (< num_skin); false if its palette matrix is not a
  // rotation (scale, shear), which sends the whole patch to the general
  // polar decomposition.
  const auto convert = [&](std::size_t b) {
    const glm::dmat3 r(glm::mat3(pose.model_from_bind[b]));
    const glm::dmat3 rtr = glm::transpose(r) * r;
    double off = 0.0;
    for (int e = 0; e < 3; ++e) {
      for (int f = 0; f < 3; ++f) off = std::max(off, std::abs(rtr[e][f] - (e == f ? 1.0 : 0.0)));
    }
    if (off > kRigidTol || glm::determinant(r) <= 0.0) return false;
    bone_matrix[b] = r;
    bone[b] = glm::normalize(glm::quat_cast(r));
    have[b] = true;
    return true;
  };
  const auto general = [&] {
    return identity_where_skipped(
        SsdControlRotations(pose.model_from_bind, k, w.joints, w.weights, rotations));
  };
  // Per chunk: the moving control points, each one's weighted slots as a
  // bit mask (bit s: slot s of the control point has nonzero weight), and
  // their kinds, 1, 2 or 3+ bones, as three lists.
  std::array<std::uint32_t, kChunk> moving, mask;
  std::array<std::uint32_t, kChunk> one, two, many;  // indices into `moving`
  // sum_b w_b R_b over the weighted slots of moving[j], in double, in slot
  // order from 0 (the order SsdControlRotations and the tests sum in).
  const auto blend_of = [&](std::size_t j) {
    const std::size_t base = moving[j] * kk;
    glm::dmat3 blend(0.0);
    for (std::uint32_t m = mask[j]; m != 0; m &= m - 1) {
      const std::size_t slot = base + static_cast<std::size_t>(__builtin_ctz(m));
      blend += static_cast<double>(weight[slot]) * bone_matrix[joint[slot]];
    }
    return blend;
  };
  for (std::size_t c0 = 0; c0 < rotations.size(); c0 += kChunk) {
    const std::size_t count = std::min(kChunk, rotations.size() - c0);
    // The control points that move, listed without a branch per point; the
    // others keep the identity.
    std::size_t num_moving = 0;
    std::size_t at = c0;
    if (ds != nullptr) {
      // Four at a time: their 12 components' != 0 (NaN included) as bits,
      // three per control point.
      const float* const d = &ds[0].x;
      const __m128 zero = _mm_setzero_ps();
      for (; at + 4 <= c0 + count; at += 4) {
        const int nonzero = _mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(d + 3 * at), zero)) |
                            _mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(d + 3 * at + 4), zero)) << 4 |
                            _mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(d + 3 * at + 8), zero)) << 8;
        for (std::size_t p = 0; p < 4; ++p) {
          rotations[at + p] = kIdentity;
          moving[num_moving] = static_cast<std::uint32_t>(at + p);
          num_moving += ((nonzero >> (3 * p)) & 7) != 0 ? 1 : 0;
        }
      }
    }
    for (; at < c0 + count; ++at) {
      rotations[at] = kIdentity;
      moving[num_moving] = static_cast<std::uint32_t>(at);
      num_moving += moves(at) ? 1 : 0;
    }
    // Their slot masks and kinds, without a branch per slot or point.
    const __m128i sign16 = _mm_set1_epi16(static_cast<short>(0x8000));
    const __m128i last16 = _mm_set1_epi16(static_cast<short>((num_skin - 1) ^ 0x8000));
    std::size_t num_one = 0, num_two = 0, num_many = 0;
    bool beyond = false;
    for (std::size_t j = 0; j < num_moving; ++j) {
      const std::size_t base = moving[j] * kk;
      std::uint32_t m = 0;
      if (kk == 4) {
        // The weights' != 0 (NaN included) as 4 bits at once, and the joints
        // beyond the palette: b > num_skin - 1 as unsigned 16-bit numbers is
        // (b ^ 0x8000) > ((num_skin - 1) ^ 0x8000) as signed ones.
        m = static_cast<std::uint32_t>(
            _mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(weight + base), _mm_setzero_ps())));
        __m128i b4;
        std::memcpy(&b4, joint + base, 8);  // 4 joints into the low half
        const __m128i over = _mm_cmpgt_epi16(_mm_xor_si128(b4, sign16), last16);
        const int over4 = _mm_movemask_ps(_mm_castsi128_ps(_mm_unpacklo_epi16(over, over)));
        beyond |= (m & static_cast<std::uint32_t>(over4)) != 0;
      } else {
        for (std::size_t i = 0; i < kk; ++i) {
          const bool used = weight[base + i] != 0.0f;
          m |= static_cast<std::uint32_t>(used) << i;
          beyond |= used & (joint[base + i] >= num_skin);
        }
      }
      mask[j] = m;
      const std::uint32_t n = (m & 0xf) == m ? kBits4[m] : PopCount(m);
      const auto jj = static_cast<std::uint32_t>(j);
      one[num_one] = jj, two[num_two] = jj, many[num_many] = jj;
      num_one += n == 1 ? 1 : 0;  // n == 0 (no weight at all; CheckSkinWeights
      num_two += n == 2 ? 1 : 0;  // rejects it): no turn
      num_many += n >= 3 ? 1 : 0;
    }
    if (beyond) return {base::JobStatus::kOutOfRange, "joint index beyond the palette"};
    for (std::size_t i = 0; i < num_one; ++i) {
      const std::size_t j = one[i];
      const std::size_t b = joint[moving[j] * kk + static_cast<std::size_t>(__builtin_ctz(mask[j]))];
      if (!have[b] && !convert(b)) return general();
      rotations[moving[j]] = glm::quat(bone[b]);
    }
    for (std::size_t i = 0; i < num_two; ++i) {
      const std::size_t j = two[i], c = moving[j];
      const std::uint32_t m = mask[j];
      const std::size_t s1 = c * kk + static_cast<std::size_t>(__builtin_ctz(m));
      const std::size_t s2 = c * kk + static_cast<std::size_t>(__builtin_ctz(m & (m - 1)));
      const std::size_t b1 = joint[s1], b2 = joint[s2];
      if (!have[b1] && !convert(b1)) return general();
      if (!have[b2] && !convert(b2)) return general();
      const glm::dquat q1 = bone[b1];
      glm::dquat rel = glm::conjugate(q1) * bone[b2];              // R1^T R2 = Rot(a, theta)
      if (rel.w < 0.0) rel = -rel;
      const glm::dvec3 v(rel.x, rel.y, rel.z);                     // sin(theta/2) a
      const double sin2 = glm::dot(v, v);
      const double w1 = weight[s1], w2 = weight[s2];
      // theta from rel = (c, s a), c = cos(theta/2), s = sin(theta/2):
      // sin theta = 2 s c, cos theta = 2 c^2 - 1 (no trigonometric calls).
      const double yc = 2.0 * w2 * rel.w;                          // y = yc s
      const double x = w1 + w2 * (2.0 * rel.w * rel.w - 1.0), y2 = yc * yc * sin2;
      const double rho = std::sqrt(x * x + y2);
      if (sin2 < 1e-24 && rho >= 1e-6) {
        rotations[c] = glm::quat(q1);
        continue;
      }
      if (rho >= 1e-6 && rho + x >= 1e-9) {
        // w1 I + w2 Rot(a, theta) is normal with eigenvalues 1 and w1 + w2 e^(+-i theta)
        // = rho e^(+-i phi), so its orthogonal polar factor is Rot(a, phi); as a
        // quaternion (cos(phi/2), sin(phi/2) a) ~ (rho + x, y a) = (rho + x, yc v),
        // of length sqrt((rho + x)^2 + y^2). q1 is a unit quaternion, so one
        // normalization of the product suffices.
        const glm::dquat turn(rho + x, yc * v);
        const double inv_len = 1.0 / std::sqrt((rho + x) * (rho + x) + y2);
        rotations[c] = glm::quat((q1 * turn) * inv_len);
        continue;
      }
      // Two opposite rotations at (nearly) equal weight: the general path.
      many[num_many++] = static_cast<std::uint32_t>(j);
    }
    // Three or more bones (and the two-bone blends above): the polar factor
    // of sum_b w_b R_b by Newton's iteration; a blend it refuses (det <=
    // kPolarNewtonMinDet: nearly singular or reflecting) by PolarRotation,
    // whose SVD fixes the sign as SsdControlRotations does.
    for (std::size_t i = 0; i < num_many; ++i) {
      const std::size_t j = many[i], base = moving[j] * kk;
      for (std::uint32_t m = mask[j]; m != 0; m &= m - 1) {
        const std::size_t b = joint[base + static_cast<std::size_t>(__builtin_ctz(m))];
        if (!have[b] && !convert(b)) return general();
      }
      const glm::dmat3 blend = blend_of(j);
      glm::dmat3 r;
      if (!PolarRotationNewton(blend, r)) r = PolarRotation(blend);
      rotations[moving[j]] = glm::normalize(glm::quat(glm::quat_cast(r)));
    }
  }
  return base::kJobOk;
}

}  // namespace deform
