// Writes the motions the project ships in samples/data, from the synthetic
// humanoid (tools/synthetic.h), as BVH:
//   generate_demo_data OUT.bvh              three cycles of the walk (the built-in demo)
//   generate_demo_data --bend OUT.bvh       elbows and left knee bending 0 -> 150 degrees
//                                           over 2 s (samples/data/bend.bvh: the
//                                           elbow_knee, elbow, biceps and knee rigs)
//   generate_demo_data --shoulder OUT.bvh   the left arm visiting five poses from the
//                                           T-pose (samples/data/shoulder.bvh)
//   generate_demo_data --hip OUT.bvh        the left leg stretching back, then lifting
//                                           forward (samples/data/hip.bvh)
//   generate_demo_data --jump OUT.bvh       the synthetic vertical jump at 30 fps, then
//                                           1.5 s standing still (samples/data/jump.bvh,
//                                           for belly_jump.json: the belly jiggles after
//                                           landing and settles while the body stands)
//   generate_demo_data --shake OUT.bvh      standing still, the head shaking "no"
//                                           (3 Hz, +-25 degrees about the neck's and
//                                           head's Y axes) from 0.5 to 1.5 s, then still
//                                           for 1.5 s (samples/data/head_shake.bvh, for
//                                           jowl.json); the shake stops at full speed

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "mocap/bvh_writer.h"
#include "tools/synthetic.h"

namespace {

constexpr double kStillAfterS = 1.5;

// Appends `seconds` of the last frame held still.
void HoldLastFrame(mocap::Motion& m, double seconds) {
  const int extra = static_cast<int>(std::lround(seconds / m.frame_time_s));
  const std::size_t nc = static_cast<std::size_t>(m.num_channels);
  const std::size_t last = static_cast<std::size_t>(m.num_frames - 1) * nc;
  for (int f = 0; f < extra; ++f) {
    for (std::size_t c = 0; c < nc; ++c) m.values.push_back(m.values[last + c]);
  }
  m.num_frames += extra;
}

// The Y rotation channel of `joint`, or -1.
int YRotationChannel(const mocap::Skeleton& s, const char* joint) {
  const int j = s.FindJoint(joint);
  if (j < 0) return -1;
  const mocap::JointChannels& ch = s.channels[static_cast<std::size_t>(j)];
  for (int k = 0; k < ch.count; ++k) {
    if (ch.types[static_cast<std::size_t>(k)] == mocap::ChannelType::kYRotation) {
      return static_cast<int>(ch.first) + k;
    }
  }
  return -1;
}

// Standing (the jump's first frame) with a head shake; see the file comment.
base::Result<mocap::Motion> MakeHeadShake(const mocap::Skeleton& skeleton) {
  synthetic::JumpOptions jump;
  jump.frame_time_s = 1.0 / 60.0;
  base::Result<mocap::Motion> stand = synthetic::MakeJumpMotion(skeleton, jump);
  if (!stand.ok()) return stand;
  mocap::Motion m = std::move(*stand);
  m.values.resize(static_cast<std::size_t>(m.num_channels));  // frame 0 only
  m.num_frames = 1;
  HoldLastFrame(m, 0.5 + 1.0 + kStillAfterS);
  const int neck = YRotationChannel(skeleton, "Neck"), head = YRotationChannel(skeleton, "Head");
  if (neck < 0 || head < 0) {
    return base::MakeError(base::ErrorCode::kNotFound, {"synthetic", 0, 0, {}},
                           "expected Neck and Head joints with Y rotation channels");
  }
  for (int f = 0; f < m.num_frames; ++f) {
    const double t = f * m.frame_time_s - 0.5;
    if (t <= 0.0 || t >= 1.0) continue;
    const double angle = 25.0 * std::sin(2.0 * std::numbers::pi * 3.0 * t);
    const std::size_t row = static_cast<std::size_t>(f) * static_cast<std::size_t>(m.num_channels);
    m.values[row + static_cast<std::size_t>(neck)] += static_cast<float>(0.4 * angle);
    m.values[row + static_cast<std::size_t>(head)] += static_cast<float>(0.6 * angle);
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc == 3 ? std::string(argv[1]) : std::string();
  if (argc != 2 && mode != "--bend" && mode != "--jump" && mode != "--shake" &&
      mode != "--shoulder" && mode != "--hip") {
    std::fprintf(
        stderr,
        "usage: generate_demo_data [--bend | --jump | --shake | --shoulder | --hip] OUT.bvh\n");
    return 1;
  }
  const mocap::Skeleton skeleton = synthetic::MakeHumanoidSkeleton();
  synthetic::WalkOptions walk;
  walk.num_cycles = 3;
  base::Result<mocap::Motion> motion = synthetic::MakeWalkMotion(skeleton, walk);
  if (mode == "--bend") motion = synthetic::MakeBendRamp(skeleton, 150.0f, 2.0);
  if (mode == "--shoulder") motion = synthetic::MakeShoulderSweep(skeleton);
  if (mode == "--hip") motion = synthetic::MakeHipSwing(skeleton);
  if (mode == "--shake") motion = MakeHeadShake(skeleton);
  if (mode == "--jump") {
    motion = synthetic::MakeJumpMotion(skeleton, {});
    if (motion.ok()) HoldLastFrame(*motion, kStillAfterS);
  }
  if (!motion.ok()) {
    std::fprintf(stderr, "%s\n", motion.error().ToString().c_str());
    return 2;
  }
  const base::Status s = mocap::WriteBvhFile(argv[argc - 1], skeleton, *motion);
  if (!s.ok()) {
    std::fprintf(stderr, "%s\n", s.error().ToString().c_str());
    return 2;
  }
  return 0;
}
