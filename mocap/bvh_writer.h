#pragma once
// BVH export: Skeleton + Motion -> BVH text.
//
// The hierarchy is written depth-first from each root (several roots give
// several ROOT blocks), one joint per block, tab-indented, with each joint's
// End Sites first among its children ("End Site <name>" when the name is not
// "End Site"). Motion columns are reordered to the written joint order when the
// skeleton's channel ranges are in another order. Numbers are printed in the
// shortest form that reads back to the same float (std::to_chars), so
// ParseBvh(FormatBvh(s, m)) gives the same skeleton and bit-identical values.
//
// Not written: SkeletonInfo and position_mode (a BVH file cannot say how its
// position channels combine with OFFSET; read it back with the same mode), rest
// rotations and scales (BVH has none; they must be identity and one).
// Unsupported, reported as kUnsupported: quaternion or scale channels, names
// that are empty or contain '{', '}' or a line end, leading/trailing blanks.

#include <string>

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace mocap {

// The BVH text of `skeleton` and `motion` (motion.num_channels must equal
// skeleton.num_channels and values hold #F x #C floats; kInvalidArgument if not).
[[nodiscard]] base::Result<std::string> FormatBvh(const Skeleton& skeleton, const Motion& motion);

// Writes FormatBvh's text to `path`: first to "<path>.tmp", then renamed over
// `path`, so a reader never sees a half-written file. kIo on failure.
[[nodiscard]] base::Status WriteBvhFile(const std::string& path, const Skeleton& skeleton,
                                        const Motion& motion);

}  // namespace mocap
