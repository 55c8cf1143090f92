#pragma once
// What a motion does with each joint's channels, for deciding which joints are
// part of a body (deform/body/body_chains.h) rather than props, IK targets or
// positioning roots:
//  - kRotates: a rotation channel takes more than one value. A root whose
//    rotation channels are declared but constant (Bandai's joint_Root, a
//    "World" node) orients the body, it never bends it.
//  - kStretches: the joint's position channels move it, relative to its
//    parent, by more than a quarter of its rest offset (and more than 1 % of
//    the rest pose's extent): the link from the parent is not a bone but a
//    positioning one (hips walking away from a root on the floor, an IK target).
//    Small drifts (a solve's bone-length noise, printed decimals) stay bones.
// Input: a checked skeleton and a motion with its channel count. Output: #J
// flag bytes. Cost: one pass over the motion, O(#F x #C).

#include <cstdint>
#include <vector>

#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace mocap {

enum JointUse : std::uint8_t {
  kJointRotates = 1,
  kJointStretches = 2,
};

// Empty when the motion's channel count does not match the skeleton's.
[[nodiscard]] std::vector<std::uint8_t> ChannelUse(const Skeleton& skeleton, const Motion& motion);

}  // namespace mocap
