#include "deform/global/rig_artifacts.h"

#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "deform/body/mannequin.h"
#include "deform/global/swd_rig.h"
#include "mocap/pose.h"
#include "tools/synthetic.h"
#include "support/tolerances.h"

namespace {

struct Body {
  mocap::Skeleton skeleton;
  std::vector<glm::mat4> bind;
  deform::SkinnedMesh mesh;
  deform::SwdRig rig;
};

Body SyntheticHumanoidBody() {
  Body b;
  b.skeleton = synthetic::MakeHumanoidSkeleton();
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(b.skeleton.num_joints()));
  mocap::RestPose(b.skeleton, locals);
  b.bind.resize(locals.size());
  EXPECT_TRUE((mocap::LocalToModelJob{.parents = b.skeleton.parents, .locals = locals,
                                     .model_from_joint = b.bind}
                  .Run()));
  auto mesh = deform::BuildMannequin(b.skeleton, b.bind);
  EXPECT_TRUE(mesh.ok());
  b.mesh = std::move(*mesh);
  auto rig = deform::BuildSwdRig(b.skeleton, b.bind, b.mesh.bind);
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  b.rig = std::move(*rig);
  return b;
}

TEST(RigArtifacts, MethodsOrderAsKnownOnTheHumanoidMannequin) {
  const Body b = SyntheticHumanoidBody();
  const std::vector<double> bends = {90.0, 120.0, 150.0};
  const std::vector<double> twists = {90.0, 180.0};
  auto r = deform::MeasureLimbArtifacts(b.skeleton, b.bind, b.mesh, b.rig, bends, twists);
  ASSERT_TRUE(r.ok()) << r.error().ToString();
  ASSERT_EQ(r->size(), 4u);
  int arms_with_wrist = 0;
  for (const deform::LimbArtifacts& l : *r) {
    ASSERT_EQ(l.collapse.size(), bends.size());
    for (const deform::AngleFigures& a : l.collapse) {
      std::printf("%s bend %.0f: SSD %.3f DQS %.3f SWD %.3f\n", l.joint.c_str(), a.degrees,
                  a.figures.ssd, a.figures.dqs, a.figures.swd);
      if (a.degrees < 100.0) continue;
      // SSD collapses more than DQS and SWD at 120 and 150 degrees.
      EXPECT_LT(a.figures.ssd, a.figures.dqs) << l.joint << " " << a.degrees;
      EXPECT_LT(a.figures.ssd, a.figures.swd) << l.joint << " " << a.degrees;
    }
    if (l.candy.empty()) continue;
    ++arms_with_wrist;
    for (const deform::AngleFigures& a : l.candy) {
      std::printf("%s twist %.0f: SSD %.3f DQS %.3f SWD %.3f\n", l.end_joint.c_str(), a.degrees,
                  a.figures.ssd, a.figures.dqs, a.figures.swd);
    }
    const deform::MethodFigures& full = l.candy.back().figures;  // 180 degrees
    EXPECT_LT(full.ssd, testsupport::kCandyWrapperCollapsedMax);
    EXPECT_GT(full.dqs, testsupport::kCandyWrapperKeptMin);
    EXPECT_GT(full.swd, testsupport::kCandyWrapperKeptMin);
  }
  EXPECT_EQ(arms_with_wrist, 2);
}

TEST(RigArtifacts, ErrorsForForeignRigs) {
  const Body b = SyntheticHumanoidBody();
  const std::vector<double> bends = {90.0};
  auto r = deform::MeasureLimbArtifacts(b.skeleton, std::span(b.bind).first(3), b.mesh, b.rig,
                                        bends, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kCountMismatch);
}

}  // namespace
