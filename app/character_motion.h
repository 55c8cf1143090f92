#pragma once
// A glTF character driven by a separate BVH motion (`render MODEL.glb --motion
// X.bvh`, or a rig with a glTF "character" and a "motion"): the BVH's joints
// are matched to the skin's joints by body topology (deform/body/humanoid_map.h),
// by name when either skeleton is no humanoid, with a user's joint map on top,
// and its rotations retargeted onto the glTF rest pose (mocap/retarget.h;
// docs/retargeting.md).

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/motion_source.h"
#include "app/character.h"
#include "deform/body/humanoid_map.h"
#include "base/error.h"

namespace app {

// `character` must be a glTF source, `motion` a BVH source (both as loaded by
// LoadMotionSource; load the BVH Y-up so its axes match glTF's). The result
// keeps the glTF's mesh and skeleton, with the retargeted motion in place of
// the glTF's own animation. Errors: kInvalidArgument when the character is not
// a glTF or the motion not a BVH, and RetargetMotion's (unmapped required
// joints, named). The retargeting warnings join the character's.
// `joint_map_file` (may be empty): a JSON object {"glTF joint": "BVH joint" or
// null} read by ReadJointMap, overriding the matched joints. `report`, when
// given, receives how the skeletons were matched.
struct RetargetReport {
  std::string method;       // "topology" or "names"
  std::string source_pose;  // "rest" or "frame N" (the motion pose aligned to the rest pose)
  std::string target_sides, source_sides;  // "geometry", "names", "guess" (topology only)
  float translation_scale = 1.0f;
  std::string target_root, source_root;
  std::vector<std::pair<std::string, std::string>> joints;  // every glTF joint -> BVH joint or ""
};
base::Result<Character> MakeRetargetedCharacter(MotionSource&& character, MotionSource&& motion,
                                                const std::string& joint_map_file = {},
                                                RetargetReport* report = nullptr);

// Reads a joint map: one JSON object whose keys are joints of the character and
// whose values are joints of the motion (a string) or null (left at rest).
// Errors: kIo (missing, unreadable, over 1 MiB), kSyntax with line and column for
// invalid JSON, kInvalidArgument for a value that is not a string or null.
base::Result<deform::JointMapEntries> ReadJointMap(const std::string& path);

// The character a command evaluates, loaded as `render` and `export` load it:
// `input` (a BVH, glTF or GLB path; empty = the built-in demo walk) read Y-up,
// driven by the BVH `motion` when that is not empty (MakeRetargetedCharacter),
// else by its own motion (MakeCharacter). Load and retarget warnings go to
// stderr unless `quiet`. A BVH gets the body `body` (MakeCharacter). Errors: those of
// LoadMotionSource and the makers. `up` (--up) gives the BVH's up axis instead of
// detecting it.
base::Result<Character> LoadCommandCharacter(const std::string& input, const std::string& motion,
                                             bool quiet, std::optional<mocap::UpAxis> up = {},
                                             const std::string& joint_map_file = {},
                                             RetargetReport* report = nullptr,
                                             BodyKind body = BodyKind::kTubes);

}  // namespace app
