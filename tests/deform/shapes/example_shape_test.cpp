// End to end through ALGORITHMS.md 4.3 and 5: a skin-vertex edit at an example
// pose is solved on the posed patch, stored in the control points' local
// frames, interpolated by the RBF and applied per frame as Q = G + A dS.
#include <gtest/gtest.h>

#include "deform/shapes/direct_manipulation.h"
#include "deform/patch/patch_fit.h"
#include "deform/shapes/pose_space.h"
#include "mocap/joint_angles.h"
#include "support/bound_tube.h"
#include "support/patch_meshes.h"
#include "support/tolerances.h"

namespace {

using deform::BSplineSurface;

TEST(ExampleShape, VertexEditAtExamplePoseReappearsThroughTheRbf) {
  // A tube patch bound to an offset skin (d != 0), 9 x 10 control points.
  const std::optional<testsupport::BoundTube> fixture = testsupport::MakeBoundTube();
  ASSERT_TRUE(fixture.has_value());
  const BSplineSurface& rest = fixture->surface;
  const deform::PatchBinding& b = fixture->binding;
  const size_t count = rest.control().size();

  // The example pose: one joint turns the whole patch rigidly (the global
  // layer carries the control points: G = R q0 + t, A = R).
  const glm::quat r_pose = glm::angleAxis(0.8f, glm::normalize(glm::vec3(1, 0.3f, 0)));
  glm::mat4 palette = glm::mat4_cast(r_pose);
  palette[3] = glm::vec4(0.5f, -1.0f, 2.0f, 1.0f);
  const std::vector<std::uint16_t> joints(count, 0);
  const std::vector<float> weights(count, 1.0f);
  std::vector<glm::quat> frames(count);
  ASSERT_TRUE(deform::SsdControlRotations(std::span(&palette, 1), 1, joints, weights, frames).ok());
  std::vector<glm::vec3> global(count);
  BSplineSurface posed = rest;
  for (size_t c = 0; c < count; ++c) {
    global[c] = glm::vec3(palette * glm::vec4(glm::vec3(rest.control()[c]), 1.0f));
    posed.mutable_control()[c] = glm::dvec3(global[c]);
  }
  auto rebuild = [&](std::span<const glm::vec3> control) {
    std::vector<glm::vec3> out(b.size());
    EXPECT_TRUE((deform::PatchRebuildJob{.control = control, .bindings = b.view(), .positions = out}
                     .Run()
                     .ok()));
    return out;
  };
  size_t rec = b.size();
  for (size_t r = 0; r < b.size(); ++r) rec = b.vertex[r] == 20 * 30 + 15 ? r : rec;
  ASSERT_LT(rec, b.size());

  // The edit at the example pose, in world space, and its storage (4.3).
  const glm::dvec3 delta(0.1, -0.05, 0.2);
  auto edit = deform::MakeVertexEdit(b, b.vertex[rec], delta);
  ASSERT_TRUE(edit.ok());
  auto moved = deform::MoveBoundVertices(posed, std::span(&*edit, 1));
  ASSERT_TRUE(moved.ok());
  ASSERT_TRUE(moved->unsatisfied.empty());
  deform::PoseExample example{.name = "bent", .features = {}};
  const glm::vec3 theta_e = mocap::QuatToRotationVector(r_pose);
  example.features = {theta_e.x, theta_e.y, theta_e.z};
  example.displacement.resize(count);
  const std::vector<glm::vec3> no_ds(count, glm::vec3(0.0f));
  ASSERT_TRUE(
      deform::StoreExampleDisplacement(frames, no_ds, moved->delta, example.displacement).ok());
  auto model = deform::RbfPoseSpace::Fit(std::span(&example, 1), 3, static_cast<int>(count));
  ASSERT_TRUE(model.ok());

  // Per frame at the example pose: dS -> Q = G + A dS -> rebuild.
  auto frame = [&](std::span<const float> theta) {
    std::vector<glm::vec3> ds(count), q(count);
    EXPECT_TRUE(
        (deform::PoseSpaceJob{.model = &*model, .features = theta, .displacement = ds}.Run().ok()));
    EXPECT_TRUE((deform::PoseSpaceApplyJob{
        .global = global, .rotations = frames, .displacement = ds, .control = q}
                     .Run()
                     .ok()));
    return rebuild(q);
  };
  const std::vector<glm::vec3> before = rebuild(global);
  const std::vector<glm::vec3> after = frame(example.features);
  EXPECT_LT(glm::length(glm::dvec3(after[rec] - before[rec]) - delta), testsupport::kRbfExactTol);
  // At the rest features dS = 0: the posed patch is untouched.
  const std::vector<float> zero(3, 0.0f);
  const std::vector<glm::vec3> at_rest = frame(zero);
  for (size_t r = 0; r < b.size(); ++r) {
    EXPECT_LT(glm::length(at_rest[r] - before[r]), testsupport::kRbfExactTol);
  }
}

}  // namespace
