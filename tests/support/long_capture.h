#pragma once
// Long captures for the memory and start-up tests: the synthetic humanoid's
// walk (mocap/synthetic.h) at 120 fps, cut to exactly `frames` frames and
// written as a BVH file. 100,000 frames make a ~50 MB file in about a second.

#include <string>

#include "mocap/bvh_writer.h"
#include "mocap/synthetic.h"

namespace testsupport {

// Writes the capture to `path`; returns its channel count (0 on failure).
inline int WriteLongCapture(const std::string& path, int frames) {
  const mocap::Skeleton skeleton = mocap::MakeHumanoidSkeleton();
  mocap::WalkOptions walk;
  walk.frame_time_s = 1.0 / 120.0;
  walk.num_cycles = frames / 120 + 1;  // cycle_s = 1: 120 frames per cycle
  mocap::Result<mocap::Motion> motion = mocap::MakeWalkMotion(skeleton, walk);
  if (!motion.ok() || motion->num_frames < frames) return 0;
  motion->num_frames = frames;
  motion->values.resize(static_cast<std::size_t>(frames) *
                        static_cast<std::size_t>(motion->num_channels));
  if (!mocap::WriteBvhFile(path, skeleton, *motion).ok()) return 0;
  return motion->num_channels;
}

}  // namespace testsupport
