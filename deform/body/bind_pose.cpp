#include "deform/body/bind_pose.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "deform/body/body_chains.h"
#include "mocap/pose.h"

namespace deform {
namespace {

// Model-space joint matrices of the rest pose (frame < 0) or of a motion frame.
bool PoseMatrices(const mocap::Skeleton& skeleton, const mocap::Motion& motion, int frame,
                  std::vector<glm::mat4>& model) {
  std::vector<mocap::JointTransform> locals(model.size());
  mocap::RestPose(skeleton, locals);
  if (frame >= 0 && !mocap::LocalPoseJob{&skeleton, motion.frame(frame), locals}.Run()) {
    return false;
  }
  return static_cast<bool>(mocap::LocalToModelJob{
      .parents = skeleton.parents, .locals = locals, .model_from_joint = model}
                               .Run());
}

// Extent along `axis` of the joints on the chains, in the pose `model`.
float BodyHeight(const BodyChains& chains, const std::vector<glm::mat4>& model, int axis) {
  float lo = std::numeric_limits<float>::max();
  float hi = std::numeric_limits<float>::lowest();
  for (const BodyChain& chain : chains.chains) {
    for (int p : chain.points) {
      const int j = chains.points[static_cast<std::size_t>(p)].joint;
      if (j < 0 || static_cast<std::size_t>(j) >= model.size()) continue;
      lo = std::min(lo, model[static_cast<std::size_t>(j)][3][axis]);
      hi = std::max(hi, model[static_cast<std::size_t>(j)][3][axis]);
    }
  }
  return hi >= lo ? hi - lo : 0.0f;
}

}  // namespace

base::Result<BindPoseChoice> ChooseBindPose(const mocap::Skeleton& skeleton,
                                            const mocap::Motion& motion, float min_branch_extent) {
  const auto nj = static_cast<std::size_t>(skeleton.num_joints());
  std::vector<glm::mat4> rest(nj), first(nj);
  BindPoseChoice choice;
  const bool have_rest = PoseMatrices(skeleton, motion, -1, rest);
  const bool have_first = motion.num_frames > 0 && PoseMatrices(skeleton, motion, 0, first);
  base::Result<BodyChains> chains =
      have_rest ? BuildBodyChains(skeleton, rest, min_branch_extent)
                : base::Result<BodyChains>(base::InvalidArgument("rest pose not evaluated"));
  if (!chains.ok() && have_first) {
    base::Result<BodyChains> again = BuildBodyChains(skeleton, first, min_branch_extent);
    if (again.ok()) chains = std::move(again);
  }
  if (!chains.ok()) return std::move(chains).error();
  const int axis = skeleton.info.up_axis == mocap::UpAxis::kZ ? 2 : 1;
  choice.rest_height = have_rest ? BodyHeight(*chains, rest, axis) : 0.0f;
  choice.first_height = have_first ? BodyHeight(*chains, first, axis) : 0.0f;
  if (have_first && choice.first_height > kRestTooLowFactor * choice.rest_height) choice.frame = 0;
  return choice;
}

}  // namespace deform
