#include "app/character_motion.h"

#include <cstdio>
#include <utility>

#include "app/demo_data.h"
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

mocap::Result<Character> LoadCommandCharacter(const std::string& input, const std::string& motion,
                                              bool quiet, BodyKind body) {
  MotionSourceOptions load;
  load.y_up = true;  // frames are rendered Y-up with the ground at the feet
  mocap::Result<MotionSource> src = input.empty()
                                        ? LoadBvhText(DemoBvhText(), "demo_walk.bvh", load)
                                        : LoadMotionSource(input, load);
  if (!src.ok()) return std::move(src).error();
  const auto print = [quiet](const std::vector<mocap::Warning>& warnings, std::size_t from) {
    if (quiet) return;
    for (std::size_t i = from; i < warnings.size(); ++i) {
      std::fprintf(stderr, "%s\n", warnings[i].ToString().c_str());
    }
  };
  print(src->warnings, 0);
  if (motion.empty()) return MakeCharacter(std::move(*src), {}, body);
  mocap::Result<MotionSource> bvh = LoadMotionSource(motion, load);
  if (!bvh.ok()) return std::move(bvh).error();
  const std::size_t printed = src->warnings.size();  // the glTF's, printed above
  mocap::Result<Character> character = MakeRetargetedCharacter(std::move(*src), std::move(*bvh));
  if (character.ok()) print(character->warnings, printed);
  return character;
}

}  // namespace app
