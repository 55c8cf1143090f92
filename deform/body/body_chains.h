#pragma once
// A skeleton's body decomposed into chains by topology (never by name), shared by
// the mannequin (one tube per chain) and the SWD rig (one sweep per chain):
//  1. Joints closer than 1e-4 S (S = largest extent of joints and end sites) to their
//     parent merge with it; end sites become leaf points.
//  2. A spine starts at each root toward the child with the most descendants. A root
//     that only positions the body is skipped: one with one child that branches, one
//     animated by position channels alone (or rotation channels the motion never
//     changes, Skeleton::channel_use) above a single-child path that branches (a BVH
//     "World" over a "Reference" over the hips), one whose heavy child the motion
//     pulls away by position channels (hips walking away from a root on the floor),
//     and one on the floor straight under the body it holds. A child the motion pulls
//     away from its parent (an IK target, a prop) is no part of the body, nor is one
//     linked to it by a bone 1.5 times longer than the body's reach (the heaviest
//     path from a spine's start): a camera or prop joint parked metres away. At every
//     branch point a chain continues into the straightest child and each other child
//     starts a new chain whose first point is the branch point. A spine skips children
//     that form a mirror pair (two subtrees with as many points and total bone lengths
//     within 20%: arms, legs) when another child is left, so it runs on to the head or
//     tail whatever the pose (mocapbank's neck starts at the same point as both collars).
//     Side branches reaching less than `min_branch_extent` S are folded into their chain
//     (fingers, eyes).

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "mocap/skeleton.h"

namespace deform {

// A point of the simplified tree: a joint with a bone of non-zero length, a root, or an
// end site.
struct BodyPoint {
  glm::vec3 pos{0.0f};       // model space (of the given rest matrices), model units
  int parent = -1;           // parent point, -1 for roots
  int joint = -1;            // skeleton joint at this point, -1 for an end site
  int bone_joint = -1;       // skeleton joint whose rotation moves the bone parent -> this
  std::vector<int> children;  // child points
  int descendants = 0;        // number of points below this one
};

enum class BodyChainKind { kSpine, kLimb };

struct BodyChain {
  // Tree points from the start (a branch point or a root) to a leaf, >= 2. Bone k runs
  // from points[k] to points[k+1] and turns with points[k+1]'s bone_joint.
  std::vector<int> points;
  BodyChainKind kind = BodyChainKind::kLimb;
  int parent_chain = -1;         // chain holding points[0] (-1 for spines)
  bool folded_branches = false;  // small side branches (fingers) were folded in
  int first_folded = -1;         // index in `points` of the first point that had them
};

struct BodyChains {
  std::vector<BodyPoint> points;  // parents before children
  std::vector<BodyChain> chains;  // spines first, then their branches (parents first)
  float size = 0.0f;              // S: largest extent of the body's points, model units
  // #J: 1 when the joint gets a part of the body (its point is a spine's start
  // or below one), 0 when it only positions the body: a root passed over by
  // rule 2 (Bandai's joint_Root, left on the floor while the hips walk away)
  // and the joints merged into it. No tube, head or weight may follow such a
  // joint: a vertex bound to it stays where the body was bound.
  std::vector<std::uint8_t> body_part_joints;
};

// Errors: kCountMismatch when the matrix count is not #J, kInvalidArgument for
// broken parent order or a skeleton without any bone of non-zero length, kNonFinite
// for non-finite matrices.
[[nodiscard]] base::Result<BodyChains> BuildBodyChains(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    float min_branch_extent);

// Which joints get a part of a generated body (BodyChains::body_part_joints),
// for bodies built on these chains (the mannequin, others): one decision for
// all of them. Errors: those of BuildBodyChains.
[[nodiscard]] base::Result<std::vector<std::uint8_t>> BodyPartJoints(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
    float min_branch_extent);

}  // namespace deform
