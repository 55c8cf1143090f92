#include "app/rig_setup.h"

#include "app/rig_patches.h"

namespace app {

mocap::Result<std::string> RigInputFile(const Rig& rig) {
  if (rig.character != "mannequin" && !rig.motion.empty()) {
    return mocap::MakeError(mocap::ErrorCode::kUnsupported, {rig.file, 0, 0, "motion"},
                            "a glTF character with a separate motion is not supported "
                            "yet; leave out \"motion\" to use the glTF's animation");
  }
  return rig.character == "mannequin" ? rig.motion : rig.character;
}

mocap::Status ApplyRigLayers(const Rig& rig, const Character& character, FramePipeline& pipeline) {
  mocap::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(rig, character);
  if (!patches.ok()) return std::move(patches).error();
  if (patches->empty()) return mocap::Status::Ok();
  return pipeline.SetPatches(std::move(*patches));
}

}  // namespace app
