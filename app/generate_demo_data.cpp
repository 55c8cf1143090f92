// Writes the motions the project ships in samples/data, from the synthetic
// humanoid (mocap/synthetic.h), as BVH:
//   generate_demo_data OUT.bvh          three cycles of the walk (the built-in demo)
//   generate_demo_data --bend OUT.bvh   elbows and left knee bending 0 -> 150 degrees
//                                       over 2 s (samples/data/bend.bvh, for the
//                                       elbow_knee.json rig)

#include <cstdio>
#include <string>

#include "mocap/bvh_writer.h"
#include "mocap/synthetic.h"

int main(int argc, char** argv) {
  const bool bend = argc == 3 && std::string(argv[1]) == "--bend";
  if (argc != 2 && !bend) {
    std::fprintf(stderr, "usage: generate_demo_data [--bend] OUT.bvh\n");
    return 1;
  }
  const mocap::Skeleton skeleton = mocap::MakeHumanoidSkeleton();
  mocap::WalkOptions walk;
  walk.num_cycles = 3;
  const mocap::Result<mocap::Motion> motion =
      bend ? mocap::MakeBendRamp(skeleton, 150.0f, 2.0) : mocap::MakeWalkMotion(skeleton, walk);
  if (!motion.ok()) {
    std::fprintf(stderr, "%s\n", motion.error().ToString().c_str());
    return 2;
  }
  const mocap::Status s = mocap::WriteBvhFile(argv[argc - 1], skeleton, *motion);
  if (!s.ok()) {
    std::fprintf(stderr, "%s\n", s.error().ToString().c_str());
    return 2;
  }
  return 0;
}
