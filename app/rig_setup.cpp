#include "app/rig_setup.h"

#include "app/elastic_layer.h"
#include "app/rig_examples.h"
#include "app/rig_patches.h"

namespace app {

std::string RigInputFile(const Rig& rig) {
  return IsBuiltInBody(rig.character) ? rig.motion : rig.character;
}

BodyKind RigBodyKind(const Rig& rig) {
  return rig.character == "generated" ? BodyKind::kGenerated : BodyKind::kTubes;
}

base::Status ApplyRigLayers(const Rig& rig, const Character& character, FramePipeline& pipeline,
                            std::vector<std::string>* notes) {
  base::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(rig, character);
  if (!patches.ok()) return std::move(patches).error();
  if (patches->empty()) return base::Status::Ok();
  // Example shapes are sculpted in the frames of the method this pipeline
  // carries the control points with; the elastic specs need the patches too.
  base::Result<RigPoseSpaces> spaces =
      BuildRigPoseSpaces(rig, character, *patches, pipeline.method());
  if (!spaces.ok()) return std::move(spaces).error();
  base::Result<std::vector<ElasticPatchSpec>> elastic = ResolveRigElastic(rig, character, *patches);
  if (!elastic.ok()) return std::move(elastic).error();
  if (base::Status s = pipeline.SetPatches(std::move(*patches)); !s.ok()) return s;
  if (base::Status s = pipeline.SetPoseSpaces(std::move(spaces->patches)); !s.ok()) return s;
  if (base::Status s = pipeline.SetElastic(std::move(*elastic)); !s.ok()) return s;
  if (notes != nullptr) {
    for (const std::string& note : spaces->notes) notes->push_back("examples: " + note);
    for (const base::Warning& w : spaces->warnings) notes->push_back(w.ToString());
    for (const ElasticPatchReport& r : pipeline.elastic_report()) {
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
