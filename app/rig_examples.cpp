#include "app/rig_examples.h"

#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/internal/rig_examples_parse.h"
#include "app/pipeline.h"
#include "deform/dqs_job.h"
#include "deform/example_shapes.h"
#include "deform/skinning_job.h"
#include "mocap/pose.h"

namespace app {
namespace {

using nlohmann::json;

// Most examples per patch and edits per example a rig may hold (the RBF takes
// at most deform::kMaxRbfCentres centres; edits beyond the free control points
// cannot all be met anyway).
constexpr std::size_t kMaxExamples = 64;
constexpr std::size_t kMaxEdits = 256;
// Largest |component| of a move (model units) and of a joint angle (degrees).
constexpr double kMaxMove = 1e6;
constexpr double kMaxAngleDeg = 360.0;

std::string Describe(const json& v) {
  if (v.is_object()) return "an object";
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return v.is_array() ? "an array " + s : s;
}

struct Ctx {
  std::string file;
  mocap::Error Fail(const std::string& path, const std::string& message) const {
    return mocap::MakeError(mocap::ErrorCode::kInvalidArgument, {file, 0, 0, path}, message);
  }
  mocap::Error Expected(const std::string& path, const std::string& what, const json& found) const {
    return Fail(path, "expected " + what + ", found " + Describe(found));
  }
  // `obj` must be an object whose keys are all in `allowed`.
  std::optional<mocap::Error> Keys(const json& obj, const std::string& path,
                                   std::initializer_list<const char*> allowed) const {
    if (!obj.is_object()) return Expected(path, "an object", obj);
    for (const auto& [key, value] : obj.items()) {
      bool known = false;
      std::string list;
      for (const char* a : allowed) {
        known = known || key == a;
        list += std::string(list.empty() ? "" : ", ") + a;
      }
      if (!known) return Fail(path + "." + key, "unknown field (expected one of: " + list + ")");
    }
    return std::nullopt;
  }
};

bool NumberIn(const json& v, double lo, double hi) {
  return v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() >= lo &&
         v.get<double>() <= hi;
}

std::optional<mocap::Error> GetVec(const Ctx& c, const json& v, const std::string& path,
                                   std::size_t n, double lo, double hi, double* out) {
  std::ostringstream what;
  what << "an array of " << n << " numbers in " << lo << ".." << hi;
  if (!v.is_array() || v.size() != n) return c.Expected(path, what.str(), v);
  for (std::size_t i = 0; i < n; ++i) {
    if (!NumberIn(v[i], lo, hi)) return c.Expected(path, what.str(), v);
    out[i] = v[i].get<double>();
  }
  return std::nullopt;
}

std::optional<mocap::Error> ParsePose(const Ctx& c, const json& v, const std::string& path,
                                      RigExamplePose& pose) {
  if (auto e = c.Keys(v, path, {"frame", "joints"})) return e;
  if (v.contains("frame") == v.contains("joints")) {
    return c.Fail(path, "expected exactly one of \"frame\" (a frame of the motion) or \"joints\" "
                        "(joint name -> [x, y, z] degrees)");
  }
  if (v.contains("frame")) {
    const json& f = v["frame"];
    if (!f.is_number_integer() || f.get<long long>() < 0 || f.get<long long>() > 100000000) {
      return c.Expected(path + ".frame", "a frame index (integer >= 0)", f);
    }
    pose.frame = f.get<int>();
    return std::nullopt;
  }
  const json& joints = v["joints"];
  if (!joints.is_object() || joints.empty()) {
    return c.Expected(path + ".joints", "an object of joint name -> [x, y, z] degrees", joints);
  }
  for (const auto& [name, angles] : joints.items()) {
    double a[3];
    if (auto e = GetVec(c, angles, path + ".joints." + name, 3, -kMaxAngleDeg, kMaxAngleDeg, a)) {
      return e;
    }
    pose.joints.emplace_back(name, glm::vec3(glm::dvec3(a[0], a[1], a[2])));
  }
  return std::nullopt;
}

std::optional<mocap::Error> ParseEdit(const Ctx& c, const json& v, const std::string& path,
                                      RigEdit& edit) {
  if (auto e = c.Keys(v, path, {"vertex", "point", "move", "frame"})) return e;
  edit.path = path;
  if (v.contains("vertex") == v.contains("point")) {
    return c.Fail(path, "expected exactly one of \"vertex\" (a mesh vertex index) or \"point\" "
                        "([u, v] on the patch)");
  }
  if (v.contains("vertex")) {
    const json& i = v["vertex"];
    if (!i.is_number_integer() || i.get<long long>() < 0 || i.get<long long>() > 100000000) {
      return c.Expected(path + ".vertex", "a vertex index (integer >= 0)", i);
    }
    edit.vertex = i.get<int>();
  } else {
    double uv[2];
    if (auto e = GetVec(c, v["point"], path + ".point", 2, 0.0, 1.0, uv)) return e;
    edit.point = {uv[0], uv[1]};
  }
  if (!v.contains("move")) return c.Fail(path + ".move", "missing ([dx, dy, dz] model units)");
  double m[3];
  if (auto e = GetVec(c, v["move"], path + ".move", 3, -kMaxMove, kMaxMove, m)) return e;
  edit.move = {m[0], m[1], m[2]};
  if (v.contains("frame")) {
    const json& f = v["frame"];
    if (!f.is_string() || (f.get<std::string>() != "bind" && f.get<std::string>() != "world")) {
      return c.Expected(path + ".frame", "\"bind\" or \"world\"", f);
    }
    edit.world = f.get<std::string>() == "world";
  }
  return std::nullopt;
}

std::optional<mocap::Error> ParsePoseSpace(const Ctx& c, const json& v, const std::string& path,
                                           RigPoseSpace& ps) {
  if (auto e = c.Keys(v, path, {"features", "kernel", "kappa", "width", "joints"})) return e;
  auto choice = [&](const char* key, std::initializer_list<const char*> options,
                    std::string& out) -> std::optional<mocap::Error> {
    if (!v.contains(key)) return std::nullopt;
    std::string list;
    bool found = false;
    for (const char* o : options) {
      list += std::string(list.empty() ? "" : ", ") + '"' + o + '"';
      if (v[key].is_string() && v[key].get<std::string>() == o) {
        out = o;
        found = true;
      }
    }
    if (!found) return c.Expected(path + "." + key, "one of " + list, v[key]);
    return std::nullopt;
  };
  if (auto e = choice("features", {"euler", "rotvec", "swingtwist"}, ps.features)) return e;
  if (auto e = choice("kernel", {"gaussian", "inverse-multiquadric", "multiquadric", "polyharmonic3"},
                      ps.kernel)) {
    return e;
  }
  if (v.contains("kappa")) {
    if (!NumberIn(v["kappa"], 1e-3, 10.0) || v["kappa"].get<double>() <= 0.0) {
      return c.Expected(path + ".kappa", "a number in 0.001..10", v["kappa"]);
    }
    ps.kappa = v["kappa"].get<double>();
  }
  if (v.contains("width")) {
    if (!NumberIn(v["width"], 0.0, 100.0)) {
      return c.Expected(path + ".width", "a number in 0..100 (radians; 0 = automatic)", v["width"]);
    }
    ps.width = v["width"].get<double>();
  }
  if (v.contains("joints")) {
    const json& list = v["joints"];
    if (!list.is_array() || list.empty()) {
      return c.Expected(path + ".joints", "a non-empty array of joint names", list);
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (!list[i].is_string() || list[i].get<std::string>().empty()) {
        return c.Expected(path + ".joints[" + std::to_string(i) + "]", "a joint name", list[i]);
      }
      ps.joints.push_back(list[i].get<std::string>());
    }
  }
  return std::nullopt;
}

bool SamePose(const RigExamplePose& a, const RigExamplePose& b) {
  return a.frame == b.frame && a.joints == b.joints;
}

}  // namespace

namespace internal {

std::optional<mocap::Error> ParsePatchExamples(const std::string& file, const json& patch,
                                               const std::string& path, RigPatch& out) {
  const Ctx c{file};
  if (patch.contains("pose_space")) {
    if (auto e = ParsePoseSpace(c, patch["pose_space"], path + ".pose_space", out.pose_space)) {
      return e;
    }
  }
  if (!patch.contains("examples")) return std::nullopt;
  const json& list = patch["examples"];
  const std::string lpath = path + ".examples";
  if (!list.is_array()) return c.Expected(lpath, "an array of examples", list);
  if (list.size() > kMaxExamples) {
    return c.Fail(lpath, "expected at most " + std::to_string(kMaxExamples) + " examples, found " +
                             std::to_string(list.size()));
  }
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string epath = lpath + "[" + std::to_string(k) + "]";
    const json& ex = list[k];
    if (auto e = c.Keys(ex, epath, {"pose", "edits"})) return e;
    RigExample example;
    example.path = epath;
    if (!ex.contains("pose")) return c.Fail(epath + ".pose", "missing ({\"frame\": N} or {\"joints\": {...}})");
    if (auto e = ParsePose(c, ex["pose"], epath + ".pose", example.pose)) return e;
    if (!ex.contains("edits")) return c.Fail(epath + ".edits", "missing (an array of edits)");
    const json& edits = ex["edits"];
    if (!edits.is_array() || edits.empty() || edits.size() > kMaxEdits) {
      return c.Expected(epath + ".edits", "an array of 1.." + std::to_string(kMaxEdits) + " edits",
                        edits);
    }
    for (std::size_t i = 0; i < edits.size(); ++i) {
      RigEdit edit;
      if (auto e = ParseEdit(c, edits[i], epath + ".edits[" + std::to_string(i) + "]", edit)) {
        return e;
      }
      example.edits.push_back(std::move(edit));
    }
    for (const RigExample& other : out.examples) {
      if (SamePose(other.pose, example.pose)) {
        return c.Fail(epath + ".pose", "duplicates the pose of " + other.path +
                                           " (one example per pose: merge their edits)");
      }
    }
    out.examples.push_back(std::move(example));
  }
  return std::nullopt;
}

}  // namespace internal

namespace {

mocap::Error At(const std::string& file, const std::string& path, mocap::Error e) {
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
mocap::Status ExampleLocals(const Rig& rig, const Character& ch, const RigExample& ex,
                            std::vector<mocap::JointTransform>& locals) {
  const mocap::Skeleton& s = ch.skeleton;
  if (ex.pose.frame >= 0) {
    if (ex.pose.frame >= ch.motion.num_frames) {
      return mocap::MakeError(mocap::ErrorCode::kInvalidArgument,
                              {rig.file, 0, 0, ex.path + ".pose.frame"},
                              "expected a frame in 0.." + std::to_string(ch.motion.num_frames - 1) +
                                  " of the motion, found " + std::to_string(ex.pose.frame));
    }
    const mocap::JobStatus st =
        mocap::LocalPoseJob{&s, ch.motion.frame(ex.pose.frame), locals}.Run();
    if (!st) return mocap::MakeError(mocap::ErrorCode::kInternal, {rig.file, 0, 0, ex.path}, st.what);
    return mocap::Status::Ok();
  }
  mocap::RestPose(s, locals);
  for (const auto& [name, xyz] : ex.pose.joints) {
    const int j = s.FindJoint(name);
    if (j < 0) {
      return mocap::MakeError(mocap::ErrorCode::kNotFound,
                              {rig.file, 0, 0, ex.path + ".pose.joints." + name},
                              "expected a joint of " + ch.source + ", found \"" + name + "\"");
    }
    // The joint's Euler channel order, then any axis it lacks (ZXY order for none).
    mocap::ChannelType axes[3];
    int n = 0;
    const mocap::JointChannels& jc = s.channels[static_cast<std::size_t>(j)];
    for (int k = 0; k < jc.count && n < 3; ++k) {
      const mocap::ChannelType t = jc.types[static_cast<std::size_t>(k)];
      if (t == mocap::ChannelType::kXRotation || t == mocap::ChannelType::kYRotation ||
          t == mocap::ChannelType::kZRotation) {
        axes[n++] = t;
      }
    }
    for (mocap::ChannelType t : {mocap::ChannelType::kZRotation, mocap::ChannelType::kXRotation,
                                 mocap::ChannelType::kYRotation}) {
      bool have = false;
      for (int k = 0; k < n; ++k) have = have || axes[k] == t;
      if (!have) axes[n++] = t;
    }
    float angles[3];
    for (int k = 0; k < 3; ++k) {
      angles[k] = axes[k] == mocap::ChannelType::kXRotation   ? xyz.x
                  : axes[k] == mocap::ChannelType::kYRotation ? xyz.y
                                                              : xyz.z;
    }
    locals[static_cast<std::size_t>(j)].rotation =
        s.rest_rotations[static_cast<std::size_t>(j)] * mocap::EulerToQuat(axes, angles, 3);
  }
  return mocap::Status::Ok();
}

mocap::Result<deform::PoseFeatureSpec> FeatureSpec(const Rig& rig, const Character& ch,
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
        return mocap::MakeError(mocap::ErrorCode::kNotFound,
                                {rig.file, 0, 0, path + ".pose_space.joints[" + std::to_string(k) + "]"},
                                "expected a joint of " + ch.source + ", found \"" +
                                    rp.pose_space.joints[k] + "\"");
      }
      spec.joints.push_back({.joint = j});
    }
  }
  if (spec.joints.empty()) {
    return mocap::MakeError(mocap::ErrorCode::kInvalidArgument, {rig.file, 0, 0, path + ".pose_space"},
                            "no joint other than the root weights this patch: name the joints "
                            "of theta in \"joints\"");
  }
  for (deform::PoseFeatureJoint& fj : spec.joints) fj.twist_axis = ChildBoneAxis(s, fj.joint);
  const mocap::Status checked = deform::CheckPoseFeatureSpec(s, spec);
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

mocap::Result<RigPoseSpaces> BuildRigPoseSpaces(const Rig& rig, const Character& ch,
                                                const std::vector<deform::PatchSetup>& patches,
                                                GlobalMethod method) {
  RigPoseSpaces out;
  out.patches.resize(rig.patches.size());
  if (patches.size() != rig.patches.size()) {
    return mocap::MakeError(mocap::ErrorCode::kInternal, {rig.file, 0, 0, "patches"},
                            "patch count differs from the rig's");
  }
  const mocap::Skeleton& s = ch.skeleton;
  const auto nj = static_cast<std::size_t>(s.num_joints());
  const std::size_t ns = ch.mesh.skin_joints.size();
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj), palette(ns);
  std::vector<deform::DualQuat> dq(ns);
  for (std::size_t i = 0; i < rig.patches.size(); ++i) {
    const RigPatch& rp = rig.patches[i];
    if (rp.examples.empty()) continue;
    const std::string path = "patches[" + std::to_string(i) + "]";
    if (method == GlobalMethod::kSwd) {
      // dS lives in control-point frames A (ALGORITHMS.md 4.3), defined here
      // for SSD and DQS only: say so instead of dropping the examples.
      return mocap::MakeError(mocap::ErrorCode::kUnsupported, {rig.file, 0, 0, path + ".examples"},
                              "example shapes need \"global\": \"ssd\" or \"dqs\" (not available "
                              "with swd yet)");
    }
    const deform::PatchSetup& patch = patches[i];
    mocap::Result<deform::PoseFeatureSpec> spec = FeatureSpec(rig, ch, rp, path, patch);
    if (!spec.ok()) return std::move(spec).error();
    const int dim = deform::PoseFeatureDimension(s, *spec);
    std::vector<deform::PoseExample> examples;
    for (const RigExample& ex : rp.examples) {
      if (mocap::Status st = ExampleLocals(rig, ch, ex, locals); !st.ok()) return st.error();
      mocap::JobStatus js = mocap::LocalToModelJob{.parents = s.parents, .locals = locals,
                                                   .model_from_root = ch.world_from_model,
                                                   .model_from_joint = model}
                                .Run();
      if (js) js = deform::BuildSkinningPalette(model, ch.mesh, palette);
      if (js && method == GlobalMethod::kDqs) js = deform::BuildDualQuatPalette(palette, dq);
      if (!js) return mocap::MakeError(mocap::ErrorCode::kInternal, {rig.file, 0, 0, ex.path}, js.what);
      std::vector<deform::ExampleEdit> edits;
      for (const RigEdit& e : ex.edits) {
        edits.push_back({.vertex = e.vertex, .uv = e.point, .move = e.move, .world_frame = e.world,
                         .loc = {rig.file, 0, 0, e.path}});
      }
      const deform::ExamplePose pose{
          .model_from_bind = palette,
          .dq_palette = method == GlobalMethod::kDqs ? std::span<const deform::DualQuat>(dq)
                                                     : std::span<const deform::DualQuat>()};
      mocap::Result<deform::SculptedExample> sculpted = deform::SculptExample(patch, ch.mesh, pose, edits);
      if (!sculpted.ok()) return At(rig.file, ex.path + ".edits", std::move(sculpted).error());
      for (mocap::Warning& w : sculpted->warnings) out.warnings.push_back(std::move(w));
      deform::PoseExample pe{.name = ex.path, .loc = {rig.file, 0, 0, ex.path + ".pose"},
                             .features = std::vector<float>(static_cast<std::size_t>(dim)),
                             .displacement = std::move(sculpted->displacement)};
      const mocap::Status f = deform::ComputePoseFeatures(s, *spec, locals, pe.features);
      if (!f.ok()) return At(rig.file, ex.path + ".pose", f.error());
      examples.push_back(std::move(pe));
    }
    const bool euler = spec->kind == deform::PoseFeatureKind::kEuler;
    mocap::Result<deform::RbfModel> model_fit = deform::RbfPoseSpace::Fit(
        examples, dim, patch.num_control(),
        {.kernel = Kernel(rp.pose_space.kernel), .kappa = rp.pose_space.kappa,
         .width = rp.pose_space.width, .wrap_angles = euler});
    if (!model_fit.ok()) return At(rig.file, path + ".examples", std::move(model_fit).error());
    for (mocap::Warning w : model_fit->warnings) {
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
