#pragma once
// Long captures for the memory and start-up tests: the synthetic humanoid's
// walk (tools/synthetic.h) at 120 fps, cut to exactly `frames` frames and
// written as a BVH file. 100,000 frames make a ~50 MB file in about a second.

#include <string>
#include <utility>

#include "mocap/bvh_writer.h"
#include "tools/synthetic.h"

namespace testsupport {

// The capture's skeleton and motion; false if the walk could not be made that long.
inline bool LongCaptureMotion(int frames, mocap::Skeleton* skeleton, mocap::Motion* motion) {
  *skeleton = synthetic::MakeHumanoidSkeleton();
  synthetic::WalkOptions walk;
  walk.frame_time_s = 1.0 / 120.0;
  walk.num_cycles = frames / 120 + 1;  // cycle_s = 1: 120 frames per cycle
  base::Result<mocap::Motion> made = synthetic::MakeWalkMotion(*skeleton, walk);
  if (!made.ok() || made->num_frames < frames) return false;
  *motion = std::move(made).value();
  motion->num_frames = frames;
  motion->values.resize(static_cast<std::size_t>(frames) *
                        static_cast<std::size_t>(motion->num_channels));
  return true;
}

// Writes the capture to `path`; returns its channel count (0 on failure).
inline int WriteLongCapture(const std::string& path, int frames) {
  mocap::Skeleton skeleton;
  mocap::Motion motion;
  if (!LongCaptureMotion(frames, &skeleton, &motion)) return 0;
  if (!mocap::WriteBvhFile(path, skeleton, motion).ok()) return 0;
  return motion.num_channels;
}

// The capture as BVH text (75 channels, ~450-500 bytes a frame); empty on failure.
inline std::string LongCaptureText(int frames) {
  mocap::Skeleton skeleton;
  mocap::Motion motion;
  if (!LongCaptureMotion(frames, &skeleton, &motion)) return {};
  base::Result<std::string> text = mocap::FormatBvh(skeleton, motion);
  return text.ok() ? std::move(text).value() : std::string();
}

}  // namespace testsupport
