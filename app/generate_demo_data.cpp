// Writes the built-in demo's motion: three cycles of the synthetic walk on the
// synthetic humanoid (mocap/synthetic.h), as BVH. Usage: generate_demo_data OUT.bvh

#include <cstdio>

#include "mocap/bvh_writer.h"
#include "mocap/synthetic.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: generate_demo_data OUT.bvh\n");
    return 1;
  }
  const mocap::Skeleton skeleton = mocap::MakeHumanoidSkeleton();
  mocap::WalkOptions walk;
  walk.num_cycles = 3;
  const mocap::Result<mocap::Motion> motion = mocap::MakeWalkMotion(skeleton, walk);
  if (!motion.ok()) {
    std::fprintf(stderr, "%s\n", motion.error().ToString().c_str());
    return 2;
  }
  const mocap::Status s = mocap::WriteBvhFile(argv[1], skeleton, *motion);
  if (!s.ok()) {
    std::fprintf(stderr, "%s\n", s.error().ToString().c_str());
    return 2;
  }
  return 0;
}
