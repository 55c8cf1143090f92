#pragma once
// A glTF character driven by a separate BVH motion (`render MODEL.glb --motion
// X.bvh`, or a rig with a glTF "character" and a "motion"): the BVH's joints
// are matched to the skin's joints by name and its rotations retargeted onto
// the glTF rest pose (conventions in mocap/retarget.h; README "Rig files").

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

}  // namespace app
