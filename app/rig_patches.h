#pragma once
// Builds a rig's patches (rig_file.h) on a loaded character: joint names are
// resolved in its skeleton, regions selected on its bind mesh
// (deform/patch/patch_region.h) and each patch fitted and bound
// (deform/patch/patch_layer.h). Errors name the rig file and the patch's field path.

#include <vector>

#include "app/character.h"
#include "app/rig_file.h"
#include "deform/patch/patch_layer.h"
#include "base/error.h"

namespace app {

// One PatchSetup per rig patch, in order. Joint regions use the joint and its
// parent as the bones, the joint's bind position as the centre and, for the
// cylinder map, the bone from the parent to the joint as the axis. Screen
// regions frame the bind mesh from the named view (front looks along -Z: the
// character faces +Z; left looks along -X at the character's left side) in a
// square 512 x 512 depth image (render/raster/region_select.h).
// Errors: an unknown or unskinned joint (kNotFound, "patches[i].region.joint"),
// a cylinder on a vertex-list or screen region (kInvalidArgument), and anything the region
// selection or the patch build reports (with "patches[i]" as the field path).
base::Result<std::vector<deform::PatchSetup>> BuildRigPatches(const Rig& rig,
                                                              const Character& character);

}  // namespace app
