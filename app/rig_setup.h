#pragma once
// What a rig file (rig_file.h) asks of the commands that evaluate frames, in
// one place so `export` follows the same rules as `render`:
//   * which input to load (the mannequin's motion, or the glTF character);
//   * the layers to put on a FramePipeline: the patches, their example shapes
//     (pose-space dS) and their elastic networks (dE). `render` puts them on
//     the right half's pipeline of a split view, `export` on its only one.

#include <string>
#include <vector>

#include "app/pipeline.h"
#include "app/rig_file.h"
#include "mocap/error.h"

namespace app {

// The file to load for a rig: its BVH motion for the mannequin, else its glTF
// character (whose own animation is the motion). kUnsupported for a glTF
// character with a separate motion (field "motion").
mocap::Result<std::string> RigInputFile(const Rig& rig);

// Builds the rig's layers on `character` (BuildRigPatches, BuildRigPoseSpaces
// for pipeline.method(), ResolveRigElastic) and installs them on `pipeline`,
// which must evaluate that character. Errors name the rig file and the field
// path. `notes` (optional) receives the lines worth printing: condition
// numbers of the example fits, their warnings, elastic step notes.
mocap::Status ApplyRigLayers(const Rig& rig, const Character& character, FramePipeline& pipeline,
                             std::vector<std::string>* notes = nullptr);

}  // namespace app
