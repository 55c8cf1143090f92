#pragma once
// Direct manipulation of a B-spline patch and example shapes (ALGORITHMS.md 4;
// minimum-norm formulation of Hsu, Hughes, Kaufman 1992 and Fowler, Bartels 1993).
//
//   one point (4.1):   dq_ij = a_ij / (sum_kl a_kl^2) * D,   a_ij = N_i(u) N_j(v)
//   several (4.2):     dQ_F = H^-1 A^T (A H^-1 A^T + lam I)^-1 R
//                      A = c x |F| basis rows restricted to the free points F,
//                      R = c x 3 stacked (t_r - s(u_r, v_r)),
//                      H = I (pseudo-inverse) or I + mu L^T L (L = grid Laplacian
//                      with the fixed points as zero boundary values: smooth spread)
//   example (4.3):     D_e,ij = dS_ij(theta_e) + A_ij^-1 dQ_ij   (local frame)
//   per frame:         Q_ij = G_ij + A_ij dS_ij(theta)
//
// A_ij is the rotation a control point moves with under the global layer: the
// polar rotation of sum_b W_ij,b dR_b for SSD, the rotation of its blended dual
// quaternion for DQS. Setup code runs in double; the solves use OpenCV inside
// the .cpp only. Control-point arrays are #C = #M x #N, row-major (index i*N + j).

#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <span>
#include <vector>

#include "deform/patch/bspline.h"
#include "deform/global/dqs_job.h"
#include "deform/patch/patch_binding.h"
#include "base/error.h"

namespace deform {

// Dense weights a_ij = N_i(u) N_j(v) of s(u,v) over the control grid: #C values,
// at most (p+1)(q+1) of them nonzero; they sum to 1.
std::vector<double> SurfacePointWeights(const BSplineSurface& surface, double u, double v);

// 4.1: the minimum-norm change of all #C control points that moves s(u,v) by
// `delta` (model units). Every control point is free (no mask).
std::vector<glm::dvec3> MoveSurfacePointMinNorm(const BSplineSurface& surface, double u, double v,
                                                const glm::dvec3& delta);

// What a constraint row fixes at (u,v): the point or a tangent (derivative rows).
enum class ConstraintKind : std::uint8_t {
  kPosition,  // s(u,v), rows a_ij = N_i(u) N_j(v)
  kTangentU,  // ds/du, rows N'_i(u) N_j(v)
  kTangentV,  // ds/dv, rows N_i(u) N'_j(v)
};

// Weights of s (or of ds/du, ds/dv) at (u,v) over the #C control points.
std::vector<double> SurfaceRowWeights(const BSplineSurface& surface, double u, double v,
                                      ConstraintKind kind);
// The current value a row constrains: s, s_u or s_v at (u,v).
glm::dvec3 ConstrainedValue(const BSplineSurface& surface, double u, double v, ConstraintKind kind);

// One constraint: s(u, v) (or its tangent) should become `target` (model space).
struct PointConstraint {
  double u = 0.0;          // parameter in [0,1]
  double v = 0.0;          // parameter in [0,1]
  glm::dvec3 target{0.0};  // desired surface point (model units) or tangent (units per parameter)
  ConstraintKind kind = ConstraintKind::kPosition;
};

// A "keep here" constraint: s(u,v) stays where it is (limits the spread).
PointConstraint KeepHere(const BSplineSurface& surface, double u, double v);

// How the change is spread over the free control points.
enum class SpreadMode : std::uint8_t {
  kPseudoInverse,  // H = I: smallest sum of |dq|^2
  kLaplacian,      // H = I + mu L^T L: smallest change plus mu x its roughness
};

// How A H^-1 A^T is inverted.
enum class ConstraintSolve : std::uint8_t {
  kRegularized,  // lam = 0 if well conditioned, else lam = 1e-9 x mean diagonal
  kSvd,          // pseudo-inverse by SVD (singular values below 1e-12 s_max dropped)
};

struct ManipulationOptions {
  // #C flags, 1 = the control point may move. Empty: all but the boundary ring
  // (the first and last row and column), so the patch border stays put (3.8).
  std::vector<std::uint8_t> free_mask{};
  SpreadMode spread = SpreadMode::kPseudoInverse;
  double laplacian_mu = 4.0;  // mu of H = I + mu L^T L (spec range 1-10), >= 0
  ConstraintSolve solve = ConstraintSolve::kRegularized;
  double max_condition = 1e10;  // above this, kRegularized adds lam I
  // A constraint is unsatisfied when |t_r - s'(u_r, v_r)| exceeds this x the
  // control-point diagonal after the solve.
  double satisfied_tol_rel = 1e-6;
};

struct ManipulationResult {
  std::vector<glm::dvec3> delta;  // #C control-point changes dQ (model space); 0 where fixed
  std::vector<double> residual;   // #c |t_r - s'(u_r, v_r)| after the change, model units
  std::vector<int> unsatisfied;   // indices of constraints left above the tolerance
  double condition = 0.0;         // 2-norm condition number of A H^-1 A^T
  double lambda = 0.0;            // regularisation used (0 when none)
};

// 4.2: solves all constraints together. Fails on an empty list, parameters
// outside [0,1] or non-finite targets, a mask of the wrong size or with no
// free point, or a negative mu. Coincident or too many constraints do not
// fail: they are regularised (or pseudo-inverted) and listed in `unsatisfied`.
base::Result<ManipulationResult> SolvePointConstraints(const BSplineSurface& surface,
                                                       std::span<const PointConstraint> constraints,
                                                       const ManipulationOptions& options = {});

// A bound skin vertex to move: its binding (u, v, d) (patch_binding.h) and the
// requested displacement.
struct VertexEdit {
  double u = 0.0, v = 0.0;  // binding parameters in [0,1]
  double d = 0.0;           // signed distance along n(u,v), model units
  glm::dvec3 delta{0.0};    // requested move of the vertex, model units
};

// The edit of mesh vertex `mesh_vertex` from its record in `binding`. Fails
// when the vertex is not bound to this patch.
base::Result<VertexEdit> MakeVertexEdit(const PatchBinding& binding, int mesh_vertex,
                                        const glm::dvec3& delta);

// Moves bound vertices p = s(u,v) + d n(u,v) by their deltas (4.2, last
// paragraph): the surface points are first sent to s + D, then up to
// `iterations` times the residual (p + D) - (s' + d n') is solved for again
// (the normal turns as the surface moves). `keep` adds "keep here"
// constraints. The result's residual and unsatisfied entries refer to the
// vertices (then the keep constraints), measured on p, not on s.
base::Result<ManipulationResult> MoveBoundVertices(const BSplineSurface& surface,
                                                   std::span<const VertexEdit> edits,
                                                   const ManipulationOptions& options = {},
                                                   int iterations = 4,
                                                   std::span<const PointConstraint> keep = {});

// The orthogonal polar factor of m (the rotation nearest m in the Frobenius
// norm, U V^T of its SVD with the sign of the last singular vector flipped if
// needed so the determinant is +1).
glm::dmat3 PolarRotation(const glm::dmat3& m);
// The same factor always by the SVD (OpenCV), the reference the faster
// iterations (PolarRotation's Newton, PolarRotationNewton) are tested against.
glm::dmat3 PolarRotationSvd(const glm::dmat3& m);

// 4.3, SSD: A_c = PolarRotation(sum_b W_c,b R_b), R_b the 3x3 part of the
// palette matrix model_from_bind[b]. `joint_indices` / `joint_weights` are
// #C x influences control-point skin weights (ALGORITHMS.md 3.7). Writes #C
// unit quaternions. kSizeMismatch / kOutOfRange on bad sizes or influences;
// the indices are not checked (as SkinningJob).
[[nodiscard]] base::JobStatus SsdControlRotations(std::span<const glm::mat4> model_from_bind,
                                                  int influences,
                                                  std::span<const std::uint16_t> joint_indices,
                                                  std::span<const float> joint_weights,
                                                  std::span<glm::quat> rotations);

// 4.3, DQS: A_c = the normalized real part of the blended dual quaternion
// (antipodality fixed relative to the most-weighted influence, as DqsJob).
[[nodiscard]] base::JobStatus DqsControlRotations(std::span<const DualQuat> palette, int influences,
                                                  std::span<const std::uint16_t> joint_indices,
                                                  std::span<const float> joint_weights,
                                                  std::span<glm::quat> rotations);

// 4.3: the example displacement in the local frames,
// D_e,c = current_ds[c] + A_c^-1 world_delta[c]. current_ds = dS(theta_e) (#C,
// local; zero for a new example), world_delta = dQ (#C, model space). Writes #C.
[[nodiscard]] base::JobStatus StoreExampleDisplacement(std::span<const glm::quat> rotations,
                                                       std::span<const glm::vec3> current_ds,
                                                       std::span<const glm::dvec3> world_delta,
                                                       std::span<glm::vec3> example);

// Per frame: Q_c = G_c + A_c dS_c(theta) (ALGORITHMS.md 0, step 2 without the
// elastic term); where dS_c is exactly (0,0,0), Q_c = G_c without reading A_c
// (PatchControlRotations writes the identity there). Never
// allocates; any split of the #C arrays gives the same bits.
struct PoseSpaceApplyJob {
  // Inputs.
  std::span<const glm::vec3> global{};        // #C control points G after the global layer (model)
  std::span<const glm::quat> rotations{};     // #C rotations A (unit)
  std::span<const glm::vec3> displacement{};  // #C dS(theta) in the local frames (PoseSpaceJob)
  // Output.
  std::span<glm::vec3> control{};  // #C Q (model); may alias `global`

  [[nodiscard]] base::JobStatus Validate() const;
  [[nodiscard]] base::JobStatus Run() const;
};

}  // namespace deform
