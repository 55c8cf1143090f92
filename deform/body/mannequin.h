#pragma once
// The mannequin: a closed, skinned body generated from any skeleton, so that a
// capture without a mesh (BVH) can be previewed and the skinning methods
// compared on it.
//
// Construction (all lengths relative to the body size S = largest extent of
// the joint and end-site positions, so cm, m and inch skeletons look alike):
//  1. Joints closer than 1e-4 S to their parent (zero-length helpers such as
//     CMU's LHipJoint) merge with it; end sites become leaf points.
//  2. The point tree splits into chains by topology, never by name: the spine
//     starts at each root toward the child with the most descendants; at
//     every branch point a chain continues into the straightest child (for a
//     spine, the straightest one not of a mirror pair of limbs; see
//     deform/body/body_chains.h) and each
//     other child starts a new chain (arms, legs, tails). Side branches whose
//     reach is below `min_branch_extent` S (fingers, eyes, small helpers) are
//     folded into a mitten on their chain.
//  3. Each chain becomes one tube swept along a centripetal Catmull-Rom curve
//     through its points, rings of `ring_vertices` vertices, radii per point
//     from the chain length and S (torso wide and flattened front to back,
//     thigh thicker than shin, feet and hands flattened), closed with domed
//     caps. A limb's first bone is left out when it is shorter than the torso
//     radius (pelvis to hip: the torso covers it). A spine with big side
//     chains (a humanoid or quadruped) is a torso ending in an ellipsoid head.
//     The result is a set of closed, outward-oriented components that overlap
//     at shoulders and hips (not one welded surface). The body size S is
//     measured without a root that only positions the body (Bandai's
//     joint_Root on the floor): a root with one child that branches is skipped.
//  4. Weights: a ring on bone k (points k -> k+1) follows the bone's parent
//     joint; around each interior point the weight moves to the next bone with
//     a smoothstep over +-`blend_width` radii (at most 0.45 of either bone), so
//     at most 2 of the 4 influences are non-zero. Weights sum to exactly 1.
//  5. body_chain_coords: per vertex, the chain its tube follows and its ring's
//     chain coordinate (head vertices: chain -1), so SWD can bind each tube
//     to the sweep it was made from instead of guessing by distance.
//
// The result's skin_joints are skeleton joint indices (sorted), joint_from_bind
// the inverses of the given rest matrices, and the mesh is in the model space
// of those matrices.

#include <span>

#include <glm/glm.hpp>

#include "deform/mesh.h"
#include "base/error.h"
#include "mocap/skeleton.h"

namespace deform {

struct MannequinOptions {
  int ring_vertices = 24;            // vertices per tube ring, 8..64
  int target_vertices = 20000;       // aimed-for total vertex count, 10000..40000
  float radius_scale = 1.0f;         // multiplies every radius, 0.25..4
  float min_branch_extent = 0.15f;   // side branches reaching less than this x S are folded in
  float blend_width = 1.0f;          // half-width of a joint's weight blend, in local radii
};

// Builds the mannequin for `skeleton` posed by rest_model_from_joint (#J
// model-space joint matrices, e.g. LocalToModelJob over RestPose, or over the
// first frame when the file's rest pose is not a usable body pose).
// Errors: kCountMismatch when the matrix count is not #J, kInvalidArgument for
// out-of-range options, broken parent order, non-finite matrices or a skeleton
// without any bone of non-zero length, kLimitExceeded when the skeleton has so
// many chains that the mesh would exceed 40000 vertices.
[[nodiscard]] base::Result<SkinnedMesh> BuildMannequin(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    const MannequinOptions& options = {});

}  // namespace deform
