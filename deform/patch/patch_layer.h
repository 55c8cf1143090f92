#pragma once
// The patch layer on top of a global deformation (ALGORITHMS.md 0, 3.7, 3.8):
//
//   setup (once):  region -> parametrization -> S x T samples -> M x N fit ->
//                  bind region vertices (u, v, d) -> control-point skin weights
//   per frame:     G_ij = control points carried by the global method (SSD, DQS:
//                  CarryControlPointsJob; SWD: the caller binds them like
//                  vertices and writes G_ij itself)
//                  Q_ij = G_ij + dQ_ij   (dQ = dS + dE, later issues; may be empty)
//                  P    = rebuild of the bound vertices from Q (PatchRebuildJob)
//                  p    = G + sum_k beta_k (P_k - G) / max(1, sum_k beta_k)   (3.8)
//                  then vertex normals from the mesh (ComputeVertexNormals).
//
// beta_k = sm(distance to the border / border_width) fades patch k out towards
// its border in parameter space (BorderWeights), so the layered mesh meets the global one without
// a seam; overlapping patches average. At the rest pose G = P = bind mesh (up
// to the binding error), so the layer is the identity there.
//
// The per-frame API is method-agnostic: ApplyPatchLayer takes the global
// vertex positions and each patch's carried control points as inputs.

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "deform/global/global_skinning.h"
#include "deform/mesh.h"
#include "deform/patch/patch_binding.h"
#include "deform/patch/patch_fit.h"
#include "base/error.h"

namespace deform {

// How one patch is generated from its region (3.2-3.4, 3.8).
struct PatchOptions {
  RegionParametrization::Kind parametrization = RegionParametrization::Kind::kCylinder;
  // Cylinder: axis through axis_origin along axis_direction (model space, bind
  // pose; e.g. the bone into the joint). Plane: axis_direction, if nonzero,
  // aligns u with it (the limb); axis_origin is unused.
  glm::dvec3 axis_origin{0.0};
  glm::dvec3 axis_direction{0.0};
  int samples_u = 8;            // S >= M
  int samples_v = 8;            // T >= N
  int grid_u = 6;               // M, 4..64
  int grid_v = 6;               // N, 4..64
  double smoothing = 0.0;       // least-squares smoothing (FitOptions::smoothing)
  float border_width = 0.1f;    // wb in parameter units, [0, 0.5]; 0 disables the fade
};

// Everything a patch needs per frame, computed once from the bind mesh.
struct PatchSetup {
  std::vector<int> region;              // #R mesh vertex indices (sorted)
  RegionParametrization param;          // the region's map into [0,1]^2
  PatchFit fit;                         // the fitted surface (bind pose, model space)
  BindResult bound;                     // #B binding records and the binding report
  std::vector<glm::vec3> rest_control;  // #M x #N control points q0 (float, model space)
  SkinWeights control_weights;          // #M x #N, 4 influences into the mesh's skin joints
  std::vector<float> border_weight;     // #B beta of each binding record (BorderWeights)

  int num_control() const { return static_cast<int>(rest_control.size()); }
  int num_bound() const { return static_cast<int>(bound.binding.size()); }
};

// Builds a patch over `region` of `mesh` (bind pose). Errors come from the
// parametrization (fold-overs, angular span), sampling, fitting and binding,
// plus kInvalidArgument for options out of range.
base::Result<PatchSetup> BuildPatchSetup(const SkinnedMesh& mesh, std::span<const int> region,
                                         const PatchOptions& options);

// Control-point skin weights (3.7): W_ij,b = sum_v B_ij(u_v, v_v) w_v,b /
// sum_v B_ij(u_v, v_v) over the bound vertices v (B_ij = N_i(u) N_j(v)); a
// control point with a negligible denominator (< 1e-6) takes the weights of
// the region vertex nearest s(xi_i, eta_j). The largest `influences` are kept
// and renormalized (NormalizeSkinWeights), so each row sums to exactly 1.
SkinWeights ControlPointWeights(const SkinnedMesh& mesh, const BSplineSurface& surface,
                                const PatchBinding& binding, std::span<const int> region,
                                int influences = 4);

// The skeleton joint whose bones carry the largest total weight over the
// patch's control points: the default driving joint of its elastic network
// (ALGORITHMS.md 6). The first such joint on a tie; 0 when there is no weight.
int DominantJoint(const SkinnedMesh& mesh, const PatchSetup& patch);

// Border fade beta = sm(min(u, 1-u, v, 1-v) / width); width 0 gives 1.
float BorderWeight(float u, float v, float width);

// Border fade of every binding record [ours, extends 3.8]: a region chosen by
// joint + radius or a vertex list does not fill the parameter square, so the
// distance to the border is the smaller of the distance to the square's edges
// and the (u,v) distance to the nearest boundary record (a bound vertex that
// shares a triangle with an unbound one); beta = sm(distance / width).
// Boundary records get 0, so the layered mesh meets the global one exactly.
// #B weights; width 0 gives all 1.
std::vector<float> BorderWeights(const PatchBinding& binding,
                                 std::span<const glm::uvec3> triangles, int num_vertices,
                                 float width);

// Carries one patch's rest control points by SSD or DQS (pose.dual_quats set),
// like skin vertices (SkinPoints).
struct CarryControlPointsJob {
  // Inputs.
  const PatchSetup* patch = nullptr;
  SkinningPose pose{};  // #S palettes
  // Outputs.
  std::span<glm::vec3> control{};                // #M x #N carried control points G

  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;
};

// Per-frame scratch of ApplyPatchLayer, sized once by Prepare (the frame loop
// then never allocates).
struct PatchLayerScratch {
  std::vector<glm::vec3> control;     // max #M x #N over the patches
  std::vector<glm::vec3> rebuilt;     // max #B
  std::vector<glm::vec3> reference_rebuilt;  // max #B, rebuild of the reference grid
  std::vector<glm::vec3> delta_sum;   // #V, sum_k beta_k (P_k - G)
  std::vector<float> beta_sum;        // #V, sum_k beta_k
  void Prepare(std::span<const PatchSetup> patches, int num_vertices);
};

// One frame of the layer for every patch, in place: `positions` holds the
// global result G (#V) on entry and the blended result on return (normals are
// the caller's: recompute them from the mesh afterwards). carried[k] holds
// patch k's carried control points (#M x #N); displacements is empty or has
// one span per patch, each empty (no displacement) or #M x #N (model space,
// added to the carried points).
// `reference` empty: P_k replaces G as in 3.8. Otherwise one #M x #N grid per
// patch (the control points as the global layer alone carries them), and the
// layer adds only what the local layer changes: p = G + sum_k beta_k
// (P_k(carried + d) - P_k(reference)) / max(1, sum_k beta_k). With nothing to
// add (carried == reference, no displacement) p is G bit for bit, and the
// fit's and the carried weights' own error never reaches the mesh.
// Errors: sizes that disagree (kInvalidArgument).
base::Status ApplyPatchLayer(std::span<const PatchSetup> patches,
                             std::span<const std::span<const glm::vec3>> carried,
                             std::span<const std::span<const glm::vec3>> displacements,
                             PatchLayerScratch& scratch, std::span<glm::vec3> positions,
                             std::span<const std::span<const glm::vec3>> reference = {});

}  // namespace deform
