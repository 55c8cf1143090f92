// The body tracker against the SSD frame pipeline it stands in for: joints and
// tracked vertices exactly where the pipeline puts them, hull bounds inside the
// body's bounds and close to them, on the synthetic humanoid's tube body
// walking and bending.

#include <algorithm>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "deform/body/mannequin.h"
#include "deform/pipeline/body_tracker.h"
#include "deform/pipeline/frame_pipeline.h"
#include "tools/synthetic.h"
#include "support/same_bits.h"

namespace {

deform::Character TubeBody(mocap::Motion (*motion)(const mocap::Skeleton&)) {
  deform::Character c;
  c.source = "synthetic";
  c.skeleton = synthetic::MakeHumanoidSkeleton();
  c.motion = motion(c.skeleton);
  const std::vector<glm::mat4> bind = deform::BindModelFromJoint(c).value();
  c.mesh = deform::BuildMannequin(c.skeleton, bind).value();
  return c;
}

mocap::Motion Walk(const mocap::Skeleton& s) { return synthetic::MakeWalkMotion(s).value(); }
mocap::Motion Bend(const mocap::Skeleton& s) { return synthetic::MakeBendRamp(s, 150.0f).value(); }

using testsupport::SameBits;

TEST(BodyTracker, JointsAndTrackedVerticesAreTheSsdFramesAndTheHullIsInsideItsBounds) {
  for (auto* motion : {&Walk, &Bend}) {
    const deform::Character c = TubeBody(motion);
    const std::vector<int> tracked = {0, 17, c.mesh.bind.num_vertices() - 1, 17};
    deform::BodyTracker tracker = deform::BodyTracker::Create(c, tracked).value();
    deform::FramePipeline ssd =
        deform::FramePipeline::Create(c, deform::GlobalMethod::kSsd, 1).value();
    // A sparse hull: a few points per part, not the mesh.
    EXPECT_LE(tracker.hull_vertices().size(), 98 * c.mesh.skin_joints.size());
    EXPECT_LT(tracker.hull_vertices().size() * 4, c.mesh.bind.positions.size());
    deform::TrackedBody body;
    deform::DeformedFrame frame;
    const double duration = c.motion.frame_time_s * (c.motion.num_frames - 1);
    for (int i = 0; i <= 20; ++i) {
      const double t = duration * i / 20.0;
      ASSERT_TRUE(tracker.Sample(t, body).ok());
      ASSERT_TRUE(ssd.Evaluate(t, frame).ok());
      EXPECT_TRUE(SameBits(body.joint_positions, frame.joint_positions)) << t;
      std::vector<glm::vec3> expected;
      for (const int v : tracked) expected.push_back(frame.positions[static_cast<std::size_t>(v)]);
      EXPECT_TRUE(SameBits(body.tracked, expected)) << t;
      // Inside: hull points are skinned vertices. Close: within 1.5% of the
      // body's largest extent on every side.
      const glm::vec3 size = frame.bounds.size();
      const float extent = std::max({size.x, size.y, size.z});
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(body.hull_bounds.min[a], frame.bounds.min[a]) << t;
        EXPECT_LE(body.hull_bounds.max[a], frame.bounds.max[a]) << t;
        EXPECT_LE(body.hull_bounds.min[a] - frame.bounds.min[a], 0.015f * extent) << t << " " << a;
        EXPECT_LE(frame.bounds.max[a] - body.hull_bounds.max[a], 0.015f * extent) << t << " " << a;
      }
    }
  }
}

TEST(BodyTracker, RefusesATrackedIndexOutsideTheMesh) {
  const deform::Character c = TubeBody(&Walk);
  for (const int bad : {-1, c.mesh.bind.num_vertices()}) {
    const std::vector<int> tracked = {0, bad};
    base::Result<deform::BodyTracker> t = deform::BodyTracker::Create(c, tracked);
    ASSERT_FALSE(t.ok());
    EXPECT_EQ(t.error().code, base::ErrorCode::kInvalidArgument);
    EXPECT_NE(t.error().message.find("tracked vertex " + std::to_string(bad)), std::string::npos)
        << t.error().message;
  }
}

}  // namespace
