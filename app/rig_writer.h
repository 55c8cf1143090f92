#pragma once
// Writes a rig (rig_file.h) as the JSON text LoadRig reads back to the same rig
// (`patchskin rig auto CAPTURE > rig.json`): an editable file, one patch per
// line group, only the fields that differ from the documented defaults.
//
// Paths (character, motion, joint map, output) are written relative to
// `folder`, the folder the file will live in, so the file resolves them as the
// in-memory rig did. Numbers are written in their shortest form that reads back
// to the same float. Examples are written when they are computed ones at a
// frame (`{"pose": {"frame": N}, "auto": "volume"}`, what an auto rig has);
// sculpted edits or joint-angle poses give kUnsupported naming the patch.
//
// Cost: linear in the number of patches.

#include <string>

#include "app/rig_file.h"
#include "base/error.h"

namespace app {

base::Result<std::string> WriteRigJson(const Rig& rig, const std::string& folder);

}  // namespace app
