#include "deform/body/generated_body.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "deform/body/body_mesher.h"
#include "deform/body/bone_heat.h"
#include "deform/body/implicit_body.h"
#include "deform/body/mannequin.h"
#include "deform/global/rig_artifacts.h"
#include "deform/global/skinning_job.h"
#include "mocap/bvh_reader.h"
#include "mocap/channel_use.h"
#include "mocap/pose.h"
#include "tools/synthetic.h"
#include "support/data_paths.h"
#include "support/test_skeletons.h"
#include "support/body_checks.h"

namespace {

using testsupport::BuiltSkeleton;
using testsupport::SkeletonFrom;

std::vector<glm::mat4> RestMatrices(const mocap::Skeleton& s) {
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(s.num_joints()));
  std::vector<glm::mat4> model(locals.size());
  mocap::RestPose(s, locals);
  EXPECT_TRUE((mocap::LocalToModelJob{.parents = s.parents, .locals = locals, .model_from_joint = model}.Run()));
  return model;
}

// Distance from p to the nearest bone of `joint` in `body` (model units).
float DistanceToJointBones(const deform::ImplicitBody& body, int joint, const glm::vec3& p) {
  float best = 1e30f;
  for (const deform::BodyBone& b : body.bones()) {
    if (b.joint != joint) continue;
    const glm::vec3 ab = b.b - b.a;
    const float t = glm::dot(ab, ab) > 0.0f ? std::clamp(glm::dot(p - b.a, ab) / glm::dot(ab, ab), 0.0f, 1.0f) : 0.0f;
    best = std::min(best, glm::distance(p, b.a + t * ab));
  }
  return best;
}

// Every property asked of a generated body, for skeleton `s` in pose `rest`.
void ExpectValidBody(const mocap::Skeleton& s, std::span<const glm::mat4> rest, const deform::SkinnedMesh& m) {
  const deform::Mesh& mesh = m.bind;
  ASSERT_TRUE(mesh.Check().ok());
  EXPECT_EQ(testsupport::BadEdges(mesh), 0) << "edges not shared by exactly two opposite triangles";
  EXPECT_EQ(testsupport::ConnectedPieces(mesh), 1);
  EXPECT_GT(testsupport::SmallestRelativeArea(mesh), 1e-6) << "degenerate triangle";
  EXPECT_GT(testsupport::EnclosedVolume(mesh.positions, mesh.triangles), 0.0) << "faces turned inward";
  EXPECT_EQ(testsupport::SelfIntersectingPairs(mesh), 0) << "the skin passes through itself at the bind pose";
  // Weights: non-negative, sum to 1, and the heaviest joint has a bone near the vertex.
  auto body = deform::BuildImplicitBody(s, rest);
  ASSERT_TRUE(body.ok());
  const int k = m.weights.influences;
  int far = 0;
  float worst_sum = 0.0f;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    float sum = 0.0f, top = -1.0f;
    int top_joint = -1;
    for (int i = 0; i < k; ++i) {
      const float w = m.weights.weights[static_cast<std::size_t>(v * k + i)];
      ASSERT_GE(w, 0.0f);
      sum += w;
      if (w > top) top = w, top_joint = m.skin_joints[m.weights.joints[static_cast<std::size_t>(v * k + i)]];
    }
    worst_sum = std::max(worst_sum, std::abs(sum - 1.0f));
    if (DistanceToJointBones(*body, top_joint, mesh.positions[static_cast<std::size_t>(v)]) > 0.2f * body->size()) ++far;
  }
  EXPECT_LT(worst_sum, 1e-5f);
  EXPECT_EQ(far, 0) << "vertices whose heaviest joint has no bone within 0.2 S";
}

TEST(ImplicitBody, RoundConeDistanceIsExact) {
  deform::BodyPrimitive cone;
  cone.a = {0, 0, 0};
  cone.b = {0, 10, 0};
  cone.r0 = 3.0f;
  cone.r1 = 1.0f;
  // Beyond the ends: spheres.
  EXPECT_NEAR(deform::PrimitiveDistance(cone, {0, -5, 0}), 2.0f, 1e-5f);
  EXPECT_NEAR(deform::PrimitiveDistance(cone, {0, 14, 0}), 3.0f, 1e-5f);
  // The side: the tangent line of both circles, sin t = (3 - 1) / 10; a point on the
  // radial line through the side's touching point on sphere a, 2 units out.
  const float sin_t = 0.2f, cos_t = std::sqrt(1.0f - sin_t * sin_t);
  const glm::vec3 on_side(3.0f * cos_t, 3.0f * sin_t, 0.0f);
  const glm::vec3 out = on_side + 2.0f * glm::vec3(cos_t, sin_t, 0.0f) + 0.5f * glm::vec3(-sin_t, cos_t, 0.0f);
  EXPECT_NEAR(deform::PrimitiveDistance(cone, out), 2.0f, 1e-4f);
  // Inside on the axis, nearer the side than either end.
  EXPECT_NEAR(deform::PrimitiveDistance(cone, {0, 5, 0}), 5.0f * sin_t - 3.0f, 1e-4f);
  // Smooth min: min far apart, below both where they meet.
  EXPECT_EQ(deform::SmoothMin(1.0f, 5.0f, 2.0f), 1.0f);
  EXPECT_NEAR(deform::SmoothMin(1.0f, 1.0f, 2.0f), 0.5f, 1e-6f);
}

// The self-intersection check itself: two octahedra in one mesh are clean while apart and
// cross along a curve once they overlap; one triangle's edge through another is one pair.
TEST(BodyChecks, SelfIntersectionFindsOverlappingParts) {
  const auto two_octahedra = [](glm::vec3 offset) {
    deform::Mesh m;
    m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (int i = 0; i < 6; ++i) m.positions.push_back(m.positions[static_cast<std::size_t>(i)] + offset);
    for (int i = 0; i < 8; ++i) m.triangles.push_back(m.triangles[static_cast<std::size_t>(i)] + glm::uvec3(6));
    return m;
  };
  EXPECT_EQ(testsupport::BadEdges(two_octahedra({5, 0, 0})), 0);
  EXPECT_EQ(testsupport::SelfIntersectingPairs(two_octahedra({5, 0, 0})), 0);
  EXPECT_GT(testsupport::SelfIntersectingPairs(two_octahedra({0.5f, 0.21f, 0.13f})), 0);
  // Two triangles far apart in one mesh, then one moved to cross the other.
  deform::Mesh two;
  two.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5f, 0.5f, 5}, {0.5f, 0.5f, 6}, {1.5f, 0.5f, 5}};
  two.triangles = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(testsupport::SelfIntersectingPairs(two), 0);
  two.positions[3].z = -1.0f;  // its edge 3-4 now passes through the first triangle
  EXPECT_EQ(testsupport::SelfIntersectingPairs(two), 1);
}

TEST(GeneratedBody, HumanoidIsOneClosedManifoldWithHeatWeights) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(1.0f, true, true, ""), false, 8.0f);
  const auto start = std::chrono::steady_clock::now();
  auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  std::printf("humanoid: %d vertices, %d triangles, %.3f s\n", m->bind.num_vertices(), m->bind.num_triangles(), s);
  ExpectValidBody(b.skeleton, b.model_from_joint, *m);
  auto body = deform::BuildImplicitBody(b.skeleton, b.model_from_joint);
  ASSERT_TRUE(body.ok());
  EXPECT_TRUE(body->humanoid());
}

TEST(GeneratedBody, QuadrupedAndTailGetABody) {
  for (const auto& specs : {testsupport::Quadruped(), testsupport::Tail(12, 60.0f)}) {
    const BuiltSkeleton b = SkeletonFrom(specs, false, 3.0f);
    auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
    ASSERT_TRUE(m.ok()) << m.error().ToString();
    std::printf("%s: %d vertices, %d triangles\n", b.skeleton.names[0].c_str(), m->bind.num_vertices(),
                m->bind.num_triangles());
    ExpectValidBody(b.skeleton, b.model_from_joint, *m);
    auto body = deform::BuildImplicitBody(b.skeleton, b.model_from_joint);
    ASSERT_TRUE(body.ok());
    EXPECT_FALSE(body->humanoid());
  }
}

TEST(GeneratedBody, CmuCaptureWithinTheTriangleBudget) {
  const auto path = testsupport::SharedDataPath("bvh/cmu_cgspeed/01_01.bvh");
  PATCHSKIN_REQUIRE_SHARED_FILE(path);
  auto file = mocap::ReadBvhFile(path.string());
  ASSERT_TRUE(file.ok()) << file.error().ToString();
  const std::vector<glm::mat4> rest = RestMatrices(file->skeleton);
  auto m = deform::BuildGeneratedBody(file->skeleton, rest);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  std::printf("01_01: %d joints, %d vertices, %d triangles\n", file->skeleton.num_joints(), m->bind.num_vertices(),
              m->bind.num_triangles());
  EXPECT_GE(m->bind.num_triangles(), 20000);
  EXPECT_LE(m->bind.num_triangles(), 60000);
  ExpectValidBody(file->skeleton, rest, *m);
}

}  // namespace
namespace {

// Manifold at coarse and fine voxels alike: the narrow band must hold every voxel near the
// smooth union's surface, also where a blend moves it outside every single part's band.
TEST(BodyMesher, ClosedManifoldAtEveryResolution) {
  for (const auto& specs : {testsupport::Quadruped(), testsupport::Tail(12, 60.0f),
                            testsupport::Humanoid(1.0f, true, true, "")}) {
    const BuiltSkeleton b = SkeletonFrom(specs, false, 3.0f);
    auto body = deform::BuildImplicitBody(b.skeleton, b.model_from_joint);
    ASSERT_TRUE(body.ok());
    for (const float res : {90.0f, 250.0f}) {
      auto mesh = deform::MeshImplicitBody(*body, {.voxels_per_size = res, .target_triangles = 0, .max_triangles = 400000});
      ASSERT_TRUE(mesh.ok()) << mesh.error().ToString();
      EXPECT_EQ(testsupport::BadEdges(*mesh), 0) << b.skeleton.names[0] << " at S/" << res;
      EXPECT_EQ(testsupport::ConnectedPieces(*mesh), 1) << b.skeleton.names[0] << " at S/" << res;
      EXPECT_GT(testsupport::SmallestRelativeArea(*mesh), 1e-6);
    }
  }
}

// Same skeleton, same bytes, whatever the number of TBB threads OpenVDB may use.
TEST(GeneratedBody, SameBytesOnOneAndFourThreads) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Humanoid(1.0f, true, false, ""), false, 8.0f);
  std::vector<deform::SkinnedMesh> runs;
  for (const std::size_t threads : {std::size_t{1}, std::size_t{4}}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
    ASSERT_TRUE(m.ok());
    runs.push_back(std::move(*m));
  }
  const auto same = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  EXPECT_TRUE(same(runs[0].bind.positions, runs[1].bind.positions));
  EXPECT_TRUE(same(runs[0].bind.triangles, runs[1].bind.triangles));
  EXPECT_TRUE(same(runs[0].bind.normals, runs[1].bind.normals));
  EXPECT_TRUE(same(runs[0].weights.weights, runs[1].weights.weights));
  EXPECT_TRUE(same(runs[0].weights.joints, runs[1].weights.joints));
}

// The second build of the same skeleton in the same pose comes from the cache, bytes equal;
// another pose misses it.
TEST(GeneratedBody, CacheReturnsTheSameBodyForTheSameRestPose) {
  const std::filesystem::path folder = testsupport::TestOutputPath("body_cache/x").parent_path();
  std::filesystem::remove_all(folder);
  const BuiltSkeleton b = SkeletonFrom(testsupport::Quadruped(), false, 3.0f);
  bool hit = true;
  auto first = deform::BuildGeneratedBodyCached(b.skeleton, b.model_from_joint, {}, folder, &hit);
  ASSERT_TRUE(first.ok());
  EXPECT_FALSE(hit);
  auto second = deform::BuildGeneratedBodyCached(b.skeleton, b.model_from_joint, {}, folder, &hit);
  ASSERT_TRUE(second.ok());
  EXPECT_TRUE(hit);
  ASSERT_EQ(first->bind.positions.size(), second->bind.positions.size());
  EXPECT_EQ(std::memcmp(first->bind.positions.data(), second->bind.positions.data(),
                        first->bind.positions.size() * sizeof(glm::vec3)), 0);
  EXPECT_EQ(first->weights.weights, second->weights.weights);
  EXPECT_EQ(first->weights.joints, second->weights.joints);
  EXPECT_EQ(first->skin_joints, second->skin_joints);
  std::vector<glm::mat4> moved = b.model_from_joint;
  moved[1][3].y += 1.0f;
  auto third = deform::BuildGeneratedBodyCached(b.skeleton, moved, {}, folder, &hit);
  ASSERT_TRUE(third.ok());
  EXPECT_FALSE(hit);
  // A damaged cache file is regenerated, not trusted.
  for (const auto& e : std::filesystem::directory_iterator(folder)) std::filesystem::resize_file(e.path(), 100);
  auto fourth = deform::BuildGeneratedBodyCached(b.skeleton, b.model_from_joint, {}, folder, &hit);
  ASSERT_TRUE(fourth.ok());
  EXPECT_FALSE(hit);
  EXPECT_EQ(fourth->weights.weights, first->weights.weights);
}

// The cache key follows which joints are body, not the motion: two motions of
// one skeleton share a body; a motion that pulls a limb off (an IK-like joint)
// gets its own.
TEST(GeneratedBody, CacheKeyFollowsTheBodyNotTheMotion) {
  const BuiltSkeleton b = SkeletonFrom(testsupport::Quadruped(), false, 3.0f);
  mocap::Skeleton still = b.skeleton, moving = b.skeleton, pulled = b.skeleton;
  const auto nj = static_cast<std::size_t>(b.skeleton.num_joints());
  still.channel_use.assign(nj, 0);
  moving.channel_use.assign(nj, mocap::kJointRotates);
  moving.channel_use[0] |= mocap::kJointStretches;  // the root walks
  pulled.channel_use = moving.channel_use;
  pulled.channel_use[nj - 1] |= mocap::kJointStretches;  // a leaf pulled off its parent
  const auto key = [&](const mocap::Skeleton& s) { return deform::GeneratedBodyKey(s, b.model_from_joint, {}); };
  EXPECT_EQ(key(still), key(b.skeleton));
  EXPECT_EQ(key(moving), key(b.skeleton));
  EXPECT_NE(key(pulled), key(b.skeleton));
}

TEST(GeneratedBody, BadSkeletonsGetABodyOrAnErrorNamingTheJoint) {
  // Zero-length bones in the middle of a chain (two joints at one place).
  {
    SCOPED_TRACE("zero-length bone");
    std::vector<testsupport::JointSpec> specs = testsupport::Tail(8, 50.0f);
    specs[4].model_pos = specs[3].model_pos;
    const BuiltSkeleton b = SkeletonFrom(specs, false, 3.0f);
    auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
    ASSERT_TRUE(m.ok()) << m.error().ToString();
    ExpectValidBody(b.skeleton, b.model_from_joint, *m);
  }
  // Every joint at one point, and a lone joint: errors that name a joint.
  {
    std::vector<testsupport::JointSpec> specs = testsupport::Tail(5, 50.0f);
    for (auto& s : specs) s.model_pos = glm::vec3(1, 2, 3);
    const BuiltSkeleton b = SkeletonFrom(specs, false, 0.0f);
    auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.error().message.find("'tail0'"), std::string::npos) << m.error().message;
    const BuiltSkeleton one = SkeletonFrom({{"lonely", -1, glm::vec3(0)}}, false, 0.0f);
    auto n = deform::BuildGeneratedBody(one.skeleton, one.model_from_joint);
    ASSERT_FALSE(n.ok());
    EXPECT_NE(n.error().message.find("'lonely'"), std::string::npos) << n.error().message;
  }
  // 500 joints in one chain: a body within the triangle limit.
  {
    SCOPED_TRACE("500 joints");
    const BuiltSkeleton b = SkeletonFrom(testsupport::Tail(500, 200.0f), false, 1.0f);
    auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
    ASSERT_TRUE(m.ok()) << m.error().ToString();
    ExpectValidBody(b.skeleton, b.model_from_joint, *m);
  }
  // A hand two kilometres away (cm units): a body or a clear error, bounded time and memory.
  {
    std::vector<testsupport::JointSpec> specs = testsupport::Humanoid(1.0f, false, false, "");
    for (auto& s : specs) {
      if (s.name == "LeftHand" || s.name == "LeftFingers") s.model_pos += glm::vec3(2e5f, 0.0f, 0.0f);
    }
    const BuiltSkeleton b = SkeletonFrom(specs, false, 0.0f);
    auto m = deform::BuildGeneratedBody(b.skeleton, b.model_from_joint);
    SCOPED_TRACE(m.ok() ? "km apart: a body" : m.error().message);
    if (m.ok()) {
      ExpectValidBody(b.skeleton, b.model_from_joint, *m);
    } else {
      EXPECT_FALSE(m.error().message.empty());
    }
  }
}

}  // namespace
namespace {

// Volume of `mesh` skinned by SSD with the synthetic humanoid posed by `model` (#J).
double SsdVolume(const deform::SkinnedMesh& mesh, std::span<const glm::mat4> model) {
  std::vector<glm::mat4> palette(mesh.skin_joints.size());
  for (std::size_t s = 0; s < palette.size(); ++s) {
    palette[s] = model[static_cast<std::size_t>(mesh.skin_joints[s])] * mesh.joint_from_bind[s];
  }
  std::vector<glm::vec3> out(mesh.bind.positions.size());
  EXPECT_TRUE((deform::SkinningJob{.model_from_bind = palette, .influences = mesh.weights.influences,
                                   .joint_indices = mesh.weights.joints, .joint_weights = mesh.weights.weights,
                                   .rest_positions = mesh.bind.positions, .rest_normals = {}, .positions = out, .normals = {}}
                   .Run()));
  return testsupport::EnclosedVolume(out, mesh.bind.triangles);
}

// SSD's volume loss, the artefact the patch layer exists to fix, on the new body and the
// tube mannequin (printed; the figures go in the report). The new body must lose volume
// where SSD is known to collapse it (a 150 degree elbow or knee).
TEST(GeneratedBody, SsdVolumeLossAgainstTheTubeBody) {
  const mocap::Skeleton s = synthetic::MakeHumanoidSkeleton();
  const std::vector<glm::mat4> rest = RestMatrices(s);
  auto generated = deform::BuildGeneratedBody(s, rest);
  auto tubes = deform::BuildMannequin(s, rest);
  ASSERT_TRUE(generated.ok() && tubes.ok());
  struct Pose {
    const char* name;
    const char* joint;
    glm::vec3 axis;  // turn axis (model space; the humanoid faces +Z, left arm along +X)
    float degrees;
  };
  const Pose poses[] = {{"elbow 90", "LeftForeArm", {0, -1, 0}, 90.0f},
                        {"elbow 150", "LeftForeArm", {0, -1, 0}, 150.0f},
                        {"knee 90", "LeftLeg", {1, 0, 0}, 90.0f},
                        {"knee 150", "LeftLeg", {1, 0, 0}, 150.0f},
                        {"hip extension 40", "LeftUpLeg", {1, 0, 0}, 40.0f},
                        {"shoulder abduction 90 (T-pose to arm up)", "LeftArm", {0, 0, 1}, 90.0f}};
  const double v_new = SsdVolume(*generated, rest), v_old = SsdVolume(*tubes, rest);
  std::printf("SSD volume change (%% of the whole body; litres), new body vs tube body:\n");
  for (const Pose& p : poses) {
    const int j = s.FindJoint(p.joint);
    ASSERT_GE(j, 0) << p.joint;
    std::vector<glm::mat4> model = rest;
    deform::TurnSubtree(s, j, glm::angleAxis(glm::radians(p.degrees), p.axis), glm::vec3(rest[static_cast<std::size_t>(j)][3]),
                        model);
    const double d_new = SsdVolume(*generated, model) - v_new, d_old = SsdVolume(*tubes, model) - v_old;
    std::printf("  %-42s new %+6.2f %% (%+.3f l)   tubes %+6.2f %% (%+.3f l)\n", p.name, 100.0 * d_new / v_new,
                d_new / 1000.0, 100.0 * d_old / v_old, d_old / 1000.0);
    if (std::string(p.name) == "elbow 150" || std::string(p.name) == "knee 150") {
      EXPECT_LT(d_new, 0.0) << p.name << ": SSD should lose volume on the new body";
    }
  }
}

}  // namespace
