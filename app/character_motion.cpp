#include "app/character_motion.h"

#include <utility>

#include "mocap/retarget.h"

namespace app {

mocap::Result<Character> MakeRetargetedCharacter(MotionSource&& character, MotionSource&& motion) {
  const std::string model_file = character.skeleton.info.source_file;
  const std::string motion_file = motion.skeleton.info.source_file;
  if (!character.gltf) {
    return mocap::MakeError(mocap::ErrorCode::kInvalidArgument, {model_file, 0, 0, {}},
                            "expected a glTF or GLB character to drive with a separate motion, "
                            "found a " + character.format + " file");
  }
  if (motion.format != "bvh") {
    return mocap::MakeError(mocap::ErrorCode::kInvalidArgument, {motion_file, 0, 0, {}},
                            "expected a BVH motion, found a " + motion.format + " file");
  }
  mocap::Result<mocap::RetargetedMotion> retargeted = mocap::RetargetMotion(
      character.skeleton, motion.skeleton, motion.motion, model_file, motion_file);
  if (!retargeted.ok()) return std::move(retargeted).error();
  character.skeleton = std::move(retargeted->skeleton);
  character.motion = std::move(retargeted->motion);
  for (mocap::Warning& w : motion.warnings) character.warnings.push_back(std::move(w));
  for (mocap::Warning& w : retargeted->warnings) character.warnings.push_back(std::move(w));
  return MakeCharacter(std::move(character));
}

}  // namespace app
