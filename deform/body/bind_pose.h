#pragma once
// The pose a body generated from a skeleton (the mannequin) is built and bound in.
//
// A BVH's rest (OFFSET) pose is usually a T- or A-pose, but not always a body pose:
// Bandai Namco's files put every bone along +X, so the body lies flat with the legs
// along the spine and the arms beside it; a body built there binds the thighs and arms
// to a trunk they touch and tears when the capture stands up. Such a rest pose is much
// lower than the captured frames, so the body is then built and bound at the first
// frame instead [ours]. Heights are measured over the body only: a root that merely
// positions the body (Bandai's joint_Root, left on the floor at the origin) would
// otherwise add the hip height to the flat rest pose (Bandai's run: 98 against 126 with
// it, 6 against 126 without).

#include <span>

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace deform {

// The first frame is used when its body height exceeds the rest pose's by this factor.
inline constexpr float kRestTooLowFactor = 1.3f;

struct BindPoseChoice {
  int frame = -1;            // motion frame to bind at; -1: the rest pose
  float rest_height = 0.0f;  // extent along the up axis of the body's joints at rest, model units
  float first_height = 0.0f; // the same at frame 0 (0 without frames)
};

// Chooses the bind pose: frame 0 when the motion has frames and frame 0's body height is
// more than kRestTooLowFactor times the rest pose's, else the rest pose. The body's joints
// are those on BuildBodyChains' chains (so a positioning root does not count), taken from
// the rest pose, or from frame 0 when the rest pose has no body (all joints at one point).
// Up is skeleton.info.up_axis. Errors: those of BuildBodyChains when neither pose gives a
// body.
[[nodiscard]] base::Result<BindPoseChoice> ChooseBindPose(const mocap::Skeleton& skeleton,
                                                          const mocap::Motion& motion,
                                                          float min_branch_extent = 0.15f);

}  // namespace deform
