// Writes the motions the project ships in samples/data, from the synthetic
// humanoid (mocap/synthetic.h), as BVH:
//   generate_demo_data OUT.bvh              three cycles of the walk (the built-in demo)
//   generate_demo_data --bend OUT.bvh       elbows and left knee bending 0 -> 150 degrees
//                                           over 2 s (samples/data/bend.bvh: the
//                                           elbow_knee, elbow, biceps and knee rigs)
//   generate_demo_data --shoulder OUT.bvh   the left arm visiting five poses from the
//                                           T-pose (samples/data/shoulder.bvh)
//   generate_demo_data --hip OUT.bvh        the left leg stretching back, then lifting
//                                           forward (samples/data/hip.bvh)

#include <cstdio>
#include <string>

#include "mocap/bvh_writer.h"
#include "mocap/synthetic.h"

int main(int argc, char** argv) {
  const std::string mode = argc == 3 ? argv[1] : "";
  if (argc != 2 && mode != "--bend" && mode != "--shoulder" && mode != "--hip") {
    std::fprintf(stderr, "usage: generate_demo_data [--bend | --shoulder | --hip] OUT.bvh\n");
    return 1;
  }
  const mocap::Skeleton skeleton = mocap::MakeHumanoidSkeleton();
  mocap::WalkOptions walk;
  walk.num_cycles = 3;
  const mocap::Result<mocap::Motion> motion =
      mode == "--bend"       ? mocap::MakeBendRamp(skeleton, 150.0f, 2.0)
      : mode == "--shoulder" ? mocap::MakeShoulderSweep(skeleton)
      : mode == "--hip"      ? mocap::MakeHipSwing(skeleton)
                             : mocap::MakeWalkMotion(skeleton, walk);
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
