#pragma once
// What a rig file (rig_file.h) asks of the commands that evaluate frames, in
// one place so `export` follows the same rules as `render`:
//   * which input to load (the mannequin's motion, or the glTF character);
//   * the layers to put on a FramePipeline: the patches, their example shapes
//     (pose-space dS) and their elastic networks (dE). `render` puts them on
//     the right half's pipeline of a split view, `export` on its only one.

#include <string>
#include <vector>

#include "app/frame_plan.h"
#include "app/pipeline.h"
#include "app/rig_file.h"
#include "base/error.h"

namespace app {

// The file to load for a rig: its BVH motion for the mannequin, else its glTF
// character (driven by rig.motion when that is set, else by its own animation).
std::string RigInputFile(const Rig& rig);

// The built-in body a rig names: "generated", else the tube body ("tubes" or
// "mannequin"). Meaningless for a glTF character.
BodyKind RigBodyKind(const Rig& rig);

// Builds the rig's layers on `character` (BuildRigPatches, BuildRigPoseSpaces
// for pipeline.method(), ResolveRigElastic) and installs them on `pipeline`,
// which must evaluate that character. Errors name the rig file and the field
// path. `notes` (optional) receives the lines worth printing: condition
// numbers of the example fits, their warnings, elastic step notes.
base::Status ApplyRigLayers(const Rig& rig, const Character& character, FramePipeline& pipeline,
                            std::vector<std::string>* notes = nullptr);

// Resolves a camera's look-at text into `spec`: a joint of the character
// (look_joint) or "patch:NAME", one of the rig's patches (look_region: the
// vertices of its region, built as BuildRigPatches builds them). Empty text
// leaves `spec` as it is. kInvalidArgument naming --look-at and what exists.
base::Status ResolveLookAt(const std::string& text, const Rig* rig, const Character& character,
                           CameraSpec& spec);

}  // namespace app
