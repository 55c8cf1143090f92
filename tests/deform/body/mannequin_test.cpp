#include "deform/body/mannequin.h"

#include <cstring>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "deform/body/body_chains.h"
#include "deform/global/dqs_job.h"
#include "deform/global/skinning_job.h"
#include "support/test_skeletons.h"
#include "support/tolerances.h"

namespace {

using testsupport::BuiltSkeleton;
using testsupport::SkeletonFrom;

float SkeletonHeight(const BuiltSkeleton& b) {
  float lo = 1e30f, hi = -1e30f;
  for (const glm::mat4& m : b.model_from_joint) lo = std::min(lo, m[3].y), hi = std::max(hi, m[3].y);
  for (const mocap::EndSite& e : b.skeleton.end_sites) {
    const float y = (b.model_from_joint[static_cast<std::size_t>(e.parent)] * glm::vec4(e.offset, 1)).y;
    lo = std::min(lo, y), hi = std::max(hi, y);
  }
  return hi - lo;
}

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
  return i;
}

// Every property the brief asks of a generated body.
void ExpectValidBody(const BuiltSkeleton& b, const deform::SkinnedMesh& m, bool check_height) {
  const deform::Mesh& mesh = m.bind;
  ASSERT_TRUE(mesh.Check().ok());
  EXPECT_GE(mesh.num_vertices(), 10000);
  EXPECT_LE(mesh.num_vertices(), 40000);
  const deform::Bounds box = deform::ComputeBounds(mesh.positions);
  const float size = std::max({box.size().x, box.size().y, box.size().z});
  // Closed, consistently oriented: each directed edge once, its reverse once.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const glm::uvec3& t : mesh.triangles) {
    ++directed[{t.x, t.y}];
    ++directed[{t.y, t.z}];
    ++directed[{t.z, t.x}];
  }
  int bad_edges = 0;
  for (const auto& [edge, count] : directed) {
    const auto rev = directed.find({edge.second, edge.first});
    if (count != 1 || rev == directed.end() || rev->second != 1) ++bad_edges;
  }
  EXPECT_EQ(bad_edges, 0) << "edges not shared by exactly two opposite triangles";
  // No degenerate triangles.
  int degenerate = 0;
  for (const glm::uvec3& t : mesh.triangles) {
    const float area = 0.5f * glm::length(glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                                                     mesh.positions[t.z] - mesh.positions[t.x]));
    if (!(area > testsupport::kMinTriangleAreaFraction * size * size)) ++degenerate;
  }
  EXPECT_EQ(degenerate, 0);
  // Outward: every connected component encloses a positive signed volume.
  std::vector<int> parent(static_cast<std::size_t>(mesh.num_vertices()));
  std::iota(parent.begin(), parent.end(), 0);
  for (const glm::uvec3& t : mesh.triangles) {
    parent[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(t.y)))] = FindRoot(parent, static_cast<int>(t.x));
    parent[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(t.z)))] = FindRoot(parent, static_cast<int>(t.x));
  }
  std::map<int, double> volume;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t.x] - box.center()), c1(mesh.positions[t.y] - box.center()),
        c2(mesh.positions[t.z] - box.center());
    volume[FindRoot(parent, static_cast<int>(t.x))] += glm::dot(a, glm::cross(c1, c2)) / 6.0;
  }
  for (const auto& [component, v] : volume) EXPECT_GT(v, 0.0) << "component " << component;
  // Weights: <= 4, >= 0, sum 1, valid indices; skin joints are skeleton joints.
  EXPECT_EQ(m.weights.influences, 4);
  EXPECT_TRUE(deform::CheckSkinWeights(m.weights, static_cast<int>(m.skin_joints.size()),
                                       mesh.num_vertices())
                  .ok());
  ASSERT_EQ(m.joint_from_bind.size(), m.skin_joints.size());
  for (int j : m.skin_joints) {
    EXPECT_GE(j, 0);
    EXPECT_LT(j, b.skeleton.num_joints());
  }
  // The rest pose reproduces the bind mesh exactly.
  std::vector<glm::mat4> palette(m.skin_joints.size());
  ASSERT_TRUE(deform::BuildSkinningPalette(b.model_from_joint, m, palette).ok());
  std::vector<glm::vec3> skinned(mesh.positions.size());
  ASSERT_TRUE((deform::SkinningJob{.model_from_bind = palette, .influences = 4,
                                   .joint_indices = m.weights.joints,
                                   .joint_weights = m.weights.weights,
                                   .rest_positions = mesh.positions, .rest_normals = {},
                                   .positions = skinned, .normals = {}})
                  .Run()
                  .ok());
  float worst = 0.0f;
  for (std::size_t v = 0; v < skinned.size(); ++v) worst = std::max(worst, glm::distance(skinned[v], mesh.positions[v]));
  EXPECT_LT(worst, testsupport::kPositionTol * size / 100.0f);
  if (check_height) {
    const float h = SkeletonHeight(b);
    EXPECT_NEAR(box.size().y, h, testsupport::kMannequinHeightTolFraction * h);
  }
}

deform::SkinnedMesh Build(const BuiltSkeleton& b) {
  auto r = deform::BuildMannequin(b.skeleton, b.model_from_joint);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().ToString());
  return r.ok() ? std::move(r).value() : deform::SkinnedMesh{};
}

TEST(Mannequin, CmuLikeWithZeroLengthHelpers) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(0.13f, true, false, ""), false, 0.13f * 10);
  ASSERT_EQ(b.skeleton.num_joints(), 31);
  const deform::SkinnedMesh m = Build(b);
  ExpectValidBody(b, m, true);
  // Helpers never carry a bone of their own, so the hip helpers only skin
  // the pelvis bone; every limb joint is a skin joint.
  EXPECT_NE(std::find(m.skin_joints.begin(), m.skin_joints.end(), b.skeleton.FindJoint("LeftLeg")),
            m.skin_joints.end());
}

TEST(Mannequin, BandaiLikeBonesAlongLocalX) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(1.0f, false, false, ""), true, 8.0f);
  ExpectValidBody(b, Build(b), true);
}

TEST(Mannequin, PositioningRootFarFromTheBodyIsIgnored) {
  // Bandai files keep joint_Root on the floor at the origin while the capture
  // walks away; the body's size must come from the body alone.
  std::vector<testsupport::JointSpec> specs = {{"joint_Root", -1, {0, 0, 0}}};
  for (testsupport::JointSpec j : testsupport::Humanoid(1.0f, false, false, "")) {
    j.parent += 1;
    j.model_pos += glm::vec3(400, 0, 300);
    specs.push_back(j);
  }
  const BuiltSkeleton b = SkeletonFrom(specs, true, 8.0f);
  const deform::SkinnedMesh m = Build(b);
  ExpectValidBody(b, m, true);
  const BuiltSkeleton centred =
      SkeletonFrom(testsupport::Humanoid(1.0f, false, false, ""), true, 8.0f);
  const deform::Bounds far = deform::ComputeBounds(m.bind.positions);
  const deform::Bounds near = deform::ComputeBounds(Build(centred).bind.positions);
  EXPECT_NEAR(far.size().x, near.size().x, testsupport::kPositionTol * 100.0f);
  EXPECT_NEAR(far.size().y, near.size().y, testsupport::kPositionTol * 100.0f);
  // joint_Root gets no body part and no weight: a vertex bound to it would stay
  // where the body was bound while the hips walk on (issue 27's 4 m tail).
  const int root = b.skeleton.FindJoint("joint_Root");
  EXPECT_EQ(std::find(m.skin_joints.begin(), m.skin_joints.end(), root), m.skin_joints.end());
  const base::Result<std::vector<std::uint8_t>> parts =
      deform::BodyPartJoints(b.skeleton, b.model_from_joint, 0.15f);
  ASSERT_TRUE(parts.ok());
  for (int j = 0; j < b.skeleton.num_joints(); ++j) {
    EXPECT_EQ((*parts)[static_cast<std::size_t>(j)], j == root ? 0 : 1) << b.skeleton.names[static_cast<std::size_t>(j)];
  }
}

TEST(Mannequin, MixamoLikeWithFingersInMetres) {
  const BuiltSkeleton b =
      SkeletonFrom(testsupport::Humanoid(0.01f, false, true, "mixamorig:"), false, 0.08f);
  const deform::SkinnedMesh m = Build(b);
  ExpectValidBody(b, m, true);
}

TEST(Mannequin, SameBodyWhateverTheUnits) {
  const BuiltSkeleton cm = SkeletonFrom(testsupport::Humanoid(1.0f, false, false, ""), false, 8.0f);
  const BuiltSkeleton inch = SkeletonFrom(testsupport::Humanoid(1.0f / 2.54f, false, false, ""), false, 8.0f / 2.54f);
  const deform::SkinnedMesh a = Build(cm);
  const deform::SkinnedMesh c = Build(inch);
  ASSERT_EQ(a.bind.num_vertices(), c.bind.num_vertices());
  for (int v = 0; v < a.bind.num_vertices(); v += 97) {
    EXPECT_NEAR(glm::distance(a.bind.positions[static_cast<std::size_t>(v)],
                              2.54f * c.bind.positions[static_cast<std::size_t>(v)]),
                0.0f, testsupport::kPositionTol * 100.0f);
  }
}

TEST(Mannequin, WeightsFallOffAcrossJoints) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(1.0f, false, false, ""), false, 8.0f);
  const deform::SkinnedMesh m = Build(b);
  const int elbow = b.skeleton.FindJoint("LeftForeArm");
  const int upper = b.skeleton.FindJoint("LeftArm");
  // Vertices near the elbow (x = 45) share upper arm and forearm; their forearm
  // weight grows with x, from 0 before the blend zone to 1 after it.
  float last_x = -1e30f, last_w = -1.0f;
  int blended = 0;
  std::vector<std::pair<float, float>> samples;
  for (int v = 0; v < m.bind.num_vertices(); ++v) {
    const glm::vec3 p = m.bind.positions[static_cast<std::size_t>(v)];
    if (p.x < 30 || p.x > 60 || std::abs(p.y - 140) > 8 || std::abs(p.z) > 8) continue;
    float w_fore = 0, w_upper = 0;
    for (int i = 0; i < 4; ++i) {
      const int j = m.skin_joints[m.weights.joints[static_cast<std::size_t>(4 * v + i)]];
      const float w = m.weights.weights[static_cast<std::size_t>(4 * v + i)];
      if (j == elbow) w_fore += w;
      if (j == upper) w_upper += w;
    }
    EXPECT_NEAR(w_fore + w_upper, 1.0f, testsupport::kFloatTol) << "at x = " << p.x;
    if (w_fore > 0.01f && w_fore < 0.99f) ++blended;
    samples.emplace_back(p.x, w_fore);
  }
  std::sort(samples.begin(), samples.end());
  for (const auto& [x, w] : samples) {
    if (x > last_x + 0.5f) {
      EXPECT_GE(w, last_w - testsupport::kFloatTol) << "at x = " << x;
    }
    last_x = x, last_w = w;
  }
  EXPECT_GT(blended, 48);  // at least two rings inside the blend zone
  EXPECT_NEAR(samples.front().second, 0.0f, testsupport::kFloatTol);
  EXPECT_NEAR(samples.back().second, 1.0f, testsupport::kFloatTol);
}

double Volume(std::span<const glm::vec3> p, std::span<const glm::uvec3> tris) {
  double v = 0.0;
  for (const glm::uvec3& t : tris) {
    v += glm::dot(glm::dvec3(p[t.x]), glm::cross(glm::dvec3(p[t.y]), glm::dvec3(p[t.z]))) / 6.0;
  }
  return v;
}

TEST(Mannequin, BentElbowsAndKneesLoseLessVolumeWithDqs) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(1.0f, false, false, ""), false, 8.0f);
  const deform::SkinnedMesh m = Build(b);
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(b.skeleton.num_joints()));
  mocap::RestPose(b.skeleton, locals);
  // Forearms (along x in the T-pose) bend about y, shins (along y) about x.
  const std::pair<const char*, glm::vec3> bends[] = {{"LeftForeArm", {0, 1, 0}},
                                                     {"RightForeArm", {0, 1, 0}},
                                                     {"LeftLeg", {1, 0, 0}},
                                                     {"RightLeg", {1, 0, 0}}};
  for (const auto& [name, axis] : bends) {
    const std::size_t j = static_cast<std::size_t>(b.skeleton.FindJoint(name));
    locals[j].rotation = glm::angleAxis(glm::radians(90.0f), axis);
  }
  std::vector<glm::mat4> model(locals.size());
  ASSERT_TRUE((mocap::LocalToModelJob{.parents = b.skeleton.parents, .locals = locals,
                                      .model_from_joint = model})
                  .Run()
                  .ok());
  std::vector<glm::mat4> palette(m.skin_joints.size());
  ASSERT_TRUE(deform::BuildSkinningPalette(model, m, palette).ok());
  std::vector<deform::DualQuat> dq(palette.size());
  ASSERT_TRUE(deform::BuildDualQuatPalette(palette, dq).ok());
  std::vector<glm::vec3> ssd(m.bind.positions.size()), dqs(ssd.size());
  ASSERT_TRUE((deform::SkinningJob{.model_from_bind = palette, .influences = 4,
                                   .joint_indices = m.weights.joints,
                                   .joint_weights = m.weights.weights,
                                   .rest_positions = m.bind.positions, .rest_normals = {},
                                   .positions = ssd, .normals = {}})
                  .Run()
                  .ok());
  ASSERT_TRUE((deform::DqsJob{.palette = dq, .influences = 4, .joint_indices = m.weights.joints,
                              .joint_weights = m.weights.weights,
                              .rest_positions = m.bind.positions, .rest_normals = {},
                              .positions = dqs, .normals = {}})
                  .Run()
                  .ok());
  const double rest = Volume(m.bind.positions, m.bind.triangles);
  const double v_ssd = Volume(ssd, m.bind.triangles);
  const double v_dqs = Volume(dqs, m.bind.triangles);
  std::printf("body volume with elbows and knees at 90 degrees / rest: SSD %.4f, DQS %.4f\n",
              v_ssd / rest, v_dqs / rest);
  EXPECT_LT(v_ssd, rest);  // the linear blend collapses the joints
  EXPECT_LT(std::abs(v_dqs - rest), std::abs(v_ssd - rest));
}

TEST(Mannequin, TailChain) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Tail(10, 50.0f), false, 3.0f);
  ExpectValidBody(b, Build(b), false);
}

TEST(Mannequin, Quadruped) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Quadruped(), false, 4.0f);
  ExpectValidBody(b, Build(b), false);
}

TEST(Mannequin, LongChainOf200Joints) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Tail(200, 300.0f), true, 0.0f);
  ExpectValidBody(b, Build(b), false);
}

TEST(Mannequin, DegenerateSkeletonsGiveClearErrors) {
  const BuiltSkeleton single = SkeletonFrom({{"root", -1, {1, 2, 3}}}, false, 0.0f);
  auto r = deform::BuildMannequin(single.skeleton, single.model_from_joint);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("non-zero length"), std::string::npos);
  const BuiltSkeleton point = SkeletonFrom(
      {{"a", -1, {1, 1, 1}}, {"b", 0, {1, 1, 1}}, {"c", 1, {1, 1, 1}}}, false, 0.0f);
  EXPECT_FALSE(deform::BuildMannequin(point.skeleton, point.model_from_joint).ok());
  // A single joint with an end site is one bone: a valid (small) body.
  const BuiltSkeleton stub = SkeletonFrom({{"a", -1, {0, 0, 0}}, {"b", 0, {0, 10, 0}}}, false, 2.0f);
  ExpectValidBody(stub, Build(stub), false);
  // Matrix count and options are checked.
  EXPECT_EQ(
      deform::BuildMannequin(stub.skeleton, std::span(stub.model_from_joint).first(1)).error().code,
      base::ErrorCode::kCountMismatch);
  EXPECT_EQ(deform::BuildMannequin(stub.skeleton, stub.model_from_joint, {.ring_vertices = 3})
                .error()
                .code,
            base::ErrorCode::kInvalidArgument);
  std::vector<glm::mat4> nan = stub.model_from_joint;
  nan[1][3].x = std::nanf("");
  EXPECT_EQ(deform::BuildMannequin(stub.skeleton, nan).error().code, base::ErrorCode::kNonFinite);
}

TEST(Mannequin, HugeSkeletonsGiveAValidMeshOrALimitError) {
  // The longest chain a Skeleton may hold: still one tube within budget.
  const BuiltSkeleton chain = SkeletonFrom(testsupport::Tail(mocap::kMaxJoints, 500.0f), false, 0.0f);
  ExpectValidBody(chain, Build(chain), false);
  // A root with 300 spokes would need 300 tubes: refused with a clear error.
  std::vector<testsupport::JointSpec> star = {{"hub", -1, {0, 0, 0}}};
  for (int i = 0; i < 300; ++i) {
    const float a = 0.1f * static_cast<float>(i);
    star.push_back({"spoke" + std::to_string(i), 0, {10 * std::cos(a), 10 * std::sin(a), 0.01f * static_cast<float>(i)}});
  }
  const BuiltSkeleton b = SkeletonFrom(star, false, 0.0f);
  auto r = deform::BuildMannequin(b.skeleton, b.model_from_joint);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, base::ErrorCode::kLimitExceeded);
  EXPECT_NE(r.error().message.find("chains"), std::string::npos) << r.error().message;
}

TEST(Mannequin, IsDeterministic) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(1.0f, true, true, ""), true, 8.0f);
  const deform::SkinnedMesh a = Build(b);
  const deform::SkinnedMesh c = Build(b);
  ASSERT_EQ(a.bind.positions.size(), c.bind.positions.size());
  EXPECT_EQ(std::memcmp(a.bind.positions.data(), c.bind.positions.data(),
                        a.bind.positions.size() * sizeof(glm::vec3)),
            0);
  EXPECT_EQ(a.bind.triangles, c.bind.triangles);
  EXPECT_EQ(a.weights.weights, c.weights.weights);
  EXPECT_EQ(a.weights.joints, c.weights.joints);
  EXPECT_EQ(a.skin_joints, c.skin_joints);
}

}  // namespace
