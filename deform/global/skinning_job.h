#pragma once
// SSD (skeletal subspace deformation, linear blend skinning), ALGORITHMS.md 2.1:
//
//   v' = sum_i w_i * (model_from_bind[j_i] * v)        (positions, w = 1)
//   n' = sum_i w_i * (model_from_bind[j_i] * n)        (normals, w = 0, not renormalized)
//
// computed as one blended 3x4 matrix per vertex, M = sum_i w_i * model_from_bind[j_i]
// (the fourth row of each palette matrix is ignored), then v' = M v. Normals use
// the same blended matrix, which is exact for rigid and uniformly scaled
// palettes; a non-uniform scale would need the inverse transpose (not done).
//
// The job works on whatever sub-range of vertices its spans cover: to split
// work across threads, give each thread the same palette and matching
// sub-spans of the per-vertex arrays. Each vertex is computed independently, in
// the same order of operations, so any split gives bit-identical output.
//
// On x86-64 the inner loop uses SSE2 (part of the x86-64 baseline, so the
// default build stays portable), and AVX for the matrix blend when the CPU
// reports it at run time and deform/simd.h's cap allows it (a function compiled
// with target("avx"), bit-identical to the SSE2 path; -DPATCHSKIN_NO_AVX_SKINNING
// removes it). Elsewhere, or with
// the CMake option PATCHSKIN_SKINNING_SIMD=OFF, a scalar loop with the same
// order of operations runs. Never -march=native, never FMA
// (the project builds with -ffp-contract=off), so results match across paths.

#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include "deform/mesh.h"
#include "base/error.h"

namespace deform {

struct SkinningJob {
  // Inputs.
  // #S skin matrices, model_from_bind[s] = model_from_joint[skin_joints[s]] *
  // joint_from_bind[s] (see BuildSkinningPalette). Only rows 0..2 are read.
  std::span<const glm::mat4> model_from_bind;
  // Influences per vertex, 1..kMaxInfluences (4 and 8 are the common cases;
  // the loop is specialised for every count).
  int influences = 4;
  // #V x influences skin-joint indices (SkinWeights::joints), each < #S. The
  // indices are not read by Validate(): check them once with CheckSkinWeights.
  std::span<const std::uint16_t> joint_indices;
  // #V x influences weights (SkinWeights::weights), >= 0, summing to 1 per
  // vertex. With an identity palette the output equals the input bit for bit
  // when the weights sum to exactly 1 in float, added in slot order
  // (NormalizeSkinWeights guarantees that).
  std::span<const float> joint_weights;
  std::span<const glm::vec3> rest_positions;  // #V, bind (model) space
  std::span<const glm::vec3> rest_normals;    // #V, bind space, or empty (no normals)

  // Outputs.
  std::span<glm::vec3> positions;  // #V, model space; may not alias the inputs
  std::span<glm::vec3> normals;    // #V; required iff rest_normals is set, else ignored

  // Sizes and parameter ranges only; reads no array contents.
  [[nodiscard]] base::JobStatus Validate() const;
  // Validate(), then skin every vertex. Never allocates; thread-safe for
  // disjoint outputs.
  [[nodiscard]] base::JobStatus Run() const;
};

// The instruction set SkinningJob uses on this machine under the current
// SetSimdCap (deform/simd.h): "avx", "sse2" or "scalar".
const char* SkinningSimdPath();

// Fills the #S skinning palette of `mesh`: model_from_bind[s] =
// model_from_joint[mesh.skin_joints[s]] * mesh.joint_from_bind[s].
// model_from_joint has #J entries (LocalToModelJob output). Returns
// kSizeMismatch if the output is not #S long or mesh arrays disagree, and
// kOutOfRange if a skin joint is not a valid index into model_from_joint.
[[nodiscard]] base::JobStatus BuildSkinningPalette(std::span<const glm::mat4> model_from_joint,
                                                   const SkinnedMesh& mesh,
                                                   std::span<glm::mat4> model_from_bind);

// Checks skin weights once, before any job runs: influences in
// 1..kMaxInfluences, array sizes #V x influences (num_vertices if >= 0),
// indices < num_skin_joints, weights finite, >= 0 and summing to 1 within
// 1e-4 per vertex.
[[nodiscard]] base::Status CheckSkinWeights(const SkinWeights& weights, int num_skin_joints,
                                            int num_vertices = -1);

// Makes each vertex's weights sum to exactly 1.0f when added in slot order
// (as the skinning jobs add them): sorts each vertex's slots by decreasing
// weight (joint indices move with their weights), divides by the sum, then
// sets the last non-zero weight to 1 minus the float sum of the others. A
// vertex whose weights are all zero (or not finite) gets weight 1 on slot 0.
void NormalizeSkinWeights(SkinWeights& weights);

}  // namespace deform
