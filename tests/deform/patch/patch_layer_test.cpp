#include "deform/patch/patch_layer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "deform/global/artifact_metrics.h"
#include "deform/patch/patch_region.h"
#include "support/patch_layer_fixture.h"
#include "support/tolerances.h"

namespace {

using testfixture::JointPos;
using testfixture::LayeredBody;

const LayeredBody& Body() {
  static const LayeredBody body = testfixture::MakeLayeredBody();
  return body;
}

const std::vector<deform::PatchSetup>& Patches() {
  static const std::vector<deform::PatchSetup> patches = [] {
    std::vector<deform::PatchSetup> p;
    p.push_back(*testfixture::MakePatch(Body(), testfixture::ElbowSpec(Body())));
    p.push_back(*testfixture::MakePatch(Body(), testfixture::KneeSpec(Body())));
    return p;
  }();
  return patches;
}

TEST(PatchRegion, JointRadiusKeepsNearVerticesOnTheBonesAndTheSide) {
  const LayeredBody& b = Body();
  const glm::vec3 elbow = JointPos(b.rest_model, b.elbow);
  const auto all = deform::SelectJointRegion(
      b.mesh, {.bone_joints = {b.shoulder, b.elbow}, .centre = elbow, .radius = 10.0f});
  ASSERT_TRUE(all.ok()) << all.error().ToString();
  const auto front = deform::SelectJointRegion(
      b.mesh, {.bone_joints = {b.shoulder, b.elbow}, .centre = elbow, .radius = 10.0f,
               .side = {0, 0, 1}, .half_angle_deg = 90.0f});
  ASSERT_TRUE(front.ok());
  EXPECT_LT(front->size(), all->size());
  EXPECT_GT(front->size(), all->size() / 4);
  std::vector<glm::vec3> normals(b.mesh.bind.positions.size());
  deform::ComputeVertexNormals(b.mesh.bind.positions, b.mesh.bind.triangles, normals);
  // Independent check: every selected vertex is within the radius and weighted to
  // the two bones; every vertex of the mesh meeting the criteria is selected.
  const std::set<int> chosen(all->begin(), all->end());
  for (int v = 0; v < b.mesh.bind.num_vertices(); ++v) {
    const auto vi = static_cast<std::size_t>(v);
    float w = 0.0f;
    for (int i = 0; i < 4; ++i) {
      const int j = b.mesh.skin_joints[b.mesh.weights.joints[vi * 4 + static_cast<std::size_t>(i)]];
      if (j == b.shoulder || j == b.elbow) w += b.mesh.weights.weights[vi * 4 + static_cast<std::size_t>(i)];
    }
    const bool expected = glm::length(b.mesh.bind.positions[vi] - elbow) <= 10.0f && w >= 0.5f;
    EXPECT_EQ(chosen.count(v) == 1, expected) << "vertex " << v;
  }
  for (const int v : *front) EXPECT_GE(normals[static_cast<std::size_t>(v)].z, -1e-5f);
}

TEST(PatchRegion, JointRadiusErrors) {
  const LayeredBody& b = Body();
  EXPECT_EQ(deform::SelectJointRegion(b.mesh, {.bone_joints = {}, .radius = 1.0f}).error().code,
            base::ErrorCode::kInvalidArgument);
  EXPECT_EQ(
      deform::SelectJointRegion(b.mesh, {.bone_joints = {b.elbow}, .radius = -1.0f}).error().code,
      base::ErrorCode::kInvalidArgument);
  // Far from any vertex: nothing qualifies.
  EXPECT_EQ(deform::SelectJointRegion(
                b.mesh, {.bone_joints = {b.elbow}, .centre = {0, 1000, 0}, .radius = 1.0f})
                .error()
                .code,
            base::ErrorCode::kNotFound);
}

TEST(PatchRegion, ExplicitListIsCheckedAndSorted) {
  const std::vector<int> ok = {5, 1, 3};
  EXPECT_EQ(*deform::CheckVertexRegion(ok, 10), (std::vector<int>{1, 3, 5}));
  const std::vector<int> past = {1, 10};
  EXPECT_EQ(deform::CheckVertexRegion(past, 10).error().message,
            "vertex region: vertex 1 (index 10) is outside the 10 vertices");
  const std::vector<int> twice = {4, 2, 4};
  EXPECT_EQ(deform::CheckVertexRegion(twice, 10).error().message,
            "vertex region: vertex 2 (index 4) appears twice");
  EXPECT_FALSE(deform::CheckVertexRegion({}, 10).ok());
}

TEST(PatchLayer, BorderWeightIsASmoothstepOfTheBorderDistance) {
  EXPECT_EQ(deform::BorderWeight(0.0f, 0.5f, 0.1f), 0.0f);
  EXPECT_EQ(deform::BorderWeight(0.5f, 0.5f, 0.1f), 1.0f);
  EXPECT_NEAR(deform::BorderWeight(0.05f, 0.5f, 0.1f), 0.5f, testsupport::kFloatTol);
  EXPECT_NEAR(deform::BorderWeight(0.5f, 0.975f, 0.1f), 0.25f * 0.25f * 2.5f,
              testsupport::kFloatTol);
  EXPECT_EQ(deform::BorderWeight(0.0f, 0.0f, 0.0f), 1.0f);  // width 0: no fade
}

TEST(PatchLayer, DominantJointCarriesTheMostControlWeight) {
  deform::SkinnedMesh mesh;
  mesh.skin_joints = {7, 3, 9};  // skin joint -> skeleton joint
  deform::PatchSetup patch;
  patch.control_weights.influences = 2;
  // Skin joint 1 (skeleton 3) carries 0.6 + 0.6 = 1.2, skin joint 0 carries 0.8.
  patch.control_weights.joints = {0, 1, 1, 2, 1, 0};
  patch.control_weights.weights = {0.4f, 0.6f, 0.6f, 0.4f, 0.0f, 0.4f};
  EXPECT_EQ(deform::DominantJoint(mesh, patch), 3);
  patch.control_weights.weights = {0.9f, 0.1f, 0.1f, 0.9f, 0.1f, 0.9f};  // skin joint 0: 1.8
  EXPECT_EQ(deform::DominantJoint(mesh, patch), 7);
  patch.control_weights.joints = {0, 1, 0, 1, 0, 1};  // a tie goes to the first
  patch.control_weights.weights.assign(6, 0.5f);
  EXPECT_EQ(deform::DominantJoint(mesh, patch), 7);
  patch.control_weights = {};
  EXPECT_EQ(deform::DominantJoint(mesh, patch), 0);
}

TEST(PatchLayer, ControlPointWeightsAreValidAndFollowTheBones) {
  const LayeredBody& b = Body();
  for (const deform::PatchSetup& p : Patches()) {
    ASSERT_GT(p.num_bound(), 100);
    const base::Status s = deform::CheckSkinWeights(
        p.control_weights, static_cast<int>(b.mesh.skin_joints.size()), p.num_control());
    EXPECT_TRUE(s.ok()) << s.error().ToString();
  }
  // Elbow: the control rows at the ends of the cylinder's height follow the
  // upper arm and the forearm respectively.
  const deform::PatchSetup& elbow = Patches()[0];
  const int nu = elbow.fit.surface.num_u(), nv = elbow.fit.surface.num_v();
  auto weight_on = [&](int c, int joint) {
    float w = 0.0f;
    for (int i = 0; i < 4; ++i) {
      const auto slot = static_cast<std::size_t>(4 * c + i);
      if (b.mesh.skin_joints[elbow.control_weights.joints[slot]] == joint) {
        w += elbow.control_weights.weights[slot];
      }
    }
    return w;
  };
  for (int i = 0; i < nu; ++i) {
    EXPECT_GT(weight_on(i * nv, b.shoulder), 0.9f) << "row " << i;
    EXPECT_GT(weight_on(i * nv + nv - 1, b.elbow), 0.9f) << "row " << i;
  }
}

TEST(PatchLayer, RestPoseGivesTheBindMesh) {
  const LayeredBody& b = Body();
  const testfixture::LayeredFrame f =
      testfixture::EvaluateLayered(b, Patches(), b.rest_model);
  for (const deform::PatchSetup& p : Patches()) {
    const double size = p.fit.surface.ControlDiagonal();
    double worst = 0.0;
    for (const int v : p.region) {
      const auto vi = static_cast<std::size_t>(v);
      worst = std::max(worst, static_cast<double>(glm::length(f.layered[vi] - b.mesh.bind.positions[vi])));
    }
    EXPECT_LT(worst, testsupport::kRebuildRelTol * size);
  }
}

// With a reference grid the layer adds only P(carried + d) - P(reference):
// nothing when carried == reference and there is no displacement (bit for bit,
// in a posed frame where the rebuild of the carried grid differs from G), and
// beta (P(Q) - P(G)) on a vertex of one patch, computed here by two rebuilds.
TEST(PatchLayer, ReferenceGridAddsOnlyWhatTheDisplacementChanges) {
  const LayeredBody& b = Body();
  const testfixture::LayeredFrame f = testfixture::EvaluateLayered(
      b, Patches(), testfixture::BendPose(b, 70.0f));
  ASSERT_NE(f.global, f.layered);  // the rebuild alone moves the skin (replace mode)
  std::vector<std::vector<glm::vec3>> carried;
  std::vector<std::span<const glm::vec3>> views;
  for (const deform::PatchSetup& p : Patches()) carried.push_back(p.rest_control);
  for (std::size_t k = 0; k < carried.size(); ++k) {
    // Any grid will do as G; move it off the rest grid so P(G) != G.
    for (glm::vec3& q : carried[k]) q += glm::vec3(0.3f, -0.2f, 0.1f);
    views.emplace_back(carried[k]);
  }
  deform::PatchLayerScratch scratch;
  std::vector<glm::vec3> same = f.global;
  ASSERT_TRUE(deform::ApplyPatchLayer(Patches(), views, {}, scratch, same, views).ok());
  EXPECT_EQ(same, f.global);

  std::vector<glm::vec3> lift(Patches()[0].rest_control.size(), glm::vec3(0.0f));
  lift[lift.size() / 2 + 2] = glm::vec3(0.0f, 1.5f, 0.0f);
  const std::span<const glm::vec3> dq[] = {lift, {}};
  std::vector<glm::vec3> moved = f.global;
  ASSERT_TRUE(deform::ApplyPatchLayer(Patches(), views, dq, scratch, moved, views).ok());
  // Independently: both rebuilds of patch 0, on its vertices no other patch binds.
  const deform::PatchSetup& p0 = Patches()[0];
  std::vector<glm::vec3> q = carried[0];
  for (std::size_t c = 0; c < q.size(); ++c) q[c] += lift[c];
  std::vector<glm::vec3> with(p0.bound.binding.size()), without(p0.bound.binding.size());
  const deform::PatchRebuildJob rebuild_with{
      .control = q, .bindings = p0.bound.binding.view(), .positions = with};
  const deform::PatchRebuildJob rebuild_without{
      .control = carried[0], .bindings = p0.bound.binding.view(), .positions = without};
  ASSERT_TRUE(rebuild_with.Run());
  ASSERT_TRUE(rebuild_without.Run());
  const std::set<int> other(Patches()[1].bound.binding.vertex.begin(),
                            Patches()[1].bound.binding.vertex.end());
  int checked = 0;
  for (std::size_t r = 0; r < with.size(); ++r) {
    const int v = p0.bound.binding.vertex[r];
    if (other.count(v)) continue;
    const glm::vec3 expected =
        f.global[static_cast<std::size_t>(v)] + p0.border_weight[r] * (with[r] - without[r]);
    EXPECT_LT(glm::length(moved[static_cast<std::size_t>(v)] - expected), 1e-5f) << v;
    ++checked;
  }
  EXPECT_GT(checked, 20);
  double largest = 0.0;
  for (std::size_t v = 0; v < moved.size(); ++v) {
    largest = std::max(largest, static_cast<double>(glm::length(moved[v] - f.global[v])));
  }
  EXPECT_GT(largest, 0.1);  // the lift shows
}

TEST(PatchLayer, ApplyChecksSizes) {
  const LayeredBody& b = Body();
  std::vector<glm::vec3> positions = b.mesh.bind.positions;
  deform::PatchLayerScratch scratch;
  const std::vector<glm::vec3> short_grid(3);
  const std::span<const glm::vec3> one[] = {short_grid};
  EXPECT_FALSE(deform::ApplyPatchLayer(Patches(), one, {}, scratch, positions).ok());
  const std::span<const glm::vec3> two[] = {Patches()[0].rest_control, short_grid};
  EXPECT_FALSE(deform::ApplyPatchLayer(Patches(), two, {}, scratch, positions).ok());
  const std::span<const glm::vec3> good[] = {Patches()[0].rest_control, Patches()[1].rest_control};
  EXPECT_FALSE(deform::ApplyPatchLayer(Patches(), good, one, scratch, positions).ok());
  EXPECT_TRUE(deform::ApplyPatchLayer(Patches(), good, {}, scratch, positions).ok());
  // A displacement moves the patch interior, not vertices outside the patches.
  std::vector<glm::vec3> lift(Patches()[0].rest_control.size(), glm::vec3(0, 1, 0));
  const std::span<const glm::vec3> dq[] = {lift, {}};
  std::vector<glm::vec3> moved = b.mesh.bind.positions;
  ASSERT_TRUE(deform::ApplyPatchLayer(Patches(), good, dq, scratch, moved).ok());
  std::set<int> in_patch(Patches()[0].bound.binding.vertex.begin(),
                         Patches()[0].bound.binding.vertex.end());
  std::set<int> in_other(Patches()[1].bound.binding.vertex.begin(),
                         Patches()[1].bound.binding.vertex.end());
  int lifted = 0;
  for (int v = 0; v < b.mesh.bind.num_vertices(); ++v) {
    const glm::vec3 d = moved[static_cast<std::size_t>(v)] - b.mesh.bind.positions[static_cast<std::size_t>(v)];
    if (!in_patch.count(v) && !in_other.count(v)) {
      EXPECT_EQ(d, glm::vec3(0.0f));
    } else if (d.y > 0.99f) {
      ++lifted;
    }
  }
  EXPECT_GT(lifted, 10);
}

// Largest |D_a - D_b| (D = layered - global) over mesh edges that cross from a
// patch vertex to a vertex outside every patch, and over edges inside patches.
struct Jumps {
  double across = 0.0, inside = 0.0;
};
Jumps BorderJumps(const LayeredBody& b, const deform::PatchSetup& p,
                  const testfixture::LayeredFrame& f) {
  std::vector<char> in(b.mesh.bind.positions.size(), 0);
  for (const int v : p.bound.binding.vertex) in[static_cast<std::size_t>(v)] = 1;
  Jumps j;
  for (const glm::uvec3& t : b.mesh.bind.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::size_t a = t[e], c = t[(e + 1) % 3];
      if (!in[a] && !in[c]) continue;
      const glm::vec3 da = f.layered[a] - f.global[a], dc = f.layered[c] - f.global[c];
      const double jump = glm::length(da - dc);
      (in[a] && in[c] ? j.inside : j.across) = std::max(in[a] && in[c] ? j.inside : j.across, jump);
    }
  }
  return j;
}

TEST(PatchLayer, BorderBlendLeavesNoJump) {
  const LayeredBody& b = Body();
  const std::vector<glm::mat4> pose = testfixture::BendPose(b, 120.0f);
  const testfixture::LayeredFrame f = testfixture::EvaluateLayered(b, Patches(), pose);
  const std::vector<deform::PatchSetup> hard = {
      *testfixture::MakePatch(b, testfixture::ElbowSpec(b), 0.0f)};
  const testfixture::LayeredFrame fh = testfixture::EvaluateLayered(b, hard, pose);
  const Jumps blended = BorderJumps(b, Patches()[0], f);
  const Jumps abrupt = BorderJumps(b, hard[0], fh);
  std::printf("elbow at 120 deg: max neighbour jump across the border %.4f (inside %.4f); "
              "without the fade %.4f\n", blended.across, blended.inside, abrupt.across);
  EXPECT_GT(blended.inside, 0.0);
  EXPECT_LE(blended.across, blended.inside);  // the border is no rougher than the interior
  EXPECT_LT(blended.across, 0.5 * abrupt.across);
}

// The SSD ring figure against cos(angle/2): rings sit within 0.6 of the plane.
constexpr double kCollapseTol = 2e-3;
// Float rounding of a few sums of positions of size ~100 (model units).
constexpr float kOverlapTol = 1e-4f;
// Least improvement of the collapse figure the patches must bring (of 1 = no collapse).
constexpr double kMinCollapseGain = 0.05;

// Collapse figure at the joint ring (bisector plane, artifact_metrics.h).
double Collapse(const LayeredBody& b, const std::vector<glm::mat4>& pose, int parent, int joint,
                int child, std::span<const glm::vec3> positions) {
  const glm::vec3 j0 = JointPos(b.rest_model, joint);
  const deform::RingPlane rest = deform::BisectorPlane(
      j0, glm::normalize(j0 - JointPos(b.rest_model, parent)),
      glm::normalize(JointPos(b.rest_model, child) - j0));
  std::vector<std::uint32_t> ring;
  for (const std::uint32_t v : deform::RingNearPlane(b.mesh.bind.positions, rest, 0.6)) {
    // This limb only: near the joint and weighted to the bones meeting there.
    float w = 0.0f;
    for (std::size_t i = 0; i < 4; ++i) {
      const int j = b.mesh.skin_joints[b.mesh.weights.joints[4 * v + i]];
      if (j == parent || j == joint) w += b.mesh.weights.weights[4 * v + i];
    }
    if (glm::length(b.mesh.bind.positions[v] - j0) < 12.0f && w > 0.99f) ring.push_back(v);
  }
  const glm::vec3 j1 = JointPos(pose, joint);
  const deform::ArtifactRing r{
      .vertices = ring, .rest_plane = rest,
      .plane = deform::BisectorPlane(j1, glm::normalize(j1 - JointPos(pose, parent)),
                                     glm::normalize(JointPos(pose, child) - j1))};
  return *deform::CollapseFigure(b.mesh.bind.positions, positions, r);
}

TEST(PatchLayer, ElbowAndKneePatchesReduceTheCollapse) {
  const LayeredBody& b = Body();
  for (const float angle : {120.0f, 150.0f}) {
    const std::vector<glm::mat4> pose = testfixture::BendPose(b, angle);
    const testfixture::LayeredFrame f = testfixture::EvaluateLayered(b, Patches(), pose);
    const double elbow_ssd = Collapse(b, pose, b.shoulder, b.elbow, b.hand, f.global);
    const double elbow_patch = Collapse(b, pose, b.shoulder, b.elbow, b.hand, f.layered);
    const double knee_ssd = Collapse(b, pose, b.hip, b.knee, b.ankle, f.global);
    const double knee_patch = Collapse(b, pose, b.hip, b.knee, b.ankle, f.layered);
    std::printf("collapse figure at %.0f deg: elbow SSD %.4f patches %.4f; knee SSD %.4f "
                "patches %.4f\n", static_cast<double>(angle), elbow_ssd, elbow_patch, knee_ssd,
                knee_patch);
    // SSD's joint ring shrinks by cos(angle / 2) (weights 1/2, 1/2): check the
    // measurement, then that the patches keep clearly more of the section.
    const double ssd_expected = std::cos(glm::radians(static_cast<double>(angle)) / 2.0);
    EXPECT_NEAR(elbow_ssd, ssd_expected, kCollapseTol) << angle;
    EXPECT_NEAR(knee_ssd, ssd_expected, kCollapseTol) << angle;
    EXPECT_GT(elbow_patch, elbow_ssd + kMinCollapseGain) << angle;
    EXPECT_GT(knee_patch, knee_ssd + kMinCollapseGain) << angle;
  }
}

}  // namespace

namespace {

// Two patches sharing vertices (front and top of the left elbow): each shared
// vertex gets G + sum_k beta_k (P_k - G) / max(1, sum_k beta_k), checked
// against one-patch runs, which give G + beta_k (P_k - G) each.
TEST(PatchLayer, OverlappingPatchesAverage) {
  const LayeredBody& b = Body();
  std::vector<deform::PatchSetup> both;
  both.push_back(*testfixture::MakePatch(b, testfixture::ElbowSpec(b)));
  both.push_back(*testfixture::MakePatch(b, {b.shoulder, b.elbow, 14.0f, glm::vec3(0, 1, 0)}));
  const std::vector<glm::mat4> pose = testfixture::BendPose(b, 120.0f);
  const testfixture::LayeredFrame f = testfixture::EvaluateLayered(b, both, pose);
  const testfixture::LayeredFrame f0 = testfixture::EvaluateLayered(b, {&both[0], 1}, pose);
  const testfixture::LayeredFrame f1 = testfixture::EvaluateLayered(b, {&both[1], 1}, pose);
  std::vector<float> beta(b.mesh.bind.positions.size(), 0.0f);
  for (const deform::PatchSetup& p : both) {
    for (std::size_t r = 0; r < p.bound.binding.size(); ++r) {
      beta[static_cast<std::size_t>(p.bound.binding.vertex[r])] += p.border_weight[r];
    }
  }
  int shared = 0;
  for (const int v : both[0].bound.binding.vertex) {
    const auto vi = static_cast<std::size_t>(v);
    const glm::vec3 g = f.global[vi];
    const glm::vec3 expected = g + ((f0.layered[vi] - g) + (f1.layered[vi] - g)) /
                                       std::max(1.0f, beta[vi]);
    EXPECT_LT(glm::length(f.layered[vi] - expected), kOverlapTol) << "vertex " << v;
    const auto& other = both[1].bound.binding.vertex;
    shared += std::find(other.begin(), other.end(), v) != other.end() && beta[vi] > 1.0f;
  }
  EXPECT_GT(shared, 20);  // the patches do overlap where both are fully on
}

}  // namespace
