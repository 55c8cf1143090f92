#pragma once
// What a rig file (rig_file.h) asks of the commands that evaluate frames, in
// one place so `export` follows the same rules as `render`:
//   * which input to load (the mannequin's motion, or the glTF character);
//   * the layers to put on a FramePipeline (the patches now; the example and
//     elastic layers hook in here as they reach the pipeline).
// render_command.cpp still does the same inline (its split view puts the
// layers on the right half only).

#include <string>

#include "app/pipeline.h"
#include "app/rig_file.h"
#include "mocap/error.h"

namespace app {

// The file to load for a rig: its BVH motion for the mannequin, else its glTF
// character (whose own animation is the motion). kUnsupported for a glTF
// character with a separate motion (field "motion").
mocap::Result<std::string> RigInputFile(const Rig& rig);

// Builds the rig's layers on `character` (BuildRigPatches) and installs them on
// `pipeline`, which must evaluate that character. Errors name the rig file
// and the field path, as BuildRigPatches does.
mocap::Status ApplyRigLayers(const Rig& rig, const Character& character, FramePipeline& pipeline);

}  // namespace app
