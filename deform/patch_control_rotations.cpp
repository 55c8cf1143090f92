// PatchControlRotations (example_shapes.h): the rotation A_c each control
// point of a patch moves with, per frame (ALGORITHMS.md 4.3).
//
// The SSD path is shaped for the per-frame budget of issue 6 (the shoulder
// patch: 54 control points, 28 with dS != 0, 21 of them blending three
// bones). Per chunk of control points: the moving ones are listed, each with
// its weighted slots as a bit mask (4 influences: one SSE compare) and its
// kind, 1, 2 or 3+ bones, without a branch per point or slot. Bones are
// converted on first use (once per call). One and two bones take closed
// forms. The blends of three or more bones are summed from a table of the
// bones in use (each blend's weight per table bone, two blends at a time in
// SSE2 doubles) straight into the rows the float Newton lanes load
// (PolarRotationsNewtonFloatRows; within kPolarFloatTol of the double
// iteration, det in (1/8, 8]); what those refuse goes to the double lanes
// (the scalar iteration's bits) on the slot-order double blend, then the SVD.
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

#include "deform/example_shapes.h"
#include "deform/polar_rotation.h"
#include "deform/polar_rotation_lanes.h"

namespace deform {
namespace {

// Most skin joints the fast SSD rotation path keeps on the stack.
constexpr std::size_t kMaxFastBones = 256;
// Largest |R^T R - I| entry for a palette matrix to count as a rotation.
constexpr double kRigidTol = 1e-4;
// Control points handled at once (stack arrays of this size; even).
constexpr std::size_t kChunk = 64;
// Most distinct bones the moving control points of a patch may use for their
// 3+-bone blends to be built in lanes from a dense weight table; past it each
// blend is summed on its own (same values up to the order of the sum).
constexpr std::size_t kMaxTableBones = 8;
// Two doubles, the x86-64 baseline's SSE2 register.
typedef double D2 __attribute__((vector_size(16)));

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

mocap::JobStatus PatchControlRotations(const PatchSetup& patch, const ExamplePose& pose,
                                       std::span<glm::quat> rotations,
                                       std::span<const glm::vec3> displacement) {
  if (!displacement.empty() && displacement.size() != rotations.size()) {
    return {mocap::JobStatus::kSizeMismatch, "displacement must be empty or #C"};
  }
  // Q = G + A dS is G whatever A is where dS is exactly zero (A 0 = 0): the
  // identity stands in for A there.
  const auto skip = [&](std::size_t c) {
    return !displacement.empty() && displacement[c] == glm::vec3(0.0f);
  };
  const auto identity_where_skipped = [&](mocap::JobStatus st) {
    if (!st) return st;
    for (std::size_t c = 0; c < rotations.size(); ++c) {
      if (skip(c)) rotations[c] = kIdentity;
    }
    return st;
  };
  const SkinWeights& w = patch.control_weights;
  if (!pose.dq_palette.empty()) {
    return identity_where_skipped(
        DqsControlRotations(pose.dq_palette, w.influences, w.joints, w.weights, rotations));
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
  // once per call and only for the bones the moving control points use; the
  // first kMaxTableBones of them also join the blends' table, their entries
  // as pairs of equal doubles.
  std::array<glm::dmat3, kMaxFastBones> bone_matrix;
  std::array<glm::dquat, kMaxFastBones> bone;
  std::array<bool, kMaxFastBones> have;
  std::fill_n(have.begin(), num_skin, false);
  std::array<std::array<D2, 9>, kMaxTableBones> table_matrix;
  std::array<std::uint32_t, kMaxFastBones> table_index;  // valid where have[b] && < num_table
  std::size_t num_table = 0;
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
    table_index[b] = static_cast<std::uint32_t>(num_table);
    if (num_table < kMaxTableBones) {
      for (int e = 0; e < 9; ++e) table_matrix[num_table][static_cast<std::size_t>(e)] = r[e / 3][e % 3] + D2{};
      ++num_table;
    }
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
  // The 3+-bone blends, rounded to float and laid out as the float lanes load
  // them (PolarRotationsNewtonFloatRows: entry e of blend i at rows[e][i]),
  // from the weights of the table's bones (table_weight[t][i], 0 where blend
  // i does not use bone t).
  alignas(32) std::array<std::array<float, kChunk>, 9> rows;
  alignas(16) std::array<std::array<double, kChunk>, kMaxTableBones> table_weight;
  std::array<glm::quat, kChunk> quats;
  std::array<std::uint8_t, kChunk> converged;
  std::array<glm::dmat3, kChunk> retry_blends;
  std::array<std::uint32_t, kChunk> retry_control;
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
    for (std::size_t c = c0; c < c0 + count; ++c) {
      rotations[c] = kIdentity;
      moving[num_moving] = static_cast<std::uint32_t>(c);
      num_moving += moves(c) ? 1 : 0;
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
    if (beyond) return {mocap::JobStatus::kOutOfRange, "joint index beyond the palette"};
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
    // of sum_b w_b R_b, written straight into the float lanes' rows as the
    // double sum rounded to float (as PolarRotationsNewtonFloat rounds a
    // dmat3 blend). With the table: the weights per table bone, then two
    // blends at a time, sum_t weight[t] R_t in table order.
    // (The weights are zeroed and summed one double at a time: a wide store
    // (memset) followed by narrow loads of its bytes stalls store
    // forwarding.)
    const std::size_t padded = (num_many + 1) & ~std::size_t{1};
    bool dense = true;  // every bone of these blends is in the table
    for (std::size_t i = 0; i < padded; ++i) {
      for (std::size_t t = 0; t < kMaxTableBones; ++t) table_weight[t][i] = 0.0;
    }
    for (std::size_t i = 0; i < num_many; ++i) {
      const std::size_t base = moving[many[i]] * kk;
      for (std::uint32_t m = mask[many[i]]; m != 0; m &= m - 1) {
        const std::size_t slot = base + static_cast<std::size_t>(__builtin_ctz(m));
        const std::size_t b = joint[slot];
        if (!have[b] && !convert(b)) return general();
        const std::size_t t = table_index[b];
        if (t >= num_table) {
          dense = false;
          continue;
        }
        table_weight[t][i] += static_cast<double>(weight[slot]);
      }
    }
    if (dense) {
      for (std::size_t i = 0; i < padded; i += 2) {
        D2 acc[9] = {};
        for (std::size_t t = 0; t < num_table; ++t) {
          const D2 wt = {table_weight[t][i], table_weight[t][i + 1]};
          for (std::size_t e = 0; e < 9; ++e) acc[e] += wt * table_matrix[t][e];
        }
        for (std::size_t e = 0; e < 9; ++e) {
          rows[e][i] = static_cast<float>(acc[e][0]);
          rows[e][i + 1] = static_cast<float>(acc[e][1]);
        }
      }
    } else {
      for (std::size_t i = 0; i < num_many; ++i) {
        const glm::dmat3 blend = blend_of(many[i]);
        for (int e = 0; e < 9; ++e) rows[static_cast<std::size_t>(e)][i] = static_cast<float>(blend[e / 3][e % 3]);
      }
    }
    (void)PolarRotationsNewtonFloatRows(std::span(&rows[0][0], 9 * kChunk),
                                        std::span(quats.data(), num_many),
                                        std::span(converged.data(), num_many));
    // A blend that is not well conditioned for float (det outside (1/8, 8])
    // takes the double lanes, and one they refuse (det <= kPolarNewtonMinDet:
    // nearly singular or reflecting) PolarRotation, whose SVD fixes the sign
    // as SsdControlRotations always did.
    std::size_t num_retry = 0;
    for (std::size_t i = 0; i < num_many; ++i) {
      const std::size_t c = moving[many[i]];
      if (converged[i]) {
        rotations[c] = quats[i];
        continue;
      }
      retry_blends[num_retry] = blend_of(many[i]);
      retry_control[num_retry++] = static_cast<std::uint32_t>(c);
    }
    if (num_retry == 0) continue;
    (void)PolarRotationsNewton(std::span(retry_blends.data(), num_retry), {},
                               std::span(converged.data(), num_retry), PolarLanesPath::kAuto,
                               std::span(quats.data(), num_retry));
    for (std::size_t i = 0; i < num_retry; ++i) {
      rotations[retry_control[i]] =
          converged[i] ? quats[i]
                       : glm::normalize(glm::quat(glm::quat_cast(PolarRotation(retry_blends[i]))));
    }
  }
  return mocap::kJobOk;
}

}  // namespace deform
