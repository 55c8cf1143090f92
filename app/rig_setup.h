#pragma once
// What a rig file (rig_file.h) asks of the commands that evaluate frames, in
// one place so `export` follows the same rules as `render`:
//   * which input to load (the mannequin's motion, or the glTF character);
//   * the layers to put on a deform::FramePipeline: the patches, their example shapes
//     (pose-space dS) and their elastic networks (dE). `render` puts them on
//     the right half's pipeline of a split view, `export` on its only one.

#include <string>
#include <vector>

#include "app/frame_plan.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_file.h"
#include "base/error.h"

namespace app {

// The file to load for a rig: its BVH motion for the mannequin, else its glTF
// character (driven by rig.motion when that is set, else by its own animation).
std::string RigInputFile(const Rig& rig);

// The one rule render, turntable and export follow for a rig file
// (docs/command-line.md, "With a rig file"): each setting the rig carries
// (the input; the motion and its joint map, for a glTF character; global, fps,
// up, size, camera, frames) applies unless its option was given on the command
// line (`o.given`, long names). The command then applies its own fields.
template <class Options>
void ApplyRigSettings(const Rig& rig, Options& o) {
  const auto given = [&o](const char* name) { return o.given.count(name) > 0; };
  o.input = RigInputFile(rig);
  if (!IsBuiltInBody(rig.character) && !rig.motion.empty() && !given("--motion")) {
    o.motion = rig.motion;
    if (!given("--joint-map")) o.joint_map = rig.joint_map;
  }
  if (!given("--global")) o.global = rig.global;
  if (!given("--fps")) o.fps = rig.fps;
  if (!given("--up")) o.up = rig.up;
  if (!given("--size")) {
    o.size = std::to_string(rig.render.size.x) + "x" + std::to_string(rig.render.size.y);
  }
  if (!given("--camera")) o.camera = rig.render.camera;
  if (!given("--frames") || o.frames.empty()) o.frames = rig.render.frames;
}

// The built-in body a rig names: "generated", else the tube body ("tubes" or
// "mannequin"). Meaningless for a glTF character.
BodyKind RigBodyKind(const Rig& rig);

// The rig's elastic patches on a character whose patches (one per rig patch,
// in order) were built by BuildRigPatches. Driving joint: the rig's
// `elastic.joint`, else the region's joint, else the joint with the largest
// total skin weight on the patch's control points. Errors (kNotFound) name
// "patches[i].elastic.joint".
base::Result<std::vector<deform::ElasticPatchSpec>> ResolveRigElastic(
    const Rig& rig, const Character& character, std::span<const deform::PatchSetup> patches);

// Builds the rig's layers on `character` (BuildRigPatches, BuildRigPoseSpaces
// for pipeline.method(), ResolveRigElastic) and installs them on `pipeline`,
// which must evaluate that character. Errors name the rig file and the field
// path. `notes` (optional) receives the lines worth printing: condition
// numbers of the example fits, their warnings, elastic step notes.
base::Status ApplyRigLayers(const Rig& rig, const Character& character,
                            deform::FramePipeline& pipeline,
                            std::vector<std::string>* notes = nullptr);

// Resolves a camera's look-at text into `spec`: a joint of the character
// (look_joint) or "patch:NAME", one of the rig's patches (look_region: the
// vertices of its region, built as BuildRigPatches builds them). Empty text
// leaves `spec` as it is. kInvalidArgument naming --look-at and what exists.
base::Status ResolveLookAt(const std::string& text, const Rig* rig, const Character& character,
                           CameraSpec& spec);

}  // namespace app
