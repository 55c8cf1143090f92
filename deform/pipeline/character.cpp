#include "deform/pipeline/character.h"

#include <string>

#include "mocap/pose.h"
#include "mocap/sampling.h"

namespace deform {

base::Result<std::vector<glm::mat4>> BindModelFromJoint(const Character& c) {
  const auto nj = static_cast<std::size_t>(c.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj);
  mocap::RestPose(c.skeleton, locals);
  if (c.bound_at_first_frame && c.motion.num_frames > 0) {
    (void)mocap::LocalPoseJob{&c.skeleton, c.motion.frame(0), locals}.Run();
  }
  const base::JobStatus s =
      mocap::LocalToModelJob{
          .parents = c.skeleton.parents, .locals = locals, .model_from_joint = model}
          .Run();
  if (!s) {
    return base::MakeError(base::ErrorCode::kInternal, {c.source, 0, 0, {}},
                           std::string("local-to-model refused to run: ") + s.what);
  }
  // A skinned mesh's own bind matrices win over the rest pose (glTF).
  for (std::size_t i = 0; i < c.mesh.skin_joints.size() && i < c.mesh.joint_from_bind.size(); ++i) {
    const auto j = static_cast<std::size_t>(c.mesh.skin_joints[i]);
    if (j < nj) model[j] = glm::inverse(c.mesh.joint_from_bind[i]);
  }
  return model;
}

base::Error StageError(const Character& c, const base::JobStatus& s, const char* stage) {
  return base::MakeError(base::ErrorCode::kInternal, {c.source, 0, 0, {}},
                         std::string(stage) + " refused to run: " + s.what);
}

base::Status CharacterPose::Sample(const Character& c, double time_s) {
  const auto nj = static_cast<std::size_t>(c.skeleton.num_joints());
  locals.resize(nj);
  scratch_.resize(nj);
  model_from_joint.resize(nj);
  if (c.motion.num_frames > 0) {
    const base::JobStatus s = mocap::SampleLocalsJob{.skeleton = &c.skeleton,
                                                     .motion = &c.motion,
                                                     .time_s = time_s,
                                                     .scratch = scratch_,
                                                     .locals = locals}
                                  .Run();
    if (!s) return StageError(c, s, "sampling");
  } else {
    mocap::RestPose(c.skeleton, locals);
  }
  const base::JobStatus s = mocap::LocalToModelJob{.parents = c.skeleton.parents,
                                                   .locals = locals,
                                                   .model_from_root = c.world_from_model,
                                                   .model_from_joint = model_from_joint}
                                .Run();
  if (!s) return StageError(c, s, "local-to-model");
  return base::Status::Ok();
}

}  // namespace deform
