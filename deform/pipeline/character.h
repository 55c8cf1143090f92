#pragma once
// What the frame pipeline deforms: a skeleton, its motion, and a skinned mesh
// bound to it. The app builds one from a capture (app/character.h: a glTF's
// own mesh, or a body generated for a BVH skeleton) and adds what only it needs.

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "deform/mesh.h"
#include "mocap/motion.h"
#include "mocap/pose.h"
#include "mocap/skeleton.h"

namespace deform {

struct Character {
  std::string source;  // file name (or "demo"), for messages and metadata
  mocap::Skeleton skeleton;
  mocap::Motion motion;
  SkinnedMesh mesh;
  glm::mat4 world_from_model{1.0f};   // glTF: node transform of the skinned mesh is ignored
                                      // (glTF rule), so identity; kept for other sources
  bool closed_surface = false;        // the bind mesh is closed and outward (IsClosedOutward)
  bool bound_at_first_frame = false;  // BVH: the rest pose was not a body pose, so the
                                      // body was built and bound at frame 0
};

// The model-space joint matrices (#J) of the pose the character's mesh was made
// in: the rest pose, or frame 0 when bound_at_first_frame; a skinned mesh's own
// bind matrices replace those of its skin joints. kInternal if a job refuses.
base::Result<std::vector<glm::mat4>> BindModelFromJoint(const Character& character);

// An error of a job the frame's stages run, named after the stage: kInternal,
// since the stages size every buffer they give it.
base::Error StageError(const Character& character, const base::JobStatus& s, const char* stage);

// The character's joints at a time: the sampled local pose (the rest pose
// without motion) and its world-space matrices (world_from_model applied).
// Keeps its buffers between calls: no allocation after the first.
struct CharacterPose {
  std::vector<mocap::JointTransform> locals;  // #J
  std::vector<glm::mat4> model_from_joint;    // #J, world space

  // Poses `character` at time_s seconds from the motion's first frame (clamped
  // to the motion). Errors: kInternal from the mocap jobs (StageError).
  base::Status Sample(const Character& character, double time_s);

 private:
  std::vector<mocap::JointTransform> scratch_;
};

}  // namespace deform
