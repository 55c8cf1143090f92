#pragma once
// Skeleton: the runtime joint hierarchy, flat and checked, shared by BVH and glTF
// import. Joints are sorted so that every parent precedes its children, so
// local -> model is one forward loop (as in ozz-animation's runtime skeleton).
//
// Units are the file's (BVH: whatever the capture used, often cm or inches;
// glTF: metres). Units and up axis as detected or chosen are recorded in
// SkeletonInfo so `inspect` can report them.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/error.h"

namespace mocap {

inline constexpr int kNoParent = -1;
// Hard limit on joints in one skeleton (Skeleton::parents is int16).
inline constexpr int kMaxJoints = 4096;
// Maximum number of channels one joint may have (BVH allows 6; glTF uses up to 10:
// 3 translation, 4 quaternion, 3 scale).
inline constexpr int kMaxChannelsPerJoint = 10;

// What one float of a motion frame drives. BVH has the first six; glTF import
// produces translation, quaternion (x, y, z, w as four consecutive channels) and
// scale channels. Rotation angles are stored in degrees as in BVH files.
enum class ChannelType : std::uint8_t {
  kXPosition,
  kYPosition,
  kZPosition,
  kXRotation,  // degrees
  kYRotation,  // degrees
  kZRotation,  // degrees
  kQuatX,      // unit quaternion components, in the order x, y, z, w
  kQuatY,
  kQuatZ,
  kQuatW,
  kXScale,
  kYScale,
  kZScale,
};

// BVH spelling ("Xposition", "Zrotation") or a descriptive name for the others.
const char* ChannelTypeName(ChannelType type);

// The channel layout of one joint: which floats of a frame it reads, and in
// which order. For BVH, the order of the rotation channels IS the Euler order:
// R = R(first) * R(second) * R(third) on column vectors.
struct JointChannels {
  std::uint32_t first = 0;  // index of this joint's first channel in a frame
  std::uint8_t count = 0;   // 0..kMaxChannelsPerJoint
  std::array<ChannelType, kMaxChannelsPerJoint> types{};
};

// How position channels combine with a joint's rest offset (BVH).
enum class PositionChannelMode : std::uint8_t {
  kReplaceOffset,  // default: the channels are the whole local translation (Blender, Assimp)
  kAddToOffset,    // the channels are added to OFFSET (three.js)
};

enum class UpAxis : std::uint8_t { kY, kZ };

// What decided SkeletonInfo::up_axis.
enum class UpAxisSource : std::uint8_t {
  kRestPose,       // the rest (OFFSET) pose: no frames, or the frames were split evenly
  kAnimatedPoses,  // the poses of frames sampled over the motion
  kGiven,          // the caller (--up)
};

struct EndSite {
  int parent = kNoParent;   // joint the end site hangs from
  glm::vec3 offset{0.0f};   // in the parent's frame, file units
  std::string name;         // "End Site" unless the file named it
};

// Facts about the source, reported by `inspect`.
struct SkeletonInfo {
  std::string source_file;
  UpAxis up_axis = UpAxis::kY;       // axis of the file (detected or given)
  UpAxisSource up_axis_source = UpAxisSource::kRestPose;
  float scale_applied = 1.0f;        // factor already applied to offsets and positions
  std::string detected_units;        // "cm", "m", "inch", "unknown"
  float rest_height = 0.0f;          // extent along the up axis of the rest pose, after scale
};

// Flat, parent-before-child joint arrays. All vectors have num_joints() entries.
// Built by the importers; Check() verifies the invariants once.
struct Skeleton {
  std::vector<std::string> names;             // unique (duplicates were renamed on import)
  std::vector<std::int16_t> parents;          // kNoParent for roots; parent index < own index
  std::vector<glm::vec3> rest_translations;   // local rest translation (BVH OFFSET), file units
  std::vector<glm::quat> rest_rotations;      // local rest rotation (identity for BVH)
  std::vector<glm::vec3> rest_scales;         // local rest scale (one for BVH)
  std::vector<JointChannels> channels;        // per joint; count 0 means not animated
  std::vector<EndSite> end_sites;             // any number, each names its parent joint
  int num_channels = 0;                       // floats per motion frame
  PositionChannelMode position_mode = PositionChannelMode::kReplaceOffset;
  // Per joint, what the loaded motion does with its channels (JointUse bits of
  // mocap/channel_use.h); empty when no motion was read with it.
  std::vector<std::uint8_t> channel_use;
  SkeletonInfo info;

  int num_joints() const { return static_cast<int>(parents.size()); }
  // Index of the joint with exactly this name, or -1.
  int FindJoint(std::string_view name) const;
  // Verifies sizes, parent order, channel ranges (contiguous, within num_channels).
  base::Status Check() const;
};

}  // namespace mocap
