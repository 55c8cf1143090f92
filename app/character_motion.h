#pragma once
// A glTF character driven by a separate BVH motion (`render MODEL.glb --motion
// X.bvh`, or a rig with a glTF "character" and a "motion"): the BVH's joints
// are matched to the skin's joints by name and its rotations retargeted onto
// the glTF rest pose (conventions in mocap/retarget.h; README "Rig files").

#include <string>

#include "app/motion_source.h"
#include "app/pipeline.h"
#include "mocap/error.h"

namespace app {

// `character` must be a glTF source, `motion` a BVH source (both as loaded by
// LoadMotionSource; load the BVH Y-up so its axes match glTF's). The result
// keeps the glTF's mesh and skeleton, with the retargeted motion in place of
// the glTF's own animation. Errors: kInvalidArgument when the character is not
// a glTF or the motion not a BVH, and RetargetMotion's (unmapped required
// joints, named). The retargeting warnings join the character's.
mocap::Result<Character> MakeRetargetedCharacter(MotionSource&& character, MotionSource&& motion);

// The character a command evaluates, loaded as `render` and `export` load it:
// `input` (a BVH, glTF or GLB path; empty = the built-in demo walk) read Y-up,
// driven by the BVH `motion` when that is not empty (MakeRetargetedCharacter),
// else by its own motion (MakeCharacter). Load and retarget warnings go to
// stderr unless `quiet`. A BVH gets the body `body` (MakeCharacter). Errors: those of
// LoadMotionSource and the makers.
mocap::Result<Character> LoadCommandCharacter(const std::string& input, const std::string& motion,
                                              bool quiet, BodyKind body = BodyKind::kTubes);

}  // namespace app
