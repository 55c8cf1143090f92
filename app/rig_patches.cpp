#include "app/rig_patches.h"

#include <optional>
#include <string>

#include "deform/patch/patch_region.h"
#include "render/camera.h"
#include "render/raster/region_select.h"

namespace app {
namespace {

base::Error At(const Rig& rig, const std::string& path, base::Error e) {
  e.loc = {rig.file, 0, 0, path};
  return e;
}

// Bind (model space) position of skeleton joint j: the inverse of its inverse
// bind matrix, found through the skin joints; walks up to the nearest skinned
// ancestor when j itself carries no skin.
std::optional<glm::vec3> BindPosition(const Character& c, int j) {
  while (j >= 0) {
    for (std::size_t s = 0; s < c.mesh.skin_joints.size(); ++s) {
      if (c.mesh.skin_joints[s] == j) {
        return glm::vec3(glm::inverse(c.mesh.joint_from_bind[s])[3]);
      }
    }
    j = c.skeleton.parents[static_cast<std::size_t>(j)];
  }
  return std::nullopt;
}

}  // namespace

base::Result<std::vector<deform::PatchSetup>> BuildRigPatches(const Rig& rig,
                                                              const Character& character) {
  std::vector<deform::PatchSetup> out;
  const deform::SkinnedMesh& mesh = character.mesh;
  for (std::size_t i = 0; i < rig.patches.size(); ++i) {
    const RigPatch& p = rig.patches[i];
    const std::string path = "patches[" + std::to_string(i) + "]";
    deform::PatchOptions options{
        .parametrization = p.cylinder ? deform::RegionParametrization::Kind::kCylinder
                                      : deform::RegionParametrization::Kind::kPlane,
        .samples_u = p.sampling.x,
        .samples_v = p.sampling.y,
        .grid_u = p.grid.x,
        .grid_v = p.grid.y,
        .border_width = p.border_width};
    std::vector<int> region;
    if (p.region.kind != RigRegion::Kind::kJoint && p.cylinder) {
      return base::InvalidArgument(
          {rig.file, 0, 0, path + ".parametrization"},
          "expected \"plane\" for a vertex-list or screen region (a cylinder "
          "needs a joint for its axis), found \"cylinder\"");
    }
    if (p.region.kind == RigRegion::Kind::kScreen) {
      // The named view frames the bind mesh; the character faces +Z, its left is +X.
      const glm::vec3 direction = p.region.view == "front"  ? glm::vec3(0, 0, -1)
                                  : p.region.view == "back" ? glm::vec3(0, 0, 1)
                                  : p.region.view == "left" ? glm::vec3(-1, 0, 0)
                                                            : glm::vec3(1, 0, 0);
      const render::Camera camera = render::FrameBounds(
          deform::ComputeBounds(mesh.bind.positions), 35.0f, 1.0f, direction);
      auto selected = render::SelectScreenRegion(camera, mesh.bind.positions, mesh.bind.normals,
                                                 mesh.bind.triangles, {.rect = p.region.rect});
      if (!selected.ok()) return At(rig, path + ".region", std::move(selected).error());
      region = std::move(*selected);
    } else if (p.region.kind == RigRegion::Kind::kVertices) {
      auto checked = deform::CheckVertexRegion(p.region.vertices, mesh.bind.num_vertices());
      if (!checked.ok()) return At(rig, path + ".region.vertices", std::move(checked).error());
      region = std::move(*checked);
    } else {
      const int j = character.skeleton.FindJoint(p.region.joint);
      if (j < 0) {
        return base::MakeError(
            base::ErrorCode::kNotFound, {rig.file, 0, 0, path + ".region.joint"},
            "expected a joint of " + character.source + ", found \"" + p.region.joint + "\"");
      }
      const int parent = character.skeleton.parents[static_cast<std::size_t>(j)];
      const std::optional<glm::vec3> centre = BindPosition(character, j);
      const std::optional<glm::vec3> base = BindPosition(character, parent);
      if (!centre || !base || glm::length(*centre - *base) <= 0.0f) {
        return base::MakeError(
            base::ErrorCode::kNotFound, {rig.file, 0, 0, path + ".region.joint"},
            "joint \"" + p.region.joint + "\" has no skinned bone from its parent");
      }
      auto selected = deform::SelectJointRegion(
          mesh, {.bone_joints = {parent, j}, .centre = *centre, .radius = p.region.radius,
                 .min_bone_weight = p.region.min_bone_weight, .side = p.region.side,
                 .half_angle_deg = p.region.half_angle_deg});
      if (!selected.ok()) return At(rig, path + ".region", std::move(selected).error());
      region = std::move(*selected);
      options.axis_origin = glm::dvec3(*base);
      options.axis_direction = glm::dvec3(*centre - *base);
    }
    auto setup = deform::BuildPatchSetup(mesh, region, options);
    if (!setup.ok()) return At(rig, path, std::move(setup).error());
    out.push_back(std::move(*setup));
  }
  return out;
}

}  // namespace app
