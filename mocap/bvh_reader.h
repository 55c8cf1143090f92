#pragma once
// BVH import: text -> (Skeleton, Motion, warnings).
//
// Output conventions
// - Joints come in file order, which is parent-before-child; several ROOTs give
//   several trees (kNoParent parents). Rest rotations are identity, rest scales
//   one, rest translations the OFFSETs; end sites are kept with their parent.
// - Motion is one contiguous #F x #C float array in the file's column order;
//   rotation channels stay in degrees and in the file's Euler order.
// - Position channels (see PositionChannelMode): by default they are the joint's
//   whole local translation and replace OFFSET (Blender, Assimp; LAFAN-style
//   files repeat the offsets in every frame). kAddToOffset adds them to OFFSET
//   (three.js). The mode is stored in Skeleton::position_mode; pose.h applies it.
// - Axes: the file's axes are kept unless `convert_to_y_up` is set and the file
//   is Z-up, in which case every offset, end site and channel is rotated by
//   -90 degrees about X, (x, y, z) -> (x, z, -y): Yposition becomes Zposition
//   (negated), Zposition becomes Yposition, Yrotation becomes Zrotation (negated),
//   Zrotation becomes Yrotation. The Euler order is kept, so poses are exactly
//   the rotated poses of the file. SkeletonInfo::up_axis then says kY.
//
// Detection rules (reported in SkeletonInfo, used by `inspect`)
// - Up axis: each bone (the OFFSET of a non-root joint without position
//   channels, and of every end site; if that leaves none, every non-root joint)
//   votes for the axis, Y or Z, on which its offset is longest, when that axis is
//   also its longest overall. More Z votes than Y votes means Z-up. Legs, spine
//   and neck are vertical in a rest pose and outnumber the forward-pointing feet;
//   arms, along X in the usual T-pose, do not vote.
// - The rule above decides from the rest pose alone, which need not be the pose
//   the capture is seen in: some files have Z-up OFFSETs and a root rotation in
//   every frame that stands the body Y-up (or the reverse). So the animated
//   poses decide first, by the limbs that hold the body up: from the hips (the
//   first joint below the root with two or more children) to the knee of each
//   limb but the spine (legs, a tail; the knee is the first joint down the limb
//   40% of its rest reach from the hips). In up to 32 frames spread evenly over
//   the motion each such thigh votes for the axis, Y or Z, it mostly lies
//   along; each frame goes to the axis most thighs vote for, and the axis most
//   frames go to is the up axis (SkeletonInfo::up_axis_source kAnimatedPoses).
//   Thighs hang down when walking, running, crawling on hands and knees or on
//   four legs, where spine and shins can lie flat. Without frames or limbs, or
//   with as many frames for each axis, the rest rule decides (kRestPose).
// - Height: extent along the up axis of the rest positions of all joints and end
//   sites (offsets chained from the roots at the origin), after scale.
// - Units from h = the larger of that rest height and the same extent in the
//   first frame's pose (some rest poses do not stand upright: Bandai Namco's
//   bones lie along X), before scale, for a human-sized figure:
//   0.5 <= h <= 3 -> "m"; 40 <= h < 100 -> "inch"; 100 <= h <= 300 -> "cm";
//   otherwise "unknown" (e.g. CMU cgspeed files, ~26 units tall).
//
// Errors (codes from base::ErrorCode, messages "file:line:col: error: ...")
// - Every frame is one non-blank line holding exactly #C numbers; a short or long
//   line is kCountMismatch "expected 96 values in frame 118, found 95".
// - A number must fill its whole token; NaN, infinity and overflow are kNonFinite.
// - More data lines than "Frames:" declares: the declared frames are loaded and a
//   warning names the extra lines. Fewer: kCountMismatch naming both counts,
//   unless allow_short_motion, which loads the complete frames found and warns.
// - The frame array is never sized from the declared count alone: at most
//   (bytes left + 1) / (2 * #C) frames can fit in the rest of the file, and no
//   more are allocated.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mocap/bvh_document.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace mocap {

struct BvhReadOptions {
  // Factor applied to offsets, end sites and position channels. 0 means
  // automatic: convert the detected units to metres (cm 0.01, inch 0.0254, m 1;
  // "unknown" keeps 1 and warns). Negative or non-finite is kInvalidArgument.
  float scale = 1.0f;
  // The file's up axis; empty = detect (rule above).
  std::optional<UpAxis> up_axis;
  // Rotate a Z-up file to Y-up (see above). No effect on a Y-up file.
  bool convert_to_y_up = false;
  PositionChannelMode position_mode = PositionChannelMode::kReplaceOffset;
  // Load the complete frames of a file with fewer data lines than declared.
  bool allow_short_motion = false;
  int max_depth = kDefaultBvhMaxDepth;  // deepest ROOT/JOINT nesting (ROOT = 1)
  int max_joints = kMaxJoints;          // most joints; values above kMaxJoints mean kMaxJoints
  // Frame data of at least this many bytes is parsed on two threads at once,
  // block by block (see block_bytes), so an hour-long capture loads in about
  // half the time. The result is the sequential pass's to the bit; any error,
  // short file or extra line falls back to the sequential pass, whose
  // messages are the reference. SIZE_MAX turns it off.
  std::size_t parallel_min_bytes = std::size_t{8} << 20;
  // Frame data is read in blocks of about this many bytes (a block ends at
  // the first line end at or after it; 0 counts as 1). The two threads take
  // blocks in file order and append their frames in that order, so besides
  // the final #F x #C array at most one block's floats per thread are held.
  // ReadBvhFile gives each block's pages of the mapped file back once parsed
  // (the sequential pass too, every block_bytes), so its peak memory is the
  // frame array plus a few blocks, not the file's size. Results and messages
  // do not depend on it; small values are for tests.
  std::size_t block_bytes = std::size_t{4} << 20;
};

struct BvhFile {
  Skeleton skeleton;
  Motion motion;
  std::vector<base::Warning> warnings;  // non-fatal findings, in file order where possible
};

// Parses a whole BVH text. `file_name_for_messages` only labels errors and warnings.
[[nodiscard]] base::Result<BvhFile> ParseBvh(std::string_view text,
                                             const std::string& file_name_for_messages,
                                             const BvhReadOptions& options = {});

// Maps `path` into memory (mmap, read-only) and parses it, giving the frame
// data's pages back as they are parsed (BvhReadOptions::block_bytes): peak
// memory is the motion's floats plus a few blocks. kIo when it cannot be
// opened, is not a regular file or cannot be mapped.
[[nodiscard]] base::Result<BvhFile> ReadBvhFile(const std::string& path,
                                                const BvhReadOptions& options = {});

// Detection helpers (rules above), exposed for tests and `inspect`.
UpAxis DetectBvhUpAxis(const Skeleton& skeleton);
// The up axis from the animated poses (rule above), the rest rule deciding a
// tie; `source` (optional) says which decided. Cost: 32 poses of #J joints.
UpAxis DetectBvhUpAxisFromPoses(const Skeleton& skeleton, const Motion& motion,
                                UpAxisSource* source = nullptr);
// Extent along `up` of the rest positions of all joints and end sites.
float RestHeight(const Skeleton& skeleton, UpAxis up);
// Extent along `up` of joints and end sites posed by frame 0 (0 without frames).
float FirstFrameHeight(const Skeleton& skeleton, const Motion& motion, UpAxis up);
// "m", "inch", "cm" or "unknown" for a figure's height.
const char* DetectUnits(float rest_height);
// Metres per unit of DetectUnits's names (m 1, cm 0.01, inch 0.0254); 0 for "unknown".
float MetresPerUnit(std::string_view units);

// Multiplies offsets, end sites and position channels of `motion` by `factor`.
void ScaleSkeletonAndMotion(float factor, Skeleton* skeleton, Motion* motion);
// Rotates a Z-up skeleton and motion to Y-up as described above.
void ConvertZUpToYUp(Skeleton* skeleton, Motion* motion);

}  // namespace mocap
