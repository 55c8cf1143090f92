#pragma once
// Humanoid skeletons matched by body topology, not by joint names, so that a
// capture drives a character whose joints are named differently (CesiumMan's
// "leg_joint_L_1" by CMU's "LeftUpLeg", Bandai's "UpperLeg_L", LAFAN's ...).
//
// FindHumanoid reads one pose of a skeleton through BuildBodyChains:
//   - the spine: the first spine chain (pelvis at its start, head tip at its end);
//   - legs and arms: mirror pairs of limb chains hanging from the spine (equal point
//     counts, lengths within 25%); the pair attached lowest is the legs, the next
//     one up the arms; the chest is the spine point the arms hang from;
//   - landmarks: wrist = where the fingers fold in (else the last joint), ankle =
//     the end of the leg's two longest consecutive bones (thigh, shin); elbow/knee
//     one point before, shoulder/hip two points before;
//   - up = pelvis -> chest; the feet's direction (ankle -> tip) across up is
//     forward, and which limb lies towards up x forward is the left one. Only when
//     the feet give no direction do the names decide ("Left", "_L", "LHip", ...),
//     and failing those the pair order (a guess, reported). The body axes are
//     then left = right hip -> left hip across up, forward = left x up.
// MatchHumanoids maps chain to chain between landmarks: a target bone covering the
// fractions [u0, u1] of its stretch's arc length is driven by the source bone that
// overlaps [u0, u1] the most (so a 4-joint spine and a 2-joint one map end to end). The pelvis follows the
// pelvis. Rest poses are aligned per bone (RetargetPlan::align): the target's body
// frame is turned onto the source's (up, forward), then each bone swung by the
// shortest arc onto its source bone, so a T-pose capture on an A-pose character
// (and the reverse) reproduces the capture's bone directions. The source's
// reference pose is its rest pose when that stands (legs pointing down from the
// pelvis), else the first of 16 evenly sampled frames that does (Bandai's OFFSET
// pose is not a standing pose). The root translation is scaled by the ratio of the
// pelvis heights above the lowest leg point in the two reference poses.
//
// Cost: one BuildBodyChains per skeleton and candidate pose, O(#J^2) at worst.

#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "deform/body/body_chains.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/retarget.h"
#include "mocap/skeleton.h"

namespace deform {

struct HumanoidLimb {
  std::vector<int> points;  // BodyChains point ids, attachment point first
  int root = 0;             // index in points of the shoulder / hip
  int extremity = 0;        // index in points of the wrist / ankle
};

struct Humanoid {
  BodyChains chains;        // of the pose it was found in
  std::vector<int> spine;   // point ids, pelvis first, head tip last
  int chest = 0;            // index in spine the arms hang from
  HumanoidLimb arms[2];     // [0] left, [1] right
  HumanoidLimb legs[2];     // [0] left, [1] right
  glm::vec3 up{0, 1, 0}, forward{0, 0, 1}, left{1, 0, 0};  // model space, unit
  std::string sides;        // "geometry", "names" or "guess"
  bool standing = false;    // both legs point down from the pelvis
};

// `model_from_joint`: #J model matrices of the pose to read. Errors:
// kInvalidArgument "expected a humanoid skeleton ..." naming what is missing, and
// BuildBodyChains's.
[[nodiscard]] base::Result<Humanoid> FindHumanoid(const mocap::Skeleton& skeleton,
                                                  std::span<const glm::mat4> model_from_joint);

// +1 when a joint name reads as left ("LeftArm", "leg_joint_L_1", "LHipJoint"),
// -1 as right, 0 otherwise.
int NameSide(const std::string& name);

// A user's override: target joint name -> source joint name ("" = leave at rest).
using JointMapEntries = std::vector<std::pair<std::string, std::string>>;

struct HumanoidMatch {
  mocap::RetargetPlan plan;
  std::string method;        // "topology" or "names" (when either is no humanoid)
  std::string source_pose;   // "rest" or "frame N": the source pose aligned to the target's rest
  std::string target_sides, source_sides;  // Humanoid::sides of each
  std::vector<base::Warning> warnings;
};

// The plan driving `target` (rest pose) with `source_motion` on `source`; entries
// of `joint_map` replace the matched source joint of their target joint. When
// either skeleton is no humanoid, joints are matched by name (mocap::PlanByName)
// before the overrides. Errors: kInvalidArgument for a joint map naming a joint
// that does not exist (naming `joint_map_file`) and PlanByName's.
[[nodiscard]] base::Result<HumanoidMatch> MatchHumanoids(const mocap::Skeleton& target,
                                                         const mocap::Skeleton& source,
                                                         const mocap::Motion& source_motion,
                                                         const JointMapEntries& joint_map,
                                                         const std::string& target_file,
                                                         const std::string& source_file,
                                                         const std::string& joint_map_file);

}  // namespace deform
