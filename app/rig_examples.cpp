#include "app/rig_examples.h"

#include <cmath>
#include <sstream>

#include "app/character.h"
#include "app/rig_file.h"
#include "deform/global/dqs_job.h"
#include "deform/shapes/corrective_example.h"
#include "deform/shapes/example_shapes.h"
#include "deform/global/skinning_job.h"
#include "mocap/joint_angles.h"
#include "mocap/pose.h"

namespace app {

namespace {

base::Error At(const std::string& file, const std::string& path, base::Error e) {
  if (e.loc.file.empty()) e.loc = {file, 0, 0, path};
  return e;
}

// Unit axis of joint j's first child bone in j's frame (the twist axis of
// swing-twist features), +Y when j has no child with an offset.
glm::vec3 ChildBoneAxis(const mocap::Skeleton& s, int j) {
  for (int c = j + 1; c < s.num_joints(); ++c) {
    if (s.parents[static_cast<std::size_t>(c)] != j) continue;
    const glm::vec3 t = s.rest_translations[static_cast<std::size_t>(c)];
    if (glm::length(t) > 0.0f) return glm::normalize(t);
  }
  return {0.0f, 1.0f, 0.0f};
}

// The local transforms of an example pose.
base::Status ExampleLocals(const Rig& rig, const Character& ch, const RigExample& ex,
                           std::vector<mocap::JointTransform>& locals) {
  const mocap::Skeleton& s = ch.skeleton;
  if (ex.pose.frame >= 0) {
    if (ex.pose.frame >= ch.motion.num_frames) {
      return base::InvalidArgument({rig.file, 0, 0, ex.path + ".pose.frame"},
                                   "expected a frame in 0.." +
                                       std::to_string(ch.motion.num_frames - 1) +
                                       " of the motion, found " + std::to_string(ex.pose.frame));
    }
    const base::JobStatus st =
        mocap::LocalPoseJob{&s, ch.motion.frame(ex.pose.frame), locals}.Run();
    if (!st) return base::MakeError(base::ErrorCode::kInternal, {rig.file, 0, 0, ex.path}, st.what);
    return base::Status::Ok();
  }
  mocap::RestPose(s, locals);
  for (const auto& [name, xyz] : ex.pose.joints) {
    const int j = s.FindJoint(name);
    if (j < 0) {
      return base::MakeError(base::ErrorCode::kNotFound,
                             {rig.file, 0, 0, ex.path + ".pose.joints." + name},
                             "expected a joint of " + ch.source + ", found \"" + name + "\"");
    }
    locals[static_cast<std::size_t>(j)].rotation = mocap::JointRotationFromAngles(s, j, xyz);
  }
  return base::Status::Ok();
}

base::Result<deform::PoseFeatureSpec> FeatureSpec(const Rig& rig, const Character& ch,
                                                  const RigPatch& rp, const std::string& path,
                                                  const deform::PatchSetup& patch) {
  const mocap::Skeleton& s = ch.skeleton;
  deform::PoseFeatureSpec spec;
  spec.kind = rp.pose_space.features == "euler"        ? deform::PoseFeatureKind::kEuler
              : rp.pose_space.features == "swingtwist" ? deform::PoseFeatureKind::kSwingTwist
                                                       : deform::PoseFeatureKind::kRotationVector;
  if (rp.pose_space.joints.empty()) {
    spec.joints = deform::InfluencingJoints(s, ch.mesh.skin_joints, patch.control_weights.influences,
                                            patch.control_weights.joints,
                                            patch.control_weights.weights);
  } else {
    for (std::size_t k = 0; k < rp.pose_space.joints.size(); ++k) {
      const int j = s.FindJoint(rp.pose_space.joints[k]);
      if (j < 0) {
        return base::MakeError(
            base::ErrorCode::kNotFound,
            {rig.file, 0, 0, path + ".pose_space.joints[" + std::to_string(k) + "]"},
            "expected a joint of " + ch.source + ", found \"" + rp.pose_space.joints[k] + "\"");
      }
      spec.joints.push_back({.joint = j});
    }
  }
  if (spec.joints.empty()) {
    return base::InvalidArgument({rig.file, 0, 0, path + ".pose_space"},
                                 "no joint other than the root weights this patch: name the joints "
                                 "of theta in \"joints\"");
  }
  for (deform::PoseFeatureJoint& fj : spec.joints) fj.twist_axis = ChildBoneAxis(s, fj.joint);
  const base::Status checked = deform::CheckPoseFeatureSpec(s, spec);
  if (!checked.ok()) return At(rig.file, path + ".pose_space", checked.error());
  return spec;
}

deform::RbfKernel Kernel(const std::string& name) {
  if (name == "inverse-multiquadric") return deform::RbfKernel::kInverseMultiquadric;
  if (name == "multiquadric") return deform::RbfKernel::kMultiquadric;
  if (name == "polyharmonic3") return deform::RbfKernel::kPolyharmonic3;
  return deform::RbfKernel::kGaussian;
}

}  // namespace

base::Result<RigPoseSpaces> BuildRigPoseSpaces(const Rig& rig, const Character& ch,
                                               const std::vector<deform::PatchSetup>& patches,
                                               deform::GlobalMethod method) {
  RigPoseSpaces out;
  out.patches.resize(rig.patches.size());
  if (patches.size() != rig.patches.size()) {
    return base::MakeError(base::ErrorCode::kInternal, {rig.file, 0, 0, "patches"},
                           "patch count differs from the rig's");
  }
  const mocap::Skeleton& s = ch.skeleton;
  const auto nj = static_cast<std::size_t>(s.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj);
  deform::SkinningPalettes palettes;
  for (std::size_t i = 0; i < rig.patches.size(); ++i) {
    const RigPatch& rp = rig.patches[i];
    if (rp.examples.empty()) continue;
    const std::string path = "patches[" + std::to_string(i) + "]";
    if (method == deform::GlobalMethod::kSwd) {
      // dS lives in control-point frames A (ALGORITHMS.md 4.3), defined here
      // for SSD and DQS only: say so instead of dropping the examples.
      return base::MakeError(base::ErrorCode::kUnsupported, {rig.file, 0, 0, path + ".examples"},
                             "example shapes need \"global\": \"ssd\" or \"dqs\" (not available "
                             "with swd yet)");
    }
    const deform::PatchSetup& patch = patches[i];
    base::Result<deform::PoseFeatureSpec> spec = FeatureSpec(rig, ch, rp, path, patch);
    if (!spec.ok()) return std::move(spec).error();
    const int dim = deform::PoseFeatureDimension(s, *spec);
    std::vector<deform::PoseExample> examples;
    for (const RigExample& ex : rp.examples) {
      if (base::Status st = ExampleLocals(rig, ch, ex, locals); !st.ok()) return st.error();
      base::JobStatus js = mocap::LocalToModelJob{.parents = s.parents,
                                                  .locals = locals,
                                                  .model_from_root = ch.world_from_model,
                                                  .model_from_joint = model}
                               .Run();
      if (js) js = palettes.Update(model, ch.mesh, method == deform::GlobalMethod::kDqs);
      if (!js)
        return base::MakeError(base::ErrorCode::kInternal, {rig.file, 0, 0, ex.path}, js.what);
      const deform::SkinningPose pose = palettes.view();
      base::Result<deform::SculptedExample> sculpted = deform::SculptedExample{};
      if (!ex.auto_kind.empty()) {
        // Computed at load, once (deform/shapes/corrective_example.h).
        const bool volume = ex.auto_kind == "volume";
        base::Result<deform::CorrectedExample> corrected = deform::CorrectExample(
            patch, ch.mesh, pose,
            volume ? deform::CorrectiveKind::kVolume : deform::CorrectiveKind::kRest);
        if (!corrected.ok()) return At(rig.file, ex.path + ".auto", std::move(corrected).error());
        std::ostringstream note;
        note << ex.path << " auto " << ex.auto_kind << ": "
             << (volume ? "region volume bind " : "rms distance to the rigid rest shape ");
        if (volume) note << corrected->report.bind_value << ", ";
        note << "before " << corrected->report.before << ", after " << corrected->report.after;
        out.notes.push_back(note.str());
        sculpted = std::move(corrected->shape);
      }
      if (!ex.edits.empty()) {
        std::vector<deform::ExampleEdit> edits;
        for (const RigEdit& e : ex.edits) {
          edits.push_back({.vertex = e.vertex, .uv = e.point, .move = e.move, .world_frame = e.world,
                           .radius = e.radius, .loc = {rig.file, 0, 0, e.path}});
        }
        base::Result<deform::SculptedExample> edited =
            deform::SculptExample(patch, ch.mesh, pose, edits);
        if (!edited.ok()) return At(rig.file, ex.path + ".edits", std::move(edited).error());
        if (!ex.auto_kind.empty()) {
          // Edits move the corrected shape further: the changes add (s is linear in Q).
          for (std::size_t c = 0; c < edited->displacement.size(); ++c) {
            edited->displacement[c] += sculpted->displacement[c];
            edited->world_delta[c] += sculpted->world_delta[c];
          }
        }
        sculpted = std::move(edited);
      }
      deform::PoseExample pe{.name = ex.path, .loc = {rig.file, 0, 0, ex.path + ".pose"},
                             .features = std::vector<float>(static_cast<std::size_t>(dim)),
                             .displacement = std::move(sculpted->displacement)};
      const base::Status f = deform::ComputePoseFeatures(s, *spec, locals, pe.features);
      if (!f.ok()) return At(rig.file, ex.path + ".pose", f.error());
      examples.push_back(std::move(pe));
    }
    const bool euler = spec->kind == deform::PoseFeatureKind::kEuler;
    base::Result<deform::RbfModel> model_fit =
        deform::RbfPoseSpace::Fit(examples, dim, patch.num_control(),
                                  {.kernel = Kernel(rp.pose_space.kernel),
                                   .kappa = rp.pose_space.kappa,
                                   .width = rp.pose_space.width,
                                   .wrap_angles = euler});
    if (!model_fit.ok()) return At(rig.file, path + ".examples", std::move(model_fit).error());
    for (base::Warning w : model_fit->warnings) {
      if (w.loc.file.empty()) w.loc = {rig.file, 0, 0, path + ".pose_space"};
      out.warnings.push_back(std::move(w));
    }
    std::ostringstream note;
    note << path << " (" << rp.name << "): " << rp.examples.size() << " example"
         << (rp.examples.size() == 1 ? "" : "s") << ", " << dim << " pose features ("
         << rp.pose_space.features << "), " << deform::RbfKernelName(model_fit->kernel)
         << " width " << model_fit->width << ", condition number " << model_fit->condition;
    out.notes.push_back(note.str());
    out.patches[i] = {.features = std::move(*spec), .model = std::move(*model_fit)};
  }
  return out;
}

}  // namespace app
