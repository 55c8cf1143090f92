#pragma once
// Retargeting: drive one skeleton (the target, e.g. a glTF character's) with
// the motion of another (the source, e.g. a BVH capture) whose joints carry the
// same names.
//
// Joint matching (MapJointsByName), for every target joint in order:
//   1. a source joint with exactly the same name;
//   2. else one whose *normalized* name is equal, where normalizing lowercases
//      and drops a namespace prefix: everything up to the last ':' or '|'
//      ("mixamorig:LeftArm", "Armature|LeftArm" -> "leftarm") and a leading
//      "mixamorig" (+ digits) with an optional '_' ("mixamorig1_LeftArm").
//   A source joint is used by at most one target joint (first come first
//   served, exact matches first).
//
// Convention (RetargetMotion). Both skeletons are assumed to stand in the same
// rest pose (e.g. both T-poses) in the same world axes (Y up after the BVH's
// Z-up conversion, facing the same way). Each mapped target joint j, driven by
// source joint b, turns in world space by the rotation b has turned from the
// source's rest pose:
//   world_rot_j(f) = [world_rot_b(f) * world_rot_b(rest)^-1] * world_rot_j(rest)
//   local_rot_j(f) = world_rot_parent(j)(f)^-1 * world_rot_j(f)
// For a BVH (identity rest rotations) with the same hierarchy this is the BVH
// local rotation, relative to the BVH rest pose, applied on top of the target's
// bind (rest) local rotation, expressed in the parent's rest frame. Unmapped
// joints keep their rest local transform; translations (bone lengths) and
// scales of the target are kept, except at the root.
// Root translation: the target joint mapped to the source's root (the hips)
// follows the source root's model-space position scaled by the ratio of hip
// heights, where a hip height is the rest-pose height (along +Y) of the root
// above the lowest joint:
//   model_pos_root(f) = hip_height(target) / hip_height(source) * src_root_model(f)
// (then expressed in the root's parent frame at rest). Both characters share
// the world origin and ground, so a capture whose feet touch y = 0 keeps the
// target's feet there; the target root's rest translation is not used.
//
// Required joints: the target joint for the source root, and every unmapped
// target joint with both a mapped ancestor and a mapped descendant (left at
// rest it would break a driven chain). Missing ones are an error naming them.

#include <span>
#include <string>
#include <vector>

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace mocap {

// Lowercase, namespace prefix and "mixamorig" prefix removed (rules above).
std::string NormalizeJointName(std::string_view name);

// For every target joint, the index of the source joint driving it, or -1
// (#J of target). Never fails; see RetargetMotion for the required joints.
std::vector<int> MapJointsByName(const Skeleton& target, const Skeleton& source);

// Rest-pose height (model +Y) of `joint` above the lowest joint of the
// skeleton, in the skeleton's units.
float HipHeight(const Skeleton& skeleton, int joint);

struct RetargetedMotion {
  // The target skeleton with its channels replaced: kQuatX..W on every mapped
  // joint, plus kX/Y/ZPosition (replacing the rest translation) on the root's
  // counterpart; every other joint has no channels (rest transform).
  Skeleton skeleton;
  Motion motion;                   // the source's frames and frame time
  std::vector<int> source_of_target;  // #J of target, see MapJointsByName
  int root = -1;                   // target joint driven by the source root
  float translation_scale = 1.0f;  // hip_height(target) / hip_height(source)
  std::vector<base::Warning> warnings;  // e.g. skin joints left unmapped
};

// How one skeleton drives another, however it was found (by name here, by body
// topology in deform/body/humanoid_map.h, or from a user's joint map).
struct RetargetPlan {
  std::vector<int> source_of_target;  // #J of target: source joint driving it, or -1
  // #J of target, or empty for all identity: a world-space rotation placed between
  // the source's turn and the target's rest, so that rest poses that differ (a
  // T-pose capture on an A-pose character) line up per bone:
  //   world_rot_j(f) = [world_rot_b(f) * world_rot_b(rest)^-1] * align[j] * world_rot_j(rest)
  // Identity reproduces the convention above (source rest = target rest).
  std::vector<glm::quat> align;
  int target_root = -1;   // target joint placed at the source root's position
  int source_root = 0;    // source joint whose model-space position is followed
  float translation_scale = 1.0f;  // target / source lengths, applied to that position
};

// The plan of the convention above: MapJointsByName, hip heights, identity
// alignment. Errors as RetargetMotion's (required joints, zero hip height).
base::Result<RetargetPlan> PlanByName(const Skeleton& target, const Skeleton& source,
                                      const std::string& target_file,
                                      const std::string& source_file,
                                      std::vector<base::Warning>* warnings);

// Runs `plan`: kQuatX..W channels on every mapped joint, kX/Y/ZPosition on
// plan.target_root, which must be mapped (kInvalidArgument otherwise, naming
// `source_file`). Cost: one pose evaluation of the source per frame.
base::Result<RetargetedMotion> ApplyRetargetPlan(const Skeleton& target, const Skeleton& source,
                                                 const Motion& source_motion,
                                                 const RetargetPlan& plan,
                                                 const std::string& source_file);

// Retargets `source_motion` (on `source`) onto `target` (conventions above).
// `target_file` and `source_file` name the files in errors:
// kInvalidArgument "expected joints ... in the motion (matched by name), found
// none for: Spine1, Neck", or a zero source hip height.
base::Result<RetargetedMotion> RetargetMotion(const Skeleton& target, const Skeleton& source,
                                              const Motion& source_motion,
                                              const std::string& target_file,
                                              const std::string& source_file);

}  // namespace mocap
