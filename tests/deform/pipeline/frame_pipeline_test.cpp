// The global layer's one interface (GlobalSkinning) against the jobs it
// dispatches to, and the frame pipeline against an independent composition of
// the public jobs, on the synthetic humanoid's tube body bending its elbows
// and knee.

#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "deform/body/mannequin.h"
#include "deform/global/dqs_job.h"
#include "deform/global/global_skinning.h"
#include "deform/global/skinning_job.h"
#include "deform/global/swd_rig.h"
#include "deform/pipeline/frame_pipeline.h"
#include "mocap/pose.h"
#include "mocap/sampling.h"
#include "tools/synthetic.h"
#include "support/same_bits.h"

namespace {

using deform::GlobalMethod;

constexpr GlobalMethod kMethods[] = {GlobalMethod::kSsd, GlobalMethod::kDqs, GlobalMethod::kSwd};

const deform::Character& BendingBody() {
  static const deform::Character character = [] {
    deform::Character c;
    c.source = "synthetic bend";
    c.skeleton = synthetic::MakeHumanoidSkeleton();
    c.motion = synthetic::MakeBendRamp(c.skeleton, 120.0f).value();
    const std::vector<glm::mat4> bind = deform::BindModelFromJoint(c).value();
    c.mesh = deform::BuildMannequin(c.skeleton, bind).value();
    return c;
  }();
  return character;
}

// The model-space joint matrices at time t, by the public jobs.
std::vector<glm::mat4> PoseAt(const deform::Character& c, double t) {
  const auto nj = static_cast<std::size_t>(c.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj), scratch(nj);
  std::vector<glm::mat4> model(nj);
  EXPECT_TRUE((mocap::SampleLocalsJob{.skeleton = &c.skeleton,
                                      .motion = &c.motion,
                                      .time_s = t,
                                      .scratch = scratch,
                                      .locals = locals}
                   .Run()));
  EXPECT_TRUE((mocap::LocalToModelJob{
      .parents = c.skeleton.parents, .locals = locals, .model_from_joint = model}
                   .Run()));
  return model;
}

using testsupport::SameBits;

deform::GlobalSkinning Posed(GlobalMethod method, const std::vector<glm::mat4>& pose) {
  const deform::Character& c = BendingBody();
  const std::vector<glm::mat4> bind = deform::BindModelFromJoint(c).value();
  deform::GlobalSkinning g =
      deform::GlobalSkinning::Create(method, c.skeleton, bind, c.mesh).value();
  EXPECT_TRUE(g.Pose(pose));
  return g;
}

// What the jobs themselves give for the whole mesh at `pose`.
std::vector<glm::vec3> SkinnedByTheJob(GlobalMethod method, const std::vector<glm::mat4>& pose) {
  const deform::Character& c = BendingBody();
  const deform::SkinnedMesh& m = c.mesh;
  std::vector<glm::vec3> out(m.bind.positions.size()), normals(out.size());
  std::vector<glm::mat4> palette(m.skin_joints.size());
  EXPECT_TRUE(deform::BuildSkinningPalette(pose, m, palette));
  if (method == GlobalMethod::kSsd) {
    EXPECT_TRUE((deform::SkinningJob{.model_from_bind = palette,
                                     .influences = m.weights.influences,
                                     .joint_indices = m.weights.joints,
                                     .joint_weights = m.weights.weights,
                                     .rest_positions = m.bind.positions,
                                     .rest_normals = m.bind.normals,
                                     .positions = out,
                                     .normals = normals}
                     .Run()));
  } else if (method == GlobalMethod::kDqs) {
    std::vector<deform::DualQuat> dq(palette.size());
    EXPECT_TRUE(deform::BuildDualQuatPalette(palette, dq));
    EXPECT_TRUE((deform::DqsJob{.palette = dq,
                                .influences = m.weights.influences,
                                .joint_indices = m.weights.joints,
                                .joint_weights = m.weights.weights,
                                .rest_positions = m.bind.positions,
                                .rest_normals = m.bind.normals,
                                .positions = out,
                                .normals = normals}
                     .Run()));
  } else {
    const std::vector<glm::mat4> bind = deform::BindModelFromJoint(c).value();
    const deform::SwdRig rig =
        deform::BuildSwdRig(c.skeleton, bind, m.bind, {.vertex_chains = m.body_chain_coords})
            .value();
    std::vector<glm::quat> rotations(pose.size());
    std::vector<glm::vec3> joints(pose.size());
    EXPECT_TRUE((deform::SwdRigJob{.rig = &rig,
                                   .model_from_joint = pose,
                                   .vertex_begin = 0,
                                   .joint_rotations = rotations,
                                   .joint_positions = joints,
                                   .keep_volume = false,
                                   .positions = out,
                                   .normals = normals}
                     .Run()));
  }
  return out;
}

TEST(GlobalSkinning, SkinsLikeItsJobWhateverTheSplit) {
  const deform::Character& c = BendingBody();
  const std::vector<glm::mat4> pose = PoseAt(c, 1.5);
  const int nv = c.mesh.bind.num_vertices();
  for (const GlobalMethod method : kMethods) {
    SCOPED_TRACE(deform::GlobalMethodName(method));
    const deform::GlobalSkinning g = Posed(method, pose);
    std::vector<glm::vec3> whole(static_cast<std::size_t>(nv)), normals(whole.size());
    ASSERT_TRUE(g.SkinVertices(0, nv, whole, normals));
    std::vector<glm::vec3> split(whole.size()), split_normals(whole.size());
    for (const auto& [begin, end] : {std::pair{0, 7}, {7, nv / 3}, {nv / 3, nv}}) {
      ASSERT_TRUE(g.SkinVertices(begin, end, split, split_normals));
    }
    EXPECT_TRUE(SameBits(whole, split));
    EXPECT_TRUE(SameBits(normals, split_normals));
    EXPECT_TRUE(SameBits(whole, SkinnedByTheJob(method, pose)));
    // The elbows bent: the result is not the rest shape.
    EXPECT_FALSE(SameBits(whole, c.mesh.bind.positions));
  }
}

TEST(GlobalSkinning, PointsBoundWithAVertexsWeightsFollowIt) {
  const deform::Character& c = BendingBody();
  const std::vector<glm::mat4> pose = PoseAt(c, 2.0);
  const deform::SkinWeights& w = c.mesh.weights;
  const auto k = static_cast<std::size_t>(w.influences);
  // Every 97th vertex as a free point with that vertex's weights.
  std::vector<int> picked;
  for (int v = 0; v < c.mesh.bind.num_vertices(); v += 97) picked.push_back(v);
  std::vector<glm::vec3> rest;
  deform::SkinWeights weights{.influences = w.influences, .joints = {}, .weights = {}};
  for (const int v : picked) {
    const auto at = static_cast<std::size_t>(v);
    rest.push_back(c.mesh.bind.positions[at]);
    weights.joints.insert(weights.joints.end(), w.joints.begin() + at * k,
                          w.joints.begin() + (at + 1) * k);
    weights.weights.insert(weights.weights.end(), w.weights.begin() + at * k,
                           w.weights.begin() + (at + 1) * k);
  }
  for (const GlobalMethod method : {GlobalMethod::kSsd, GlobalMethod::kDqs}) {
    SCOPED_TRACE(deform::GlobalMethodName(method));
    const deform::GlobalSkinning g = Posed(method, pose);
    const deform::SkinBoundPoints points = g.BindPoints(rest, weights, {}).value();
    std::vector<glm::vec3> carried(rest.size());
    ASSERT_TRUE(g.CarryPoints(points, carried));
    std::vector<glm::vec3> skinned(c.mesh.bind.positions.size());
    ASSERT_TRUE(g.SkinVertices(0, c.mesh.bind.num_vertices(), skinned, {}));
    for (std::size_t i = 0; i < picked.size(); ++i) {
      EXPECT_EQ(carried[i], skinned[static_cast<std::size_t>(picked[i])]) << "vertex " << picked[i];
    }
  }
  // SWD binds points by their guide vertex's sweeps; at the bind pose they
  // come back where they were (ALGORITHMS.md 2.3).
  const std::vector<glm::mat4> bind = deform::BindModelFromJoint(c).value();
  const deform::GlobalSkinning swd = Posed(GlobalMethod::kSwd, bind);
  const deform::SkinBoundPoints points = swd.BindPoints(rest, weights, picked).value();
  std::vector<glm::vec3> carried(rest.size());
  ASSERT_TRUE(swd.CarryPoints(points, carried));
  for (std::size_t i = 0; i < rest.size(); ++i) {
    EXPECT_LT(glm::distance(carried[i], rest[i]), 1e-3f) << "vertex " << picked[i];
  }
  // A count that differs from the bound points is refused.
  std::vector<glm::vec3> short_out(rest.size() - 1);
  EXPECT_FALSE(swd.CarryPoints(points, short_out));
}

TEST(FramePipeline, FramesAreTheJobsAtTheSampledPoseForAnyThreadCount) {
  const deform::Character& c = BendingBody();
  for (const GlobalMethod method : kMethods) {
    SCOPED_TRACE(deform::GlobalMethodName(method));
    deform::FramePipeline one = deform::FramePipeline::Create(c, method, 1).value();
    deform::FramePipeline three = deform::FramePipeline::Create(c, method, 3).value();
    for (const double t : {0.0, 0.7, 2.0}) {
      deform::DeformedFrame a, b;
      ASSERT_TRUE(one.Evaluate(t, a).ok());
      ASSERT_TRUE(three.Evaluate(t, b).ok());
      EXPECT_TRUE(SameBits(a.positions, b.positions)) << "t = " << t;
      EXPECT_TRUE(SameBits(a.normals, b.normals)) << "t = " << t;
      const std::vector<glm::mat4> pose = PoseAt(c, t);
      EXPECT_TRUE(SameBits(a.positions, SkinnedByTheJob(method, pose))) << "t = " << t;
      ASSERT_EQ(a.joint_positions.size(), pose.size());
      for (std::size_t j = 0; j < pose.size(); ++j) {
        EXPECT_EQ(a.joint_positions[j], glm::vec3(pose[j][3]));
      }
      for (const glm::vec3& n : a.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
    }
  }
}

}  // namespace
