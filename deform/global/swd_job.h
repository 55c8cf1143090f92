#pragma once
// SWD per-frame job: skin vertices (or patch control points) bound to sweep chains
// follow the chains' centre curves and frames (ALGORITHMS.md 2.3):
//   p = c(u) + dR(u) s(u) o              (one sweep; s = 1 unless keep_volume)
//   p = om p_branch + (1 - om) p_trunk   (junction zone, two sweeps)
//   n = dR(u) n0, blended and renormalized in a junction zone
// c, dR and s are evaluated from each chain's SweepPose, recomputed at the start of every
// Run() from the joint rotations and positions (a few quaternion operations per joint), so
// the job holds no state between frames and any split of the vertex range into sub-spans
// gives bit-identical results.

#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/global/sweep.h"
#include "base/error.h"

namespace deform {

// Elliptic scaling of one joint region's cross-sections (Hyun et al.'s ellipses, used for
// bulge control): p = c + dR E0 diag(sa', sb', 1) E0^T o with E0 from the binding's
// section_axis, sa' = 1 + (sa - 1) 4x(1-x) and likewise sb' over the region parameter x,
// so the full scales apply at the joint (x = 1/2) and fade to 1 at the region's ends.
struct SectionScale {
  std::uint16_t chain = 0;  // index into SwdJob::chains
  std::uint16_t joint = 1;  // interior joint k (1..K-1) whose region is scaled
  float scale_a = 1.0f;     // sa > 0, along the section axis e_a
  float scale_b = 1.0f;     // sb > 0, along e_b (e_a x e_b = hat(c0'))
};

// Most chains one SwdJob evaluates (a body uses 5: two arms, two legs, the spine).
inline constexpr int kMaxSwdChains = 16;

struct SwdJob {
  // Inputs.
  std::span<const SweepChain> chains;            // #C <= kMaxSwdChains, from BuildSweepChain
  std::span<const glm::quat> joint_rotations;    // #J dQ_j, rotation of W_j B_j^-1, unit
  std::span<const glm::vec3> joint_positions;    // #J current joint positions, model space
  std::span<const SweepVertexBinding> bindings;  // #V from BindToSweeps (any sub-range)
  std::span<const glm::vec3> rest_normals;       // #V bind-pose unit normals, or empty
  // Scale cross-sections in joint regions by sqrt(l0/l) (smoothly, see SweepScale) so
  // a bent joint keeps roughly its rest volume. Normals are not corrected for it.
  bool keep_volume = false;
  // Optional elliptic scaling per joint region (#S, at most one entry per region; the last
  // wins). Combined with keep_volume by multiplication. Normals are not corrected for it.
  std::span<const SectionScale> section_scales;
  // Outputs.
  std::span<glm::vec3> positions;  // #V model space
  std::span<glm::vec3> normals;    // #V unit; required iff rest_normals is set

  // Sizes, chain joint indices and section scales (chain, interior joint, finite scales
  // > 0) only (kMissingInput, kOutOfRange, kSizeMismatch, kMissingOutput); reads no
  // per-vertex data.
  [[nodiscard]] base::JobStatus Validate() const;
  // Validate(), a pass checking every binding's chain index (kOutOfRange), then the
  // deformation. Never allocates; thread-safe over disjoint output ranges.
  [[nodiscard]] base::JobStatus Run() const;
};

}  // namespace deform
