// The elastic layer's kinematics sampler (deform/elastic/internal/driving_sampler.h)
// against mocap::SampleJointKinematics: the same bits at RK4 stage times, frame
// times, both ends and outside the clip, for every joint of a walk and a jump
// (slow and fast turning, so both branches of the slerp and the shorter-arc flip run).

#include "deform/elastic/internal/driving_sampler.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "support/fast_turns_clip.h"
#include "mocap/kinematics.h"
#include "mocap/synthetic.h"

namespace {

bool SameBits(const glm::quat& a, const glm::quat& b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool SameBits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSame(const std::vector<mocap::JointKinematics>& kin, int nj, double h, double end) {
  int compared = 0, slerped = 0;
  for (int j = 0; j < nj; ++j) {
    deform::internal::KinematicsDrivingSampler sampler(kin, nj, j, h);
    std::vector<double> times = {-1.0, 0.0, end, end + 0.3, 0.5 * h, 2.0 * h};
    for (double t = -0.01; t < end + 0.02; t += 1.0 / 480) times.push_back(t);  // stage times
    for (double t = end; t > 0.0; t -= 0.37 * h) times.push_back(t);           // backwards
    for (const double t : times) {
      mocap::JointKinematics k;
      ASSERT_TRUE(mocap::SampleJointKinematics(kin, nj, j, h, t, &k));
      const deform::DrivingFrame d = sampler.Sample(t);
      ASSERT_TRUE(SameBits(d.rotation, k.rotation)) << "joint " << j << " t " << t;
      ASSERT_TRUE(SameBits(d.linear_acceleration, k.local_linear_acceleration)) << j << " " << t;
      ASSERT_TRUE(SameBits(d.angular_velocity, k.local_angular_velocity)) << j << " " << t;
      ASSERT_TRUE(SameBits(d.angular_acceleration, k.local_angular_acceleration)) << j << " " << t;
      ++compared;
      slerped += glm::length(k.angular_velocity) > 1.0f;
    }
  }
  EXPECT_GT(compared, 500);
  EXPECT_GT(slerped, 100);  // turning joints, not only the nearly-equal lerp branch
}

void ExpectSameAsSampleJointKinematics(const mocap::Skeleton& skel, const mocap::Motion& motion) {
  ExpectSame(mocap::ComputeKinematics(skel, motion).value(), skel.num_joints(),
             motion.frame_time_s, motion.duration_s());
}

TEST(KinematicsDrivingSampler, JumpAt120FpsMatchesSampleJointKinematics) {
  const mocap::Skeleton skel = mocap::MakeHumanoidSkeleton();
  mocap::JumpOptions options;
  options.frame_time_s = 1.0 / 120;
  ExpectSameAsSampleJointKinematics(skel, mocap::MakeJumpMotion(skel, options).value());
}

TEST(KinematicsDrivingSampler, WalkAt30FpsMatchesSampleJointKinematics) {
  const mocap::Skeleton skel = mocap::MakeHumanoidSkeleton();
  ExpectSameAsSampleJointKinematics(skel, mocap::MakeWalkMotion(skel).value());
}

// One joint turning 0.9 rad per frame with every other quaternion negated (the
// shorter-arc flip) and a stretch of identical frames (the lerp branch).
TEST(KinematicsDrivingSampler, FastTurnsAndSignFlipsMatchSampleJointKinematics) {
  const std::vector<mocap::JointKinematics> kin = test_clips::FastTurnsClip();
  ExpectSame(kin, 1, 1.0 / 30, 39.0 / 30);
}

}  // namespace
