#pragma once
// Artifact figures of a rigged body (ALGORITHMS.md 2.3, "Artifact figures") for SSD, DQS
// and SWD side by side, under synthetic poses applied to the joints the SWD rig found by
// topology (deform/global/swd_rig.h: elbow/knee = SwdLimb::middle, wrist = the joint after it;
// of zero-length helpers at the same place, the topmost is turned and named):
// - collapse: the elbow or knee bent by each angle (the joint's subtree turned about the
//   joint, about an axis across the bone); ring = the mesh ring nearest the rest bisector
//   plane among the vertices bound to that limb's sweep, within 0.6 Lmin of the joint.
// - candy wrapper (arms with a wrist): the hand turned about the forearm axis at the
//   wrist; rings across the forearm's outer half and the wrist; figure = smallest ratio.
// The same rings serve every method. Analysis code: allocates, double precision areas.

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "deform/mesh.h"
#include "deform/global/swd_rig.h"
#include "base/error.h"
#include "mocap/skeleton.h"

namespace deform {

// One figure per method (area ratios, 1 = kept).
struct MethodFigures {
  double ssd = 0.0;
  double dqs = 0.0;
  double swd = 0.0;
};

struct AngleFigures {
  double degrees = 0.0;  // bend or twist angle
  MethodFigures figures;
};

struct LimbArtifacts {
  std::string joint;     // skeleton name of the bent joint (elbow/knee)
  std::string end_joint;  // skeleton name of the twisted joint (wrist), empty if none
  bool arm = false;      // SwdLimb::arm
  std::vector<AngleFigures> collapse;  // one per bend angle
  std::vector<AngleFigures> candy;     // one per twist angle (arms with a wrist), else empty
};

// Model matrices (#J) with the subtree of `joint` (it and all its descendants) turned by
// `rotation` about `pivot` (model space).
void TurnSubtree(const mocap::Skeleton& skeleton, int joint, const glm::quat& rotation,
                 const glm::vec3& pivot, std::span<glm::mat4> model_from_joint);

// Figures for every limb of `rig`. `mesh` is the skinned mesh the rig was built on,
// bind_model_from_joint the #J matrices of its bind pose. Errors: kCountMismatch for a
// matrix count other than #J or a rig of another mesh, kInvalidArgument when the rig
// has no limb or a ring cannot be found, and errors of the skinning jobs (kInternal).
[[nodiscard]] base::Result<std::vector<LimbArtifacts>> MeasureLimbArtifacts(
    const mocap::Skeleton& skeleton, std::span<const glm::mat4> bind_model_from_joint,
    const SkinnedMesh& mesh, const SwdRig& rig, std::span<const double> bend_degrees,
    std::span<const double> twist_degrees);

}  // namespace deform
