#pragma once
// The mannequin of the synthetic humanoid with patches on the left elbow and
// left knee, posed by the elbow/knee bend ramp (tools/synthetic.h), shared by
// the patch layer tests.

#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "deform/body/mannequin.h"
#include "deform/patch/patch_layer.h"
#include "deform/patch/patch_region.h"
#include "deform/global/skinning_job.h"
#include "mocap/pose.h"
#include "tools/synthetic.h"

namespace testfixture {

struct LayeredBody {
  mocap::Skeleton skeleton;
  std::vector<glm::mat4> rest_model;  // #J
  deform::SkinnedMesh mesh;
  int elbow = -1, shoulder = -1, hand = -1, knee = -1, hip = -1, ankle = -1;
};

inline LayeredBody MakeLayeredBody() {
  LayeredBody b;
  b.skeleton = synthetic::MakeHumanoidSkeleton();
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(b.skeleton.num_joints()));
  mocap::RestPose(b.skeleton, locals);
  b.rest_model.resize(locals.size());
  (void)mocap::LocalToModelJob{.parents = b.skeleton.parents, .locals = locals,
                               .model_from_joint = b.rest_model}
      .Run();
  b.mesh = *deform::BuildMannequin(b.skeleton, b.rest_model);
  b.shoulder = b.skeleton.FindJoint("LeftArm");
  b.elbow = b.skeleton.FindJoint("LeftForeArm");
  b.hand = b.skeleton.FindJoint("LeftHand");
  b.hip = b.skeleton.FindJoint("LeftUpLeg");
  b.knee = b.skeleton.FindJoint("LeftLeg");
  b.ankle = b.skeleton.FindJoint("LeftFoot");
  return b;
}

inline glm::vec3 JointPos(const std::vector<glm::mat4>& model, int j) {
  return glm::vec3(model[static_cast<std::size_t>(j)][3]);
}

// A joint + radius region on the inner side of a bend and a cylinder about
// the bone into the joint.
struct PatchSpec {
  int parent, joint;
  float radius;
  glm::vec3 side;
};

inline base::Result<deform::PatchSetup> MakePatch(const LayeredBody& b, const PatchSpec& spec,
                                                  float border_width = 0.1f) {
  const glm::vec3 j = JointPos(b.rest_model, spec.joint);
  const glm::vec3 p = JointPos(b.rest_model, spec.parent);
  base::Result<std::vector<int>> region =
      deform::SelectJointRegion(b.mesh, {.bone_joints = {spec.parent, spec.joint},
                                         .centre = j,
                                         .radius = spec.radius,
                                         .min_bone_weight = 0.5f,
                                         .side = spec.side,
                                         .half_angle_deg = 120.0f});
  if (!region.ok()) return std::move(region).error();
  return deform::BuildPatchSetup(
      b.mesh, *region,
      {.parametrization = deform::RegionParametrization::Kind::kCylinder,
       .axis_origin = glm::dvec3(p), .axis_direction = glm::dvec3(j - p),
       .border_width = border_width});
}

inline PatchSpec ElbowSpec(const LayeredBody& b) {
  return {b.shoulder, b.elbow, 14.0f, glm::vec3(0, 0, 1)};
}
inline PatchSpec KneeSpec(const LayeredBody& b) {
  return {b.hip, b.knee, 20.0f, glm::vec3(0, 0, -1)};
}

// The pose of the bend ramp (elbows and left knee) at `angle_deg` <= 150.
inline std::vector<glm::mat4> BendPose(const LayeredBody& b, float angle_deg) {
  const mocap::Motion ramp = *synthetic::MakeBendRamp(b.skeleton, angle_deg, 1.0, 1.0);
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(b.skeleton.num_joints()));
  (void)mocap::LocalPoseJob{&b.skeleton, ramp.frame(ramp.num_frames - 1), locals}.Run();
  std::vector<glm::mat4> model(locals.size());
  (void)mocap::LocalToModelJob{.parents = b.skeleton.parents, .locals = locals,
                               .model_from_joint = model}
      .Run();
  return model;
}

// SSD of the whole mesh and the layered result for the given patches.
struct LayeredFrame {
  std::vector<glm::vec3> global;   // #V SSD
  std::vector<glm::vec3> layered;  // #V SSD + patches
};

inline LayeredFrame EvaluateLayered(const LayeredBody& b, std::span<const deform::PatchSetup> patches,
                                    const std::vector<glm::mat4>& model) {
  LayeredFrame f;
  std::vector<glm::mat4> palette(b.mesh.skin_joints.size());
  (void)deform::BuildSkinningPalette(model, b.mesh, palette);
  f.global.resize(b.mesh.bind.positions.size());
  (void)deform::SkinningJob{.model_from_bind = palette, .influences = b.mesh.weights.influences,
                            .joint_indices = b.mesh.weights.joints,
                            .joint_weights = b.mesh.weights.weights,
                            .rest_positions = b.mesh.bind.positions, .rest_normals = {},
                            .positions = f.global, .normals = {}}
      .Run();
  std::vector<std::vector<glm::vec3>> carried(patches.size());
  std::vector<std::span<const glm::vec3>> views;
  for (std::size_t k = 0; k < patches.size(); ++k) {
    carried[k].resize(patches[k].rest_control.size());
    (void)deform::CarryControlPointsJob{
        .patch = &patches[k], .pose = {.model_from_bind = palette}, .control = carried[k]}
        .Run();
    views.emplace_back(carried[k]);
  }
  f.layered = f.global;
  deform::PatchLayerScratch scratch;
  (void)deform::ApplyPatchLayer(patches, views, {}, scratch, f.layered);
  return f;
}

}  // namespace testfixture
