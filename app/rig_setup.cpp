#include "app/rig_setup.h"

#include "app/rig_examples.h"
#include "app/rig_patches.h"

namespace app {

std::string RigInputFile(const Rig& rig) {
  return IsBuiltInBody(rig.character) ? rig.motion : rig.character;
}

BodyKind RigBodyKind(const Rig& rig) {
  return rig.character == "generated" ? BodyKind::kGenerated : BodyKind::kTubes;
}

base::Result<std::vector<deform::ElasticPatchSpec>> ResolveRigElastic(
    const Rig& rig, const Character& character, std::span<const deform::PatchSetup> patches) {
  std::vector<deform::ElasticPatchSpec> specs;
  for (std::size_t i = 0; i < rig.patches.size() && i < patches.size(); ++i) {
    const RigPatch& p = rig.patches[i];
    if (!p.elastic) continue;
    const std::string field = "patches[" + std::to_string(i) + "].elastic.joint";
    deform::ElasticPatchSpec spec;
    spec.patch = static_cast<int>(i);
    spec.cutoff_hz = p.elastic->cutoff_hz;
    spec.params = p.elastic->params;
    spec.params.units_per_metre = p.elastic->units_per_metre > 0.0f
                                      ? p.elastic->units_per_metre
                                      : UnitsPerMetre(character.skeleton.info.detected_units,
                                                      character.skeleton.info.rest_height);
    const std::string& name = !p.elastic->joint.empty()                  ? p.elastic->joint
                              : p.region.kind == RigRegion::Kind::kJoint ? p.region.joint
                                                                         : std::string();
    if (name.empty()) {
      spec.joint = deform::DominantJoint(character.mesh, patches[i]);
    } else {
      spec.joint = character.skeleton.FindJoint(name);
      if (spec.joint < 0) {
        return base::MakeError(
            base::ErrorCode::kNotFound, {rig.file, 0, 0, field},
            "expected a joint of " + character.source + ", found \"" + name + "\"");
      }
    }
    specs.push_back(spec);
  }
  return specs;
}

base::Status ApplyRigLayers(const Rig& rig, const Character& character,
                            deform::FramePipeline& pipeline, std::vector<std::string>* notes) {
  base::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(rig, character);
  if (!patches.ok()) return std::move(patches).error();
  if (patches->empty()) return base::Status::Ok();
  // Example shapes are sculpted in the frames of the method this pipeline
  // carries the control points with; the elastic specs need the patches too.
  base::Result<RigPoseSpaces> spaces =
      BuildRigPoseSpaces(rig, character, *patches, pipeline.method());
  if (!spaces.ok()) return std::move(spaces).error();
  base::Result<std::vector<deform::ElasticPatchSpec>> elastic =
      ResolveRigElastic(rig, character, *patches);
  if (!elastic.ok()) return std::move(elastic).error();
  if (base::Status s = pipeline.SetPatches(std::move(*patches)); !s.ok()) return s;
  if (base::Status s = pipeline.SetPoseSpaces(std::move(spaces->patches)); !s.ok()) return s;
  if (base::Status s = pipeline.SetElastic(std::move(*elastic)); !s.ok()) return s;
  if (notes != nullptr) {
    for (const std::string& note : spaces->notes) notes->push_back("examples: " + note);
    for (const base::Warning& w : spaces->warnings) notes->push_back(w.ToString());
    for (const deform::ElasticPatchReport& r : pipeline.elastic_report()) {
      for (const std::string& note : r.messages) {
        notes->push_back(rig.file + ": patches[" + std::to_string(r.patch) +
                         "].elastic: note: " + note);
      }
    }
  }
  return base::Status::Ok();
}

base::Status ResolveLookAt(const std::string& text, const Rig* rig, const Character& ch,
                           CameraSpec& spec) {
  if (text.empty()) return base::Status::Ok();
  const std::string prefix = "patch:";
  if (!text.starts_with(prefix)) {
    spec.look_joint = ch.skeleton.FindJoint(text);
    if (spec.look_joint >= 0) return base::Status::Ok();
    return ArgError("--look-at",
                    "expected a joint of " + ch.source + " or patch:NAME, found '" + text + "'");
  }
  const std::string name = text.substr(prefix.size());
  std::string names;
  for (std::size_t i = 0; rig != nullptr && i < rig->patches.size(); ++i) {
    if (rig->patches[i].name != name) {
      names += (names.empty() ? "" : ", ") + rig->patches[i].name;
      continue;
    }
    base::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(*rig, ch);
    if (!patches.ok()) return std::move(patches).error();
    spec.look_region = (*patches)[i].region;
    return base::Status::Ok();
  }
  return ArgError("--look-at", "expected the name of one of the rig's patches (" +
                                   (names.empty() ? std::string("it has none") : names) +
                                   "), found '" + name + "'");
}

}  // namespace app
