#include "deform/global/swd_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "deform/body/body_chains.h"
#include "deform/body/mannequin.h"
#include "deform/global/swd_job.h"
#include "mocap/pose.h"
#include "tools/synthetic.h"
#include "support/test_skeletons.h"
#include "support/tolerances.h"

namespace {

using testsupport::BuiltSkeleton;
using testsupport::SkeletonFrom;

struct Rigged {
  BuiltSkeleton b;
  deform::SkinnedMesh mesh;
  deform::SwdRig rig;
};

Rigged MakeRigged(BuiltSkeleton b) {
  Rigged r{std::move(b), {}, {}};
  auto mesh = deform::BuildMannequin(r.b.skeleton, r.b.model_from_joint);
  EXPECT_TRUE(mesh.ok()) << mesh.error().ToString();
  r.mesh = std::move(*mesh);
  auto rig = deform::BuildSwdRig(r.b.skeleton, r.b.model_from_joint, r.mesh.bind);
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  if (rig.ok()) r.rig = std::move(*rig);
  return r;
}

BuiltSkeleton SyntheticHumanoid() {
  BuiltSkeleton b;
  b.skeleton = synthetic::MakeHumanoidSkeleton();
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(b.skeleton.num_joints()));
  mocap::RestPose(b.skeleton, locals);
  b.model_from_joint.resize(locals.size());
  EXPECT_TRUE((mocap::LocalToModelJob{.parents = b.skeleton.parents, .locals = locals,
                                     .model_from_joint = b.model_from_joint}
                  .Run()));
  return b;
}

// Runs the rig over all vertices split into `pieces` ranges.
std::vector<glm::vec3> Deform(const deform::SwdRig& rig, std::span<const glm::mat4> model,
                              int pieces, std::vector<glm::vec3>* normals = nullptr) {
  const int nv = rig.num_vertices();
  std::vector<glm::vec3> pos(static_cast<std::size_t>(nv));
  std::vector<glm::vec3> nrm(static_cast<std::size_t>(nv));
  std::vector<glm::quat> rot(model.size());
  std::vector<glm::vec3> joints(model.size());
  for (int p = 0; p < pieces; ++p) {
    const int begin = nv * p / pieces;
    const int end = nv * (p + 1) / pieces;
    const auto n = static_cast<std::size_t>(end - begin);
    const base::JobStatus s =
        deform::SwdRigJob{.rig = &rig,
                          .model_from_joint = model,
                          .vertex_begin = begin,
                          .joint_rotations = rot,
                          .joint_positions = joints,
                          .keep_volume = false,
                          .positions = std::span(pos).subspan(static_cast<std::size_t>(begin), n),
                          .normals = std::span(nrm).subspan(static_cast<std::size_t>(begin), n)}
            .Run();
    EXPECT_TRUE(s) << s.what;
  }
  if (normals != nullptr) *normals = std::move(nrm);
  return pos;
}

float MeshSize(const deform::Mesh& m) {
  const glm::vec3 e = deform::ComputeBounds(m.positions).size();
  return std::max({e.x, e.y, e.z});
}

// Largest growth of an edge (deformed minus rest length) over the mesh size: a tear
// (a part following the wrong bone) opens gaps of a limb's radius, several percent.
float MaxEdgeGrowth(const deform::Mesh& rest, std::span<const glm::vec3> pos) {
  float worst = 0.0f;
  for (const glm::uvec3& t : rest.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      const float l0 = glm::distance(rest.positions[a], rest.positions[b]);
      worst = std::max(worst, glm::distance(pos[a], pos[b]) - l0);
    }
  }
  return worst / MeshSize(rest);
}

void ExpectRestAndRigid(const Rigged& r) {
  const float size = MeshSize(r.mesh.bind);
  const std::vector<glm::vec3> rest = Deform(r.rig, r.b.model_from_joint, 1);
  float err = 0.0f;
  for (std::size_t v = 0; v < rest.size(); ++v) {
    err = std::max(err, glm::distance(rest[v], r.mesh.bind.positions[v]));
  }
  EXPECT_LT(err, 10.0f * testsupport::kSwdRebuildRelTol * size);
  // A rigid motion of the whole skeleton moves every vertex rigidly.
  const glm::mat4 rigid = glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, -0.2f, 0.5f) * size) *
                          glm::mat4_cast(glm::angleAxis(1.1f, glm::normalize(glm::vec3(1, 2, 3))));
  std::vector<glm::mat4> moved = r.b.model_from_joint;
  for (glm::mat4& m : moved) m = rigid * m;
  std::vector<glm::vec3> normals;
  const std::vector<glm::vec3> pos = Deform(r.rig, moved, 3, &normals);
  err = 0.0f;
  float nerr = 0.0f;
  for (std::size_t v = 0; v < pos.size(); ++v) {
    err = std::max(err, glm::distance(pos[v], glm::vec3(rigid * glm::vec4(r.mesh.bind.positions[v], 1))));
    nerr = std::max(nerr, glm::distance(normals[v], glm::mat3(rigid) * r.mesh.bind.normals[v]));
  }
  EXPECT_LT(err, 10.0f * testsupport::kSwdRebuildRelTol * size);
  EXPECT_LT(nerr, 1e-3f);
}

// Model matrices with the subtree of `joint` turned by `q` about its joint position.
std::vector<glm::mat4> TurnSubtree(const mocap::Skeleton& s, std::vector<glm::mat4> model,
                                   int joint, const glm::quat& q) {
  const glm::vec3 pivot(model[static_cast<std::size_t>(joint)][3]);
  const glm::mat4 turn = glm::translate(glm::mat4(1.0f), pivot) * glm::mat4_cast(q) *
                         glm::translate(glm::mat4(1.0f), -pivot);
  std::vector<bool> inside(model.size(), false);
  for (std::size_t j = 0; j < model.size(); ++j) {
    const int p = s.parents[j];
    inside[j] = static_cast<int>(j) == joint || (p >= 0 && inside[static_cast<std::size_t>(p)]);
    if (inside[j]) model[j] = turn * model[j];
  }
  return model;
}

TEST(SwdRig, SyntheticHumanoidHasFiveSweepsFourLimbsAndFourJunctions) {
  const Rigged r = MakeRigged(SyntheticHumanoid());
  EXPECT_EQ(r.rig.chains().size(), 5u);
  EXPECT_EQ(r.rig.junctions().size(), 4u);
  ASSERT_EQ(r.rig.limbs().size(), 4u);
  int arms = 0;
  for (const deform::SwdLimb& l : r.rig.limbs()) {
    arms += l.arm ? 1 : 0;
    const deform::SweepChain& c = r.rig.chains()[static_cast<std::size_t>(l.chain)];
    const int elbow = c.joint(l.middle);
    const std::string& name = r.b.skeleton.names[static_cast<std::size_t>(elbow)];
    // The joint that moves the forearm / shin, found by topology only.
    EXPECT_TRUE(name.find("ForeArm") != std::string::npos || name.find("Leg") != std::string::npos)
        << name;
    EXPECT_EQ(name.find("UpLeg"), std::string::npos) << name;
  }
  EXPECT_EQ(arms, 2);
  // The mannequin is made of separate tubes, each bound to one chain family: no seam
  // where the primary sweep switches, so no seam fade (it pulled limbs lying against
  // the trunk onto it).
  for (const deform::SweepJunction& j : r.rig.junctions()) EXPECT_EQ(j.seam_band, 0.0f);
  ExpectRestAndRigid(r);
}

// CMU's naming and proportions (model units ~ CMU's): zero-length helpers (LHipJoint,
// LeftShoulder, LeftFingerBase), a clavicle (3.6) longer than the forearm (3.5) and
// folded fingers. The elbow must be LeftForeArm's joint, not the shoulder.
std::vector<testsupport::JointSpec> CmuNamedSkeleton() {
  std::vector<testsupport::JointSpec> j;
  const auto add = [&](const std::string& name, int parent, glm::vec3 pos) {
    j.push_back({name, parent, pos});
    return static_cast<int>(j.size()) - 1;
  };
  const int hips = add("Hips", -1, {0, 18, 0});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string s = side == 0 ? "L" : "R", full = side == 0 ? "Left" : "Right";
    int p = add(s + "HipJoint", hips, {0, 18, 0});
    p = add(full + "UpLeg", p, {1.4f * x, 16.2f, 0.8f});
    p = add(full + "Leg", p, {1.6f * x, 9.0f, 0.8f});
    p = add(full + "Foot", p, {1.8f * x, 1.6f, 0.8f});
    add(full + "ToeBase", p, {1.9f * x, 1.2f, 3.1f});
  }
  int p = add("LowerBack", hips, {0, 18, 0});
  p = add("Spine", p, {0, 20, -0.2f});
  const int chest = add("Spine1", p, {0, 22.1f, -0.2f});
  p = add("Neck", chest, {0, 22.1f, -0.2f});
  p = add("Neck1", p, {0, 23.9f, 0});
  add("Head", p, {0, 25.6f, -0.1f});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string full = side == 0 ? "Left" : "Right", s = side == 0 ? "L" : "R";
    p = add(full + "Shoulder", chest, {0, 22.1f, -0.2f});
    p = add(full + "Arm", p, {3.4f * x, 23.3f, -0.5f});
    p = add(full + "ForeArm", p, {8.4f * x, 23.3f, -0.5f});
    const int hand = add(full + "Hand", p, {11.9f * x, 23.3f, -0.5f});
    p = add(full + "FingerBase", hand, {11.9f * x, 23.3f, -0.5f});
    add(s + "Fingers", p, {12.6f * x, 23.3f, -0.5f});
    add(s + "Thumb", hand, {11.9f * x, 23.3f, -0.5f});
  }
  return j;
}

// Names of the elbow/knee joints the rig found, arms first.
std::vector<std::string> LimbJointNames(const Rigged& r) {
  std::vector<std::string> names;
  for (bool arms : {true, false}) {
    for (const deform::SwdLimb& l : r.rig.limbs()) {
      if (l.arm != arms) continue;
      const deform::SweepChain& c = r.rig.chains()[static_cast<std::size_t>(l.chain)];
      names.push_back(r.b.skeleton.names[static_cast<std::size_t>(c.joint(l.middle))]);
    }
  }
  return names;
}

TEST(SwdRig, CmuNamedSkeletonFindsElbowsNotShoulders) {
  const Rigged r = MakeRigged(SkeletonFrom(CmuNamedSkeleton(), false, 0.6f));
  std::vector<std::string> names = LimbJointNames(r);
  ASSERT_EQ(names.size(), 4u);
  std::sort(names.begin(), names.begin() + 2);
  std::sort(names.begin() + 2, names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"LeftForeArm", "RightForeArm", "LeftLeg", "RightLeg"}));
  ExpectRestAndRigid(r);
}

TEST(SwdRig, ArmWithoutClavicleKeepsItsFirstJoint) {
  // Upper arm, forearm and a short hand leave the chest directly: joint 1 is the elbow.
  const Rigged r = MakeRigged(SkeletonFrom(
      {{"root", -1, {0, 0, 0}},      {"chest", 0, {0, 20, 0}},     {"head", 1, {0, 30, 0}},
       {"upper_l", 1, {0, 20, 0}},   {"fore_l", 3, {12, 20, 0}},   {"hand_l", 4, {23, 20, 0}},
       {"upper_r", 1, {0, 20, 0}},   {"fore_r", 6, {-12, 20, 0}},  {"hand_r", 7, {-23, 20, 0}},
       {"thigh_l", 0, {3, 0, 0}},    {"shin_l", 9, {3, -12, 0}},   {"foot_l", 10, {3, -24, 0}},
       {"thigh_r", 0, {-3, 0, 0}},   {"shin_r", 12, {-3, -12, 0}}, {"foot_r", 13, {-3, -24, 0}}},
      false, 3.0f));
  for (const std::string& name : LimbJointNames(r)) {
    EXPECT_TRUE(name.rfind("fore_", 0) == 0 || name.rfind("shin_", 0) == 0) << name;
  }
}

TEST(SwdRig, BodiesOfOtherShapes) {
  ExpectRestAndRigid(MakeRigged(SkeletonFrom(testsupport::Humanoid(1.0f, true, false, ""), false, 5.0f)));
  ExpectRestAndRigid(MakeRigged(SkeletonFrom(testsupport::Humanoid(1.0f, false, true, ""), true, 2.0f)));
  ExpectRestAndRigid(MakeRigged(SkeletonFrom(testsupport::Tail(10, 50.0f), false, 3.0f)));
  const Rigged quad = MakeRigged(SkeletonFrom(testsupport::Quadruped(), false, 4.0f));
  EXPECT_EQ(quad.rig.limbs().size(), 5u);  // four legs and the tail
  ExpectRestAndRigid(quad);
}

TEST(SwdRig, ChainsLongerThanOneSweepAreCutWithJunctions) {
  const Rigged r = MakeRigged(SkeletonFrom(testsupport::Tail(20, 100.0f), false, 3.0f));
  ASSERT_GE(r.rig.chains().size(), 3u);
  for (const deform::SweepChain& c : r.rig.chains()) EXPECT_LE(c.num_bones(), deform::kMaxSweepBones);
  EXPECT_EQ(r.rig.junctions().size(), r.rig.chains().size() - 1);
  ExpectRestAndRigid(r);
}

TEST(SwdRig, AnySplitOfTheVerticesGivesTheSameBits) {
  const Rigged r = MakeRigged(SyntheticHumanoid());
  auto walk = synthetic::MakeWalkMotion(r.b.skeleton);
  ASSERT_TRUE(walk.ok());
  std::vector<mocap::JointTransform> locals(r.b.model_from_joint.size());
  std::vector<glm::mat4> model(locals.size());
  ASSERT_TRUE((mocap::LocalPoseJob{&r.b.skeleton, walk->frame(walk->num_frames / 3), locals}.Run()));
  ASSERT_TRUE((mocap::LocalToModelJob{.parents = r.b.skeleton.parents, .locals = locals,
                                     .model_from_joint = model}
                  .Run()));
  const std::vector<glm::vec3> one = Deform(r.rig, model, 1);
  const std::vector<glm::vec3> seven = Deform(r.rig, model, 7);
  ASSERT_EQ(one.size(), seven.size());
  EXPECT_EQ(0, std::memcmp(one.data(), seven.data(), one.size() * sizeof(glm::vec3)));
  // No tearing anywhere while walking (shoulders and hips included).
  EXPECT_LT(MaxEdgeGrowth(r.mesh.bind, one), testsupport::kSwdMaxEdgeGrowthFraction);
}

TEST(SwdRig, BentElbowsAndKneesDoNotTear) {
  const Rigged r = MakeRigged(SyntheticHumanoid());
  std::vector<glm::mat4> model = r.b.model_from_joint;
  for (const deform::SwdLimb& l : r.rig.limbs()) {
    const deform::SweepChain& c = r.rig.chains()[static_cast<std::size_t>(l.chain)];
    const glm::vec3 axis = glm::normalize(glm::cross(glm::vec3(c.rest_axis(l.middle)), glm::vec3(0, 0, 1)) +
                                          glm::vec3(0, 0, 1e-3f));
    model = TurnSubtree(r.b.skeleton, model, c.joint(l.middle), glm::angleAxis(glm::radians(120.0f), axis));
  }
  const std::vector<glm::vec3> pos = Deform(r.rig, model, 2);
  EXPECT_LT(MaxEdgeGrowth(r.mesh.bind, pos), testsupport::kSwdMaxEdgeGrowthFraction);
}

TEST(SwdRig, PointsBoundLikeVerticesMatchTheVertexBindings) {
  const Rigged r = MakeRigged(SyntheticHumanoid());
  // Each vertex, bound as an extra point guided by itself, gets its own binding back:
  // the guide's sweeps hold the vertex's nearest one, and the same rules apply.
  std::vector<glm::vec3> points;
  std::vector<int> guides;
  for (int v = 0; v < r.rig.num_vertices(); v += 7) {
    points.push_back(r.mesh.bind.positions[static_cast<std::size_t>(v)]);
    guides.push_back(v);
  }
  auto bound = deform::BindPointsLikeVertices(r.rig, points, guides);
  ASSERT_TRUE(bound.ok()) << bound.error().ToString();
  int junction_points = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const deform::SweepVertexBinding& a = (*bound)[i];
    const deform::SweepVertexBinding& b = r.rig.bindings()[static_cast<std::size_t>(guides[i])];
    ASSERT_EQ(a.primary.chain, b.primary.chain) << guides[i];
    EXPECT_EQ(a.primary.u, b.primary.u) << guides[i];
    EXPECT_EQ(a.primary.offset, b.primary.offset) << guides[i];
    EXPECT_EQ(a.weight, b.weight) << guides[i];
    if (b.weight < 1.0f) {
      ++junction_points;
      EXPECT_EQ(a.secondary.chain, b.secondary.chain) << guides[i];
      EXPECT_EQ(a.secondary.u, b.secondary.u) << guides[i];
    }
  }
  EXPECT_GT(junction_points, 0);
  // Points off the surface still rebuild exactly at the bind pose.
  std::vector<glm::vec3> off;
  for (const glm::vec3& p : points) off.push_back(p * 1.01f);
  auto off_bound = deform::BindPointsLikeVertices(r.rig, off, guides);
  ASSERT_TRUE(off_bound.ok());
  std::vector<glm::quat> rot(r.b.model_from_joint.size());
  std::vector<glm::vec3> joints(rot.size()), rebuilt(off.size());
  ASSERT_TRUE(deform::ComputeSwdJointState(r.rig, r.b.model_from_joint, rot, joints));
  ASSERT_TRUE((deform::SwdJob{.chains = r.rig.chains(), .joint_rotations = rot,
                              .joint_positions = joints, .bindings = *off_bound,
                              .rest_normals = {}, .keep_volume = false, .section_scales = {},
                              .positions = rebuilt, .normals = {}}
                   .Run()));
  const glm::vec3 e = deform::ComputeBounds(r.mesh.bind.positions).size();
  const float size = std::max({e.x, e.y, e.z});
  for (std::size_t i = 0; i < off.size(); ++i) {
    EXPECT_LT(glm::distance(rebuilt[i], off[i]) / size, testsupport::kSwdRebuildRelTol) << i;
  }
  // Errors.
  EXPECT_EQ(deform::BindPointsLikeVertices(r.rig, points, std::span(guides).first(1)).error().code,
            base::ErrorCode::kInvalidArgument);
  std::vector<int> bad = guides;
  bad[0] = r.rig.num_vertices();
  EXPECT_EQ(deform::BindPointsLikeVertices(r.rig, points, bad).error().code,
            base::ErrorCode::kInvalidArgument);
  std::vector<glm::vec3> nan = points;
  nan[0].x = std::nanf("");
  EXPECT_EQ(deform::BindPointsLikeVertices(r.rig, nan, guides).error().code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(
      deform::ComputeSwdJointState(r.rig, std::span(r.b.model_from_joint).first(2), rot, joints)
          .code,
      base::JobStatus::kSizeMismatch);
}

TEST(SwdRig, ClearErrors) {
  const Rigged r = MakeRigged(SyntheticHumanoid());
  // Too many sweeps for one body.
  const BuiltSkeleton chain = SkeletonFrom(testsupport::Tail(200, 300.0f), true, 0.0f);
  auto mesh = deform::BuildMannequin(chain.skeleton, chain.model_from_joint);
  ASSERT_TRUE(mesh.ok());
  auto big = deform::BuildSwdRig(chain.skeleton, chain.model_from_joint, mesh->bind);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().code, base::ErrorCode::kLimitExceeded);
  EXPECT_NE(big.error().message.find("sweeps"), std::string::npos);
  // No bone at all.
  const BuiltSkeleton point = SkeletonFrom({{"a", -1, {1, 1, 1}}, {"b", 0, {1, 1, 1}}}, false, 0.0f);
  auto none = deform::BuildSwdRig(point.skeleton, point.model_from_joint, r.mesh.bind);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code, base::ErrorCode::kInvalidArgument);
  // Bad job inputs.
  std::vector<glm::quat> rot(r.b.model_from_joint.size());
  std::vector<glm::vec3> joints(rot.size()), pos(4);
  EXPECT_EQ((deform::SwdRigJob{.rig = &r.rig,
                               .model_from_joint = r.b.model_from_joint,
                               .vertex_begin = r.rig.num_vertices() - 2,
                               .joint_rotations = rot,
                               .joint_positions = joints,
                               .keep_volume = false,
                               .positions = pos,
                               .normals = {}}
                 .Run()
                 .code),
            base::JobStatus::kOutOfRange);
  EXPECT_EQ((deform::SwdRigJob{.rig = &r.rig,
                               .model_from_joint = std::span(r.b.model_from_joint).first(2),
                               .vertex_begin = 0,
                               .joint_rotations = rot,
                               .joint_positions = joints,
                               .keep_volume = false,
                               .positions = pos,
                               .normals = {}}
                 .Run()
                 .code),
            base::JobStatus::kSizeMismatch);
}

}  // namespace

namespace {

// mocapbank's layout: both collars and the neck leave the chest at one point, well above
// it, and the arms hang beside the chest (y up, ~170 units tall).
std::vector<testsupport::JointSpec> SharedCollarPointHangingArms() {
  std::vector<testsupport::JointSpec> j;
  const auto add = [&](const std::string& name, int parent, glm::vec3 pos) {
    j.push_back({name, parent, pos});
    return static_cast<int>(j.size()) - 1;
  };
  const int hips = add("hips", -1, {0, 95, 0});
  for (float x : {1.0f, -1.0f}) {
    int p = add(x > 0 ? "hip_l" : "hip_r", hips, {9 * x, 95, 3});
    p = add(x > 0 ? "knee_l" : "knee_r", p, {9 * x, 50, 3});
    add(x > 0 ? "ankle_l" : "ankle_r", p, {9 * x, 10, 0});
  }
  const int chest = add("chest", add("chest_low", hips, {0, 105, 0}), {0, 121, -2});
  const glm::vec3 top(0, 138, 0);
  for (float x : {1.0f, -1.0f}) {
    int p = add(x > 0 ? "collar_l" : "collar_r", chest, top);
    p = add(x > 0 ? "shoulder_l" : "shoulder_r", p, {16 * x, 135, 2});
    p = add(x > 0 ? "elbow_l" : "elbow_r", p, {18.5f * x, 110, 3});
    add(x > 0 ? "wrist_l" : "wrist_r", p, {21 * x, 88, 4});
  }
  add("head", add("neck", chest, top), {0, 150, 4});
  return j;
}

int JointNamed(const mocap::Skeleton& s, const std::string& name) {
  return static_cast<int>(std::find(s.names.begin(), s.names.end(), name) - s.names.begin());
}

TEST(SwdRig, SpineRunsOnToTheHeadPastCollarsStartingWithTheNeck) {
  const BuiltSkeleton b = SkeletonFrom(SharedCollarPointHangingArms(), false, 8.0f);
  auto chains = deform::BuildBodyChains(b.skeleton, b.model_from_joint, 0.15f);
  ASSERT_TRUE(chains.ok()) << chains.error().ToString();
  // The neck, both collars start at one point: the straightest was the left arm; the
  // collars are a mirror pair, so the spine takes the neck.
  std::string last;
  for (int p : chains->chains[0].points) {
    const int j = chains->points[static_cast<std::size_t>(p)].joint;
    if (j >= 0) last = b.skeleton.names[static_cast<std::size_t>(j)];
  }
  EXPECT_EQ(last, "head");
  EXPECT_EQ(chains->chains.size(), 5u);
}

TEST(SwdRig, MannequinTubesBindToTheChainTheyWereMadeOn) {
  Rigged r{SkeletonFrom(SharedCollarPointHangingArms(), false, 8.0f), {}, {}};
  auto mesh = deform::BuildMannequin(r.b.skeleton, r.b.model_from_joint);
  ASSERT_TRUE(mesh.ok()) << mesh.error().ToString();
  r.mesh = std::move(*mesh);
  const std::vector<deform::BodyChainCoord>& coords = r.mesh.body_chain_coords;
  ASSERT_EQ(coords.size(), r.mesh.bind.positions.size());
  auto placed = deform::BuildSwdRig(r.b.skeleton, r.b.model_from_joint, r.mesh.bind,
                                    {.vertex_chains = coords});
  ASSERT_TRUE(placed.ok()) << placed.error().ToString();
  auto by_distance = deform::BuildSwdRig(r.b.skeleton, r.b.model_from_joint, r.mesh.bind);
  ASSERT_TRUE(by_distance.ok());
  ASSERT_EQ(placed->chains().size(), 5u);  // no chain is cut: sweep index = chain index
  int on_tubes = 0;
  for (std::size_t v = 0; v < coords.size(); ++v) {
    if (coords[v].chain < 0) continue;
    ++on_tubes;
    const deform::SweepBinding& b = placed->bindings()[v].primary;
    ASSERT_EQ(static_cast<int>(b.chain), coords[v].chain) << "vertex " << v;
    ASSERT_EQ(b.u, coords[v].u) << "vertex " << v;
  }
  EXPECT_GT(on_tubes, r.mesh.bind.num_vertices() / 2);
  r.rig = std::move(*placed);
  ExpectRestAndRigid(r);
  // Arms raised 80 degrees sideways and elbows bent 90: the inner side of each hanging
  // upper arm lies nearer the arm chain's start (inside the chest) than its own axis, so
  // distance binding tore it off; bound to its own ring it stays on.
  std::vector<glm::mat4> model = r.b.model_from_joint;
  for (float x : {1.0f, -1.0f}) {
    const std::string side = x > 0 ? "_l" : "_r";
    model = TurnSubtree(r.b.skeleton, model, JointNamed(r.b.skeleton, "shoulder" + side),
                        glm::angleAxis(glm::radians(80.0f) * x, glm::vec3(0, 0, 1)));
    model = TurnSubtree(r.b.skeleton, model, JointNamed(r.b.skeleton, "elbow" + side),
                        glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0)));
  }
  const float growth = MaxEdgeGrowth(r.mesh.bind, Deform(r.rig, model, 2));
  const float growth_by_distance = MaxEdgeGrowth(r.mesh.bind, Deform(*by_distance, model, 2));
  std::printf("arms raised, elbows bent: largest edge growth %.4f (by distance %.4f)\n", growth,
              growth_by_distance);
  EXPECT_LT(growth, testsupport::kSwdCaptureMaxEdgeGrowthFraction);
}

TEST(SwdRig, BodyChainCoordsThatDoNotFitAreRefused) {
  const BuiltSkeleton b = SkeletonFrom(SharedCollarPointHangingArms(), false, 8.0f);
  auto mesh = deform::BuildMannequin(b.skeleton, b.model_from_joint);
  ASSERT_TRUE(mesh.ok());
  std::vector<deform::BodyChainCoord> coords = mesh->body_chain_coords;
  coords.pop_back();
  auto short_list = deform::BuildSwdRig(b.skeleton, b.model_from_joint, mesh->bind, {.vertex_chains = coords});
  ASSERT_FALSE(short_list.ok());
  EXPECT_EQ(short_list.error().code, base::ErrorCode::kInvalidArgument);
  coords = mesh->body_chain_coords;
  coords[0].chain = 99;  // a chain this skeleton does not have
  auto wrong = deform::BuildSwdRig(b.skeleton, b.model_from_joint, mesh->bind, {.vertex_chains = coords});
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("vertex 0"), std::string::npos) << wrong.error().message;
  coords = mesh->body_chain_coords;
  coords[1] = {0, 1e6f};  // past the chain's end
  EXPECT_FALSE(deform::BuildSwdRig(b.skeleton, b.model_from_joint, mesh->bind, {.vertex_chains = coords}).ok());
}

}  // namespace
