#pragma once
// Dual quaternion skinning (Kavan, Collins, Zara, O'Sullivan 2007), the modern
// baseline of ALGORITHMS.md 2.2:
//
//   b = sum_i s_i w_i dq_i,   s_i = -1 if dot(real(dq_i), real(dq_m)) < 0 else +1,
//   m = the most-weighted influence (antipodality fix relative to it),
//   r = real(b) / |real(b)|, d = dual(b) / |real(b)|,
//   v' = r v r* + t,  t = 2 (r.w d.xyz - d.w r.xyz + r.xyz x d.xyz),
//   n' = r n r*.
//
// The palette must be rigid (rotation + translation): BuildDualQuatPalette drops
// any scale. Same job shape and splitting rules as SkinningJob: any split of
// the per-vertex spans gives bit-identical output. Scalar code (DQS is the
// comparison baseline here, not the production path).

#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"

namespace deform {

// A unit dual quaternion real + eps dual for the rigid map p -> R p + t:
// real = rotation R, dual = 0.5 * (0, t) * real.
struct DualQuat {
  glm::quat real{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat dual{0.0f, 0.0f, 0.0f, 0.0f};
};

// Converts #S rigid skin matrices (model_from_bind, see BuildSkinningPalette)
// to dual quaternions. The rotation is taken from the matrix's 3x3 part with
// its columns normalized (scale is discarded). Sizes must match.
[[nodiscard]] base::JobStatus BuildDualQuatPalette(std::span<const glm::mat4> model_from_bind,
                                                   std::span<DualQuat> palette);

struct DqsJob {
  // Inputs.
  std::span<const DualQuat> palette;           // #S, from BuildDualQuatPalette
  int influences = 4;                          // 1..kMaxInfluences
  std::span<const std::uint16_t> joint_indices;  // #V x influences, each < #S (not checked here)
  std::span<const float> joint_weights;        // #V x influences, >= 0, sum 1 per vertex
  std::span<const glm::vec3> rest_positions;   // #V, bind space
  std::span<const glm::vec3> rest_normals;     // #V or empty

  // Outputs.
  std::span<glm::vec3> positions;  // #V, model space
  std::span<glm::vec3> normals;    // #V unit length; required iff rest_normals is set

  [[nodiscard]] base::JobStatus Validate() const;  // sizes and ranges only
  [[nodiscard]] base::JobStatus Run() const;       // Validate(), then skin; never allocates
};

}  // namespace deform
