#pragma once
// The character a command renders or exports: a capture's skeleton and motion
// with a skinned mesh (deform::Character), plus what only the app needs: the
// loader's warnings and the renderer's textures.

#include <memory>
#include <string>
#include <vector>

#include "base/error.h"
#include "deform/body/mannequin.h"
#include "deform/global/global_skinning.h"
#include "deform/pipeline/character.h"

namespace app {

struct MotionSource;
struct CharacterTextures;  // app/frame_render.h

// "ssd", "dqs", "swd" (also "lbs" for ssd); kInvalidArgument naming --global otherwise.
base::Result<deform::GlobalMethod> ParseGlobalMethod(const std::string& name);

struct Character : deform::Character {
  std::vector<base::Warning> warnings;
  // The renderer's mip pyramids of mesh.materials' textures, built once (null: untextured).
  std::shared_ptr<const CharacterTextures> textures;
};

// Which body a BVH skeleton gets: the tube mannequin (deform/body/mannequin.h; rig files name
// its vertices) or the generated body (deform/body/generated_body.h: one smooth closed
// skin with bone-heat weights, read from the body cache when it was built before).
enum class BodyKind { kTubes, kGenerated };
// "tubes" or "generated"; kInvalidArgument (naming --body) otherwise.
base::Result<BodyKind> ParseBodyKind(const std::string& name);

// Builds a Character from a loaded source: glTF keeps its mesh; BVH gets a
// body of `kind`, bound at the rest pose unless the rest pose is much lower than the
// first frame's pose (rest poses that lie flat, e.g. Bandai Namco's), in which
// case it is bound at frame 0 (deform::ChooseBindPose: heights of the body's
// joints, without a root that only positions it). The generated body is also bound
// at frame 0 when the rest pose is much taller (arms raised beside the head would
// fuse into one skin). With SWD each mannequin tube is bound to the sweep of the
// chain it was generated on (body_chain_coords).
base::Result<Character> MakeCharacter(MotionSource&& source,
                                      const deform::MannequinOptions& mannequin = {},
                                      BodyKind body = BodyKind::kTubes);

}  // namespace app
