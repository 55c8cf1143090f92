// PatchControlRotations (example_shapes.h): the rotation A_c each control
// point of a patch moves with, per frame (ALGORITHMS.md 4.3).
//
// The SSD path is shaped for the per-frame budget of issue 6 (the shoulder
// patch: 54 control points, 28 with dS != 0, 21 of them blending three
// bones): the bones are converted once per call, one and two bones take
// closed forms, and the blends of three or more bones are batched for
// Newton's polar iteration in float SIMD lanes (polar_rotation_lanes.h;
// within 1e-6 of the double iteration for the blends it takes, det in
// (1/8, 8]), then in double lanes (the scalar iteration's bits) for the
// rest, then the SVD. (Sorting all control points into per-kind index lists
// first, to avoid data-dependent branches, was measured slower: more
// instructions for no gain; only the moving ones are listed.)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

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
// Control points handled at once (stack arrays of this size).
constexpr std::size_t kChunk = 64;

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
  if (k < 1 || k > kMaxInfluences || num_skin > kMaxFastBones ||
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
  // Bone rotations as matrices and quaternions, converted once per call and
  // only for the bones the moving control points use.
  std::array<glm::dmat3, kMaxFastBones> bone_matrix;
  std::array<glm::dquat, kMaxFastBones> bone;
  std::array<bool, kMaxFastBones> have{};
  const auto kk = static_cast<std::size_t>(k);
  // The slots of control point c with nonzero weight, in slot order; returns
  // their number.
  const auto nonzero_slots = [&](std::size_t c, std::array<std::size_t, kMaxInfluences>& slots) {
    std::size_t n = 0;
    for (std::size_t slot = c * kk; slot < (c + 1) * kk; ++slot) {
      slots[n] = slot;
      n += weight[slot] != 0.0f ? 1 : 0;
    }
    return n;
  };
  std::array<std::uint32_t, kChunk> moving;
  std::array<glm::dmat3, kChunk> blends;
  std::array<glm::quat, kChunk> quats;
  std::array<std::uint8_t, kChunk> converged;
  std::array<std::size_t, kChunk> blend_control;
  std::array<std::size_t, kMaxInfluences> slots{};
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
    // The bones these control points use, marked without a branch per slot.
    std::array<bool, kMaxFastBones> needed{};
    bool beyond = false;
    for (std::size_t j = 0; j < num_moving; ++j) {
      const std::size_t c = moving[j];
      for (std::size_t slot = c * kk; slot < (c + 1) * kk; ++slot) {
        const std::size_t b = joint[slot];
        const bool used = weight[slot] != 0.0f, inside = b < num_skin;
        beyond |= used & !inside;
        needed[inside ? b : 0] |= used & inside;
      }
    }
    if (beyond) return {mocap::JobStatus::kOutOfRange, "joint index beyond the palette"};
    // A palette matrix that is not a rotation (scale, shear) sends the whole
    // patch to the general polar decomposition.
    for (std::size_t b = 0; b < num_skin; ++b) {
      if (!needed[b] || have[b]) continue;
      const glm::dmat3 r(glm::mat3(pose.model_from_bind[b]));
      const glm::dmat3 rtr = glm::transpose(r) * r;
      double off = 0.0;
      for (int i = 0; i < 3; ++i) {
        for (int jj = 0; jj < 3; ++jj) off = std::max(off, std::abs(rtr[i][jj] - (i == jj ? 1.0 : 0.0)));
      }
      if (off > kRigidTol || glm::determinant(r) <= 0.0) {
        return identity_where_skipped(
            SsdControlRotations(pose.model_from_bind, k, w.joints, w.weights, rotations));
      }
      bone_matrix[b] = r;
      bone[b] = glm::normalize(glm::quat_cast(r));
      have[b] = true;
    }
    std::size_t batched = 0;
    for (std::size_t j = 0; j < num_moving; ++j) {
      const std::size_t c = moving[j];
      const std::size_t n = nonzero_slots(c, slots);
      if (n == 0) continue;  // no weight at all (CheckSkinWeights rejects it): no turn
      if (n == 1) {
        rotations[c] = glm::quat(bone[joint[slots[0]]]);
        continue;
      }
      if (n == 2) {
        const glm::dquat q1 = bone[joint[slots[0]]];
        glm::dquat rel = glm::conjugate(q1) * bone[joint[slots[1]]];  // R1^T R2 = Rot(a, theta)
        if (rel.w < 0.0) rel = -rel;
        const glm::dvec3 v(rel.x, rel.y, rel.z);                     // sin(theta/2) a
        const double s2 = glm::dot(v, v);
        const double w1 = weight[slots[0]], w2 = weight[slots[1]];
        // theta from rel = (c, s a), c = cos(theta/2), s = sin(theta/2):
        // sin theta = 2 s c, cos theta = 2 c^2 - 1 (no trigonometric calls).
        const double yc = 2.0 * w2 * rel.w;                          // y = yc s
        const double x = w1 + w2 * (2.0 * rel.w * rel.w - 1.0), y2 = yc * yc * s2;
        const double rho = std::sqrt(x * x + y2);
        if (s2 < 1e-24 && rho >= 1e-6) {
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
      }
      // Three or more bones: the polar factor of sum_b w_b R_b, in the batch.
      glm::dmat3 blend(0.0);
      for (std::size_t i = 0; i < n; ++i) {
        blend += static_cast<double>(weight[slots[i]]) * bone_matrix[joint[slots[i]]];
      }
      blends[batched] = blend;
      blend_control[batched++] = c;
    }
    // The polar factors of the blends, in float SIMD lanes; a blend that is
    // not well conditioned for float (det outside (1/8, 8]) takes the double
    // lanes, and one they refuse (det <= kPolarNewtonMinDet: nearly singular
    // or reflecting) PolarRotation, whose SVD fixes the sign as
    // SsdControlRotations always did.
    (void)PolarRotationsNewtonFloat(std::span(blends.data(), batched),
                                    std::span(quats.data(), batched),
                                    std::span(converged.data(), batched));
    std::size_t retry = 0;
    for (std::size_t i = 0; i < batched; ++i) {
      rotations[blend_control[i]] = quats[i];
      blends[retry] = blends[i];
      blend_control[retry] = blend_control[i];
      retry += converged[i] ? 0 : 1;
    }
    if (retry == 0) continue;
    (void)PolarRotationsNewton(std::span(blends.data(), retry), {},
                               std::span(converged.data(), retry), PolarLanesPath::kAuto,
                               std::span(quats.data(), retry));
    for (std::size_t i = 0; i < retry; ++i) {
      rotations[blend_control[i]] =
          converged[i] ? quats[i]
                       : glm::normalize(glm::quat(glm::quat_cast(PolarRotation(blends[i]))));
    }
  }
  return mocap::kJobOk;
}

}  // namespace deform
