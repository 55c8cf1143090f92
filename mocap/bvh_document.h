#pragma once
// BvhDocument: the HIERARCHY section of a BVH file as parsed, close to the text
// (names as written, per-joint channel order, end sites, file locations), plus
// the MOTION header (declared frame count, frame time) and where the frame data
// starts. BuildBvhSkeleton turns it into the runtime, checked mocap::Skeleton.
//
// Grammar accepted (keywords in any case; see bvh_tokenizer.h for line ends):
//
//   file      := 'HIERARCHY' joint+ 'MOTION' 'Frames:' INT ['Frame' 'Time:' NUMBER] data
//   joint     := ('ROOT' | 'JOINT') NAME '{' 'OFFSET' x y z ['CHANNELS' n type*n]
//                (joint | endsite)* '}'
//   endsite   := 'End' 'Site' [NAME] '{' 'OFFSET' x y z '}'
//   type      := Xposition | Yposition | Zposition | Xrotation | Yrotation | Zrotation
//
// - More than one ROOT is allowed; each starts a new tree.
// - NAME is the rest of the line up to '{' or the line end, blanks trimmed, so
//   names may hold spaces, ':' or '.'. Duplicate names are made unique by the
//   builder (suffix "_2", "_3", ...) with a warning.
// - CHANNELS: 0..6 entries, each type at most once, in any order and any subset
//   (so one- and two-axis joints work). It must come before the joint's
//   children. The order of the rotation entries is the Euler order.
// - OFFSET and CHANNELS may come in either order; OFFSET is required once.
// - "Frames:" and "Frame Time:" may be glued to their value ("Frames:12") or
//   followed by blanks or tabs. A missing "Frame Time:" line gives
//   kDefaultBvhFrameTimeS and a warning.
// - Nesting deeper than BvhParseLimits::max_depth or more than max_joints joints
//   is an error (kLimitExceeded). The parser keeps an explicit stack: no
//   recursion whose depth the file controls.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "mocap/skeleton.h"

namespace mocap {

// Frame time used when a file has no "Frame Time:" line: 1/30 s, the most common
// capture rate in BVH files that omit it.
inline constexpr double kDefaultBvhFrameTimeS = 1.0 / 30.0;
// Default nesting limit (ROOT is depth 1).
inline constexpr int kDefaultBvhMaxDepth = 256;

struct BvhJoint {
  std::string name;           // as written (trimmed)
  int parent = kNoParent;     // index into BvhDocument::joints, or kNoParent
  glm::vec3 offset{0.0f};     // OFFSET, file units, in the parent's frame
  int num_channels = 0;       // 0..6
  ChannelType channels[6]{};  // in file order; the rotation order is the Euler order
  int line = 0;               // location of the joint's name in the file
  int column = 0;
};

struct BvhEndSite {
  std::string name;        // the name written after "End Site", or "End Site"
  int parent = kNoParent;  // index into BvhDocument::joints
  glm::vec3 offset{0.0f};  // OFFSET, file units
  int line = 0;            // location of the "End" keyword
  int column = 0;
};

struct BvhDocument {
  std::string file_name;              // for messages, as given by the caller
  std::vector<BvhJoint> joints;       // #J in file order (parents before children)
  std::vector<BvhEndSite> end_sites;  // in file order
  int num_channels = 0;               // sum of the joints' channel counts
  long long declared_frames = 0;      // the "Frames:" value, >= 0, not yet trusted
  int frames_line = 0;                // location of the "Frames:" value
  int frames_column = 0;
  double frame_time_s = kDefaultBvhFrameTimeS;  // > 0, as written (or the default)
  bool has_frame_time = false;                  // false when the file had no "Frame Time:" line
  std::size_t motion_offset = 0;                // byte offset just after the MOTION header
  int motion_line = 1;                          // line number at motion_offset
  std::size_t motion_line_start = 0;            // byte offset of the start of that line
  std::vector<base::Warning> warnings;
};

struct BvhParseLimits {
  int max_depth = kDefaultBvhMaxDepth;  // deepest allowed nesting of ROOT/JOINT
  int max_joints = kMaxJoints;          // most ROOT + JOINT entries allowed (<= kMaxJoints)
};

// Parses HIERARCHY and the MOTION header of `text`. Does not read frame data.
// `file_name` is used only in messages.
[[nodiscard]] base::Result<BvhDocument> ParseBvhHierarchy(std::string_view text,
                                                          const std::string& file_name,
                                                          const BvhParseLimits& limits = {});

// Builds the runtime skeleton: joints in file order (parent before child),
// unique names (duplicates renamed, with a warning appended to `warnings`),
// rest translations = OFFSET, rest rotations identity, rest scales one,
// contiguous channel ranges in file order, end sites, position_mode as given,
// info.source_file set. Units, scale and up axis are left for the reader.
[[nodiscard]] base::Result<Skeleton> BuildBvhSkeleton(const BvhDocument& document,
                                                      PositionChannelMode position_mode,
                                                      std::vector<base::Warning>* warnings);

}  // namespace mocap
