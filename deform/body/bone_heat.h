#pragma once
// Automatic skin weights by bone heat (Baran and Popovic 2007, "Automatic rigging and
// animation of 3D characters", section 4), the method behind Blender's "automatic
// weights".
//
// Each joint j's weight w_j over the surface is the equilibrium temperature of a heat
// diffusion in which every vertex i is warmed by the bone nearest it:
//     -Delta w_j + H w_j = H p_j
// Delta: the surface's cotangent Laplacian; H: diagonal, H_ii = c / d(i)^2 with d(i) the
// distance from vertex i to its nearest *visible* bone (the straight segment from the
// vertex to the bone's nearest point stays inside the body), 0 when no bone is visible;
// p_j(i) = 1 when that nearest bone turns with joint j, else 0 (k bones tied: 1/k each,
// H_ii = k c / d^2). Multiplying row i by vertex i's area A_i (a third of its triangles)
// gives the symmetric positive definite system
//     (L + A H) w_j = A H p_j,   L_ik = -(cot a_ik + cot b_ik) / 2,   L_ii = -sum_k L_ik
// whose matrix is the same for every joint: one sparse Cholesky (LDL^T) factorisation,
// then two triangular solves per joint.
//
// Because the cotangent Laplacian is not an M-matrix on obtuse triangles, w may dip a
// little below 0 or above 1: weights are clamped at 0, the `max_influences` largest kept
// and renormalised to sum to 1. A vertex whose weights all vanish gets its nearest bone.
//
// Inputs: a closed mesh, bones (segments with a joint each), and the body's signed
// distance for the visibility test. Cost: O(#V #B) for nearest bones and visibility, one
// factorisation of a #V x #V matrix with ~7 #V non-zeros, and O(#J) solves.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/body/implicit_body.h"
#include "deform/mesh.h"
#include "base/error.h"

namespace deform {

struct BoneHeatOptions {
  float heat = 1.0f;        // c above, > 0 (larger: weights follow the nearest bone more closely)
  int max_influences = 4;   // 1..4
  // A segment from a vertex to a bone counts as inside the body while the body's signed
  // distance stays below this many `inside_tolerance_size` x S.
  float inside_tolerance = 0.004f;
};

struct BoneHeatWeights {
  int influences = 4;
  std::vector<int> joints;     // #V x influences, skeleton joint indices (-1: unused slot)
  std::vector<float> weights;  // #V x influences, >= 0, each row sums to 1, descending
};

// `distance` is the body's signed distance (negative inside), `size` the body size S.
// Errors: kInvalidArgument for options out of range, no bones, or a mesh the Cholesky
// factorisation rejects (not one closed piece).
[[nodiscard]] base::Result<BoneHeatWeights> ComputeBoneHeatWeights(
    const Mesh& mesh, std::span<const BodyBone> bones,
    const std::function<float(const glm::vec3&)>& distance, float size,
    const BoneHeatOptions& options = {});

}  // namespace deform
