#pragma once
// The patch layer without writing a rig (`render CAPTURE --layer auto`,
// `patchskin rig auto CAPTURE`): a rig (rig_file.h) placed on a character from
// its skeleton's topology alone, never from joint names.
//
// Input: a loaded Character (the generated/tube body of a BVH, or a glTF
// character driven by a capture) and the file names the rig records.
// Output: an app::Rig whose patches sit where the paper's demos put them, and
// the notes worth printing (what was placed, what was skipped and why).
//
// Placement (deform::FindHumanoid on the bind pose finds the pelvis, spine,
// head, arms and legs and the body's up / forward / left axes):
//   - per side: back of the elbow, biceps, top of the shoulder, front of the
//     knee, back of the hip (buttock);
//   - elastic belly (the spine point about 45 % of the way pelvis -> chest, front
//     side) and elastic jowl (the head joint, front side), driven by the capture;
//   - a computed corrective example (`"auto": "volume"`) at the capture's frame
//     of largest bend on the back of each elbow, the front of each knee and the
//     back of each hip (the joints whose skin SSD collapses);
//   - region sizes are fractions of the bone lengths (radius of the elbow
//     patch 0.45 x the forearm, ...), so a child and an adult get the same layout;
//   - which side of a hinge is its back: the direction the child bone swings to
//     at the capture's frame of largest bend (in the parent bone's bind frame);
//     a joint that hardly bends (< 20 degrees) falls back to the body's forward.
// A skeleton that is no humanoid (a quadruped) gets an elastic belly under the
// first spine chain (down = from the spine towards the leg tips) and a note of
// what was skipped; a skeleton without any spine chain gets no patch and a note.
//
// Cost: one FindHumanoid (O(#J^2) at worst) and one forward-kinematics pass over
// at most 2000 sampled frames; no mesh is touched (well under 1 ms per joint).

#include <string>
#include <utility>
#include <vector>

#include "app/character.h"
#include "app/rig_file.h"
#include "base/error.h"

namespace app {

struct AutoRig {
  Rig rig;
  std::vector<std::string> notes;  // placed patches, skipped ones and why
  // Patch name -> a joint to try when the first choice has no skin there.
  std::vector<std::pair<std::string, std::string>> alternate_joints;
};

// `character_name`: "generated", "tubes" or the glTF path (Rig::character);
// `motion_file`: the capture (Rig::motion); `label` names the rig in messages
// and output folders (Rig::file). Errors: deform::BindModelFromJoint's.
base::Result<AutoRig> BuildAutoRig(const Character& character, const std::string& character_name,
                                   const std::string& motion_file, const std::string& label);

// Loads the character as `render` does (a BVH on the `body` built-in body, or
// the glTF `body` driven by the BVH `capture`) and builds its rig. `up`: the
// BVH's up axis as --up gives it (empty = detected). Errors: the loader's,
// kInvalidArgument naming --body for an unknown body.
base::Result<AutoRig> MakeAutoRig(const std::string& capture, const std::string& body,
                                  const std::string& up, bool quiet);

// What `--layer LAYER` on render/turntable/export does with a command's input:
// "auto" makes the rig (MakeAutoRig) and prints its notes to stderr unless
// `quiet`. The capture is `input` (a BVH; empty = the built-in demo walk) on the
// body `body` (built-in or a glTF character), or, with `motion` set, the BVH
// `motion` driving the glTF `input`. kInvalidArgument naming --layer for any
// other value, a rig file as the input, or a glTF input without --motion.
base::Result<Rig> AutoRigForCommand(const std::string& layer, const std::string& input,
                                    const std::string& motion, const std::string& body,
                                    const std::string& up, bool quiet);

}  // namespace app
