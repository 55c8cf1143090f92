#include "app/character.h"

#include <string>
#include <utility>

#include "app/frame_render.h"
#include "app/motion_source.h"
#include "deform/body/bind_pose.h"
#include "deform/body/generated_body.h"
#include "mocap/bvh_reader.h"

namespace app {

base::Result<deform::GlobalMethod> ParseGlobalMethod(const std::string& name) {
  if (name == "ssd" || name == "lbs") return deform::GlobalMethod::kSsd;
  if (name == "dqs") return deform::GlobalMethod::kDqs;
  if (name == "swd") return deform::GlobalMethod::kSwd;
  return base::InvalidArgument({"--global", 0, 0, {}},
                               "expected ssd, dqs or swd, found '" + name + "'");
}

base::Result<BodyKind> ParseBodyKind(const std::string& name) {
  if (name == "tubes") return BodyKind::kTubes;
  if (name == "generated") return BodyKind::kGenerated;
  return base::InvalidArgument(
      {"--body", 0, 0, {}}, "expected generated, tubes or a glTF/GLB file, found '" + name + "'");
}

base::Result<Character> MakeCharacter(MotionSource&& source,
                                      const deform::MannequinOptions& mannequin, BodyKind kind) {
  Character c;
  c.source =
      source.gltf ? source.gltf->skeleton.info.source_file : source.skeleton.info.source_file;
  c.skeleton = std::move(source.skeleton);
  c.motion = std::move(source.motion);
  c.warnings = std::move(source.warnings);
  if (c.source.empty()) c.source = "<input>";
  if (source.gltf) {
    c.mesh = std::move(source.gltf->mesh);
    c.textures = BuildCharacterTextures(c.mesh);
    c.closed_surface = deform::IsClosedOutward(c.mesh.bind.positions, c.mesh.bind.triangles);
    return c;
  }
  // A rest pose far lower than the first frame's is not a body pose (limbs
  // folded or lying flat): build and bind the body at frame 0 instead. Without a
  // body in either pose BuildMannequin below reports why.
  base::Result<deform::BindPoseChoice> pose =
      deform::ChooseBindPose(c.skeleton, c.motion, mannequin.min_branch_extent);
  c.bound_at_first_frame = pose.ok() && pose->frame == 0;
  // One welded skin fuses whatever touches in its bind pose: a rest pose much taller
  // than the first frame (LAFAN's arms raised beside the head) would fuse arms and head,
  // so the generated body is bound at frame 0 then.
  if (kind == BodyKind::kGenerated && !c.bound_at_first_frame && c.motion.num_frames > 0) {
    const float rest = mocap::RestHeight(c.skeleton, c.skeleton.info.up_axis);
    const float first = mocap::FirstFrameHeight(c.skeleton, c.motion, c.skeleton.info.up_axis);
    c.bound_at_first_frame = first > 0.0f && rest > 1.15f * first;
  }
  base::Result<std::vector<glm::mat4>> model = deform::BindModelFromJoint(c);
  if (!model.ok()) return std::move(model).error();
  base::Result<deform::SkinnedMesh> body =
      kind == BodyKind::kGenerated
          ? deform::BuildGeneratedBodyCached(c.skeleton, *model, {}, deform::BodyCacheFolder())
          : deform::BuildMannequin(c.skeleton, *model, mannequin);
  if (!body.ok()) {
    base::Error e = std::move(body).error();
    if (e.loc.file.empty()) e.loc.file = c.source;
    return e;
  }
  c.mesh = std::move(*body);
  c.closed_surface = deform::IsClosedOutward(c.mesh.bind.positions, c.mesh.bind.triangles);
  return c;
}

}  // namespace app
