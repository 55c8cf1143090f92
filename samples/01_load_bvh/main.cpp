// Sample 01: load a BVH capture, print its skeleton and evaluate one frame.
// Usage: sample_01_load_bvh FILE.bvh [FRAME]

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "mocap/bvh_reader.h"
#include "mocap/pose.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE.bvh [FRAME]\n", argv[0]);
    return 1;
  }
  // Untrusted input comes back as a Result: a value, or an Error with file:line:column.
  base::Result<mocap::BvhFile> file = mocap::ReadBvhFile(argv[1]);
  if (!file.ok()) {
    std::fprintf(stderr, "%s\n", file.error().ToString().c_str());
    return 2;
  }
  for (const base::Warning& w : file->warnings) std::fprintf(stderr, "%s\n", w.ToString().c_str());
  const mocap::Skeleton& skeleton = file->skeleton;
  const mocap::Motion& motion = file->motion;
  std::printf("%d joints, %d channels, %d frames at %g fps, units %s\n", skeleton.num_joints(),
              skeleton.num_channels, motion.num_frames, mocap::NominalFps(motion.frame_time_s),
              skeleton.info.detected_units.c_str());

  const int frame = argc > 2 ? std::atoi(argv[2]) : 0;
  if (motion.num_frames == 0 || frame < 0 || frame >= motion.num_frames) {
    std::fprintf(stderr, "%s: error: frame %d is not in 0..%d\n", argv[1], frame, motion.num_frames - 1);
    return 2;
  }
  // Jobs take spans of caller-owned buffers: channel values -> local transforms -> model matrices.
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(skeleton.num_joints()));
  std::vector<glm::mat4> model(locals.size());
  if (!mocap::LocalPoseJob{&skeleton, motion.frame(frame), locals}.Run() ||
      !mocap::LocalToModelJob{.parents = skeleton.parents, .locals = locals, .model_from_joint = model}
           .Run()) {
    std::fprintf(stderr, "internal error: a pose job refused to run\n");
    return 3;
  }
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const glm::vec3 p(model[static_cast<std::size_t>(j)][3]);
    std::printf("  %-24s %10.4f %10.4f %10.4f\n", skeleton.names[static_cast<std::size_t>(j)].c_str(),
                p.x, p.y, p.z);
  }
  return 0;
}
