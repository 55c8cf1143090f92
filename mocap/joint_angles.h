#pragma once
// Joint angles: the inverse of EulerToQuat (mocap/pose.h), plus the quaternion
// features of ALGORITHMS.md 5.1 and 5.4 used by the pose-space RBF.
//
// Euler convention (same as pose.h): the rotation channels of a joint, in the
// order the file lists them, compose as R = R(axes[0], a0) * R(axes[1], a1) *
// R(axes[2], a2) on column vectors. Angles are DEGREES here, because Motion
// stores degrees; the quaternion features below are in RADIANS.
//
// All functions are pure, allocate nothing and are safe to call from any thread.
// Internally they compute in double and round the result to float once.

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mocap/skeleton.h"

namespace mocap {

// Euler angles (degrees) of rotation `q` for `count` (1..3) DISTINCT axes
// (ChannelType::kXRotation/kYRotation/kZRotation; other types are ignored and
// give 0). Written to angles_deg[0..count).
// - 3 axes (any of the 6 orders XYZ, XZY, YXZ, YZX, ZXY, ZYX): exact inverse,
//   EulerToQuat(axes, angles, 3) == +-q. The middle angle is in [-90, 90], the
//   outer ones in (-180, 180]. At gimbal lock (|middle| = 90) only a0 + a2 (or
//   a0 - a2) is defined: a2 is set to 0.
// - 2 axes (a, b): the joint cannot reach every rotation. a0 is chosen so that
//   R(a, a0) maps axis b where q maps it; a1 is the twist of the remainder
//   about b. Exact when q is reachable (q = R(a, x) R(b, y)).
// - 1 axis: the twist angle of q about that axis (5.4), exact when q is a
//   rotation about it.
void QuatToEuler(const glm::quat& q, const ChannelType* axes, int count, float* angles_deg);

// As QuatToEuler, but among the equivalent angle sets picks the one closest to
// `reference_deg` (e.g. the previous frame's angles): each angle is moved by a
// multiple of 360 degrees, and for 3 axes the alternative solution
// (a0 + 180, 180 - a1, a2 + 180) is also considered. Used to re-extract Euler
// channels without 360-degree jumps. reference_deg and angles_deg may alias.
void QuatToEulerNear(const glm::quat& q, const ChannelType* axes, int count,
                     const float* reference_deg, float* angles_deg);

// Joint angles theta of one joint (the Euler pose feature of 5.1): the angles of
// its Euler channels, in its own channel order, for `local_rotation` relative to
// its rest rotation (LocalPoseJob builds rest_rotation * Euler). Writes up to 3
// angles (degrees) in the order the channels appear and returns how many (0 for
// a joint without Euler channels). With `reference_deg` (optional, same count)
// the angles continue it as QuatToEulerNear does. joint must be in range.
int JointEulerAngles(const Skeleton& skeleton, int joint, const glm::quat& local_rotation,
                     float* angles_deg, const float* reference_deg = nullptr);

// The local rotation of `joint` for angles (x, y, z) in degrees about its X, Y
// and Z axes: rest_rotation * the axis rotations composed in the joint's own
// channel order (as LocalPoseJob builds it), the axes it has no channel for
// following in Z, X, Y order. For a joint with three rotation channels this
// inverts JointEulerAngles (angles in its range). joint must be in range.
glm::quat JointRotationFromAngles(const Skeleton& skeleton, int joint, const glm::vec3& xyz_deg);

// Rotation vector (axis * angle, radians) of a unit quaternion, on the shorter
// arc: q is first negated if w < 0, so |r| <= pi. r = 2 atan2(|v|, w) v/|v|,
// and r = 2 v when |v| < 1e-12 (ALGORITHMS.md 5.1).
glm::vec3 QuatToRotationVector(const glm::quat& q);

// Unit quaternion of a rotation vector (radians): the inverse of
// QuatToRotationVector for |r| <= pi.
glm::quat RotationVectorToQuat(const glm::vec3& r);

// Rotation-vector pose feature of one joint (5.1, recommended): the rotation
// vector of q_rest^-1 * q_local. Radians, |r| <= pi, independent of Euler order.
glm::vec3 RotationVectorFeature(const glm::quat& rest_rotation, const glm::quat& local_rotation);

// Swing-twist decomposition about a unit axis (5.4).
struct SwingTwist {
  glm::quat swing{1.0f, 0.0f, 0.0f, 0.0f};  // rotation about an axis perpendicular to `axis`
  glm::quat twist{1.0f, 0.0f, 0.0f, 0.0f};  // rotation about `axis`
  float twist_angle_rad = 0.0f;             // signed angle of `twist` about `axis`, in [-pi, pi]
};

// q = swing * twist (the twist happens first, in the joint's own frame; this is
// the order for a twist about the child bone axis expressed in the joint frame).
// The twist is t = normalize(w, dot(v, a) a), the identity when that norm is
// below 1e-9 (a 180-degree swing: the twist is undefined). q is first made
// w >= 0, so the twist angle is in [-pi, pi]. `axis` must be unit length.
SwingTwist DecomposeSwingTwist(const glm::quat& q, const glm::vec3& axis);

// The upstream order q = twist * swing (twist applied last, about an axis of
// the parent frame): same twist, swing = t^-1 q.
SwingTwist DecomposeTwistSwing(const glm::quat& q, const glm::vec3& axis);

// Swing-twist pose feature (5.1): (swing_gain * s.u, swing_gain * s.w,
// twist_gain * twist angle), where s is the swing's rotation vector (radians,
// perpendicular to `axis`) and (u, w) a fixed orthonormal basis across `axis`
// (the one PerpendicularBasis returns). Lets a patch weight flexion over roll.
glm::vec3 SwingTwistFeature(const glm::quat& q, const glm::vec3& axis, float swing_gain,
                            float twist_gain);

// A deterministic orthonormal pair (u, w) with (u, w, axis) right-handed, for a
// unit axis. Continuous except where axis is close to +-X (the helper switches
// reference vector there).
void PerpendicularBasis(const glm::vec3& axis, glm::vec3* u, glm::vec3* w);

}  // namespace mocap
