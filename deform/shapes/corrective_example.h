#pragma once
// Computed corrective examples (issue 26; ALGORITHMS.md 8.2). This is the
// project's addition to the paper, whose examples are only sculpted by hand:
// at an example pose the change dQ of the patch's free control points is
// computed so the region gets back what the global layer lost there, then
// stored like any sculpted example (4.3: D_e = A^-1 dQ in the control points'
// frames) and interpolated over theta by the pose-space RBF.
//
// The region's posed points, as the pipeline builds them (patch_layer.h:
// the layer adds P(Q) - P(G)):
//   x_v(dQ) = G_v + beta_v (P_{G+dQ}(u_v, v_v) - P_G(u_v, v_v))    bound vertices
//   x_v     = G_v                                                   other region vertices
// with G_v the globally skinned vertex, P_Q(u,v) = s_Q(u,v) + d n_Q(u,v) and
// beta_v its border fade. Linearised (the normal's turn ignored):
//   dx_v = beta_v sum_c a_vc dq_c,   a_vc = N_i(u_v) N_j(v_v).
//
// kRest: the region follows its bind shape carried rigidly by the bones:
// each bound vertex's bind point p_v by the palette matrix T_v of its most
// weighted skin joint (one driving bone for the whole region would drag the
// half on the other side of the joint along with it: spikes at a bent elbow):
//   min (1/#B) sum_v |x_v(dQ) - T_v p_v|^2 + mu/#F |L2 dQ|^2
// (L2 = second differences of the control-grid change along u and v), solved
// by Gauss-Newton: the linearised problem `iterations` times, re-evaluating x.
//
// kVolume: the region's signed volume against the driving joint's centre c
// (divergence theorem over the region's triangles, x_0..x_2 counter-clockwise
// seen from outside):
//   V(x) = sum_t (1/6) dot(x_t0 - c, cross(x_t1 - c, x_t2 - c))
// returns to its bind value V_b (V is invariant under the rigid motion of all
// points and c, so V_b is what a rigidly carried region would have). Each
// Gauss-Newton step takes the smoothest change meeting the linearised volume:
//   min dQ^T H dQ  s.t.  g . dQ = V_b - V(x),   H = I + mu' L2^T L2,
//   g_c = sum_v beta_v a_vc dV/dx_v,   dV/dx_t0 = (1/6) cross(x_t1 - c, x_t2 - c) (cyclic)
//   => dQ = H^-1 g (V_b - V) / (g^T H^-1 g).
// Cross-sections' areas are not fitted (TODO(26): per-ring area rows).
//
// Setup only (rig load), never per frame: cost one skinning of the mesh, a
// sparse factorisation of #F unknowns and `iterations` re-evaluations of the
// #B bound vertices.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/mesh.h"
#include "deform/patch/patch_layer.h"
#include "deform/shapes/example_shapes.h"
#include "base/error.h"

namespace deform {

enum class CorrectiveKind : std::uint8_t {
  kRest,    // back toward the bind shape carried by the driving bone
  kVolume,  // back to the bind volume of the region
};

struct CorrectiveOptions {
  std::vector<std::uint8_t> free_mask{};  // #C, 1 = free; empty: all but the boundary ring
  double smoothness = 0.05;               // mu of the rest fit's second-difference term
  double volume_smoothness = 10.0;        // mu' of H = I + mu' L2^T L2 for the volume step
  int iterations = 3;                     // Gauss-Newton steps, 1..20
};

// What the correction achieved, in the kind's measure: kVolume, the region
// volume (model units^3) at bind, at the pose before and after; kRest, the
// RMS distance (model units) of the bound vertices from their rigid targets
// (0 at bind) before and after.
struct CorrectiveReport {
  double bind_value = 0.0;
  double before = 0.0;
  double after = 0.0;
};

struct CorrectedExample {
  SculptedExample shape;      // displacement (#C, local frames) and world_delta (#C, model)
  CorrectiveReport report;
  int driving_skin_joint = -1;  // index into the mesh's skin joints
};

// The skin joint of `vertex` with the largest weight (first on ties).
int DominantSkinJoint(const SkinWeights& weights, int vertex);

// The skin joint (index into mesh.skin_joints) with the largest total weight
// over the patch's control points; -1 when the patch has none.
int DrivingSkinJoint(const PatchSetup& patch, int num_skin_joints);

// V(x) above over the triangles `subset` of `triangles`, positions #V.
double RegionVolume(std::span<const glm::dvec3> positions, std::span<const glm::uvec3> triangles,
                    std::span<const int> subset, const glm::dvec3& centre);
// dV/dx_v for every vertex (#V, zero off the subset).
void RegionVolumeGradient(std::span<const glm::dvec3> positions,
                          std::span<const glm::uvec3> triangles, std::span<const int> subset,
                          const glm::dvec3& centre, std::span<glm::dvec3> gradient);

// Computes the corrective example of `patch` at `pose` (same conventions as
// SculptExample). Errors: palette sizes, an empty region, no free point,
// iterations out of range (kInvalidArgument); a volume with no sensitivity
// (kInvalidArgument: the region's triangles are all fixed or degenerate).
base::Result<CorrectedExample> CorrectExample(const PatchSetup& patch, const SkinnedMesh& mesh,
                                              const SkinningPose& pose, CorrectiveKind kind,
                                              const CorrectiveOptions& options = {});

}  // namespace deform
