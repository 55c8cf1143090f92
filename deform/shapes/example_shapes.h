#pragma once
// Example shapes of a patch (ALGORITHMS.md 4.2, 4.3, 5): the setup step that
// turns edits sculpted at an example pose into the displacement the pose-space
// RBF interpolates, and the fitted pose space one patch carries per frame.
//
//   at example pose theta_e (dynamics off, no other example applied):
//     G      = the patch's rest control points carried by the global layer
//     dQ     = minimum-norm change of the free control points of s(G) that
//              moves each edited bound vertex p = s(u,v) + d n(u,v) (or
//              surface point s(u,v)) by its requested world move (4.2)
//     D_e,c  = A_c^-1 dQ_c          (A_c: rotation control point c moves with)
//   per frame:
//     Q_c = G_c + A_c dS_c(theta),  dS = RBF over {(0, 0)} + {(theta_e, D_e)}
//
// At theta_e the RBF is exact, so Q = G + dQ and the edited vertex lands where
// it was asked to (up to the rebuild's float round-off). Storing D in the
// control points' own frames keeps the shape attached to the limb however the
// body is turned (4.3).

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "deform/shapes/brush_edit.h"
#include "deform/shapes/direct_manipulation.h"
#include "deform/global/global_skinning.h"
#include "deform/mesh.h"
#include "deform/patch/patch_layer.h"
#include "deform/shapes/pose_space.h"
#include "base/error.h"

namespace deform {

// One requested move at an example pose: a bound skin vertex, or a surface
// point s(u,v) of the patch.
struct ExampleEdit {
  int vertex = -1;          // mesh vertex index (must be bound to the patch), or -1: `uv` is used
  glm::dvec2 uv{0.0};       // surface point parameters in [0,1]^2 when vertex < 0
  glm::dvec3 move{0.0};     // requested displacement, model units (finite)
  // false: `move` is given in the bind pose's frame and turned with the body
  // (the vertex's skinning rotation, PolarRotation(sum_b w_b R_b); a surface
  // point uses its control points' rotations weighted by N_i(u) N_j(v));
  // true: `move` is a world (model-space) vector at the example pose.
  bool world_frame = false;
  // > 0: a brush (brush_edit.h): the point moves by `move` and drags the
  // surface around it with a smooth falloff over this radius (parameter
  // units). 0: the plain minimum-norm edit (4.2).
  double radius = 0.0;
  base::FileLoc loc{};  // where it was defined (rig file field path), for messages
};

// A sculpted example's displacement and how well the solve met the edits.
struct SculptedExample {
  std::vector<glm::vec3> displacement;  // #C D_e in the control points' local frames
  std::vector<glm::dvec3> world_delta;  // #C dQ (model space) at the example pose
  double max_residual = 0.0;            // max over edits of |missed move|, model units
  double condition = 0.0;               // condition number of the constraint system
  std::vector<base::Warning> warnings;  // edits left unsatisfied (coincident, too many)
};

// Smallest border fade beta (3.8) an edited vertex may have: the patch layer
// blends p = G + beta (P - G), so the rebuilt vertex is asked to move by
// move / beta for the visible vertex to move by `move`; closer to the border
// that would take an unbounded change.
inline constexpr float kMinEditableBorderWeight = 0.05f;

// 4.2 + 4.3: sculpts one example of `patch` (built on `mesh`) at `pose`.
// Vertex edits are solved together (MoveBoundVertices, `iterations` passes
// for the turning normal); each is scaled by 1 / beta of its vertex so the
// blended vertex moves by exactly `move` when the patch does not overlap
// another. Errors (kInvalidArgument, at the edit's loc): no edits, a vertex
// out of range, not bound to the patch or too close to its border (beta <
// kMinEditableBorderWeight), (u,v) outside [0,1]^2, a non-finite move; palette
// sizes that disagree with the mesh (kInvalidArgument).
// When any edit has a radius > 0 the example is solved as brush strokes
// (SolveBrushStrokes: field fit + smoothness, every edit's surface point
// s(u,v) moved by its move as a heavy row; a vertex's offset d n is then not
// re-solved for the turning normal); without one, exactly as before.
base::Result<SculptedExample> SculptExample(const PatchSetup& patch, const SkinnedMesh& mesh,
                                            const SkinningPose& pose,
                                            std::span<const ExampleEdit> edits,
                                            const ManipulationOptions& options = {},
                                            int iterations = 4);

// The rotations A_c (#C unit quaternions) the control points of `patch` move
// with under the global layer: DqsControlRotations when pose.dual_quats is
// set; otherwise the SSD polar rotation of sum_b W_c,b R_b (4.3), the same
// rotation SsdControlRotations gives (to round-off, ~1e-12 before the cast to
// float) but faster: in closed form for a control point with one or two
// bones (with R1^T R2 = Rot(a, theta),
// polar(w1 R1 + w2 R2) = R1 Rot(a, atan2(w2 sin theta, w1 + w2 cos theta))),
// by Newton's polar iteration (PolarRotationNewton) for three or more, on
// the blend summed in slot order in double, as SsdControlRotations sums it.
// Blends with det <= kPolarNewtonMinDet (reflecting or nearly singular), and
// a palette that is not rigid, take PolarRotation / SsdControlRotations.
// Defined in patch_control_rotations.cpp.
//
// `displacement` (optional, #C or empty): the dS(theta) these rotations will
// turn (PoseSpaceJob's output). Where it is exactly (0,0,0), A is not
// computed and the identity is written: Q = G + A dS is then G for any
// rotation A, so PoseSpaceApplyJob's result is the same, and the bones only
// such control points use are not even converted. Control points that no
// example moves (by default the boundary ring, which direct manipulation
// keeps fixed) have dS exactly 0 at every pose.
// kSizeMismatch on a `displacement` of another size; kOutOfRange on a
// weighted joint index beyond the palette (rotations then unspecified).
// Never allocates.
[[nodiscard]] base::JobStatus PatchControlRotations(const PatchSetup& patch,
                                                    const SkinningPose& pose,
                                                    std::span<glm::quat> rotations,
                                                    std::span<const glm::vec3> displacement = {});

// What one patch needs per frame for dS: which joints make theta and the
// fitted interpolant. A default-constructed value (no model) means the patch
// has no examples.
struct PatchPoseSpace {
  PoseFeatureSpec features{};  // theta of this patch (5.1)
  RbfModel model{};            // fitted over rest + the examples (num_centres 0: none)

  bool active() const { return model.num_centres > 0; }
};

}  // namespace deform
